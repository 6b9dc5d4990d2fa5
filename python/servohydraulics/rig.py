"""Rig parameters: the paper's presets and TOML rig files.

A rig file is TOML with one table per subsystem and keys named after the
symbols of Zhao et al. (2003), Table I, in SI units; the specimens
(Bouc-Wen, MR damper) are in ``[specimen]`` and the delays inside the loop in
``[delays]`` (docs/specimens.md).  Unknown keys are an error.  ``PARAMETERS``
(keys, units, sources) and ``EFFECTS`` come from the core's one parameter table
(``_core.RIG_PARAMETERS``, ``_core.EFFECTS``), ``FLOW_CURVE_KINDS`` from its
flow-curve name table; the README's key table is generated from it
(``python -m servohydraulics.rig``).
``Rig`` has ``==``, ``repr``, ``copy.copy`` and pickle from the binding.
"""

from __future__ import annotations

import copy
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import _core
from .atomic import write_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

import tomli_w

Rig = _core.Rig
Error = _core.ServoHydraulicsError


@dataclass(frozen=True)
class Parameter:
    section: str
    key: str
    unit: str
    doc: str
    source: str


#: Every numeric key of a rig file, from the core's one table (parameters.hpp:
#: kRigParameters, which also drives Rig.validate() and the binding).
PARAMETERS: tuple[Parameter, ...] = tuple(
    Parameter(p["section"], p["key"], p["unit"], p["doc"], p["source"]) for p in _core.RIG_PARAMETERS)

#: The switches of [effects], from the core's table (parameters.hpp: kEffects).
EFFECTS: tuple[str, ...] = tuple(e["key"] for e in _core.EFFECTS)

#: The keys whose value is a name, from the core's table (parameters.hpp: ChoiceInfo): key ->
#: (section, {name: the core's enum}); e.g. ``[specimen] mr_input = "current"``.
CHOICES: dict[str, tuple[str, dict[str, Any]]] = {
    c["key"]: (c["section"], dict(c["names"])) for c in _core.RIG_CHOICES}


def choice_name(rig: Rig, key: str) -> str:
    """The name of a choice key's value in ``rig`` (``"current"`` for ``rig.mr_input``)."""
    value = getattr(rig, key)
    return next(name for name, v in CHOICES[key][1].items() if v == value)


FLOW_CURVE_KEYS = ("kind", "b", "opening", "flow")
#: servovalve.flow_curve.kind: name -> FlowCurve.Kind (the core's table, rig.hpp).
FLOW_CURVE_KINDS = dict(_core.FLOW_CURVE_KIND_NAMES)


def _flow_curve_kind_name(kind: _core.FlowCurve.Kind) -> str:
    return next(name for name, value in FLOW_CURVE_KINDS.items() if value == kind)


def zhao2003(variant: str = "calibrated", actuator_attached: bool = True) -> Rig:
    """The rig of Zhao et al. (2003), Table I.

    Args:
        variant: ``"calibrated"`` (default: K_a and C_l recalibrated so that the
            model reproduces the paper's reported behaviour, docs/calibration.md)
            or ``"printed"`` (Table I as printed; its displacement loop is unstable).
        actuator_attached: dissipation identified with the actuator attached
            (c = 2.1 kN s/m, F_c = 31.6 N) or of the free structure (1.1 kN s/m, 95.7 N).
    """
    variants = {"calibrated": _core.Zhao2003Variant.Calibrated, "printed": _core.Zhao2003Variant.Printed}
    if variant not in variants:
        raise ValueError(f"invalid variant = {variant!r}: expected one of {sorted(variants)}")
    return _core.zhao2003(variants[variant], bool(actuator_attached))


def rig_to_dict(rig: Rig) -> dict[str, dict[str, Any]]:
    """The rig as nested dicts, in the layout of a rig file."""
    out: dict[str, dict[str, Any]] = {}
    for p in PARAMETERS:
        out.setdefault(p.section, {})[p.key] = float(getattr(rig, p.key))
    fc = rig.flow_curve
    curve: dict[str, Any] = {"kind": _flow_curve_kind_name(fc.kind)}
    if fc.kind == _core.FlowCurve.Kind.Rational:
        curve["b"] = float(fc.b)
    else:
        curve["opening"] = [float(v) for v in fc.opening]
        curve["flow"] = [float(v) for v in fc.flow]
    out["servovalve"]["flow_curve"] = curve
    for key, (section, _) in CHOICES.items():
        out[section][key] = choice_name(rig, key)
    out["effects"] = {name: bool(getattr(rig.effects, name)) for name in EFFECTS}
    return out


def _number(where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"invalid {where} = {value!r}: expected a number")
    try:
        v = float(value)
    except OverflowError:  # an integer beyond the double range
        raise ValueError(f"invalid {where} = an integer of {value.bit_length()} bits: too large for a number "
                         "(> 1.8e308)") from None
    if not math.isfinite(v):
        raise ValueError(f"invalid {where} = {value!r}: must be finite")
    return v


def rig_from_dict(data: dict[str, Any], base: Rig | None = None) -> Rig:
    """Builds a rig from nested dicts (a parsed rig file) over ``base``
    (default: the calibrated preset).  Unknown sections or keys are an error;
    the result is validated (ValueError naming the field and value)."""
    rig = copy.copy(base) if base is not None else zhao2003()
    _apply(rig, data)
    rig.validate()
    return rig


def _apply(rig: Rig, data: dict[str, Any]) -> None:
    known: dict[str, set[str]] = {}
    for p in PARAMETERS:
        known.setdefault(p.section, set()).add(p.key)
    sections = set(known) | {"effects"}
    for section, table in data.items():
        if section not in sections:
            raise ValueError(f"unknown rig section [{section}]: expected one of {sorted(sections)}")
        if not isinstance(table, dict):
            raise ValueError(f"invalid [{section}] = {table!r}: expected a table")
        for key, value in table.items():
            where = f"{section}.{key}"
            if section == "effects":
                if key not in EFFECTS:
                    raise ValueError(f"unknown rig key {where}: expected one of {list(EFFECTS)}")
                if not isinstance(value, bool):
                    raise ValueError(f"invalid {where} = {value!r}: expected true or false")
                setattr(rig.effects, key, value)
            elif section == "servovalve" and key == "flow_curve":
                rig.flow_curve = _flow_curve_from_dict(value)
            elif key in CHOICES and CHOICES[key][0] == section:
                names = CHOICES[key][1]
                if not isinstance(value, str) or value not in names:
                    raise ValueError(f"invalid {where} = {value!r}: expected one of {list(names)}")
                setattr(rig, key, names[value])
            elif key in known[section]:
                setattr(rig, key, _number(where, value))
            else:
                choices = [k for k, (sec, _) in CHOICES.items() if sec == section]
                raise ValueError(f"unknown rig key {where}: expected one of {sorted(known[section]) + choices}")


def _flow_curve_from_dict(table: Any) -> _core.FlowCurve:
    if not isinstance(table, dict):
        raise ValueError(f"invalid servovalve.flow_curve = {table!r}: expected a table")
    for key in table:
        if key not in FLOW_CURVE_KEYS:
            raise ValueError(f"unknown rig key servovalve.flow_curve.{key}: expected one of {list(FLOW_CURVE_KEYS)}")
    fc = _core.FlowCurve()
    kind = table.get("kind", _flow_curve_kind_name(fc.kind))
    if not isinstance(kind, str) or kind not in FLOW_CURVE_KINDS:
        raise ValueError(f"invalid servovalve.flow_curve.kind = {kind!r}: expected one of {list(FLOW_CURVE_KINDS)}")
    fc.kind = FLOW_CURVE_KINDS[kind]
    if fc.kind == _core.FlowCurve.Kind.Rational:
        fc.b = _number("servovalve.flow_curve.b", table.get("b", fc.b))
    else:
        for key in ("opening", "flow"):
            if key not in table or not isinstance(table[key], list):
                raise ValueError(f"invalid servovalve.flow_curve.{key}: a table curve needs a list of numbers")
        fc.opening = [_number(f"servovalve.flow_curve.opening[{i}]", v) for i, v in enumerate(table["opening"])]
        fc.flow = [_number(f"servovalve.flow_curve.flow[{i}]", v) for i, v in enumerate(table["flow"])]
    fc.validate()
    return fc


def copy_rig(rig: Rig) -> Rig:
    """An independent copy of a rig (``copy.copy(rig)``: every field is a value)."""
    return copy.copy(rig)


def load_rig(path: str | Path) -> Rig:
    """Reads a TOML rig file over the calibrated preset (keys not given keep
    the preset's values)."""
    path = Path(path)
    try:  # utf-8-sig: an editor's byte-order mark is not TOML
        data = tomllib.loads(path.read_bytes().decode("utf-8-sig"))
    except FileNotFoundError:
        raise FileNotFoundError(f"rig file not found: {path}") from None
    except UnicodeDecodeError as e:
        raise ValueError(f"rig file {path} is not UTF-8 text ({e.reason} at byte {e.start})") from None
    except (tomllib.TOMLDecodeError, ValueError) as e:  # ValueError: e.g. an integer of > 4300 digits
        raise ValueError(f"rig file {path} is not valid TOML: {e}") from None
    except IsADirectoryError:
        raise ValueError(f"rig file {path} is a directory") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or tables
        raise ValueError(f"rig file {path} is not valid TOML here: arrays or tables nested too deeply "
                         f"(beyond Python's recursion limit of {sys.getrecursionlimit()})") from None
    try:
        return rig_from_dict(data)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


def save_rig(rig: Rig, path: str | Path) -> Path:
    """Writes every parameter of the rig to a TOML file (SI units), whole or not at all."""
    rig.validate()
    path = Path(path)
    header = "# servohydraulics rig file: SI units, keys after Zhao et al. (2003) Table I\n"
    return write_text(path, header + tomli_w.dumps(rig_to_dict(rig)))


def parameter_table() -> str:
    """Markdown table of every rig-file key (for the README)."""
    default = zhao2003()
    lines = ["| key | unit | default | meaning | source |", "|---|---|---|---|---|"]
    for p in PARAMETERS:
        lines.append(f"| `{p.section}.{p.key}` | {p.unit} | {getattr(default, p.key):.6g} | {p.doc} | {p.source} |")
    fc = default.flow_curve
    pts = ", ".join(f"({o:g}, {q:g})" for o, q in zip(fc.opening, fc.flow))
    lines.append("| `servovalve.flow_curve.kind` | - | table | `table` (lists `opening`, `flow`: normalised "
                 "Q/K_v, mirrored for x < 0) or `rational` (g = x/(1 + b abs(x)), key `b`) | Fig 4a |")
    lines.append(f"| `servovalve.flow_curve.opening`, `.flow` | - | {pts} | linear below 10 %, rated flow "
                 "at full opening | p. 1780, MTS 256.09 rating; docs/calibration.md |")
    for c in _core.RIG_CHOICES:
        lines.append(f"| `{c['section']}.{c['key']}` | name | {c['default']} | {c['doc']} | {c['source']} |")
    for name in EFFECTS:
        lines.append(f"| `effects.{name}` | bool | {str(getattr(default.effects, name)).lower()} | "
                     "switch the effect on/off | |")
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    print(parameter_table())
