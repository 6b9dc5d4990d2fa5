"""Numerics of the diagnosis: records as cases, simulation with the record's own
command, normalised residuals, noise floor, screening by signatures, fitting by
simulation error, BIC and intervals.

The parts shared with ``sh.identify`` come from :mod:`servohydraulics.identification`:
the record simulation (``run.simulate_command``), the fitting coordinates
(``coordinates.Coordinates``, reciprocal where "absent" is infinite) and the
statistics (``stats``: AR(1) effective samples and the one HAC covariance rule).
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import savgol_filter

from .. import _core
from ..identification.coordinates import Coordinates
from ..identification.run import simulate_command
from ..identification.stats import LEVEL, ar1_coefficient, ar1_effective_n, noise_sigma, quantile
from ..identification.stats import covariance as hac_covariance
from ..rig import Rig
from ..simulate import METHODS, MODES, SimulationError, solver_options
from .effects import INTERACT_SPAN, LOAD_TERMS, Candidate, Context, nominal_value, set_nominal, split_delay
from .types import Case, FitResult, Screening, Sim

#: Plant channels the diagnosis does not compare: the abscissa, the valve drive (a function of the
#: command and the fed-back channels in closed loop) and the valve flow (not measured on a rig).
NOT_COMPARED = frozenset({"time", "drive", "flow"})
#: The actuator's channels, absent in free mode (a free record's force column is the applied force).
ACTUATOR_CHANNELS = frozenset({"force", "pressure", "spool"})
#: the channels of a diagnosis simulation (``Sim``), in the core's table order
SIM_CHANNELS = tuple(c for c, _ in _core.PLANT_CHANNELS if c not in NOT_COMPARED)
#: channels compared per mode (those present in the record are used)
CHANNELS = {mode: tuple(c for c in SIM_CHANNELS if not (mode == "free" and c in ACTUATOR_CHANNELS))
            for mode in MODES}
N_SEGMENTS = 6  #: held-out split: contiguous segments, even ones train, odd ones test


def make_case(rec: Any, mode: str, name: str, controller_dt: float | None = None) -> Case:
    """A record (``read_record``'s result: ``.channels``, ``.dt``) prepared for the diagnosis,
    simulated with the controller sample ``controller_dt`` [s] (None: the record's)."""
    ch = rec.channels
    t = ch["time"] - ch["time"][0]
    dt = rec.dt
    meas, scale, sigma = {}, {}, {}
    for c in CHANNELS[mode]:
        if c not in ch:
            continue
        y = np.asarray(ch[c], dtype=float)
        s = float(np.sqrt(np.mean(y ** 2)))
        if s <= 0.0:
            continue
        meas[c] = y
        scale[c] = s
        sigma[c] = max(noise_sigma(y), 1e-5 * s)
    if "displacement" not in meas:
        raise ValueError(f"{name}: column 'displacement' is all zero: nothing to diagnose")
    n = len(t)
    seg = np.minimum((np.arange(n) * N_SEGMENTS) // n, N_SEGMENTS - 1)
    train = seg % 2 == 0
    # Velocity and acceleration for the balance-equation screen: measured, or
    # Savitzky-Golay derivatives of the displacement (window ~25 ms).
    win = max(7, int(round(0.025 / dt)) | 1)
    win = min(win, (n - 1) | 1 if (n - 1) % 2 else n - 2)
    x = ch["displacement"]
    derived = {
        "displacement": savgol_filter(x, win, 3) if n > win else x,
        "velocity": ch["velocity"] if "velocity" in ch else (savgol_filter(x, win, 3, deriv=1, delta=dt)
                                                            if n > win else np.gradient(x, dt)),
        "acceleration": ch["acceleration"] if "acceleration" in ch else (
            savgol_filter(x, win, 3, deriv=2, delta=dt) if n > win else np.gradient(np.gradient(x, dt), dt)),
        "force": ch["force"] if mode != "free" else ch["command"],
    }
    derived["rms_v"] = float(np.sqrt(np.mean(derived["velocity"] ** 2)))
    x0, x0_sd = initial_displacement(t, x, sigma["displacement"])
    return Case(name, mode, dt, t, np.asarray(ch["command"], float), meas, scale, sigma, train, derived,
                x0, x0_sd, float(np.max(np.abs(derived["velocity"]))), controller_dt)


def initial_displacement(t: np.ndarray, x: np.ndarray, sigma: float) -> tuple[float, float]:
    """The displacement at t = 0 with the noise averaged out, and its standard
    deviation: x0 + a t^2 + b t^3 + c t^4 fitted to the first 100 ms (a record
    starts at rest, so x(t) has no linear term; it has a cubic one when the
    command ramps in from the first sample: an even polynomial then puts x0 off
    by several of its own standard deviations).  ``refine_x0`` then fits it
    against the model."""
    m = min(int(np.searchsorted(t, 0.1)), t.size // 20)
    if m < 6:
        return float(x[0]), sigma
    X = np.column_stack([np.ones(m), t[:m] ** 2, t[:m] ** 3, t[:m] ** 4])
    coef = np.linalg.lstsq(X, x[:m], rcond=None)[0]
    sd = sigma * math.sqrt(float(np.linalg.inv(X.T @ X)[0, 0]))
    return float(coef[0]), sd


def refine_x0(rig: Rig, cases: list[Case], tau: float) -> tuple[float, ...]:
    """Each record's initial displacement (a nuisance state, not an effect)
    fitted by simulation error with the current model, within +-4 sd of the
    estimate from the record alone (so that it cannot absorb a missing effect)."""
    out = []
    for case in cases:
        x0, sd = case.x0_data, max(case.x0_sd, 1e-8)

        def fun(z, case=case):
            return residuals([simulate_case(rig, case, tau, float(z[0]), search=True)], [case])

        try:
            res = least_squares(fun, [x0], bounds=([x0 - 4 * sd], [x0 + 4 * sd]), x_scale=[sd], diff_step=1e-3,
                                max_nfev=10)
            out.append(float(res.x[0]))
        except ValueError:
            out.append(x0)
    return tuple(out)


# --- simulation ---------------------------------------------------------------------

def run_options(search: bool):
    """The integrator of a diagnosis run.  The runs of the search (the least-squares fits'
    residuals and difference columns, the screening's signatures, the fits' starts, the initial
    displacements) use the time stage's tolerance of ``sh.identify`` (``identification.fit.FIT_RTOL``,
    1e-6: its differences are clean, 1e-2 of a column at worst on the UTFSM chirp against rtol
    1e-9); every run a decision reads (the channel statistics of the BIC, the held-out error, the
    gaps) uses the core's default (rtol 1e-8).  A search run costs 1.5 (a friction rig) to 23 (the
    UTFSM MR damper, whose default run turns stiff) times less; a fit's own runs go on RK4 where
    that agrees with this pair (``search_options``).  No run is checked by the pair's
    shadow (``stiff_check``: the diagnosis reads no flag; the results are the same to the bit).
    The pair hands a sample to its stiff integrator where Hairer's stiffness test finds it stiff
    (``stiffness_test``, ``STIFFNESS_TEST``) or past ``STIFF_STEPS`` dopri5 steps in it (100, not the
    core's 24); the stiff samples of a search run and of a decision's go to the core's error-controlled
    Rosenbrock method (``stiff_rosenbrock``, ``SEARCH_STIFF_ROSENBROCK``, ``DECISION_STIFF_ROSENBROCK``)
    rather than CVODE (the core's default)."""
    from ..identification.fit import FIT_RTOL

    opts = solver_options(rtol=FIT_RTOL if search else None, stiff_check=False)
    if STIFF_STEPS is not None:
        opts.stiff_steps = int(STIFF_STEPS)
    if SEARCH_STIFF_ROSENBROCK if search else DECISION_STIFF_ROSENBROCK:
        opts.stiff_rosenbrock = True
    opts.stiffness_test = STIFFNESS_TEST
    opts.rosenbrock_order = ROSENBROCK_ORDER
    return opts


#: dopri5's steps in one sample beyond which the pair's runs redo the sample by their stiff integrator
#: (``run_options``; None: the core's ``stiff_steps``, 24).  100: a sample of a rig re-sized by the load
#: term (the loop re-fit of a long record) that needs 25-100 steps is accuracy-limited, not stiff, and
#: dopri5 does it for less than CVODE from a restart; a stiff sample (Coulomb friction's rig) still goes
#: to the stiff integrator, 76 wasted steps later.  Measured (docs/benchmarks.md, stops 45 and 46): the
#: UTFSM 1 A sweep 2.25 times faster with the same answer; the diagnosis evaluation's records the same
#: to the last digit; the four whole-record runs of docs/diagnose.md the same names and gaps (May 1 A ->
#: 0 A at another point of the load term's flat valley).  benchmarks/lab_speed.py --stiff-steps sets another.
STIFF_STEPS: int | None = 100

#: the search's pair does its stiff samples by the core's error-controlled Rosenbrock method
#: (SolverOptions.stiff_rosenbrock: a one-step method that carries its step across the samples, where CVODE's
#: BDF restarts at each) instead of CVODE: on the stiff friction rigs a run costs 3.6 times less and is as
#: close to the decisions' rtol-1e-8 run (docs/benchmarks.md, stop 46).  False: CVODE; with
#: ``SEARCH_ROS2_SUBSTEPS = (8, 16)`` the search of stop 45 (benchmarks/lab_speed.py --search-stiff cvode).
SEARCH_STIFF_ROSENBROCK = True
#: the decisions' runs likewise, at their rtol of 1e-8: by RODAS4 (``ROSENBROCK_ORDER``) such a run is 2-10 times
#: closer to CVODE at rtol 1e-10 than the pair with CVODE for its stiff samples (docs/benchmarks.md, stop 47;
#: no faster on benchmarks/lab_speed.py's cases, whose decisions are few and mostly not stiff).
#: False: CVODE, the decisions of stop 46 (benchmarks/lab_speed.py --decision-stiff cvode)
DECISION_STIFF_ROSENBROCK = True
#: the order of that Rosenbrock method (SolverOptions.rosenbrock_order): 4, RODAS4, which on the stiff friction
#: rigs takes fewer steps than the second-order formula at the search's and the decisions' tolerances, each run
#: cheaper and closer to a tight reference (docs/benchmarks.md, stop 47; studies/pair_stiff_rodas4.py).
#: 2: stop 46's formula (benchmarks/lab_speed.py --rosenbrock-order 2)
ROSENBROCK_ORDER = 4
#: the pair's runs find a stiff sample by Hairer's stiffness test as well as by ``STIFF_STEPS``
#: (SolverOptions.stiffness_test): the dopri5 steps a stiff sample wastes before it goes to the stiff
#: integrator are fewer (docs/benchmarks.md, stop 47).  False: the step count alone (--stiffness-test off)
STIFFNESS_TEST = True


class RunCache:
    """The diagnosis' runs already made, by what determines them: the rig (its ``repr``: every
    field), the record's command (its bytes' digest), mode, sample and controller times, the
    command delay, the initial displacement and the integrator's options (their ``repr``).  A
    diagnosis runs the same model many times over (the current model as each candidate's "absent"
    in its start's and its fits' comparisons, the search's pair in ``search_options`` and
    ``agrees``: 383 of the runs of benchmarks/lab_speed.py's diagnose10, docs/benchmarks.md); a run is
    deterministic, so a repeat is served from here, the very arrays of the first (read-only).
    Least recently used runs are dropped beyond ``max_bytes``; ``clear()`` empties it.  ``diagnose``
    runs inside ``session()``, which empties it when the last of the diagnoses running at the time
    (on other threads: a lab's sweep of records) returns, not under one still running."""

    def __init__(self, max_bytes: int = 256 * 2 ** 20) -> None:
        import threading
        from collections import OrderedDict

        self.max_bytes = int(max_bytes)
        self._runs: OrderedDict = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self.hits = self.misses = 0
        self._sessions = 0

    @staticmethod
    def key(rig: Rig, case: Case, tau: float, x0: float, options) -> tuple:
        import hashlib

        u = np.ascontiguousarray(case.u, dtype=float)
        digest = hashlib.blake2b(u.tobytes(), digest_size=16).digest()
        return (repr(rig), digest, u.size, case.mode, float(case.dt), case.controller_dt, float(tau), float(x0),
                repr(options))

    def get(self, key: tuple):
        """(True, the run) where ``key`` was run before, else (False, None)."""
        with self._lock:
            if key in self._runs:
                self._runs.move_to_end(key)
                self.hits += 1
                return True, self._runs[key][0]
            self.misses += 1
        return False, None

    def put(self, key: tuple, sim: Sim | None) -> Sim | None:
        if sim is not None:
            for a in sim.values():
                a.setflags(write=False)  # shared by every caller of this run
        size = 0 if sim is None else sum(a.nbytes for a in sim.values())
        with self._lock:
            if key not in self._runs and size <= self.max_bytes:
                self._runs[key] = (sim, size)
                self._bytes += size
                while self._bytes > self.max_bytes:
                    _, (_, dropped) = self._runs.popitem(last=False)
                    self._bytes -= dropped
        return sim

    def clear(self) -> None:
        with self._lock:
            self._empty()

    def _empty(self) -> None:  # the caller holds the lock
        self._runs.clear()
        self._bytes = 0

    @contextmanager
    def session(self):
        """The runs of one diagnosis: on leaving the last open session the cache is emptied (its runs are those
        diagnoses'; a later one on other records would not hit them)."""
        with self._lock:
            self._sessions += 1
        try:
            yield self
        finally:
            with self._lock:
                self._sessions -= 1
                if self._sessions == 0:
                    self._empty()


#: the runs of the diagnosis (``RunCache``)
RUNS = RunCache()


def simulate_case(rig: Rig, case: Case, tau: float, x0: float, search: bool = False, options=None) -> Sim:
    """``run_case`` from ``RUNS`` where the same run was made before (the same arrays, read-only)."""
    opts = options if options is not None else run_options(search)
    key = RUNS.key(rig, case, tau, x0, opts)
    hit, sim = RUNS.get(key)
    if hit:
        return sim
    return RUNS.put(key, run_case(rig, case, tau, x0, options=opts))


def run_case(rig: Rig, case: Case, tau: float, x0: float, search: bool = False, options=None) -> Sim:
    """The model's channels for the record's command delayed by ``tau`` [s]
    from the initial displacement ``x0`` [m] (None if the run fails).
    The default error-controlled pair (dopri5, CVODE for its stiff samples; ``search``: at the
    search's tolerance, ``run_options``), or ``options`` where given (a fit's ``search_options``;
    where that is RK4 and its run diverges, as it does where a fit made the rig stiffer (a larger
    damping), RK4 at the next counts of ``SEARCH_RK4_LADDER``, then the search's pair: a diverging
    run stops within milliseconds of its start; where it is ROS2, which is L-stable, the pair next);
    CVODE alone if that run fails."""
    if fixed_step(options) and options.rk4_substeps > 0:
        from ..identification.fit import rk4_options

        chain = (options, *(rk4_options(n) for n in SEARCH_RK4_LADDER if n > options.rk4_substeps),
                 run_options(True))
    elif fixed_step(options):  # ROS2: L-stable, it does not diverge where a fit made the rig stiffer
        chain = (options, run_options(True))
    else:
        chain = (options if options is not None else run_options(search),)
    for opts in (*chain, solver_options(method="cvode")):
        try:
            r = simulate_command(rig, case.mode, case.u, case.dt, float(x0), opts, dt=case.controller_dt, delay=tau)
        except (SimulationError, ValueError):
            continue
        return {c: r.channels[c] for c in SIM_CHANNELS}
    return None


#: the RK4 substep counts a fit's runs may use (``search_options``), fewest first
SEARCH_RK4_SUBSTEPS = (3, 4, 6, 8)
#: the counts a diverged RK4 run tries next (each stable up to a larger damping); beyond 12 the
#: search's pair costs less (studies/diagnose_run_costs.py: the UTFSM rig with its MR damper's c0 at
#: 1e6 N s/m diverges below 8 substeps; pair 0.034 s, RK4 0.023 s at 8, 0.030 s at 12 for 10 s)
SEARCH_RK4_LADDER = (6, 8, 12)
#: the ROS2 substep counts a fit's runs may use where no RK4 count agrees (``search_options``): a rig made
#: stiff by a fast state (a regularised Coulomb law's slope F_c / v_stick, a re-sized oil column), where RK4
#: diverges or needs hundreds of substeps.  None since the search's pair does its stiff samples by the
#: error-controlled Rosenbrock (``SEARCH_STIFF_ROSENBROCK``): on those rigs the pair then costs less than ROS2 at
#: 8 and 16 fixed substeps (docs/benchmarks.md, stop 46); stop 45's search, on CVODE, had (8, 16)
SEARCH_ROS2_SUBSTEPS: tuple = ()


def fixed_step(options) -> bool:
    """Whether ``options`` is a fixed-step integrator (RK4 or ROS2): a run whose accuracy a fit checks
    against the search's pair (``agrees``), not the pair itself."""
    return options is not None and options.method in (METHODS["rk4"], METHODS["ros2"])


def ros2_options(substeps: int):
    """ROS2 at ``substeps`` per sample (``simulate.solver_options``)."""
    return solver_options(method="ros2", ros2_substeps=int(substeps))


def agreement(sim: Sim, ref: Sim, case: Case) -> tuple[float, float]:
    """How far the run ``sim`` is from the run ``ref`` over the record's compared channels: (the
    largest difference, the largest rms difference of a channel), each as a fraction of the measured
    channel's standard deviation ((inf, inf) when either run failed)."""
    if sim is None or ref is None:
        return math.inf, math.inf
    worst, rms = 0.0, 0.0
    for c, y in case.meas.items():
        d = (np.asarray(sim[c]) - np.asarray(ref[c])) / max(float(np.std(y)), 1e-300)
        worst, rms = max(worst, float(np.max(np.abs(d)))), max(rms, float(np.sqrt(np.mean(d ** 2))))
    return (worst, rms) if math.isfinite(worst) and math.isfinite(rms) else (math.inf, math.inf)


def search_options(rig: Rig, cases: list[Case], tau: float, x0s) -> list:
    """The integrator of a fit's runs, per record, chosen as ``sh.identify`` chooses its time stage's
    (``identification.fit.RK4_SUBSTEPS``): RK4 at the fewest substeps of ``SEARCH_RK4_SUBSTEPS`` whose
    run of ``rig`` (the fit's start: a candidate's parameters change the rig's stiffness, so each fit
    checks its own) agrees with the search's error-controlled pair (``run_options(True)``) to
    ``segments.AGREEMENT`` (largest) and ``AGREEMENT_RMS`` (rms) of each channel's standard
    deviation; else ROS2 at the fewest of ``SEARCH_ROS2_SUBSTEPS`` that agrees (none by default; stop 45's
    search, the pair's stiff samples by CVODE, had (8, 16)); the pair where none does
    (a rig too stiff for RK4: a regularised Coulomb law, a re-sized oil column; a Coulomb friction's
    switch that a fixed step straddles on a large, fast record).
    A fixed step also keeps the residual a smooth function of the parameters (clean difference
    columns).  ``fit`` checks the result again (``agrees``)."""
    from ..identification.fit import rk4_options
    from ..identification.segments import AGREEMENT, AGREEMENT_RMS

    out = []
    for case, x0 in zip(cases, x0s):
        pair = run_options(True)
        ref = simulate_case(rig, case, tau, x0, options=pair)
        chosen = pair
        if ref is not None:
            ladder = [rk4_options(n) for n in SEARCH_RK4_SUBSTEPS] + [ros2_options(n) for n in SEARCH_ROS2_SUBSTEPS]
            for opts in ladder:
                worst, rms = agreement(simulate_case(rig, case, tau, x0, options=opts), ref, case)
                if worst <= AGREEMENT and rms <= AGREEMENT_RMS:
                    chosen = opts
                    break
        out.append(chosen)
    return out


def agrees(rig: Rig, cases: list[Case], tau: float, x0s, options: list) -> bool:
    """Whether the runs of ``rig`` by ``options`` (per record) agree with the search's pair
    (``search_options``' test); true where a record's option is the pair itself."""
    from ..identification.segments import AGREEMENT, AGREEMENT_RMS

    for case, x0, opts in zip(cases, x0s, options):
        if not fixed_step(opts):  # the pair itself
            continue
        worst, rms = agreement(simulate_case(rig, case, tau, x0, options=opts),
                               simulate_case(rig, case, tau, x0, search=True), case)
        if not (worst <= AGREEMENT and rms <= AGREEMENT_RMS):
            return False
    return True


def residuals(sims: list, cases: list[Case], which: str = "all", weights: dict | None = None) -> np.ndarray:
    """Stacked normalised residuals (measured - simulated) / rms(measured), each (record, channel)
    series times its weight in ``weights`` (default 1)."""
    out = []
    for sim, case in zip(sims, cases):
        mask = {"all": slice(None), "train": case.train, "test": ~case.train}[which]
        for c, y in case.meas.items():
            e = (y - sim[c]) / case.scale[c] if sim is not None else np.full(y.size, 10.0)
            out.append(e[mask] * (weights.get((case.name, c), 1.0) if weights else 1.0))
    return np.concatenate(out)


def likelihood_weights(stats: dict) -> dict:
    """Channel weights that make a least-squares fit follow the BIC's -2 log L,
    sum_c n_eff,c log SSR_c, about the model of ``stats`` (its first-order expansion):
    sqrt(n_eff,c / SSR_c) per (record, channel), scaled to a geometric mean of 1."""
    ne = n_eff(stats)
    w = {k: math.sqrt(ne[k] / max(s["ssr"], 1e-300)) for k, s in stats.items()}
    g = math.exp(sum(math.log(v) for v in w.values()) / len(w))
    return {k: v / g for k, v in w.items()}


def channel_stats(sims: list, cases: list[Case], which: str = "all") -> dict:
    """Per (record, channel): normalised SSR, count, lag-1 autocorrelation, noise-floor SSR."""
    out = {}
    for sim, case in zip(sims, cases):
        mask = {"all": np.ones(case.t.size, bool), "train": case.train, "test": ~case.train}[which]
        for c, y in case.meas.items():
            e = ((y - sim[c]) / case.scale[c] if sim is not None else np.full(y.size, 10.0))[mask]
            out[(case.name, c)] = {
                "ssr": float(e @ e), "n": int(e.size), "rho": ar1_coefficient(e),
                "floor": float(e.size * (case.sigma[c] / case.scale[c]) ** 2),
            }
    return out


def n_eff(stats: dict) -> dict:
    """Effective sample size per channel from the residual's lag-1 autocorrelation:
    n (1 - rho) / (1 + rho), at least 10."""
    return {k: max(10.0, ar1_effective_n(s["n"], s["rho"])) for k, s in stats.items()}


def bic(stats: dict, k: int, neff: dict) -> float:
    """BIC with a per-channel unknown noise variance and effective sample sizes:
    sum_c n_eff,c log(SSR_c / n_c) + k log(sum_c n_eff,c)."""
    total = sum(neff.values())
    return float(sum(neff[c] * math.log(max(s["ssr"], 1e-300) / s["n"]) for c, s in stats.items())
                 + k * math.log(total))


def gap(sims: list, cases: list[Case]) -> dict:
    """Normalised RMS gap per channel (over all records): rms(meas - sim) / rms(meas)."""
    num, den = {}, {}
    for sim, case in zip(sims, cases):
        for c, y in case.meas.items():
            e = y - sim[c] if sim is not None else y * 10
            num[c] = num.get(c, 0.0) + float(e @ e)
            den[c] = den.get(c, 0.0) + float(y @ y)
    return {c: math.sqrt(num[c] / den[c]) for c in num}


#: an effect must close at least this share of the nominal model's gap above the noise floor on some channel
#: (``share_closed``): significant but smaller corrections (a mass 0.07 % off at 55 dB) are not named
MATERIAL_MIN = 0.01
#: a channel whose nominal gap is within this factor of its noise floor has no gap to close (left out of
#: ``share_closed``)
MATERIAL_FLOOR = 1.1


def share_closed(now: dict, fitted: dict, nominal: dict, floor: dict) -> float | None:
    """The largest share of the nominal model's gap above the noise floor that a fit closes on one channel:
    the largest over the channels of (gap now - gap fitted) / (nominal gap - floor).  A measure of size only
    (what one channel costs another is the BIC's to weigh); channels whose nominal gap is within
    ``MATERIAL_FLOOR`` of their floor (nothing to close) are left out; None when none is left."""
    den = {c: nominal[c] - floor[c] for c in nominal if nominal[c] > MATERIAL_FLOOR * floor[c]}
    if not den:
        return None
    return float(max((now[c] - fitted[c]) / d for c, d in den.items()))


def floor_gap(cases: list[Case]) -> dict:
    """The gap that measurement noise alone leaves, per channel."""
    num, den = {}, {}
    for case in cases:
        for c, y in case.meas.items():
            num[c] = num.get(c, 0.0) + y.size * case.sigma[c] ** 2
            den[c] = den.get(c, 0.0) + float(y @ y)
    return {c: math.sqrt(num[c] / den[c]) for c in num}


def at_noise_floor(stats: dict, margin: float = 0.05) -> bool:
    """True if every channel's residual variance is within (1 + margin) of its
    noise floor, or within four standard deviations of a chi-square with n_eff
    degrees of freedom if that is wider."""
    ne = n_eff(stats)
    return all(s["ssr"] <= s["floor"] * (1 + max(margin, 4 * math.sqrt(2 / ne[k]))) for k, s in stats.items())


# --- parameters in fitting coordinates ---------------------------------------------------

@dataclass
class Space:
    """A candidate's fitted parameters (main + interacting) in fitting coordinates
    (reciprocals where "absent" is infinite)."""

    cand: Candidate
    ctx: Context
    interacting: tuple[tuple[str, str], ...]

    def __post_init__(self) -> None:
        c = self.cand
        mask = np.asarray(c.active(self.ctx) if c.active is not None else [True] * len(c.params), bool)
        self.main_idx = np.flatnonzero(mask)
        self.params = tuple(c.params[i] for i in self.main_idx)
        self.full_absent = np.asarray(c.absent(self.ctx), float)  #: every own parameter, external units
        self.n_main = len(self.params)
        # interacting nominal parameters: +-INTERACT_SPAN about the current value, except the load-dependent
        # loop terms (effects.LOAD_TERMS), which range over their whole span ("off" included)
        terms = [LOAD_TERMS.get(k) for k, _ in self.interacting]
        rec = [p.reciprocal for p in self.params] + [t is not None and t.reciprocal for t in terms]
        self.rec = np.array(rec, bool)
        self.coords = Coordinates.absolute([p.key for p in self.params] + [k for k, _ in self.interacting], self.rec)
        lo, hi = c.bounds(self.ctx)
        lo, hi = np.asarray(lo, float)[self.main_idx], np.asarray(hi, float)[self.main_idx]
        cur = np.array([nominal_value(self.ctx.rig, k) for k, _ in self.interacting], float)
        span = [t.bounds(self.ctx) if t is not None else (v * (1 - INTERACT_SPAN), v * (1 + INTERACT_SPAN))
                for t, v in zip(terms, cur)]
        ext_lo = np.concatenate([lo, [a for a, _ in span]])
        ext_hi = np.concatenate([hi, [b for _, b in span]])
        self.lo = np.where(self.rec, np.where(ext_hi >= 1e9, 0.0, 1.0 / ext_hi), ext_lo)
        self.hi = np.where(self.rec, 1.0 / np.maximum(ext_lo, 1e-300), ext_hi)
        self.absent = self.to_internal(np.concatenate([self.full_absent[self.main_idx], cur]))
        probe = self.to_internal(np.concatenate([np.asarray(c.probe(self.ctx), float)[self.main_idx], cur]))
        self.probe = np.clip(probe, self.lo, self.hi)
        # the scale of each parameter (the least-squares x_scale and the covariance's column scaling): the probe's
        # step from "absent"; where the probe does not move a parameter (a Bouc-Wen yield displacement while its
        # yield force is "absent"), a tenth of its value (a scale of 1e-12 made its Jacobian column vanish in the
        # covariance: its interval came out infinite or zero-wide, 6 of the 10 misses of the evaluation's coverage)
        step = np.abs(self.probe - self.absent)
        tenth = 0.1 * np.maximum(np.abs(self.absent), np.abs(self.probe))
        self.scale = np.where(np.arange(step.size) < self.n_main, np.maximum(np.where(step > 0, step, tenth), 1e-12),
                              np.maximum(np.abs(self.absent) * 0.1, 1e-30))
        #: own parameters whose interval is tested against "absent"
        self.tests_absent = np.array([p.tests_absent for p in self.params] + [False] * len(self.interacting), bool)

    def to_internal(self, ext: np.ndarray) -> np.ndarray:
        return self.coords.z(ext)

    def to_external(self, z: np.ndarray) -> np.ndarray:
        return self.coords.values(z)

    def own_parameters(self, ext_main: np.ndarray) -> np.ndarray:
        """Every own parameter of the candidate (external units): the fitted
        ones from ``ext_main``, the inactive ones at "absent"."""
        main = self.full_absent.copy()
        main[self.main_idx] = np.asarray(ext_main, float)[: self.n_main]
        return main

    def rig_and_tau(self, z: np.ndarray, base_tau: float) -> tuple[Rig, float]:
        ext = self.to_external(z)
        main = self.own_parameters(ext)
        rig, tau = self.cand.apply(self.ctx.rig, main), base_tau
        if self.cand.delays_command:
            tau += split_delay(main[0])[1]
        for (key, _), v in zip(self.interacting, ext[self.n_main:]):
            rig = set_nominal(rig, key, v)
        return rig, tau


#: candidates whose ``apply`` also rescales another effect's rig key (stiffness_error scales k_2 with k):
#: applied first in a joint fit so that the other effect's own value is set after it
_APPLY_FIRST = ("stiffness_error",)


class JointSpace:
    """The parameters of several accepted effects fitted together (the joint
    re-fit): first each effect's own (main) parameters, a block per effect in
    its own fitting coordinates and bounds (the ``Space`` of the round that
    accepted it), then the nominal parameters the effects' kept interacting
    re-fits moved (each key once, with the bounds of the last effect that
    re-fitted it; a key that is also an effect's own parameter is fitted as
    that).  The effects are applied on top of ``base``, the model the greedy
    rounds built, in the order given (``stiffness_error`` first: it rescales
    k_2); a command delay adds to the base delay passed to ``rig_and_tau``.
    Duck-types ``Space`` for ``fit``, ``covariance``, ``intervals`` and
    ``joint_excludes_absent``."""

    def __init__(self, spaces: list[Space], base: Rig) -> None:
        self.spaces = list(spaces)
        self.base = base
        sizes = [sp.n_main for sp in self.spaces]
        edges = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        #: slice of each effect's own parameters in the joint vector (order of ``spaces``)
        self.blocks = [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
        self.n_main = int(edges[-1])
        own = {prm.key for sp in self.spaces for prm in sp.params}
        last: dict[str, tuple[int, int]] = {}
        for i, sp in enumerate(self.spaces):
            for jj, (key, _) in enumerate(sp.interacting):
                if key not in own:
                    last[key] = (i, sp.n_main + jj)
        #: (space index, index in that space's vector) of each re-fitted nominal parameter
        self.inter_src = list(last.values())
        self.interacting = tuple(self.spaces[i].interacting[j - self.spaces[i].n_main] for i, j in self.inter_src)

        def cat(attr: str) -> np.ndarray:
            return np.concatenate([getattr(sp, attr)[: sp.n_main] for sp in self.spaces]
                                  + [np.asarray([getattr(self.spaces[i], attr)[j] for i, j in self.inter_src],
                                                getattr(self.spaces[0], attr).dtype)])

        self.params = tuple(prm for sp in self.spaces for prm in sp.params)
        self.rec = cat("rec").astype(bool)
        self.coords = Coordinates.absolute([p.key for p in self.params] + [k for k, _ in self.interacting], self.rec)
        self.lo, self.hi, self.absent, self.probe, self.scale = (cat(a) for a in ("lo", "hi", "absent", "probe",
                                                                                  "scale"))
        self.tests_absent = cat("tests_absent").astype(bool)
        first = [i for i, sp in enumerate(self.spaces) if sp.cand.name in _APPLY_FIRST]
        self.order = first + [i for i in range(len(self.spaces)) if i not in first]

    def index_of(self, key: str) -> int | None:
        """Index of a rig key in the joint vector (an effect's own non-reciprocal
        parameter or a re-fitted nominal parameter), or None."""
        for (k, _), j in zip(self.interacting, range(self.n_main, self.n_main + len(self.interacting))):
            if k == key:
                return j
        for sp, blk in zip(self.spaces, self.blocks):
            for jj, prm in enumerate(sp.params):
                if prm.key == key and not prm.reciprocal:
                    return blk.start + jj
        return None

    def to_internal(self, ext: np.ndarray) -> np.ndarray:
        return self.coords.z(ext)

    def to_external(self, z: np.ndarray) -> np.ndarray:
        return self.coords.values(z)

    def rig_and_tau(self, z: np.ndarray, base_tau: float) -> tuple[Rig, float]:
        """The model with every effect at its block of ``z``, the re-fitted
        nominal parameters at theirs, and the command delay (``base_tau`` plus
        any fitted delay) [s]."""
        ext = self.to_external(z)
        rig, tau = self.base, base_tau
        for i in self.order:
            sp = self.spaces[i]
            main = sp.own_parameters(ext[self.blocks[i]])
            rig = sp.cand.apply(rig, main)
            if sp.cand.delays_command:
                tau += split_delay(main[0])[1]
        for (key, _), v in zip(self.interacting, ext[self.n_main:]):
            rig = set_nominal(rig, key, v)
        return rig, tau


def simulate_all(rig: Rig, cases: list[Case], tau: float, x0s, search: bool = False, options=None) -> list[Sim]:
    """``simulate_case`` of every record, each from its initial displacement in ``x0s`` [m]
    (``search``: at the search's tolerance, ``run_options``; ``options``: per record, a fit's
    ``search_options``)."""
    opts = [None] * len(cases) if options is None else options
    return [simulate_case(rig, c, tau, x0, search, o) for c, x0, o in zip(cases, x0s, opts)]


_POOL = None


def workers():
    """The map of the fits' difference columns: a thread pool of ``fit.default_workers()`` threads
    (the core releases the GIL while it simulates; scipy's ``least_squares(workers=...)`` keeps the
    columns, and so the fit, identical to the serial ones), None on one core."""
    global _POOL
    from concurrent.futures import ThreadPoolExecutor

    from ..identification.fit import default_workers

    n = default_workers()
    if n <= 1:
        return None
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=n, thread_name_prefix="diagnose")
    return _POOL.map


# --- screening ----------------------------------------------------------------------------

def secant_screen(space: Space, cases: list[Case], x0s, r0: np.ndarray, base_tau: float) -> Screening:
    """Regress the current residual ``r0`` on the effect's signature: the change
    of the simulated channels (from the initial displacements ``x0s``) between
    "absent" and a probe value of each parameter.  Returns the explained
    fraction of the residual and the implied estimate."""
    cols = []
    for i in range(space.n_main):
        z = space.absent.copy()
        z[i] = space.probe[i]
        rig, tau = space.rig_and_tau(z, base_tau)
        sims = simulate_all(rig, cases, tau, x0s, search=True)
        if any(s is None for s in sims):
            return Screening(0.0, space.probe.copy(), None, failed=True)
        cols.append(-(residuals(sims, cases) - r0))  # change of the normalised simulation
    D = np.column_stack(cols)
    alpha, *_ = np.linalg.lstsq(D, r0, rcond=None)
    z0 = space.absent.copy()
    z0[: space.n_main] = space.absent[: space.n_main] + alpha * (space.probe[: space.n_main]
                                                                 - space.absent[: space.n_main])
    z0 = np.clip(z0, space.lo, space.hi)
    alpha_c = np.where(np.abs(space.probe[: space.n_main] - space.absent[: space.n_main]) > 0,
                       (z0[: space.n_main] - space.absent[: space.n_main])
                       / np.where(space.probe[: space.n_main] == space.absent[: space.n_main], 1.0,
                                  space.probe[: space.n_main] - space.absent[: space.n_main]), 0.0)
    rr = float(r0 @ r0)
    res = r0 - D @ alpha_c
    score = max(0.0, 1.0 - float(res @ res) / rr) if rr > 0 else 0.0
    return Screening(score, z0, D @ alpha_c)


def balance_screen(rig: Rig, cases: list[Case], signature) -> float:
    """R^2 of the structure's equation-of-motion residual regressed on one effect's
    signature: e = F - (m a + f_s(x) + c v + F_f(v, z = 0)) with measured (or
    differentiated) displacement, velocity, acceleration and force, the
    structure's forces from the core (``Dynamics.structure_forces``, Eq 5).
    The friction is the static law with its Stribeck level; with LuGre friction
    the bristle deflection z is not measured and is taken as 0, so F_f is only
    the bristle damping sigma_1 v (the screen then sees the rest of the
    friction as residual)."""
    es, ss = [], []
    for case in cases:
        d = case.derived
        x, v, a, F = d["displacement"], d["velocity"], d["acceleration"], d["force"]
        structure = _core.Dynamics(rig, MODES[case.mode]).structure_forces(x, v)
        e = F - (rig.m * a + structure)
        s = signature(rig, d)  # the record's derived channels (and rms_v)
        n = x.size
        cut = slice(n // 50, n - n // 50)  # drop the filter's edge samples
        es.append(e[cut] / max(np.sqrt(np.mean(F ** 2)), rig.k * np.sqrt(np.mean(x ** 2)), 1e-9))
        ss.append(s[cut])
    e, s = np.concatenate(es), np.concatenate(ss)
    e = e - e.mean()
    s = s - s.mean()
    den = float(s @ s) * float(e @ e)
    return float((s @ e) ** 2 / den) if den > 0 else 0.0


# --- fitting ----------------------------------------------------------------------------

def fit(space: Space, cases: list[Case], z0: np.ndarray, base_tau: float, which: str, x0s,
        max_nfev: int = 30, weights: dict | None = None) -> FitResult:
    """Bounded least-squares fit of the candidate's parameters by simulation error,
    with each record's initial displacement co-fitted as a nuisance parameter
    (started from ``x0s``, within +-4 sd of its estimate from the record alone):
    an initial state refined against the model without the effect is biased
    towards hiding it (in a free decay a 40 um offset is a third of F_c / k).
    The result's ``jac`` and ``nuisance_scale`` include the x0 columns (for the
    intervals).  ``weights``: per (record, channel) factors of the residual (``residuals``).

    The runs use ``search_options`` at the start (RK4 at the fewest agreeing substeps, else the
    search's pair); when the RK4 runs of the result no longer agree with the pair's (the fit moved
    the candidate somewhere stiffer), the fit goes on from there on the pair's runs (``FIT_CONTINUATION``
    ``"pair"``, the default), or (``"search"``) on ``search_options`` chosen again there, checked again at
    its result and, where that no longer agrees either, on the pair's."""
    sd = np.array([max(c.x0_sd, 1e-8) for c in cases])
    cen = np.array([c.x0_data for c in cases])
    lo = np.concatenate([space.lo, cen - 4 * sd])
    hi = np.concatenate([space.hi, cen + 4 * sd])
    p = space.n_main + len(space.interacting)
    zs = np.concatenate([np.asarray(z0, float), np.clip(np.asarray(x0s, float), cen - 4 * sd, cen + 4 * sd)])
    zs = np.clip(zs, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))

    def run(zs: np.ndarray, options: list):
        def fun(z):
            rig, tau = space.rig_and_tau(z[:p], base_tau)
            return residuals(simulate_all(rig, cases, tau, z[p:], options=options), cases, which, weights)

        ftol = fit_ftol(fun(zs), series_lengths(cases, which))  # its run is the fit's first: served by RUNS
        return least_squares(fun, zs, bounds=(lo, hi), x_scale=np.concatenate([space.scale, sd]), diff_step=1e-3,
                             max_nfev=max_nfev, method="trf", xtol=1e-6, ftol=ftol, workers=workers())

    rig0, tau0 = space.rig_and_tau(zs[:p], base_tau)
    options = search_options(rig0, cases, tau0, zs[p:])
    res = run(zs, options)
    nfev = int(res.nfev)
    rechosen = FIT_CONTINUATION == "search"
    while any(fixed_step(o) for o in options):
        rig1, tau1 = space.rig_and_tau(res.x[:p], base_tau)
        if agrees(rig1, cases, tau1, res.x[p:], options):
            break
        z1 = np.clip(res.x, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
        if rechosen:  # once: the integrator chosen again where the fixed step stopped agreeing
            options, rechosen = search_options(rig1, cases, tau1, z1[p:]), False
        else:
            options = [run_options(True)] * len(cases)
        res = run(z1, options)
        nfev += int(res.nfev)
    return FitResult(z=res.x[:p].copy(), x0=res.x[p:].copy(), jac=res.jac, fun=res.fun, nuisance_scale=sd,
                     nfev=nfev)


#: the decisions' -2 log likelihood a fit's step must gain for the fit to go on (``fit_ftol``): a parameter a
#: tenth of its standard error from the optimum costs 0.01, so the values and intervals the report gives are not
#: moved by where the fit stopped (0.25, a fortieth of the BIC's threshold, moved one of the evaluation's valve
#: bandwidths by 0.8 of its standard error and its interval off the truth: docs/benchmarks.md, "Stop 47")
FIT_STEP_GAIN = 0.01
#: the fits' relative stopping tolerance at most (``fit_ftol``): sh.identify's (``identification.fit.FTOL``)
FIT_FTOL_MAX = 1e-4


def fit_ftol(r: np.ndarray, lengths: list[int]) -> float:
    """The relative cost reduction below which a fit's step ends it (least_squares' ``ftol``): the step's gain
    in the decisions' statistic, -2 log L = sum over the series of n_eff log SSR, about ``FIT_STEP_GAIN``
    (the BIC and held-out tests ask for 10).  A relative reduction d of the cost gains
    about d sum(n_eff) there, n_eff each (record, channel) series' AR(1) effective sample size at the fit's
    start ``r`` (its residuals, stacked as ``residuals`` does; ``lengths``: the series' lengths), so the
    tolerance is ``FIT_STEP_GAIN / sum(n_eff)``, at most ``FIT_FTOL_MAX`` (3.9e-6 on the first 10 s of the UTFSM
    1 A chirp, n_eff 2,566 through the 0 A rig).  Before stop 47 it was 1e-8 whatever the record, and a fit went
    on to its evaluation budget on steps that no decision could see (docs/benchmarks.md, "Stop 47")."""
    parts = np.split(np.asarray(r, float), np.cumsum(lengths)[:-1])
    n = sum(max(1.0, ar1_effective_n(x.size, ar1_coefficient(x))) for x in parts if x.size > 2)
    return float(min(FIT_FTOL_MAX, FIT_STEP_GAIN / max(n, 1.0)))


#: where a fit goes on when its fixed step's result no longer agrees with the search's pair (``fit``): "pair"
#: (the default) or "search" (``search_options`` chosen again at that point, then the pair): a measurement's
#: switch (benchmarks/lab_speed.py ``--continuation``; docs/benchmarks.md, "Stop 44"), not a user setting
FIT_CONTINUATION = "pair"


def series_lengths(cases: list[Case], which: str = "all") -> list[int]:
    """Lengths of the (record, channel) series stacked by ``residuals``, in order."""
    out = []
    for case in cases:
        m = {"all": case.t.size, "train": int(case.train.sum()), "test": int((~case.train).sum())}[which]
        out += [m] * len(case.meas)
    return out


def covariance(space: Space, res: FitResult, lengths: list[int]) -> np.ndarray:
    """The covariance of the candidate's parameters in fitting coordinates: the HAC sandwich of
    ``identification.stats.covariance`` (the rule ``sh.identify`` uses) over the parameters and
    the records' initial displacements (scaled by ``space.scale`` and their standard deviations),
    the initial displacements then marginalised out.  A parameter the data do not determine has
    an infinite variance."""
    scale = np.concatenate([space.scale, res.nuisance_scale])[: res.jac.shape[1]]
    return hac_covariance(res.jac, res.fun, scale, lengths).block(space.scale.size).matrix


def uncertainty(space: Space, res: FitResult, lengths: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """95 % intervals (fitting coordinates) from the HAC sandwich ``covariance`` and the
    parameters' correlation matrix (NaN where a variance is infinite or zero)."""
    scale = np.concatenate([space.scale, res.nuisance_scale])[: res.jac.shape[1]]
    cov = hac_covariance(res.jac, res.fun, scale, lengths).block(space.scale.size)
    sd = np.sqrt(np.maximum(np.diag(cov.matrix), 0.0))
    z = res.z[: sd.size]
    q = quantile(LEVEL)
    return z - q * sd, z + q * sd, cov.correlation


def intervals(space: Space, res: FitResult, lengths: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """95 % intervals (fitting coordinates) from the HAC sandwich ``covariance``."""
    lo, hi, _ = uncertainty(space, res, lengths)
    return lo, hi


def joint_excludes_absent(space: Space, res: FitResult, lengths: list[int], tested: np.ndarray) -> tuple[bool, float]:
    """Joint 95 % test that the effect is present: the Wald statistic of the
    tested own parameters against "absent", (z - z_0)' C^-1 (z - z_0) with C
    their HAC covariance, against the chi-square 95 % point with as many degrees
    of freedom.  For a two-parameter effect whose parameters trade against each
    other (a valve's f_v and zeta_v at low frequency) each interval alone can
    include "absent" while the pair clearly does not.  Returns (excluded, p-value)."""
    from scipy.stats import chi2

    idx = np.flatnonzero(tested)
    if idx.size == 0:
        return False, 1.0
    C = covariance(space, res, lengths)[np.ix_(idx, idx)]
    if not np.all(np.isfinite(C)):
        return False, 1.0
    d = (res.z[: space.absent.size] - space.absent)[idx]
    w = float(d @ np.linalg.pinv(C, rcond=1e-12) @ d)
    pval = float(chi2.sf(w, idx.size))
    return pval < 0.05, pval
