"""Units of record channels: the factor that takes a file's value to SI.

A channel's SI unit comes from the project's channel table
(``response.channel_units("record")``: ``m``, ``N``, ``s``, ``m/s``, ...); a
unit given for it (``--units displacement=mm``, a header ``force_kN`` or
``Force [kN]``) must be of the same dimension.  The command is in m
(displacement control) or N (force control): it takes a length or a force
unit, and the unit says which.  ``time`` also takes ``samples``: a column of
sample numbers, times the sample interval.

Units are case-sensitive (``mm`` is not ``Mm``, ``MN`` is not ``mN``); the
few aliases below are spellings labs use.
"""

from __future__ import annotations

import math

#: unit -> factor to SI, per dimension (named by its SI unit)
UNITS: dict[str, dict[str, float]] = {
    "m": {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "µm": 1e-6, "in": 0.0254, "ft": 0.3048},
    "N": {"N": 1.0, "kN": 1e3, "MN": 1e6, "lbf": 4.4482216152605, "kip": 4448.2216152605, "kgf": 9.80665,
          "tf": 9806.65},
    "s": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "min": 60.0},
    "m/s": {"m/s": 1.0, "mm/s": 1e-3, "cm/s": 1e-2, "in/s": 0.0254},
    "m/s^2": {"m/s^2": 1.0, "mm/s^2": 1e-3, "cm/s^2": 1e-2, "g": 9.80665, "gal": 1e-2},
    "Pa": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "bar": 1e5, "psi": 6894.757293168361},
    "V": {"V": 1.0, "mV": 1e-3},
    "m^3/s": {"m^3/s": 1.0, "l/s": 1e-3, "l/min": 1e-3 / 60.0},
    "-": {"-": 1.0, "%": 1e-2},
}
#: other spellings of the units above
ALIASES = {"sec": "s", "msec": "ms", "micron": "um", "KN": "kN", "kips": "kip", "lb": "lbf", "m/s2": "m/s^2",
           "mm/s2": "mm/s^2", "inch": "in", "inches": "in", "1": "-"}
#: the unit of a column of sample numbers (time only): the sample interval is needed
SAMPLES = "samples"


def dimension_of(si_unit: str) -> tuple[str, ...]:
    """The dimensions a channel of SI unit ``si_unit`` may be given in (the command: two)."""
    if si_unit == "m or N":
        return ("m", "N")
    return (si_unit,) if si_unit in UNITS else ()


def known_units(si_unit: str) -> list[str]:
    """Every unit a channel of this SI unit accepts."""
    out = [u for d in dimension_of(si_unit) for u in UNITS[d]]
    if si_unit == "s":
        out.append(SAMPLES)
    return out or [si_unit]


def unit_factor(channel: str, si_unit: str, unit: str, where: str) -> tuple[float, str]:
    """(factor to SI, the dimension's SI unit) of ``unit`` for ``channel``; ValueError naming
    ``where``, the channel and the unit when the unit is unknown or of another dimension.
    ``samples`` (time) returns (nan, "samples"): the caller multiplies by the sample interval."""
    u = ALIASES.get(unit.strip(), unit.strip())
    if si_unit == "s" and u == SAMPLES:
        return math.nan, SAMPLES
    for d in dimension_of(si_unit):
        if u in UNITS[d]:
            return UNITS[d][u], d
    if u == si_unit:
        return 1.0, si_unit
    other = [d for d, table in UNITS.items() if u in table]
    why = (f"a {other[0]} unit, but {channel} is in {si_unit}" if other else "not a unit this reader knows")
    raise ValueError(f"{where}: invalid unit of {channel!r} = {unit!r}: {why}; known: "
                     f"{', '.join(known_units(si_unit))}")


def header_unit(text: str) -> tuple[str, str | None]:
    """(name, unit or None) of a header that carries its unit: ``force_kN``, ``Force [kN]``,
    ``force (kN)``, ``force/kN``; the unit is not checked here."""
    t = text.strip()
    for open_, close in (("[", "]"), ("(", ")"), ("{", "}")):
        if t.endswith(close) and open_ in t:
            i = t.rindex(open_)
            return t[:i].strip(), t[i + 1:-1].strip()
    return t, None


def parse_assignments(values, flag: str) -> dict[str, str]:
    """``NAME=VALUE[,NAME=VALUE...]`` (a string, or a list of them from repeated flags) as a dict;
    ValueError naming ``flag`` and the text for a malformed item or a name given twice."""
    if values is None:
        return {}
    if isinstance(values, str):
        values = [values]
    out: dict[str, str] = {}
    for text in values:
        for item in str(text).split(","):
            if not item.strip():
                continue
            name, eq, value = item.partition("=")
            if not eq or not name.strip() or not value.strip():
                raise ValueError(f"invalid {flag} = {text!r}: expected NAME=VALUE[,NAME=VALUE...], got "
                                 f"{item.strip()!r}")
            name = name.strip()
            if name in out:
                raise ValueError(f"invalid {flag} = {text!r}: {name!r} is given twice")
            out[name] = value.strip()
    return out


def parse_scales(values, flag: str = "--scale") -> dict[str, float]:
    """``NAME=FACTOR,...`` as floats (finite, non-zero); ValueError naming the flag, the channel and the value."""
    out = {}
    for name, text in (values.items() if isinstance(values, dict) else parse_assignments(values, flag).items()):
        try:
            if isinstance(text, bool):
                raise TypeError
            v = float(text)
        except (TypeError, ValueError):
            raise ValueError(f"invalid {flag} {name} = {text!r}: not a number") from None
        if not math.isfinite(v) or v == 0.0:
            raise ValueError(f"invalid {flag} {name} = {text!r}: must be finite and non-zero")
        out[name] = v
    return out


__all__ = ["ALIASES", "SAMPLES", "UNITS", "dimension_of", "header_unit", "known_units", "parse_assignments",
           "parse_scales", "unit_factor"]
