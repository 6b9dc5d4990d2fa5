"""Whole-record simulation of the plant: NumPy in, NumPy out."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import _core
from .rig import Rig

MODES = {
    "displacement": _core.ControlMode.Displacement,
    "force": _core.ControlMode.Force,
    "free": _core.ControlMode.Free,
}
METHODS = {"cvode": _core.SolverOptions.Method.CvodeBdf, "rk4": _core.SolverOptions.Method.Rk4}
RESTARTS = {"on_input_change": _core.SolverOptions.Restart.OnInputChange, "never": _core.SolverOptions.Restart.Never}


class SimulationError(RuntimeError):
    """The integration failed or diverged; the message names the time and the cause."""


@dataclass
class SimulationResult:
    """Every channel of a run, SI units, one row per controller sample.

    Row k is the state at ``time[k]``, measured before ``command[k]`` is applied.
    """

    time: np.ndarray  #: [s]
    command: np.ndarray  #: [m] displacement mode, [N] force/free mode
    displacement: np.ndarray  #: [m]
    velocity: np.ndarray  #: [m/s]
    acceleration: np.ndarray  #: [m/s^2]
    force: np.ndarray  #: load-cell force [N]
    pressure: np.ndarray  #: load pressure [Pa]
    spool: np.ndarray  #: spool opening [-]
    drive: np.ndarray  #: valve drive [V]
    flow: np.ndarray  #: valve flow [m^3/s]
    flags: np.ndarray  #: OutputFlag bits per row
    internal_steps: np.ndarray  #: CVODE internal steps of the sample starting at row k
    rhs_evals: np.ndarray  #: right-hand-side evaluations of that sample
    mode: str = "displacement"
    dt: float = 5e-4
    summary: dict = field(default_factory=dict)

    @property
    def capacity_exceeded(self) -> bool:
        """True if the load-cell force exceeded the rated capacity F_cap anywhere."""
        return bool(np.any(self.flags & _core.FLAG_CAPACITY_EXCEEDED))

    @property
    def supply_limited(self) -> bool:
        """True if |p| reached 98 % of the supply pressure anywhere."""
        return bool(np.any(self.flags & _core.FLAG_SUPPLY_LIMITED))

    def warnings(self, rig: Rig | None = None) -> list[str]:
        """Plain-language notes on the limits the run hit (``rig`` adds the limit values)."""
        return limit_warnings(self.flags, self.time, self.summary, rig)


def limit_warnings(flags: np.ndarray, time: np.ndarray, summary: dict, rig: Rig | None = None) -> list[str]:
    """Notes on the physical limits a run hit, from its per-row OutputFlag bits."""
    def first(bit: int) -> float:
        return float(time[np.argmax((flags & bit) > 0)])

    out = []
    if np.any(flags & _core.FLAG_CAPACITY_EXCEEDED):
        cap = f" > {rig.F_cap / 1e3:.0f} kN" if rig is not None else ""
        out.append(f"actuator capacity exceeded: peak force {summary['peak_force'] / 1e3:.1f} kN{cap}, "
                   f"first at t = {first(_core.FLAG_CAPACITY_EXCEEDED):.3f} s")
    if np.any(flags & _core.FLAG_SUPPLY_LIMITED):
        lim = f" (p_s A = {rig.p_s * rig.A / 1e3:.1f} kN)" if rig is not None else ""
        out.append(f"load pressure reached the supply pressure{lim}, force limited, "
                   f"first at t = {first(_core.FLAG_SUPPLY_LIMITED):.3f} s")
    if np.any(flags & _core.FLAG_STROKE_EXCEEDED):
        lim = f" (+-{rig.stroke * 1e3:.0f} mm)" if rig is not None else ""
        out.append(f"displacement beyond the actuator stroke{lim} first at t = "
                   f"{first(_core.FLAG_STROKE_EXCEEDED):.3f} s: a real actuator would hit its end stop")
    if np.any(flags & _core.FLAG_SPOOL_SATURATED):
        out.append(f"servovalve spool saturated (fully open) first at t = {first(_core.FLAG_SPOOL_SATURATED):.3f} s")
    if np.any(flags & _core.FLAG_DRIVE_SATURATED):
        out.append(f"servovalve drive saturated first at t = {first(_core.FLAG_DRIVE_SATURATED):.3f} s")
    return out


def solver_options(method: str = "cvode", rtol: float = 1e-6, restart: str = "on_input_change",
                   rk4_substeps: int = 0, max_steps_per_sample: int = 2000,
                   max_order: int = 5) -> _core.SolverOptions:
    """Builds solver options; see ``SolverOptions`` in plant.hpp."""
    if method not in METHODS:
        raise ValueError(f"invalid method = {method!r}: expected one of {sorted(METHODS)}")
    if restart not in RESTARTS:
        raise ValueError(f"invalid restart = {restart!r}: expected one of {sorted(RESTARTS)}")
    o = _core.SolverOptions()
    o.method = METHODS[method]
    o.restart = RESTARTS[restart]
    o.rtol = rtol
    o.rk4_substeps = rk4_substeps
    o.max_steps_per_sample = max_steps_per_sample
    o.max_order = max_order
    o.validate()
    return o


def _check_dt(dt: float) -> float:
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt) or dt <= 0:
        raise ValueError(f"invalid dt = {dt!r}: the controller sample time must be finite and > 0 [s]")
    return float(dt)


def _command_array(command, duration: float | None, dt: float) -> np.ndarray:
    if command is None:
        if duration is None:
            raise ValueError("give a command array or a duration [s]")
        if not math.isfinite(duration) or duration <= 0:
            raise ValueError(f"invalid duration = {duration!r}: must be finite and > 0 [s]")
        n = int(round(duration / dt)) + 1
        return np.zeros(n)
    u = np.asarray(command, dtype=float)
    if u.ndim != 1:
        raise ValueError(f"invalid command shape = {u.shape}: expected a 1-D array")
    if u.size < 2:
        raise ValueError(f"invalid command length = {u.size}: need at least 2 samples")
    bad = np.flatnonzero(~np.isfinite(u))
    if bad.size:
        raise ValueError(f"invalid command[{bad[0]}] = {u[bad[0]]}: commands must be finite (no NaN or inf)")
    if duration is not None:
        n = int(round(duration / dt)) + 1
        if n != u.size:
            raise ValueError(f"invalid command length = {u.size}: duration = {duration} s at dt = {dt} s "
                             f"needs {n} samples")
    return u


def make_plant(rig: Rig, mode: str, dt: float = 5e-4, options: _core.SolverOptions | None = None,
               x0: float = 0.0) -> _core.Plant:
    """Constructs and resets a plant (validates everything, raises ValueError)."""
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    if not math.isfinite(x0):
        raise ValueError(f"invalid x0 = {x0!r}: must be finite [m]")
    plant = _core.Plant(rig, MODES[mode], _check_dt(dt), options or _core.SolverOptions())
    plant.reset(float(x0))
    return plant


def simulate(rig: Rig, mode: str = "displacement", command=None, dt: float = 5e-4,
             duration: float | None = None, x0: float = 0.0,
             options: _core.SolverOptions | None = None, raise_on_failure: bool = True) -> SimulationResult:
    """Simulates the rig under a held command, one controller sample per element.

    Args:
        rig: the rig (e.g. ``zhao2003()`` or ``load_rig(path)``).
        mode: ``"displacement"`` (command in m), ``"force"`` (command in N) or
            ``"free"`` (the structure alone, no actuator, released from ``x0``;
            a command, if given, is an ideal external force in N).
        command: 1-D array, or None for a zero command over ``duration``.
        dt: controller sample time [s] (the paper's DSP ran at 2 kHz).
        duration: run length [s] when ``command`` is None (checked against it otherwise).
        x0: initial displacement [m]; the run starts from static equilibrium there.
        options: solver options (``solver_options(...)``); CVODE BDF by default.
        raise_on_failure: raise SimulationError on a solver failure or divergence
            (otherwise return the rows computed so far with ``summary['status']``).
    """
    dt = _check_dt(dt)
    u = _command_array(command, duration, dt)
    plant = make_plant(rig, mode, dt, options, x0)
    channels, s = _core.run_record(plant, u)
    n = s.rows
    summary = {
        "status": s.status.message,
        "ok": s.status.ok(),
        "failure_time": s.status.t if not s.status.ok() else None,
        "cvode_flag": s.status.cvode_flag,
        "internal_steps": s.internal_steps,
        "rhs_evals": s.rhs_evals,
        "restarts": s.restarts,
        "max_internal_steps": s.max_internal_steps,
        "peak_force": s.peak_force,
        "first_capacity_time": s.first_capacity_time,
    }
    if not s.status.ok() and raise_on_failure:
        raise SimulationError(f"simulation failed at t = {s.status.t:.6g} s: {s.status.message}"
                              + (f" (CVODE flag {s.status.cvode_flag})" if s.status.cvode_flag else ""))
    cut = {k: v[:n] for k, v in channels.items()}
    return SimulationResult(command=u[:n], mode=mode, dt=dt, summary=summary, **cut)
