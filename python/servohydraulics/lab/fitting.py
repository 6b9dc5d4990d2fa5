"""The two stages of identification: the frequency response, then the time domain.

* :func:`fit_frequency` (stage 1): the H1 estimates channel/command of every
  record (coherence >= 0.9, inside the command's band) fitted by the
  linearised model (``sh.analysis.linearize``, i.e. ``_core.linearize_dynamics``
  about the record's initial displacement) in relative complex least squares
  weighted by the coherence.  Keys that do not change the linear model
  (friction, hysteresis) are left for stage 2.
* :func:`fit_time` (stage 2): the records' commands simulated through the
  nonlinear model (the fast integrator, RK4 with the substep count fixed at
  the start so the residual is a smooth function of the keys; CVODE if the
  start is too stiff for it), the residual (sim - measured) / std(measured) of
  every channel, weighted by the inverse of that channel's rms residual at the
  start (channels fitted as well as the model allows weigh in equally: a
  linear spring-dashpot standing in for an MR damper leaves a 40 % force
  residual that would otherwise pull the loop's keys), minimised by
  ``scipy.optimize.least_squares`` (trust region reflective, Jacobian by
  forward differences of 0.1 % steps in the fitting coordinates).

Both work in :class:`~servohydraulics.lab.keys.Coordinates` (log space for
positive keys).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..response import Response, SimulationError
from ..rig import Error, Rig
from ..simulate import make_plant, solver_options
from .frf import FrequencyResponse, command_band, h1
from .keys import Coordinates
from .run import initial_displacement, simulate_record

MIN_COHERENCE = 0.9
MAX_POINTS = 80  #: frequency points per channel in stage 1 (log-spaced thinning)
FAILED = 10.0  #: normalised residual of a failed simulation


@dataclass(frozen=True, eq=False)
class StageResult:
    z: np.ndarray
    cost: float
    nfev: int
    fun: np.ndarray
    jac: np.ndarray | None = None


def _thin(mask: np.ndarray, f: np.ndarray) -> np.ndarray:
    idx = np.flatnonzero(mask)
    if idx.size <= MAX_POINTS:
        return idx
    grid = np.geomspace(f[idx[0]], f[idx[-1]], MAX_POINTS)
    return np.unique(idx[np.clip(np.searchsorted(f[idx], grid), 0, idx.size - 1)])


def frequency_targets(records: list[Response], channels: tuple[str, ...]) -> list[tuple]:
    """(record, channel, f [Hz], H, coherence) of every record and channel, in the fitted band."""
    out = []
    for rec in records:
        u = np.asarray(rec.command, dtype=float)
        f_hi = command_band(u, rec.dt)
        for ch in channels:
            est: FrequencyResponse = h1(u, np.asarray(rec.channels[ch], dtype=float), rec.dt)
            f_lo = 2.0 / (est.nperseg * rec.dt)
            idx = _thin(est.band(MIN_COHERENCE, f_lo, f_hi), est.frequency)
            if idx.size >= 3:
                out.append((rec, ch, est.frequency[idx], est.response[idx], est.coherence[idx]))
    if not out:
        raise ValueError("no frequency with coherence >= 0.9 inside the commands' band: the records carry no "
                         "usable frequency response")
    return out


def linear_response(rig: Rig, mode: str, x0: float, channels: tuple[str, ...], f: np.ndarray) -> np.ndarray:
    """Frequency response of the linearised model, rows = channels, columns = f [Hz]."""
    from ..analysis import linearize

    sys = linearize(rig, mode, x0=x0, outputs=channels)
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    s = 2j * np.pi * f
    X = np.linalg.solve(s[:, None, None] * np.eye(A.shape[0]) - A, np.broadcast_to(B, (f.size,) + B.shape))
    return (C @ X)[..., 0].T + D


def fit_frequency(records: list[Response], rig: Rig, coords: Coordinates, mode: str,
                  channels: tuple[str, ...]) -> tuple[StageResult, list[str]]:
    """Stage 1; returns the result and the keys it fitted (those the linear model sees)."""
    targets = frequency_targets(records, channels)
    x0s = {id(r): initial_displacement(r) for r in records}

    def residual(z: np.ndarray, active: np.ndarray) -> np.ndarray:
        zz = np.zeros(len(coords.keys))
        zz[active] = z
        out = []
        for rec, ch, f, H, coh in targets:
            try:  # an invalid rig (ValueError naming the key) or a singular model: a failed point
                Hm = linear_response(coords.apply(rig, zz), mode, x0s[id(rec)], (ch,), f)[0]
            except (ValueError, np.linalg.LinAlgError):
                return np.full(sum(2 * t[2].size for t in targets), FAILED)
            e = np.sqrt(coh) * (Hm - H) / np.abs(H)
            out.append(np.concatenate([e.real, e.imag]) / np.sqrt(f.size))
        return np.concatenate(out)

    everything = np.ones(len(coords.keys), dtype=bool)
    base = residual(np.zeros(len(coords.keys)), everything)
    sees = np.array([np.max(np.abs(residual(np.eye(len(coords.keys))[i] * 0.05, everything) - base)) > 1e-9
                     for i in range(len(coords.keys))])
    fitted = [k for k, s in zip(coords.keys, sees) if s]
    if not fitted:
        return StageResult(np.zeros(len(coords.keys)), float(base @ base) / 2, 1, base), []
    lo, hi = coords.bounds()
    sol = least_squares(lambda z: residual(z, sees), np.zeros(int(sees.sum())), bounds=(lo[sees], hi[sees]),
                        method="trf", x_scale=1.0, max_nfev=200)
    z = np.zeros(len(coords.keys))
    z[sees] = sol.x
    return StageResult(z, float(sol.cost), int(sol.nfev), sol.fun), fitted


MAX_RK4_SUBSTEPS = 200


def fixed_rk4(rig: Rig, records: list[Response], mode: str, margin: float = 2.0):
    """RK4 options with the substep count fixed at ``margin`` times the automatic count
    of the start; CVODE when that count would exceed ``MAX_RK4_SUBSTEPS``."""
    dt = min(r.dt for r in records)
    try:
        n = make_plant(rig, mode, dt, solver_options(method="rk4"), initial_displacement(records[0])).rk4_substeps
    except Error:
        n = MAX_RK4_SUBSTEPS + 1
    if margin * n > MAX_RK4_SUBSTEPS:
        return solver_options(method="cvode")
    return solver_options(method="rk4", rk4_substeps=max(1, int(np.ceil(margin * n))))


def time_residual(rig: Rig, records: list[Response], mode: str, channels: tuple[str, ...], options,
                  dt: float | None = None, weights: dict | None = None) -> np.ndarray:
    """w_ch (sim - measured) / std(measured) of every record and channel, concatenated
    (w_ch = 1 unless ``weights`` gives it)."""
    out = []
    for rec in records:
        try:
            sim = simulate_record(rig, rec, mode, dt=dt, options=options)
        except (SimulationError, ValueError):
            sim = None
        for ch in channels:
            m = np.asarray(rec.channels[ch], dtype=float)
            s = sim[ch] if sim is not None and np.all(np.isfinite(sim[ch])) else None
            w = 1.0 if weights is None else weights[ch]
            out.append(np.full(m.size, FAILED) if s is None else w * (s - m) / np.std(m))
    return np.concatenate(out)


def channel_weights(rig: Rig, records: list[Response], mode: str, channels: tuple[str, ...], options,
                    dt: float | None = None) -> dict[str, float]:
    """1 / (rms normalised residual) of each channel over all records at ``rig`` (floored at 1e-3)."""
    e = time_residual(rig, records, mode, channels, options, dt)
    sizes = [rec.time.size for rec in records for _ in channels]
    parts = np.split(e, np.cumsum(sizes)[:-1])
    names = [ch for _ in records for ch in channels]
    return {ch: 1.0 / max(float(np.sqrt(np.mean(np.concatenate([p for p, n in zip(parts, names) if n == ch])
                                                    ** 2))), 1e-3) for ch in channels}


def fit_time(records: list[Response], rig: Rig, coords: Coordinates, z0: np.ndarray, mode: str,
             channels: tuple[str, ...], options, dt: float | None = None, max_nfev: int = 60,
             progress=None, weights: dict | None = None) -> StageResult:
    """Stage 2 from z0 (see the module docstring)."""
    n = sum(rec.time.size for rec in records) * len(channels)

    def residual(z: np.ndarray) -> np.ndarray:
        if progress is not None:
            progress.update(1)
        try:
            r = coords.apply(rig, z)
        except ValueError:  # the step left the rig's valid range: a failed point
            return np.full(n, FAILED)
        return time_residual(r, records, mode, channels, options, dt, weights)

    lo, hi = coords.bounds()
    sol = least_squares(residual, np.clip(z0, lo, hi), bounds=(lo, hi), method="trf", jac="2-point",
                        diff_step=1e-3, x_scale=1.0, xtol=1e-8, ftol=1e-8, max_nfev=max_nfev)
    return StageResult(sol.x, float(sol.cost), int(sol.nfev), sol.fun, sol.jac)


__all__ = ["MAX_RK4_SUBSTEPS", "MIN_COHERENCE", "StageResult", "channel_weights", "fit_frequency", "fit_time", "fixed_rk4", "frequency_targets",
           "linear_response", "time_residual"]
