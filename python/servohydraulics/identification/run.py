"""The one record-simulation helper: a command through a rig, as a ``Response``
on the command's own time axis (``sh.identify``, ``compare``, ``sh.diagnose`` and
the paper-era fits all simulate through :func:`simulate_command`).

The controller sample is the record's dt unless told otherwise.  A controller
``dt`` that divides the record's sample time (an integer ratio n) gets the
command linearly interpolated onto its grid and every n-th output kept; a
controller n times slower gets every n-th command sample and its outputs
linearly interpolated back onto the record's times.  A command ``delay`` [s]
shifts the command by whole and fractional samples (linear interpolation,
holding the first value before the record starts).  :func:`simulate_record`
starts at rest at the record's initial displacement (the median of its first 20
samples, which averages the sensor noise).  A record made at other settings of the rig
(``Response.settings``, e.g. an MR damper's coil current) runs with them over the rig's
(:func:`record_rig`).
"""

from __future__ import annotations

import math

import numpy as np

from ..response import Response, SimulationError
from ..rig import Rig
from ..simulate import simulate
from ..timegrid import MAX_SAMPLES, positive

#: the channels a record and a simulation share, compared in this order
CHANNELS = ("displacement", "force")
#: the channels compare and identify read from a record besides time
REQUIRED_CHANNELS = ("command", *CHANNELS)


def initial_displacement(record: Response, samples: int = 20) -> float:
    """The record's initial displacement [m]: the median of its first samples."""
    return float(np.median(np.asarray(record.displacement)[:samples]))


def controller_ratio(record_dt: float, samples: int, dt: float | None) -> tuple[int, bool]:
    """(n, faster): a controller sample ``dt`` [s] runs n times faster (True) or slower than a
    record of ``samples`` samples at ``record_dt`` [s] (None: the record's own, (1, True)).
    ValueError naming ``dt`` when it is not finite and > 0, neither divides nor is a multiple of
    the record's sample, makes more samples than ``simulate`` allows (``MAX_SAMPLES``, checked
    before any grid is allocated) or is too slow to give two samples of the record."""
    if dt is None:
        return 1, True
    dt = positive("dt", dt)
    for a, b, faster in ((record_dt, dt, True), (dt, record_dt, False)):
        n = a / b
        if math.isfinite(n) and abs(n - round(n)) <= 1e-6 * n and round(n) >= 1:
            n = int(round(n))
            if faster and (samples - 1) * n + 1 > MAX_SAMPLES:
                raise ValueError(f"invalid dt = {dt!r}: {(samples - 1) * n + 1:,} controller samples for the "
                                 f"record's {samples:,} at {record_dt!r} s, more than the {MAX_SAMPLES:,} allowed")
            if not faster and n > samples - 1:
                raise ValueError(f"invalid dt = {dt!r}: longer than the record ({samples:,} samples at "
                                 f"{record_dt!r} s), the controller would sample it once")
            return n, faster
    raise ValueError(f"invalid dt = {dt!r}: the controller sample must divide the record's {record_dt!r} s "
                     "or be an integer multiple of it")


#: largest magnitude of a record's value: its squares and their sums over any record stay finite
MAX_ABS = 1e100


def record_name(record: Response) -> str:
    return record.path.stem if record.path is not None else "record"


def check_record(record: Response) -> Response:
    """``record`` when ``compare`` and ``identify`` can use it: at least ``frf.MIN_SAMPLES``
    samples, every value of its time, command, displacement and force finite and within
    ``MAX_ABS``, a command that varies; else a ValueError naming the record, the channel
    (with the row) and the value."""
    from .frf import MIN_SAMPLES

    where = record.path if record.path is not None else "record"
    n = np.asarray(record.time).size
    if n < MIN_SAMPLES:
        raise ValueError(f"{where}: invalid record length = {n} samples: compare and identify need at least "
                         f"{MIN_SAMPLES} (an H1 estimate of six segments)")
    for ch in ("time", *REQUIRED_CHANNELS):
        if ch not in record.channels:
            raise ValueError(f"{where}: missing channel {ch!r}")
        v = np.asarray(record.channels[ch], dtype=float)
        bad = np.flatnonzero(~(np.abs(v) <= MAX_ABS))
        if bad.size:
            raise ValueError(f"{where}: invalid {ch}[{bad[0]}] = {float(v[bad[0]])!r}: must be finite and within "
                             f"+-{MAX_ABS:g}")
    u = np.asarray(record.command, dtype=float)
    if np.all(u == u[0]):
        raise ValueError(f"{where}: invalid command = constant {float(u[0])!r}: no energy to estimate a frequency "
                         "range from")
    return record


def delayed(u: np.ndarray, dt: float, tau: float) -> np.ndarray:
    """The command delayed by tau [s]: integer + fractional samples by linear
    interpolation, holding the first value before the record starts (tau < 0
    advances it, holding the last value past the end)."""
    if tau == 0.0:
        return u
    k = np.arange(u.size) - tau / dt
    return np.interp(k, np.arange(u.size), u, left=u[0], right=u[-1])


def simulate_command(rig: Rig, mode: str, command: np.ndarray, record_dt: float, x0: float = 0.0, options=None,
                     dt: float | None = None, delay: float = 0.0) -> Response:
    """The command (sampled at ``record_dt`` [s], delayed by ``delay`` [s]) through the rig with a
    controller sample ``dt`` (default ``record_dt``), from rest at ``x0`` [m]: a ``Response`` of
    kind ``"plant"`` with every plant channel on the command's time axis (``time`` from 0).

    Raises SimulationError (the solver's message, with the time) when the run fails."""
    u = delayed(np.asarray(command, dtype=float), record_dt, float(delay))
    n, faster = controller_ratio(record_dt, u.size, dt)
    tr = np.arange(u.size) * record_dt
    if faster:
        uc = u if n == 1 else np.interp(np.arange((u.size - 1) * n + 1) * (record_dt / n), tr, u)
        res = simulate(rig, mode=mode, command=uc, dt=record_dt / n, x0=x0, options=options)
        data = {k: np.asarray(v)[::n] for k, v in res.channels.items() if k != "time"}
        if n > 1:  # a row's flags: every controller sample since the previous row (none is lost)
            starts = np.r_[0, np.arange(u.size - 1) * n + 1]  # row k >= 1: controller rows (k-1) n + 1 .. k n
            data["flags"] = np.bitwise_or.reduceat(np.asarray(res.flags), starts)
    else:
        uc = u[::n]
        res = simulate(rig, mode=mode, command=uc, dt=record_dt * n, x0=x0, options=options)
        ts = np.arange(uc.size) * record_dt * n
        data = {k: np.interp(tr, ts, np.asarray(v, dtype=float)) for k, v in res.channels.items()
                if k not in ("time", "flags", "internal_steps", "rhs_evals")}
        data["flags"] = np.asarray(res.flags)[np.minimum(np.arange(u.size) // n, uc.size - 1)]
    data["time"] = tr
    data["command"] = u
    return Response(data, kind="plant", mode=mode, dt=record_dt, rig=rig, work=res.work)


def record_rig(rig: Rig, record: Response) -> Rig:
    """The rig the record was made with: ``rig``, or a copy with the record's ``settings`` (rig
    keys, e.g. ``{"mr_current": 0.5}``) over it."""
    settings = getattr(record, "settings", None)
    if not settings:
        return rig
    import copy

    out = copy.copy(rig)
    for key, value in settings.items():
        setattr(out, key, value)
    return out


def simulate_record(rig: Rig, record: Response, mode: str, dt: float | None = None, options=None,
                    x0: float | None = None, delay: float = 0.0) -> Response:
    """:func:`simulate_command` of the record's command from its initial displacement (``x0``
    overrides it), through :func:`record_rig` (the record's own settings over the rig)."""
    start = initial_displacement(record) if x0 is None else float(x0)
    return simulate_command(record_rig(rig, record), mode, record.command, record.dt, start, options, dt, delay)


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


__all__ = ["CHANNELS", "MAX_ABS", "REQUIRED_CHANNELS", "SimulationError", "check_record", "controller_ratio",
           "delayed", "initial_displacement", "nrmse_demeaned_pct", "nrmse_pct",
           "record_name", "record_rig", "simulate_command", "simulate_record"]
