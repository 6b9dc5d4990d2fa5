"""A record's command through a rig: the simulated channels on the record's own time axis.

The controller sample is the record's dt unless told otherwise.  A controller
``dt`` that divides the record's sample time (an integer ratio n) gets the
command linearly interpolated onto its grid and every n-th output kept; a
controller n times slower gets every n-th command sample and its outputs
linearly interpolated back onto the record's times.  The run starts at rest
at the record's initial displacement (the median of its first 20 samples,
which averages the sensor noise).
"""

from __future__ import annotations

import math

import numpy as np

from ..response import Response, SimulationError
from ..rig import Rig
from ..simulate import simulate, solver_options
from ..timegrid import MAX_SAMPLES, positive

#: the channels a record and a simulation share, compared in this order
CHANNELS = ("displacement", "force")


def initial_displacement(record: Response, samples: int = 20) -> float:
    """The record's initial displacement [m]: the median of its first samples."""
    return float(np.median(np.asarray(record.displacement)[:samples]))


def _ratio(record_dt: float, dt: float) -> tuple[int, bool]:
    """(n, faster): the controller runs n times faster (True) or slower than the record."""
    positive("dt", dt)
    for a, b, faster in ((record_dt, dt, True), (dt, record_dt, False)):
        n = a / b
        if abs(n - round(n)) <= 1e-6 * n and round(n) >= 1:
            return int(round(n)), faster
    raise ValueError(f"invalid dt = {dt!r}: the controller sample must divide the record's {record_dt!r} s "
                     "or be an integer multiple of it")


def fast_options(method: str = "rk4"):
    """The integrator identification uses for its many runs (RK4, automatic substeps)."""
    return solver_options(method=method)


def simulate_record(rig: Rig, record: Response, mode: str, dt: float | None = None, options=None,
                    x0: float | None = None) -> dict[str, np.ndarray]:
    """Simulated channels (``CHANNELS`` and the plant's others) on the record's time axis.

    Raises SimulationError (the solver's message, with the time) when the run fails."""
    rdt = record.dt
    u = np.asarray(record.command, dtype=float)
    n, faster = (1, True) if dt is None else _ratio(rdt, float(dt))
    start = initial_displacement(record) if x0 is None else float(x0)
    if faster:
        if (u.size - 1) * n + 1 > MAX_SAMPLES:  # simulate's cap, checked before the grid is allocated
            raise ValueError(f"invalid dt = {dt!r}: {(u.size - 1) * n + 1:,} controller samples for the record's "
                             f"{u.size:,} at {rdt!r} s, more than the {MAX_SAMPLES:,} allowed")
        t = np.arange((u.size - 1) * n + 1) * (rdt / n)
        uc = np.interp(t, np.arange(u.size) * rdt, u)
        res = simulate(rig, mode=mode, command=uc, dt=rdt / n, x0=start, options=options)
        return {k: np.asarray(v)[::n] for k, v in res.channels.items() if k != "time"}
    uc = u[::n]
    res = simulate(rig, mode=mode, command=uc, dt=rdt * n, x0=start, options=options)
    tr, ts = np.arange(u.size) * rdt, np.arange(uc.size) * rdt * n
    return {k: np.interp(tr, ts, np.asarray(v, dtype=float)) for k, v in res.channels.items() if k != "time"}


def nrmse_pct(simulated: np.ndarray, measured: np.ndarray) -> float:
    """100 rms(sim - measured) / std(measured) [%] (the issue's definition)."""
    m = np.asarray(measured, dtype=float)
    sd = float(np.std(m))
    if not sd > 0 or not math.isfinite(sd):
        raise ValueError("invalid measured channel: constant, its NRMSE is undefined")
    return 100.0 * float(np.sqrt(np.mean((np.asarray(simulated, dtype=float) - m) ** 2))) / sd


def nrmse_demeaned_pct(simulated: np.ndarray, measured: np.ndarray) -> float:
    """100 std(sim - measured) / std(measured) [%]: the error with its mean (a
    static offset) removed, the figure the UTFSM README quotes."""
    m = np.asarray(measured, dtype=float)
    return 100.0 * float(np.std(np.asarray(simulated, dtype=float) - m)) / float(np.std(m))


__all__ = ["CHANNELS", "SimulationError", "fast_options", "initial_displacement", "nrmse_demeaned_pct",
           "nrmse_pct", "simulate_record"]
