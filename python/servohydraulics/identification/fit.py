"""The two stages of identification: the frequency response, then the time domain.

* :func:`fit_frequency` (stage 1): the H1 estimates channel/command of every
  record (coherence >= 0.9, inside the command's band) fitted by the
  linearised model (``linear_plant.plant_matrices``, i.e. ``_core.linearize_dynamics``
  about the record's initial displacement) in relative complex least squares
  weighted by the coherence.  Keys that do not change the linear model
  (friction, hysteresis) are left for stage 2.
* :func:`fit_time` (stage 2): the records' commands simulated through the
  nonlinear model (a ``segments.Target``: the records in segments on the threads,
  RK4 at a fixed number of substeps, :data:`RK4_SUBSTEPS`, or the error-controlled
  pair, :func:`fit_options`), the residual (sim - measured) / std(measured) of every
  channel (optionally weighted per channel), minimised by
  ``scipy.optimize.least_squares`` (trust region reflective, Jacobian by forward
  differences of 0.1 % steps in the fitting coordinates, its columns' runs together
  on the threads) over the active keys.  ``records.py`` runs it block by block
  (loop keys on the displacement, force keys on the force) in displacement control,
  and checks the result against the pair's whole runs.
* :func:`keep_best`: the start and the stages compared by the time-domain cost
  (:func:`time_costs`), the best kept, so that identification never ends worse
  than it starts (``sh.diagnose`` keeps the same invariant for its candidate
  fits).  ``records.identify`` runs the time stage from stage 1 and, when that ends
  worse than the start, once more from the start.

Both work in :class:`~servohydraulics.identification.coordinates.Coordinates` (log space for
positive keys).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .. import _core
from ..linear_plant import friction_off, plant_matrices
from ..response import Response
from ..rig import Error, Rig
from ..simulate import make_plant, solver_options
from .coordinates import Coordinates
from .frf import FrequencyResponse, command_band, h1
from .run import initial_displacement, record_rig
from .segments import FAILED, Target, whole

MIN_COHERENCE = 0.9
MAX_POINTS = 80  #: frequency points per channel in stage 1 (log-spaced thinning)


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
        names = ", ".join(str(r.path or "record") for r in records)
        raise ValueError(f"{names}: invalid frequency response = none usable: no 3 frequencies with coherence "
                         f">= {MIN_COHERENCE} inside the command's band (a longer or broader-band record)")
    return out


def linear_response(rig: Rig, mode: str, x0: float, channels: tuple[str, ...], f: np.ndarray) -> np.ndarray:
    """Frequency response of the linearised model, rows = channels, columns = f [Hz]."""
    pm = plant_matrices(friction_off(rig), mode, x0=x0, outputs=channels)
    A, B, C, D = (np.asarray(m, dtype=float) for m in (pm.A, pm.B, pm.C, pm.D))
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
                Hm = linear_response(record_rig(coords.apply(rig, zz), rec), mode, x0s[id(rec)], (ch,), f)[0]
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


#: the hysteretic specimens' rate bound uses this multiple of the records' peak velocity
V_REF_MARGIN = 2.0


def records_peak_velocity(records: list[Response]) -> float:
    """The largest 99.9th percentile of |velocity| [m/s] over the records (displacement
    low-passed at 200 Hz and differenced)."""
    from .generic import record_scales

    return max(record_scales(r)["v_pk"] for r in records)


#: relative tolerance of the time stage's Dormand-Prince runs
FIT_RTOL = 1e-6


def automatic_substeps(rig: Rig, records: list[Response], mode: str) -> int | None:
    """RK4's automatic substep count per sample for the records' runs of ``rig`` (the core's rule from
    the plant's rate bound: the stiffer the rig, the more substeps; a hysteretic specimen's rate
    bounded with ``V_REF_MARGIN`` times the records' peak velocity), None when the core refuses the rig."""
    dt = min(r.dt for r in records)
    v_ref = V_REF_MARGIN * max(records_peak_velocity(records), 1e-4)
    try:
        return make_plant(rig, mode, dt, solver_options(method="rk4", rk4_v_ref=v_ref),
                          initial_displacement(records[0])).rk4_substeps
    except Error:
        return None


def fit_options(rig: Rig, records: list[Response], mode: str, method: str = "dopri5", margin: float = 1.5):
    """The time stage's integrator.  ``"dopri5"``: Dormand-Prince 5(4) (the core's default,
    CVODE for a stiff sample) at rtol ``FIT_RTOL``.  ``"rk4"``: RK4 with the substep count
    fixed at ``margin`` times the automatic count of the start (a hysteretic specimen's
    rate bounded with ``V_REF_MARGIN`` times the records' peak velocity; a fixed count keeps
    the residual a smooth function of the keys), CVODE when that count would exceed
    ``MAX_RK4_SUBSTEPS``.  Without the integrators' accuracy checks (the default's check of a run
    that turned stiff, RK4's companion): they never change a result, and a fit's thousands of runs
    would pay for them (up to 2.5x per run); ``compare`` of the fitted rig runs them."""
    if method == "dopri5":
        return solver_options(method="dopri5", rtol=FIT_RTOL, stiff_check=False)
    if method != "rk4":
        raise ValueError(f"invalid method = {method!r}: expected 'dopri5' or 'rk4'")
    n = automatic_substeps(rig, records, mode)
    n = MAX_RK4_SUBSTEPS + 1 if n is None else n
    if margin * n > MAX_RK4_SUBSTEPS:
        return solver_options(method="cvode")
    return solver_options(method="rk4", rk4_substeps=max(1, int(np.ceil(margin * n))), rk4_flag_rtol=0.0)


def checked_options(options):
    """``options`` with the integrators' accuracy checks back on (the core's defaults of
    ``stiff_check`` and ``rk4_flag_rtol``): for the fitted rig's reported runs."""
    default = _core.SolverOptions()
    out = _core.SolverOptions()
    for f in _core.SOLVER_OPTION_FIELDS:
        setattr(out, f["name"], getattr(options, f["name"]))
    out.stiff_check, out.rk4_flag_rtol = default.stiff_check, default.rk4_flag_rtol
    return out


#: the time stage's runs: classical RK4 at a fixed number of substeps per sample (a residual that
#: is a smooth function of the keys: the differences are clean, 2e-2 of a column at worst on the
#: UTFSM chirp against rtol 1e-9, as the pair's at rtol 1e-6), the fewest of these that agrees
#: with the error-controlled pair on the start (``segments.Target.agrees``); the pair where none does
RK4_SUBSTEPS = (3, 4, 6, 8, 12, 16)


def rk4_options(substeps: int):
    """RK4 at ``substeps`` per sample without its companion check (the time stage checks its runs
    against the error-controlled pair's instead: ``segments.Target.agrees``)."""
    return solver_options(method="rk4", rk4_substeps=int(substeps), rk4_flag_rtol=0.0)


def time_residual(rig: Rig, records: list[Response], mode: str, channels: tuple[str, ...], options,
                  dt: float | None = None, weights: dict | None = None) -> np.ndarray:
    """w_ch (sim - measured) / std(measured) of every record and channel, concatenated
    (w_ch = 1 unless ``weights`` gives it), each record run whole."""
    target = Target(records, mode, channels, options, dt, [whole(r) for r in records])
    return target.residual(rig, weights)


def channel_weights(target: Target, rig: Rig, channels: tuple[str, ...] | None = None) -> dict[str, float]:
    """1 / (rms normalised residual) of each channel over all records at ``rig`` (floored at 1e-3)."""
    chans = target.channels if channels is None else tuple(channels)
    e = target.residual(rig, channels=chans)
    parts = np.split(e, np.cumsum(target.lengths_of(chans))[:-1])
    names = [ch for _ in target.records for ch in chans]
    return {ch: 1.0 / max(float(np.sqrt(np.mean(np.concatenate([p for p, n in zip(parts, names) if n == ch])
                                                    ** 2))), 1e-3) for ch in chans}


#: least_squares' stopping tolerances: a relative cost change below 1e-4 is far below
#: what separates the models compared here (NRMSE differences of 0.1 %)
FTOL, XTOL = 1e-4, 1e-6

#: relative forward-difference step of the time-domain Jacobian (in the fitting coordinates)
DIFF_STEP = 1e-3


def default_workers() -> int:
    """Threads for the runs: the core releases the GIL while it simulates."""
    import os

    return max(1, min(2, os.cpu_count() or 1))


def forward_jacobian(fun, z: np.ndarray, f0: np.ndarray, hi: np.ndarray, workers: int, many=None) -> np.ndarray:
    """Forward differences of ``fun`` at z (steps DIFF_STEP max(1, |z_i|), backwards at an
    upper bound), the columns evaluated on ``workers`` threads, or by ``many`` (a function of a
    list of points returning their residuals, which runs them together)."""
    from concurrent.futures import ThreadPoolExecutor

    h = DIFF_STEP * np.maximum(1.0, np.abs(z))
    h = np.where(z + h > hi, -h, h)
    points = []
    for i in range(z.size):
        zi = z.copy()
        zi[i] += h[i]
        points.append(zi)
    if many is not None:
        values = many(points)
    elif workers <= 1:
        values = [fun(p) for p in points]
    else:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            values = list(pool.map(fun, points))
    return np.column_stack([(v - f0) / hi_ for v, hi_ in zip(values, h)])


class _Problem:
    """The residual of ``target`` in the fitting coordinates of the ``active`` keys (the others at
    z0), one point or several at once; an invalid rig is a failed point."""

    def __init__(self, target: Target, rig: Rig, coords: Coordinates, z0: np.ndarray, active: np.ndarray,
                 channels: tuple[str, ...], weights: dict | None, progress) -> None:
        self.target, self.rig, self.coords, self.z0, self.active = target, rig, coords, z0, active
        self.channels, self.weights, self.progress = channels, weights, progress

    def full(self, za: np.ndarray) -> np.ndarray:
        z = np.array(self.z0, dtype=float)
        z[self.active] = za
        return z

    def rig_at(self, za: np.ndarray) -> Rig | None:
        try:
            return self.coords.apply(self.rig, self.full(za))
        except ValueError:  # the step left the rig's valid range: a failed point
            return None

    def many(self, points: list) -> list[np.ndarray]:
        if self.progress is not None:
            self.progress.update(len(points))
        return self.target.residuals([self.rig_at(p) for p in points], self.weights, self.channels)

    def __call__(self, za: np.ndarray) -> np.ndarray:
        return self.many([za])[0]


def fit_time(target: Target, rig: Rig, coords: Coordinates, z0: np.ndarray, channels: tuple[str, ...],
             max_nfev: int = 60, progress=None, weights: dict | None = None,
             active: np.ndarray | None = None) -> StageResult:
    """Stage 2 from z0 (see the module docstring) on ``target``'s runs: the ``active`` keys
    (default all) move on the ``channels``, the others stay at z0; the Jacobian's columns run
    together on the target's threads.  The result's z covers every key; its ``jac`` the active ones."""
    act = np.ones(z0.size, dtype=bool) if active is None else np.asarray(active, dtype=bool)
    problem = _Problem(target, rig, coords, np.asarray(z0, dtype=float), act, tuple(channels), weights, progress)
    lo, hi = (b[act] for b in coords.bounds())

    def jac(za: np.ndarray) -> np.ndarray:
        return forward_jacobian(problem, za, problem(za), hi, target.workers, problem.many)

    sol = least_squares(problem, np.clip(np.asarray(z0, dtype=float)[act], lo, hi), bounds=(lo, hi), method="trf",
                        jac=jac, x_scale=1.0, xtol=XTOL, ftol=FTOL, max_nfev=max_nfev)
    return StageResult(problem.full(sol.x), float(sol.cost), int(sol.nfev), sol.fun, sol.jac)


def jacobian_at(target: Target, rig: Rig, coords: Coordinates, z: np.ndarray, weights: dict | None = None,
                progress=None) -> StageResult:
    """The residual and its Jacobian over every key at z (for the uncertainty after a block-wise fit)."""
    z = np.asarray(z, dtype=float)
    problem = _Problem(target, rig, coords, z, np.ones(z.size, dtype=bool), target.channels, weights, progress)
    f0 = problem(z)
    J = forward_jacobian(problem, z, f0, coords.bounds()[1], target.workers, problem.many)
    return StageResult(z, float(f0 @ f0) / 2, 1 + z.size, f0, J)


def time_costs(target: Target, start: Rig, coords: Coordinates, candidates: dict) -> dict[str, float]:
    """The time-domain cost of each candidate (name -> z): half the sum of squares of
    (sim - measured) / std(measured) over every record and channel, i.e. of the NRMSEs the
    comparison reports (no channel weights, so that every candidate is judged alike); the
    candidates run together."""
    rigs = []
    for z in candidates.values():
        try:
            rigs.append(coords.apply(start, z))
        except ValueError:  # the candidate is no valid rig
            rigs.append(None)
    res = target.residuals(rigs)
    return {name: (float(r @ r) / 2 if rig is not None else float("inf"))
            for (name, r), rig in zip(zip(candidates, res), rigs)}


def best(costs: dict) -> str:
    """The candidate of least cost; a tie keeps the earlier one (a stage that leaves the cost
    where it was did not improve on it)."""
    names = list(costs)
    return min(names, key=lambda k: (costs[k], names.index(k)))


def keep_best(target: Target, start: Rig, coords: Coordinates, candidates: dict, bar):
    """The best of the start and the stages' results (``candidates``: name -> z, in order) by
    :func:`time_costs`; returns (the name kept, the costs, the channel weights there (1 / rms of
    each channel's residual), the residual and Jacobian over every key there)."""
    costs = time_costs(target, start, coords, candidates)
    kept = best(costs)
    weights = channel_weights(target, coords.apply(start, candidates[kept]))
    final = jacobian_at(target, start, coords, candidates[kept], weights, bar)
    return kept, costs, weights, final


def not_improved_flags(kept: str, costs: dict) -> list[str]:
    """Says so when the fit could not improve on its start (or the time stage on the frequency stage)."""
    if kept == "time":
        return []
    worse = ", ".join(f"{k} {v:.6g}" for k, v in costs.items() if k != kept)
    what = "the fit could not improve on its start" if kept == "start" else \
        "the time stage did not improve on the frequency stage"
    return [f"{what}: the result is the {kept} (time-domain cost {costs[kept]:.6g}; {worse})"]


__all__ = ["DIFF_STEP", "MAX_RK4_SUBSTEPS", "MIN_COHERENCE", "StageResult", "channel_weights", "default_workers",
           "checked_options", "fit_frequency", "fit_options", "fit_time", "forward_jacobian", "frequency_targets",
           "jacobian_at",
           "best", "keep_best", "not_improved_flags", "time_costs",
           "linear_response", "records_peak_velocity", "time_residual"]
