"""One time-response type for every run and record, and one error.

:class:`Response` is shaped like python-control's ``TimeResponseData`` and
scipy's ``OdeResult``: ``time``, named ``channels`` with ``units``, the
provenance of the data (``kind``, ``mode``, ``dt``, ``rig``) and the outcome
(``success``, ``status``, ``message``, ``work``).  ``simulate``, ``run_eft``,
``run_rpsd``, ``run_tracking`` and ``read_record`` all return it;
``to_csv`` writes every channel and ``read_record`` reads it back.

Row k holds the sensors at ``time[k]``, before command k is applied (the
row convention of record.hpp and loops.hpp).

Channel names and units come from the C++ core's channel tables (one place:
:func:`channel_units`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .atomic import atomic_path
from .timegrid import uniform_dt

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from .rig import Rig

KINDS = ("plant", "eft", "rpsd", "tracking", "record", "rths", "marths", "multi")

#: Columns a record file must have (the diagnosis needs them).
REQUIRED = ("time", "command", "displacement", "force")

#: Per-row bookkeeping of a run (integer counts, not measurements).
_COUNTS = {"flags": "-", "internal_steps": "-", "rhs_evals": "-"}
_INTEGER = frozenset(_COUNTS)

#: Old CSV column names still read (with a DeprecationWarning) for one release.
DEPRECATED_COLUMNS = {"ground_accel": "ground_acceleration"}


def _core_tables() -> tuple[tuple[tuple[str, str], ...], ...]:
    """(plant, EFT, RPsD) channel tables as ((name, unit), ...) from the C++ core."""
    return tuple(tuple(map(tuple, t)) for t in (_core.PLANT_CHANNELS, _core.EFT_CHANNELS, _core.RPSD_CHANNELS))


def _command_unit(mode: str | None) -> str:
    return {"displacement": "m", "force": "N", "free": "N"}.get(mode or "", "m or N")


def channel_units(kind: str = "record", mode: str | None = None) -> dict[str, str]:
    """Every channel a response of ``kind`` can carry, in file order, name -> SI unit.

    ``"plant"``/``"tracking"``: the plant's channels, the held command (unit
    from ``mode``) and the per-row counts.  ``"eft"``/``"rpsd"``: the plant's
    channels, the flags and the method's channels.  ``"record"``: the union of
    all of them (what a record file may hold).  ``"rths"``: the RTHS loop's
    channels (``_core.rths.RTHS_CHANNELS``) and its optional ``step_seconds``
    (the per-DOF channels of a trial carry their units with them: ``rths.Trial``); ``"marths"``:
    the maRTHS loop's (``_core.marths.MARTHS_CHANNELS``) and ``step_seconds``.
    ``"multi"``: the coupled multi-actuator rig's node channels (``node.<name>``) and the counts (the
    actuators' ``actuator<i>.<name>`` carry their units with the response: ``multi_rig.MultiResponse``).
    """
    if kind not in KINDS:
        raise ValueError(f"invalid kind = {kind!r}: expected one of {list(KINDS)}")
    if kind == "rths":
        return {**dict(map(tuple, _core.rths.RTHS_CHANNELS)), "step_seconds": "s"}
    if kind == "marths":
        return {**dict(map(tuple, _core.marths.MARTHS_CHANNELS)), "step_seconds": "s"}
    if kind == "multi":  # the node's; the actuators' (actuator<i>.<name>) come with the response (multi_rig.py)
        return {"time": "s", **{f"node.{n}": u for n, u in _core.NODE_CHANNELS}, **_COUNTS}
    plant, eft, rpsd = _core_tables()
    out = dict(plant)
    if kind in ("plant", "tracking", "record"):
        out["command"] = _command_unit(mode)
        out.update(_COUNTS)
    if kind in ("eft", "record"):
        out["flags"] = _COUNTS["flags"]
        out.update((n, u) for n, u in eft if n != "command" or kind == "eft")
    if kind in ("rpsd", "record"):
        out["flags"] = _COUNTS["flags"]
        out.update((n, u) for n, u in rpsd if n != "command" or kind == "rpsd")
    return out


class Work(SimpleNamespace):
    """The run's summary counts, copied from the core's ``RunSummary`` (record.hpp: every
    loop's, the RTHS loop's too; so a Response pickles): ``ok``, ``rows``, ``internal_steps``,
    ``rhs_evals``, ``restarts``, ``max_internal_steps``, ``flags_any``, ``peak_force`` [N],
    ``peak_displacement`` [m], ``peak_velocity`` [m/s], ``failure_time`` [s] (-1: none),
    ``first_capacity_time`` [s], and ``status`` (``ok``, ``code``, ``message``, ``t`` [s],
    ``cvode_flag``, ...), whatever fields the core exports."""

    @classmethod
    def from_core(cls, summary: Any) -> Work:
        return cls(**_public_fields(summary))


def _public_fields(obj: Any) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name in dir(obj):
        if name.startswith("_"):
            continue
        v = getattr(obj, name)
        if name == "ok" and callable(v):
            out["ok"] = bool(v())
        elif name == "code":
            out["code"] = _snake(v.name)
        elif isinstance(v, _core.Status):
            out[name] = SimpleNamespace(**_public_fields(v))
        elif not callable(v) and not isinstance(v, type):
            out[name] = v
    return out


def _snake(name: str) -> str:
    return "".join(f"_{c.lower()}" if c.isupper() else c for c in name).lstrip("_")


def _first_time(time: np.ndarray, flags: np.ndarray, bit: int) -> float:
    return float(time[np.argmax((flags & bit) > 0)])


def solver_notes(work: Any) -> list[tuple[str, str]]:
    """(code, note) of how the integrator coped: ``run_accuracy`` for a run whose accuracy check
    says it probably misses the method's stated accuracy (``work.error_estimate`` > 1: the
    real-time option's (RK4) companion at twice the substeps, or the default's check of a run that
    turned stiff, a second run at rtol / 10; measured against the run's peak displacement and
    force), ``run_solver`` for the samples the default pair found stiff (CVODE took them)."""
    out: list[tuple[str, str]] = []
    if work is None:
        return out
    est = getattr(work, "error_estimate", 0.0)
    n_bad = getattr(work, "inaccurate_samples", 0)
    n_stiff = getattr(work, "stiff_samples", 0)
    if not est <= 1.0:  # NaN too: the check itself went non-finite
        where = f"; {n_bad} sample(s) flagged" if n_bad else ""
        if n_stiff:
            out.append(("run_accuracy",
                        f"the run turned stiff and its check (a second run at rtol / 10) departs from it by "
                        f"{est:.3g}x the bound: it may miss the default's stated 1e-3 of the peak displacement or "
                        f"force (a high-gain or supply-limited loop that amplifies the integration error{where}); "
                        "use a smaller rtol"))
        else:
            out.append(("run_accuracy",
                        f"a run at twice the RK4 substeps departs from this one by {est:.3g}x rk4_flag_rtol of "
                        f"the peak displacement or force: it probably misses RK4's stated 1e-2{where}; use the "
                        "default method (dopri5), more rk4_substeps or rk4_max_refinements"))
    if n_stiff:
        out.append(("run_solver", f"{n_stiff} sample(s) were stiff for the explicit pair and integrated by CVODE"))
    return out


def solver_warnings(work: Any) -> list[str]:
    """The notes of :func:`solver_notes`."""
    return [text for _, text in solver_notes(work)]


def limit_notes(flags: np.ndarray, time: np.ndarray, peak_force: float, rig: Rig | None = None
                ) -> list[tuple[str, str, float]]:
    """(code, note, first time [s]) of each physical limit a run hit, from its per-row
    OutputFlag bits (``rig`` adds the limit values to the notes).  Codes: ``run_capacity``,
    ``run_supply``, ``run_stroke``, ``run_spool``, ``run_drive``."""
    out = []
    if np.any(flags & _core.FLAG_CAPACITY_EXCEEDED):
        cap = f" > {rig.F_cap / 1e3:.0f} kN" if rig is not None else ""
        t = _first_time(time, flags, _core.FLAG_CAPACITY_EXCEEDED)
        out.append(("run_capacity", f"actuator capacity exceeded: peak force {peak_force / 1e3:.1f} kN{cap}, "
                                    f"first at t = {t:.3f} s", t))
    if np.any(flags & _core.FLAG_SUPPLY_LIMITED):
        lim = f" (p_s A = {rig.p_s * rig.A / 1e3:.1f} kN)" if rig is not None else ""
        t = _first_time(time, flags, _core.FLAG_SUPPLY_LIMITED)
        out.append(("run_supply", f"load pressure reached the supply pressure{lim}, force limited, "
                                  f"first at t = {t:.3f} s", t))
    if np.any(flags & _core.FLAG_STROKE_EXCEEDED):
        lim = f" (+-{rig.stroke * 1e3:.0f} mm)" if rig is not None else ""
        t = _first_time(time, flags, _core.FLAG_STROKE_EXCEEDED)
        out.append(("run_stroke", f"displacement beyond the actuator stroke{lim} first at t = {t:.3f} s: a real "
                                  "actuator would hit its end stop", t))
    if np.any(flags & _core.FLAG_SPOOL_SATURATED):
        t = _first_time(time, flags, _core.FLAG_SPOOL_SATURATED)
        out.append(("run_spool", f"servovalve spool saturated (fully open) first at t = {t:.3f} s", t))
    if np.any(flags & _core.FLAG_DRIVE_SATURATED):
        t = _first_time(time, flags, _core.FLAG_DRIVE_SATURATED)
        out.append(("run_drive", f"servovalve drive saturated first at t = {t:.3f} s", t))
    return out


def limit_warnings(flags: np.ndarray, time: np.ndarray, peak_force: float, rig: Rig | None = None) -> list[str]:
    """Notes on the physical limits a run hit, from its per-row OutputFlag bits
    (``rig`` adds the limit values): the notes of :func:`limit_notes`."""
    return [note for _, note, _ in limit_notes(flags, time, peak_force, rig)]


def mr_law_warnings(rig: Rig | None) -> list[str]:
    """A note when the rig's MR damper runs at a field input outside the range its law was
    identified on (``mr_law_min`` ... ``mr_law_max``): the run extrapolates the law."""
    if rig is None or not rig.effects.mr_damper:
        return []
    current = rig.mr_input == _core.MrInput.Current
    u = float(rig.mr_current if current else rig.mr_voltage)
    lo, hi = float(rig.mr_law_min), float(rig.mr_law_max)
    if lo <= u <= hi:
        return []
    kind, unit = ("current", "A") if current else ("voltage", "V")
    return [f"MR damper {kind} {u:g} {unit} is outside the range its law was identified on ({lo:g} ... {hi:g} {unit}, "
            "specimen.mr_law_min/mr_law_max): the run extrapolates the law"]


class Channels(Mapping):
    """Read-only name -> array mapping whose channels are also attributes."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, np.ndarray]):
        object.__setattr__(self, "_data", dict(data))

    def __getitem__(self, name: str) -> np.ndarray:
        return self._data[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __getattr__(self, name: str) -> np.ndarray:
        try:
            return object.__getattribute__(self, "_data")[name]
        except KeyError:
            raise AttributeError(f"no channel {name!r}; channels: {list(self._data)}") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("channels are read-only")

    def __repr__(self) -> str:
        return f"Channels({list(self._data)})"

    def __reduce__(self):
        return (Channels, (self._data,))


class Response:
    """Every channel of a run or record, SI units, one row per controller sample.

    Attributes:
        time: [s], the same array as ``channels["time"]``.
        channels: read-only mapping name -> array (also attributes:
            ``res.displacement``); it includes ``time``.
        units: name -> SI unit of each channel.
        kind: ``"plant"`` (simulate), ``"eft"``, ``"rpsd"``, ``"tracking"``, ``"record"``,
            ``"rths"`` (``rths.run_trial``: the RTHS benchmark loop) or ``"multi"``
            (``simulate_multi``: the coupled multi-actuator rig, a ``MultiResponse``).
        mode: control mode (``"displacement"``, ``"force"``, ``"free"``), None if unknown.
        dt: controller sample time [s].
        rig: the rig the run used (RPsD: the physical rig), None for a record.
        success: the run finished (no solver failure or divergence).
        status: ``"ok"`` or the failure code (``"solver_failure"``, ``"too_much_work"``, ``"non_finite"``).
        message: ``"ok"`` or what failed, when and why.
        work: the run's summary counts (:class:`Work`, from the core's
            ``RunSummary``: rows, internal steps, rhs evaluations, restarts,
            peak force, displacement and velocity, failure time, status); None for a record.
        path: the file of a record, else None.
        metadata: how a record was read (``read_record``: columns, units, scales, offsets, the
            file's header block); empty for a run.
        settings: rig keys the record was made at, which its simulation uses over any rig's
            (e.g. ``{"mr_current": 0.5}``: an MR damper's coil current; ``identification.run``);
            empty unless given (:meth:`with_settings`).
    """

    def __init__(self, channels: Mapping[str, ArrayLike], *, kind: str = "record", mode: str | None = None,
                 dt: float | None = None, rig: Rig | None = None, work: _core.RunSummary | Work | None = None,
                 units: Mapping[str, str] | None = None, path: str | Path | None = None,
                 metadata: Mapping[str, Any] | None = None, settings: Mapping[str, float] | None = None):
        if kind not in KINDS:
            raise ValueError(f"invalid kind = {kind!r}: expected one of {list(KINDS)}")
        if "time" not in channels:
            raise ValueError(f"invalid channels {list(channels)}: a response needs a 'time' channel")
        data = {n: (np.asarray(v) if n in _INTEGER or n.endswith(".flags") else np.asarray(v, dtype=float))
                for n, v in channels.items()}
        table = channel_units(kind, mode)
        self.channels = Channels(data)
        self.units = {n: (units or {}).get(n, table.get(n, "?")) for n in data}
        if work is not None and not isinstance(work, Work):
            work = Work.from_core(work)
        self.kind, self.mode, self.rig, self.work = kind, mode, rig, work
        self.path = None if path is None else Path(path)
        self.metadata = dict(metadata or {})
        self.settings = dict(settings or {})
        t = data["time"]
        self.dt = float(dt) if dt is not None else (float((t[-1] - t[0]) / (t.size - 1)) if t.size > 1 else math.nan)
        status = None if work is None else work.status
        self.success = True if status is None else bool(status.ok)
        self.status = "ok" if self.success else status.code
        self.message = "ok" if self.success else _failure_message(kind, status)

    # ---- channel access ------------------------------------------------------------
    @property
    def time(self) -> np.ndarray:
        """Sample times [s]."""
        return self.channels["time"]

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("_") or name == "channels":
            raise AttributeError(name)
        try:
            return self.channels[name]
        except KeyError:
            raise AttributeError(f"{type(self).__name__} has no attribute or channel {name!r}; "
                                 f"channels: {list(self.channels)}") from None

    def __len__(self) -> int:
        return int(self.time.size)

    def __repr__(self) -> str:
        return (f"Response(kind={self.kind!r}, mode={self.mode!r}, rows={len(self)}, dt={self.dt:.6g}, "
                f"status={self.status!r}, channels={list(self.channels)})")

    def with_settings(self, **settings: float) -> Response:
        """A copy (sharing the channel arrays) whose ``settings`` are these rig keys [SI] over its own."""
        import copy

        out = copy.copy(self)
        out.settings = {**self.settings, **{k: float(v) for k, v in settings.items()}}
        return out

    # ---- outcome ---------------------------------------------------------------------
    @property
    def flags(self) -> np.ndarray:
        """OutputFlag bits per row (zeros for a record without a ``flags`` column)."""
        if "flags" in self.channels:
            return self.channels["flags"]
        return np.zeros(len(self), dtype=np.uint32)

    @property
    def capacity_exceeded(self) -> bool:
        """|load-cell force| > F_cap somewhere."""
        return bool(np.any(self.flags & _core.FLAG_CAPACITY_EXCEEDED))

    @property
    def supply_limited(self) -> bool:
        """|p| >= 0.98 p_s somewhere."""
        return bool(np.any(self.flags & _core.FLAG_SUPPLY_LIMITED))

    def first_flag_time(self, flags: int) -> float | None:
        """Time of the first row with any of ``flags`` [s], or None."""
        hit = np.flatnonzero(self.flags & flags)
        return float(self.time[hit[0]]) if hit.size else None

    def warnings(self, rig: Rig | None = None) -> list[str]:
        """Plain-language notes on the limits the run hit and, for a failed run, the
        failure (``rig`` overrides the run's rig for the limit values)."""
        return self._warning_list(rig)

    def _warning_list(self, rig: Rig | None) -> list[str]:
        return [text for _, text in self.notes(rig)]

    def notes(self, rig: Rig | None = None) -> list[tuple[str, str]]:
        """(code, note) of every warning (:meth:`warnings`): the limits the run hit
        (``limit_notes``' codes), ``run_mr_law``, ``run_accuracy`` and ``run_solver`` for the
        integrator's notes (:func:`solver_notes`) and ``run_failed`` for a failure."""
        rig = self.rig if rig is None else rig
        peak = getattr(self.work, "peak_force", None)
        if peak is None:
            peak = float(np.max(np.abs(self.channels.get("force", np.zeros(0))), initial=0.0))
        out = [(code, text) for code, text, _ in limit_notes(self.flags, self.time, peak, rig)]
        out += [("run_mr_law", text) for text in mr_law_warnings(rig)]
        out += solver_notes(self.work)
        if not self.success:
            out.append(("run_failed", self.message))
        return out

    # ---- export ----------------------------------------------------------------------
    def to_pandas(self) -> pd.DataFrame:
        """One column per channel (``time`` first), units in ``df.attrs["units"]``."""
        import pandas as pd

        df = pd.DataFrame({n: self.channels[n] for n in self.channels})
        df.attrs["units"] = dict(self.units)
        return df

    def to_csv(self, path: str | Path) -> Path:
        """Writes every channel to a record CSV (``time, command, displacement,
        force`` first); ``read_record`` reads it back.  Returns the path.  The file is
        written whole or not at all (``atomic``: an OSError naming it on failure)."""
        path = Path(path)
        missing = [c for c in REQUIRED if c not in self.channels]
        if missing:
            raise ValueError(f"cannot write {path}: missing channel(s) {missing}")
        names = list(REQUIRED) + [n for n in self.channels if n not in REQUIRED]
        cols = [np.asarray(self.channels[n], dtype=float) for n in names]
        n0 = cols[0].size
        for n, c in zip(names, cols):
            if c.shape != (n0,):
                raise ValueError(f"cannot write {path}: channel {n!r} has shape {c.shape}, expected ({n0},)")
            if not np.all(np.isfinite(c)):
                raise ValueError(f"cannot write {path}: channel {n!r} has non-finite values")
        uniform_dt(cols[0], f"cannot write {path}")
        with atomic_path(path) as tmp:
            np.savetxt(tmp, np.column_stack(cols), delimiter=",", header=",".join(names), comments="", fmt="%.10g")
        return path


_LABELS = {"plant": "simulation", "eft": "EFT", "rpsd": "RPsD", "tracking": "tracking", "record": "record",
           "rths": "RTHS", "marths": "maRTHS", "multi": "multi-actuator run"}


def _failure_message(kind: str, status: SimpleNamespace) -> str:
    flag = f" (CVODE flag {status.cvode_flag})" if status.cvode_flag else ""
    return f"{_LABELS[kind]} failed at t = {status.t:.6g} s: {status.message}{flag}"


class SimulationError(RuntimeError):
    """A run failed (solver failure, overrun or divergence).

    Attributes:
        status: the failure code (``Response.status``).
        partial: the :class:`Response` up to the failure.
    """

    def __init__(self, partial: Response):
        super().__init__(partial.message)
        self.status = partial.status
        self.partial = partial


def finish(res: Response, raise_on_failure: bool) -> Response:
    """Returns the response, or raises SimulationError carrying it when it failed."""
    if not res.success and raise_on_failure:
        raise SimulationError(res)
    return res


__all__ = ["Channels", "Response", "Work", "SimulationError", "channel_units", "limit_notes", "limit_warnings",
           "solver_notes", "solver_warnings", "uniform_dt"]
