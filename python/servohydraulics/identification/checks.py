"""Plausibility checks of a record against the rig, run by ``compare``, ``identify`` and
``diagnose`` before their work (docs/lab-records.md, "Checks").

Each finding is a :class:`Check`: a code, a level, the file, the channel, a message
and the numbers behind it; the commands print it and write it to their JSON
(``"checks"``).  Two levels:

* **error** (the command stops, exit 2): the record cannot be what the user meant.
  No lab record looks like it, so a result would be a number about nothing (a record
  in millimetres read as metres compares at a 278 % NRMSE and says nothing else).
  Each message says how to fix it: ``--units``, ``--dt``, the rig file.  The
  thresholds sit far from any real test: a factor 2 beyond the rig's stroke or
  capacity (the smallest unit slip, centimetres for inches, is 2.54), the
  command and the response a factor 10 apart in size, a time step beyond 0.1 s or
  below 1 us, a controller slower than 100 Hz, a half-stroke beyond 1.5 m or a
  velocity beyond 30 m/s (no servo-hydraulic rig has them).
* **warning** (the command runs, exit 0): the record is possible, but the result needs
  care: the run went beyond the stroke or capacity by less than a factor 2 (the
  actuator hit a stop, or the rig file's limit is low), the measured record sits flat
  at an extreme while the command goes on (an end stop, a saturated spool or drive, a
  clipped sensor), the controller samples coarsely for the loop, and the simulated
  run's own limits and solver notes (``Response.notes``).  A user who has read one
  acknowledges it (``accept=`` / ``--accept CODE``): it stays in the JSON with
  ``"acknowledged": true`` and leaves the screen.  Errors cannot be acknowledged.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..response import Response
from ..rig import Rig
from .stats import noise_sigma

ERROR, WARNING = "error", "warning"

#: code -> (level, what it means)
CODES: dict[str, tuple[str, str]] = {
    "time_step": (ERROR, "the record's sample time is outside 1 us .. 0.1 s (a time column in ms read as s?)"),
    "controller_step": (ERROR, "the controller sample is slower than 100 Hz (give --dt)"),
    "command_unit": (ERROR, "the command's unit is a force in displacement control, or a length in force control"),
    "channel_units": (ERROR, "the response and the command differ in size by more than a factor 10 (units?)"),
    "displacement_outside_stroke": (ERROR, "the measured displacement goes beyond twice the rig's half-stroke"),
    "force_outside_capacity": (ERROR, "the measured force (or the force command) goes beyond twice the capacity"),
    "displacement_implausible": (ERROR, "a displacement beyond 1.5 m: no servo-hydraulic rig has that stroke"),
    "velocity_implausible": (ERROR, "a velocity beyond 30 m/s: no servo-hydraulic rig moves that fast"),
    "controller_step_coarse": (WARNING, "the controller sample is coarse for the loop (hold lag > 5 deg at the "
                                        "loop's corner, or fewer than 10 samples per valve period)"),
    "command_beyond_stroke": (WARNING, "the command goes beyond the rig's half-stroke (a warning at any factor: the "
                                       "loop need not follow a command's fast content; its measured displacement "
                                       "is checked for errors)"),
    "displacement_beyond_stroke": (WARNING, "the measured displacement goes beyond the rig's half-stroke"),
    "force_beyond_capacity": (WARNING, "the measured force (or the force command) goes beyond the capacity"),
    "flat_at_limit": (WARNING, "a measured channel sits flat at its extreme while the command goes on (an end "
                               "stop, a saturated spool or drive, the capacity, a clipped sensor)"),
    "scale_mismatch": (WARNING, "a measured channel and its simulation differ in size by more than a factor 10 "
                                "(a unit slip the record's own channels cannot show, e.g. kN read as N; or a rig "
                                "far from the lab's)"),
    "run_stroke": (WARNING, "the simulated run went beyond the stroke"),
    "run_capacity": (WARNING, "the simulated run exceeded the capacity"),
    "run_supply": (WARNING, "the simulated run reached the supply pressure"),
    "run_spool": (WARNING, "the simulated run saturated the spool"),
    "run_drive": (WARNING, "the simulated run saturated the valve drive"),
    "run_mr_law": (WARNING, "the MR damper ran outside the field range its law was identified on"),
    "run_accuracy": (WARNING, "the simulated run probably misses its integrator's stated accuracy (its check, a "
                              "second run at a tighter tolerance or at twice the RK4 substeps, departs from it)"),
    "run_solver": (WARNING, "the integrator's notes on the simulated run"),
    "run_failed": (WARNING, "the simulated run failed"),
}

#: the thresholds (see the module docstring)
TIME_STEP_RANGE = (1e-6, 0.1)  #: plausible record sample times [s]
CONTROLLER_STEP_MAX = 0.01  #: slowest plausible controller sample [s]
SIZE_RATIO = 10.0  #: response / command size beyond this factor (or below its inverse): different units
LIMIT_FACTOR = 2.0  #: beyond this factor of the stroke or the capacity: a unit slip, not a test
MAX_HALF_STROKE = 1.5  #: [m] largest plausible half-stroke
MAX_VELOCITY = 30.0  #: [m/s] largest plausible velocity
HOLD_LAG_MAX_DEG, VALVE_SAMPLES_MIN = 5.0, 10.0  #: the coarse-controller warning
FLAT_MIN_S, FLAT_MIN_SAMPLES, FLAT_BEYOND = 0.02, 10, 0.1  #: a plateau's length and the command's overshoot


@dataclass(frozen=True)
class Check:
    """One finding (see the module docstring); ``values`` holds the numbers in SI units."""

    code: str
    file: str
    channel: str | None
    message: str
    values: dict = field(default_factory=dict)
    acknowledged: bool = False

    @property
    def level(self) -> str:
        return CODES[self.code][0]

    def line(self) -> str:
        """One line for the screen: ``FILE: [code] message``."""
        return f"{self.file}: [{self.code}] {self.message}"

    def to_dict(self) -> dict[str, Any]:
        return {"code": self.code, "level": self.level, "file": self.file, "channel": self.channel,
                "message": self.message, "values": self.values, "acknowledged": self.acknowledged}


#: the order errors are told in (the one the message shows in full first): the clock, the units, the rig's limits
ERROR_ORDER = ("time_step", "controller_step", "command_unit", "channel_units", "displacement_outside_stroke",
               "force_outside_capacity", "displacement_implausible", "velocity_implausible")


class CheckError(ValueError):
    """Error-level checks: the record cannot be what the user meant (exit 2 from the CLI)."""

    def __init__(self, checks: Sequence[Check]):
        checks = sorted(checks, key=lambda c: ERROR_ORDER.index(c.code) if c.code in ERROR_ORDER else len(ERROR_ORDER))
        self.checks = list(checks)
        more = (f" (and {len(checks) - 1} more: " + ", ".join(f"[{c.code}] {c.channel}" for c in checks[1:]) + ")"
                if len(checks) > 1 else "")
        super().__init__(checks[0].line() + more)


def check_accept(accept: Iterable[str] | str | None) -> frozenset[str]:
    """The codes a user acknowledges; ValueError naming an unknown or error-level code."""
    if accept is None:
        return frozenset()
    if isinstance(accept, str):
        accept = [a for a in accept.split(",")]
    out = set()
    for a in accept:
        a = str(a).strip()
        if not a:
            continue
        if a not in CODES:
            raise ValueError(f"invalid accept = {a!r}: not a check; warnings: "
                             f"{', '.join(c for c, (lv, _) in CODES.items() if lv == WARNING)}")
        if CODES[a][0] == ERROR:
            raise ValueError(f"invalid accept = {a!r}: an error-level check cannot be acknowledged (fix the record's "
                             "units, --dt or the rig file)")
        out.add(a)
    return frozenset(out)


def settle(checks: Iterable[Check], accept: Iterable[str] | str | None = None) -> list[Check]:
    """The checks with the accepted warnings marked acknowledged; raises :class:`CheckError`
    when any is an error."""
    ok = check_accept(accept)
    checks = list(checks)
    errors = [c for c in checks if c.level == ERROR]
    if errors:
        raise CheckError(errors)
    return [Check(c.code, c.file, c.channel, c.message, c.values, c.code in ok) for c in checks]


def _where(record: Response) -> str:
    return str(record.path) if record.path is not None else "record"


def _peak(v: np.ndarray) -> float:
    return float(np.max(np.abs(v))) if v.size else 0.0


def _velocity(x: np.ndarray, dt: float) -> np.ndarray:
    """|dx/dt| of the displacement averaged over 5 ms (sensor noise does not pass for speed)."""
    k = max(1, int(round(0.005 / dt)))
    if x.size <= k:
        return np.zeros(0)
    c = np.cumsum(np.r_[0.0, x])
    smooth = (c[k:] - c[:-k]) / k
    return np.abs(np.diff(smooth)) / dt


def _runs(mask: np.ndarray) -> tuple[int, int]:
    """(start, stop) of the longest run of True (0, 0 if none)."""
    if not mask.any():
        return 0, 0
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    i = int(np.argmax(stops - starts))
    return int(starts[i]), int(stops[i])


def _noise(y: np.ndarray) -> float:
    return noise_sigma(y) if y.size > 3 else 0.0


def _limits(rec: Response, rig: Rig | None, mode: str, where: str) -> list[Check]:
    """Stroke and capacity, relative to the rig (a factor 2: error; beyond: warning) and absolute."""
    out = []
    u, x, f = (np.asarray(rec.channels[c], dtype=float) for c in ("command", "displacement", "force"))
    disp_cmd = mode == "displacement"
    items = [("displacement", x, "displacement", "stroke")]
    if disp_cmd:
        items.insert(0, ("command", u, "command", "stroke"))
    items.append(("force", f, "force", "capacity"))
    if mode == "force":
        items.append(("command", u, "force", "capacity"))
    for ch, v, kind, limit in items:
        peak = _peak(v)
        unit, scale = ("m", 1.0) if kind != "force" else ("kN", 1e-3)
        ratio = 0.0
        if rig is not None:
            lim = float(rig.stroke if limit == "stroke" else rig.F_cap)
            ratio = peak / lim
            vals = {"peak": peak, "limit": lim, "ratio": ratio}
            name = ("command" if ch == "command" else "displacement") if kind != "force" else "force"
            if ratio > LIMIT_FACTOR and ch != "command":
                both = "command=mm,displacement=mm" if disp_cmd else f"{ch}=mm"
                hint = f"--units {both}, or in, cm" if kind != "force" else f"--units {ch}=..., or --scale {ch}=FACTOR"
                out.append(Check(f"{name}_outside_{limit}", where, ch, (
                    f"invalid {ch} = {scale * peak:.4g} {unit} (max |{ch}|): {ratio:.3g} times the rig's {limit} "
                    f"{scale * lim:.4g} {unit}: no test on this rig reaches that; a unit slip ({hint}) or the wrong "
                    f"rig (its [actuator] {'stroke' if limit == 'stroke' else 'F_cap'})?"), vals))
                continue
            if ratio > 1.0:
                out.append(Check(f"{name}_beyond_{limit}", where, ch, (
                    f"max |{ch}| = {scale * peak:.4g} {unit} is beyond the rig's {limit} {scale * lim:.4g} {unit} "
                    f"({ratio:.3g} times): the actuator would hit a stop, or the rig file's {limit} is low"), vals))
        if kind != "force" and peak > MAX_HALF_STROKE:
            out.append(Check("displacement_implausible", where, ch, (
                f"invalid {ch} = {peak:.4g} m (max |{ch}|): no servo-hydraulic rig has a half-stroke beyond "
                f"{MAX_HALF_STROKE:g} m; a record in millimetres read as metres? --units {ch}=mm"),
                {"peak": peak, "limit": MAX_HALF_STROKE}))
    return out


def _flat(rec: Response, rig: Rig | None, mode: str, where: str, dt: float) -> list[Check]:
    """Measured channels flat at an extreme while the command goes on (see ``CODES``)."""
    out = []
    u = np.asarray(rec.channels["command"], dtype=float)
    n_min = max(FLAT_MIN_SAMPLES, int(round(FLAT_MIN_S / dt)))
    for ch in ("displacement", "force"):
        y = np.asarray(rec.channels[ch], dtype=float)
        span = float(np.ptp(y)) if y.size else 0.0
        if span == 0.0:
            continue
        driven = (mode == "displacement" and ch == "displacement") or (mode == "force" and ch == "force")
        tol = max(3.0 * _noise(y), 1e-3 * span)
        for side in (1.0, -1.0):
            ext = float(np.max(side * y))
            a, b = _runs(side * y >= ext - tol)
            if b - a < n_min:
                continue
            seg_u = side * u[a:b]
            if driven:  # the command (same unit) went on beyond the plateau
                beyond = float(np.max(seg_u)) - ext
                if beyond <= FLAT_BEYOND * span:
                    continue
                why = (f"while the command went {beyond / span:.0%} of the range beyond it (to "
                       f"{side * float(np.max(seg_u)):.4g}): the actuator stopped there (its stroke, a saturated "
                       "spool or drive)")
            else:
                moved = float(np.ptp(u[a:b])) / max(float(np.ptp(u)), 1e-300)
                at_cap = rig is not None and ch == "force" and ext >= 0.95 * rig.F_cap
                clipped = float(np.ptp(y[a:b])) == 0.0
                if moved <= FLAT_BEYOND or not (at_cap or clipped):
                    continue
                why = ("at the rig's capacity" if at_cap else "at one exact value (a sensor or acquisition range?)") \
                    + f" while the command moved {moved:.0%} of its range"
            unit, scale = ("mm", 1e3) if ch == "displacement" else ("kN", 1e-3)
            out.append(Check("flat_at_limit", where, ch, (
                f"{ch} sits flat at {scale * side * ext:.4g} {unit} for {(b - a) * dt:.3g} s from t = "
                f"{float(rec.time[a] - rec.time[0]):.3f} s {why}"),
                {"level": side * ext, "start_s": float(rec.time[a] - rec.time[0]), "duration_s": (b - a) * dt}))
    return out


def record_checks(record: Response, rig: Rig | None = None, mode: str = "displacement",
                  dt: float | None = None) -> list[Check]:
    """Every check of a record (see ``CODES``) against ``rig`` (None: the rig-free ones only,
    e.g. ``identify`` from a generic start scaled from the record itself) in ``mode``, with
    the controller sample ``dt`` [s] (None: the record's)."""
    where = _where(record)
    out: list[Check] = []
    rdt = float(record.dt)
    lo, hi = TIME_STEP_RANGE
    if not lo <= rdt <= hi:
        out.append(Check("time_step", where, "time", (
            f"invalid time step = {rdt:.6g} s: a servo-hydraulic test is sampled between {1 / hi:g} Hz and "
            f"{1 / lo:.0f} Hz; a time column in milliseconds read as seconds? --units time=ms"),
            {"dt": rdt, "range": [lo, hi]}))
        return out  # nothing else means anything on a wrong clock
    cdt = rdt if dt is None else float(dt)
    if cdt > CONTROLLER_STEP_MAX:
        out.append(Check("controller_step", where, "time", (
            f"invalid controller sample = {cdt:.6g} s ({'--dt' if dt is not None else 'the record' + chr(39) + 's'}):"
            f" no servo-hydraulic controller runs slower than {1 / CONTROLLER_STEP_MAX:.0f} Hz; give the "
            "controller's sample time with --dt (the command is interpolated onto it)"), {"dt": cdt}))
    out += _units(record, mode, where)
    if mode in ("displacement", "force"):
        out += _limits(record, rig, mode, where)
    v = _velocity(np.asarray(record.displacement, dtype=float), rdt)
    vmax = float(v.max()) if v.size else 0.0
    if vmax > MAX_VELOCITY:
        out.append(Check("velocity_implausible", where, "displacement", (
            f"invalid velocity = {vmax:.4g} m/s (the displacement's peak rate): no servo-hydraulic rig moves faster "
            f"than {MAX_VELOCITY:g} m/s; displacement in millimetres read as metres (--units displacement=mm) or "
            "time in milliseconds read as seconds the other way?"), {"peak": vmax}))
    if any(c.level == ERROR for c in out):
        return out
    if rig is not None:
        out += _coarse(rig, mode, cdt, where)
    if mode in ("displacement", "force"):
        out += _flat(record, rig, mode, where, rdt)
    return out


def _units(record: Response, mode: str, where: str) -> list[Check]:
    """The command's declared unit against the mode, and the response's size against the command's."""
    out = []
    declared = (record.metadata.get("units") or {}).get("command")
    if declared is not None and mode in ("displacement", "force"):
        from ..readers.units import UNITS

        dim = "m" if declared in UNITS["m"] else ("N" if declared in UNITS["N"] else None)
        want = "m" if mode == "displacement" else "N"
        if dim is not None and dim != want:
            out.append(Check("command_unit", where, "command", (
                f"invalid command unit = {declared!r}: a {'force' if dim == 'N' else 'length'} in {mode} control "
                f"(the command is in {want}): the wrong --mode, or the wrong column as command?"),
                {"unit": declared, "mode": mode}))
    if mode in ("displacement", "force"):
        ch = "displacement" if mode == "displacement" else "force"
        su = float(np.std(record.command))
        sy = float(np.std(record.channels[ch]))
        if su > 0 and sy > 0:
            r = sy / su
            if not 1.0 / SIZE_RATIO <= r <= SIZE_RATIO:
                out.append(Check("channel_units", where, ch, (
                    f"invalid {ch} / command size = {r:.4g} (std {sy:.4g} against {su:.4g}): in {mode} control the "
                    f"{ch} follows the command, so the two are in different units (--units {ch}=... or "
                    "command=...)"), {"ratio": r, "std_response": sy, "std_command": su}))
    return out


def _coarse(rig: Rig, mode: str, cdt: float, where: str) -> list[Check]:
    """The controller sample against the loop: the hold's lag at the loop's corner (displacement
    control: G_p C_F K_s K_v / A) and the samples per valve period."""
    lag = math.degrees(0.5 * cdt * rig.G_p * rig.C_F_disp * rig.K_s * rig.K_v / rig.A) if mode == "displacement" \
        else 0.0
    per = 1.0 / (rig.f_v * cdt) if rig.f_v > 0 else math.inf
    if lag > HOLD_LAG_MAX_DEG or per < VALVE_SAMPLES_MIN:
        return [Check("controller_step_coarse", where, "time", (
            f"controller sample {cdt:.6g} s is coarse for this rig: the hold lags {lag:.3g} deg at the loop's corner "
            f"and the valve's period ({rig.f_v:.4g} Hz) has {per:.3g} samples; if the controller runs faster than "
            "the record, give its sample time with --dt"), {"dt": cdt, "hold_lag_deg": lag, "valve_samples": per})]
    return []


def run_checks(sim: Response, rig: Rig | None, where: str) -> list[Check]:
    """The simulated run's warnings (``Response.notes``: limits, solver notes, failure) as checks."""
    return [Check(code, where, None, f"simulated run: {text}") for code, text in sim.notes(rig)]


def scale_checks(measured: dict, simulated: dict, where: str) -> list[Check]:
    """Per channel: the measured and simulated std more than ``SIZE_RATIO`` apart."""
    out = []
    for ch in measured:
        sm, ss = float(np.std(measured[ch])), float(np.std(simulated[ch]))
        if sm > 0 and ss > 0 and not 1.0 / SIZE_RATIO <= sm / ss <= SIZE_RATIO:
            out.append(Check("scale_mismatch", where, ch, (
                f"measured {ch} is {sm / ss:.3g} times the simulated one (std {sm:.4g} against {ss:.4g}): a unit "
                f"slip (--units {ch}=...) or a rig far from the lab's"), {"ratio": sm / ss, "std_measured": sm,
                                                                          "std_simulated": ss}))
    return out


def gate(records: Sequence[Response], rig: Rig | None, mode: str, dt: float | None = None,
         accept: Iterable[str] | str | None = None) -> list[Check]:
    """:func:`record_checks` of every record, settled (:func:`settle`: errors raise
    :class:`CheckError`, accepted warnings are acknowledged)."""
    ok = check_accept(accept)
    return settle([c for r in records for c in record_checks(r, rig, mode, dt)], ok)


def shown(checks: Iterable[Check]) -> list[Check]:
    """The checks a command prints: those not acknowledged."""
    return [c for c in checks if not c.acknowledged]


__all__ = ["CODES", "Check", "CheckError", "ERROR", "WARNING", "check_accept", "gate", "record_checks",
           "run_checks", "scale_checks", "settle", "shown"]
