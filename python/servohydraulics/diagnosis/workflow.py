"""The diagnosis workflow: nominal gap, then rounds of screening, shortlisting,
confirmation by simulation-error fits and a decision (accept by BIC with
effective sample sizes, held-out error and intervals; ambiguous; stop), greedy
for a second and third effect, a joint re-fit of the accepted effects after each
one from the second on, the loop re-fits once the actuator is re-sized, the
restoring re-fit where the model tracks a channel worse than the nominal one,
verdict."""

from __future__ import annotations

import copy
import dataclasses
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..identification.checks import gate, run_checks, settle
from ..identification.records import as_records
from ..identification.run import controller_ratio, simulate_command
from ..identification.stats import precision_order
from ..rig import Rig, rig_to_dict
from ..simulate import MODES, SimulationError
from ..workers import single_blas_thread
from . import engine
from .confirm import confirm, param_groups, param_report
from .effects import LIBRARY, Context, check_names, interacting, nested, separating_experiment
from .joint import RESTORE_HEAD, joint_refit, loop_refit, loop_refit_displacement, restore_refit, worse_than_nominal
from .types import Accepted, CandidateLog, Case, Fit, JointRefit, Round, Screening, Sim

#: acceptance thresholds (documented in docs/diagnose.md)
DELTA_BIC_MIN = 10.0  #: "very strong" evidence on the Kass-Raftery scale
DELTA_FIT_AMBIGUOUS = 6.0  #: two passing candidates whose fits (-2 log L) differ by less are "equally good"
HELDOUT_MIN = 0.02  #: held-out SSR must fall by at least 2 % ...
#: ... or, for effects small against the noise, significantly: the held-out -2 log likelihood (effective
#: sample sizes of the held-out residual before the effect) must fall by at least this much
HELDOUT_LR_MIN = 10.0
KEEP = 3  #: candidates kept by screening for the full fit
MAX_EFFECTS = 3


@dataclass
class Diagnosis:
    """What ``diagnose`` found; ``to_dict()`` is the content of diagnosis.json."""

    verdict: str  #: "effect_found", "no_effect" or "ambiguous"
    #: per effect added, in order: name, doc, parameters (key -> value, unit, interval_95, absent, rig_key),
    #: delta_bic, heldout_improvement, gap_after, round and (command_delay) note
    effects: list[dict[str, Any]]
    gap_before: dict[str, float]  #: channel -> normalised RMS gap of the nominal model
    gap_after: dict[str, float]  #: channel -> normalised RMS gap of the final model
    candidates: list[CandidateLog]  #: every candidate of every round
    rig: Rig  #: the nominal rig with the effects added
    mode: str
    records: list[str]
    noise_floor: dict[str, float] = field(default_factory=dict)
    gap_closed: dict[str, float | None] = field(default_factory=dict)
    gap_where: dict[str, Any] = field(default_factory=dict)
    ambiguous_between: list[str] = field(default_factory=list)
    separating_experiment: str = ""
    #: the joint re-fits of the accepted effects (one per round from the second effect on; the last is the final one)
    joint_refit: list[JointRefit] = field(default_factory=list)
    #: every fitted parameter of the effects, from the best determined to the worst (``stats.precision_order``)
    determined: list[dict[str, Any]] = field(default_factory=list)
    #: groups of parameters ("effect: key") the records cannot tell apart (``stats.inseparable_groups``)
    inseparable: list[list[str]] = field(default_factory=list)
    command_delay: float = 0.0  #: the model's command delay (rig command_delay + record shift) [s]
    record_shift: float = 0.0  #: the part of it < 0: the record's command shifted (response rows lead it) [s]
    summary: str = ""
    runtime_s: float = 0.0
    checks: list = field(default_factory=list)  #: the records' plausibility checks (``identification.checks``)
    dt: float | None = None  #: the controller sample time the records were simulated with [s] (None: each record's)
    #: arrays for the report (not in the JSON): cases, sims_before, sims_after, history, signatures
    plots: dict[str, Any] = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "verdict": self.verdict,
            "summary": self.summary,
            "mode": self.mode,
            "records": self.records,
            "effects": self.effects,
            "determined": self.determined,
            "inseparable": self.inseparable,
            "joint_refit": [j.to_dict() for j in self.joint_refit],
            "gap_before": self.gap_before,
            "gap_after": self.gap_after,
            "noise_floor": self.noise_floor,
            "gap_closed": self.gap_closed,
            "gap_where": self.gap_where,
            "candidates": [c.to_dict() for c in self.candidates],
            "ambiguous_between": self.ambiguous_between,
            "separating_experiment": self.separating_experiment,
            "command_delay_s": self.command_delay,
            "record_shift_s": self.record_shift,
            "rig_updated": rig_to_dict(self.rig),
            "runtime_s": self.runtime_s,
            "controller_dt_s": self.dt,
            "checks": [c.to_dict() for c in self.checks],
        }

    def write(self, out: str | Path) -> Path:
        """Writes diagnosis.json, rig_updated.toml and report.md (with plots) to ``out``."""
        from .report import write_outputs

        return write_outputs(self, Path(out))


def _progress(total: int, enabled: bool, desc: str):
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, disable=not enabled, file=sys.stderr, leave=False,
                bar_format="{desc}: {n_fmt}/{total_fmt} {bar} {elapsed} {postfix}")


def gap_where(sims: list, cases: list[Case]) -> dict:
    """Where the gap sits, for the channel with the largest normalised gap:
    residual rms by time segment, frequency band, |displacement| quartile,
    velocity sign and |velocity| (reversals vs. motion)."""
    g = engine.gap(sims, cases)
    ch = max(g, key=g.get)
    e = np.concatenate([(c.meas[ch] - s[ch]) / c.scale[ch] for s, c in zip(sims, cases)])
    x = np.concatenate([c.derived["displacement"] for c in cases])
    v = np.concatenate([c.derived["velocity"] for c in cases])
    dt = cases[0].dt

    def rms(m):
        return float(np.sqrt(np.mean(e[m] ** 2))) if np.any(m) else float("nan")

    n = e.size
    seg = np.minimum(np.arange(n) * 10 // n, 9)
    out: dict[str, Any] = {"channel": ch, "time_deciles": [rms(seg == i) for i in range(10)]}
    spec = np.abs(np.fft.rfft(e - e.mean())) ** 2
    f = np.fft.rfftfreq(n, dt)
    bands = [(0, 1), (1, 3), (3, 10), (10, 30), (30, 100), (100, 1 / (2 * dt))]
    tot = float(spec.sum()) or 1.0
    out["frequency_share"] = {f"{a:g}-{b:g} Hz": float(spec[(f >= a) & (f < b)].sum() / tot) for a, b in bands}
    q = np.quantile(np.abs(x), [0.25, 0.5, 0.75])
    ax = np.abs(x)
    out["abs_displacement_quartiles"] = [rms(ax <= q[0]), rms((ax > q[0]) & (ax <= q[1])),
                                         rms((ax > q[1]) & (ax <= q[2])), rms(ax > q[2])]
    out["velocity_sign"] = {"positive": rms(v > 0), "negative": rms(v <= 0)}
    vs = np.quantile(np.abs(v), 0.2)
    out["velocity_magnitude"] = {"near_reversal": rms(np.abs(v) <= vs), "moving": rms(np.abs(v) > vs)}
    return out


# --- the state of a diagnosis ----------------------------------------------------------

@dataclass(frozen=True, eq=False)
class _Setup:
    """What stays fixed over the rounds."""

    nominal: Rig
    mode: str
    cases: list[Case]
    names: list[str]
    keep: int
    refit_interacting: bool
    joint_refit: bool
    bar: Any = None  #: the progress bar (set once the nominal model runs)


@dataclass(eq=False)
class _State:
    """The model the rounds have built so far (``_accept`` moves it on)."""

    rig: Rig
    tau: float  #: command delay [s]
    x0: tuple[float, ...]  #: each record's fitted initial displacement [m]
    sims: list[Sim]
    effects: list[dict[str, Any]] = field(default_factory=list)
    accepted: list[Accepted] = field(default_factory=list)
    log: list[CandidateLog] = field(default_factory=list)
    joint_log: list[JointRefit] = field(default_factory=list)
    history: list[tuple[str, dict]] = field(default_factory=list)
    signatures: dict[str, Any] = field(default_factory=dict)
    #: groups across effects the last kept joint re-fit could not tell apart (None: no joint re-fit kept)
    joint_groups: list[list[str]] | None = None


@dataclass(frozen=True, eq=False)
class _Screened:
    name: str
    space: engine.Space
    screening: Screening
    balance: float | None


@dataclass(frozen=True, eq=False)
class _Passing:
    name: str
    fit: Fit
    screening: Screening


@single_blas_thread  # the simulations' threads need the cores (workers.blas_threads)
def diagnose(records, rig: Rig, mode: str = "displacement", progress: bool = True,
             keep: int = KEEP, max_effects: int = MAX_EFFECTS, candidates: Sequence[str] | None = None,
             refit_interacting: bool = True, joint_refit: bool = True, dt: float | None = None, layout=None,
             accept=None) -> Diagnosis:
    """Finds the effect the model ``rig`` is missing in lab ``records``.

    Args:
        records: one or more records of the same rig (paths to CSV files or
            records read with ``read_record``: uniform time).
        rig: the nominal model you believe in.
        mode: ``"displacement"``, ``"force"`` or ``"free"``; the records'
            command column is the command sent in that mode (m or N).
        progress: show progress on the terminal (stderr).
        keep: candidates kept by screening for the full simulation fit.
        max_effects: most effects added greedily.
        candidates: restrict the library (names); default all.
        refit_interacting: try a bounded (+-25 %) re-fit of the nominal
            parameters each effect interacts with; it is kept only if it
            improves the BIC.
        joint_refit: after each effect from the second on, re-fit all
            accepted effects' parameters together (``joint.joint_refit``); kept
            only if its BIC is not worse than the greedy fit's.  Also switches the
            loop re-fits and, after the last round, the restoring re-fit
            (``joint.restore_refit``: where the model tracks a channel worse than
            ``rig`` did) on or off.
        dt: the controller's sample time [s] (default: each record's own).  A record sampled
            slower than the controller (a 1 kHz record of a 2 kHz rig) simulated at its own
            rate holds the command twice as long and shows a spurious command delay; with
            ``dt`` the command is interpolated onto the controller's grid
            (``identification.run.simulate_command``, as ``compare`` and ``identify`` do).
        layout: how record paths are read (``read_record``'s ``layout``: units, columns...).
        accept: codes of warning-level plausibility checks acknowledged (``identification.checks``);
            an error-level check raises ``CheckError`` (a ValueError) before any work.

    Returns:
        A ``Diagnosis`` (``.write(dir)`` writes diagnosis.json, rig_updated.toml, report.md).
    """
    with engine.RUNS.session():  # emptied when the last diagnosis running at the time returns
        return _diagnose(records, rig, mode, progress, keep, max_effects, candidates, refit_interacting, joint_refit,
                         dt, layout, accept)


def _diagnose(records, rig: Rig, mode: str, progress: bool, keep: int, max_effects: int,
              candidates: Sequence[str] | None, refit_interacting: bool, joint_refit: bool, dt: float | None, layout,
              accept) -> Diagnosis:
    """``diagnose``'s work (inside ``engine.RUNS.session()``, which empties the runs' cache after it)."""
    t_start = time.time()
    recs = as_records(records, layout)
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    for r in recs:
        controller_ratio(r.dt, r.time.size, dt)
    checks = gate(recs, rig, mode, dt, accept)
    setup = _prepare(recs, rig, mode, candidates, keep, refit_interacting, joint_refit, dt)
    current = copy.copy(rig)
    x0 = engine.refine_x0(current, setup.cases, 0.0)
    sims0 = engine.simulate_all(current, setup.cases, 0.0, x0)
    if any(s is None for s in sims0):
        raise ValueError("the nominal rig's simulation fails on this record: check the rig and --mode")
    # the nominal run as compare makes it (the core's defaults, its check of a run that turned stiff included:
    # 6 s of one core on the 52 s UTFSM sweep) reads nothing the rounds make: it runs beside them
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="diagnose-nominal-checks")
    nominal_checks = pool.submit(_nominal_run_checks, copy.deepcopy(current), setup.cases, x0, accept)
    try:
        setup = dataclasses.replace(setup, bar=_progress(max_effects * (len(setup.names) + keep), progress,
                                                         "diagnose"))
        state = _State(rig=current, tau=0.0, x0=x0, sims=sims0,
                       history=[("nominal", engine.gap(sims0, setup.cases))])
        last = None
        for rnd in range(1, max_effects + 1):
            outcome = _round(setup, state, rnd)
            state.log.extend(outcome.log)
            if outcome.outcome != "accept":
                last = outcome
                break
            _accept(setup, state, outcome)
        if setup.joint_refit and state.accepted:
            _restore(setup, state, max(e["round"] for e in state.effects))
        checks += nominal_checks.result()
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
    setup.bar.close()
    d = _result(setup, state, sims0, last, time.time() - t_start)
    d.checks, d.dt = checks, dt
    return d


def _nominal_run_checks(rig: Rig, cases: list[Case], x0s, accept) -> list:
    """The nominal rig's run of each record as ``compare`` reports it (issue 25, item 4): the
    stroke, capacity, supply, spool and drive limits it hit and its solver notes, as checks."""
    out = []
    for case, x0 in zip(cases, x0s):
        try:
            sim = simulate_command(rig, case.mode, case.u, case.dt, float(x0), None, dt=case.controller_dt)
        except (SimulationError, ValueError):
            continue  # the engine's own run (CVODE as the fallback) went through: nothing to add here
        out += settle(run_checks(sim, rig, case.name), accept)
    return out


def _prepare(records, rig: Rig, mode: str, candidates: Sequence[str] | None, keep: int, refit_interacting: bool,
             joint_refit: bool, dt: float | None = None) -> _Setup:
    """Checks the arguments and prepares the records (unique names)."""
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    names = check_names(candidates) if candidates is not None else list(LIBRARY)
    recs = as_records(records)
    rig.validate()
    cases: list[Case] = []
    for i, r in enumerate(recs):
        path = getattr(r, "path", None)
        c = engine.make_case(r, mode, str(path) if path else f"record{i}", dt)
        cases.append(dataclasses.replace(c, name=f"{c.name}#{i}") if any(c.name == o.name for o in cases) else c)
    return _Setup(rig, mode, cases, names, keep, refit_interacting, joint_refit)


def _context(setup: _Setup, state: _State) -> Context:
    """What the candidates see of the current model and the records."""
    cases, sims = setup.cases, state.sims
    return Context(rig=state.rig, nominal=setup.nominal, mode=setup.mode,
                   peak_spool=max(float(np.max(np.abs(s["spool"]))) for s in sims),
                   peak_pressure=max(float(np.max(np.abs(s["pressure"]))) for s in sims),
                   peak_x=max(float(np.max(np.abs(c.meas["displacement"]))) for c in cases),
                   rms_v=float(np.mean([c.derived["rms_v"] for c in cases])), dt=min(c.dt for c in cases),
                   peak_force=max(float(np.max(np.abs(c.derived["force"]))) for c in cases))


# --- one round: screen, shortlist, confirm, decide ------------------------------------------

def _round(setup: _Setup, state: _State, rnd: int) -> Round:
    """One round of the search for the next effect.  There is no stop at the noise
    floor: an effect whose share of the variance is below the floor estimate's own
    uncertainty (a 150 N Coulomb term under 1.6 kN of noise) is still found by its
    structured signature (a fit gains about n (F_c / sigma)^2 in -2 log L); the
    search stops when no candidate passes."""
    stats = engine.channel_stats(state.sims, setup.cases)
    ctx = _context(setup, state)
    screened, log = _screen_all(setup, state, ctx, rnd)
    survivors = _shortlist(screened, setup.keep)
    kept = {s.name for s in survivors}
    if len(survivors) != setup.keep:  # the bar counted keep fits: the look-alikes and the structural one add theirs
        setup.bar.total += len(survivors) - setup.keep
        setup.bar.refresh()
    for rank, s in enumerate(screened):
        if s.name not in kept:
            log[s.name] = dataclasses.replace(
                log[s.name], rejection=(f"screening: its signature explains {100 * s.screening.score:.1f} % of the "
                                        f"residual (rank {rank + 1}; kept the best {setup.keep})"))
    passing = _confirm_all(setup, state, ctx, survivors, stats, log)
    return _decide(rnd, passing, log, stats)


def _not_screened(name: str, added: set[str], mode: str, ctx: Context) -> str | None:
    """Why a candidate is not screened this round, or None."""
    if name in added:
        return "already added"
    within = sorted(a for a in added if name in LIBRARY[a].nests)
    if within:  # its parameters are the added effect's, already fitted: a re-fit of them, not a new effect
        return f"already in the model: a limit of {within[0]} (added), whose fit covers it"
    if mode not in LIBRARY[name].modes:
        return f"cannot act in {mode} mode"
    return LIBRARY[name].exercised(ctx) or None


def _screen_all(setup: _Setup, state: _State, ctx: Context, rnd: int) -> tuple[list[_Screened], dict]:
    """Screens every candidate (secant signature against the current residual,
    and for structural ones the balance-equation screen); returns them best
    first and the round's log (name -> row, in library order)."""
    cases = setup.cases
    r0 = engine.residuals(state.sims, cases)
    setup.bar.set_description_str(f"round {rnd}: screening")
    added = {e["name"] for e in state.effects}
    log, spaces = {}, {}
    for nme in setup.names:
        why = _not_screened(nme, added, setup.mode, ctx)
        if why:
            log[nme] = CandidateLog(nme, rnd, rejection=why)
            continue
        cand = LIBRARY[nme]
        inter = interacting(cand, state.rig, setup.mode) if setup.refit_interacting else ()
        spaces[nme] = engine.Space(cand, ctx, inter)

    def screen(nme: str) -> _Screened:
        space, cand = spaces[nme], LIBRARY[nme]
        sc = engine.secant_screen(space, cases, state.x0, r0, state.tau)
        bal = (engine.balance_screen(state.rig, cases, cand.structural_signature)
               if cand.structural_signature is not None else None)
        return _Screened(nme, space, sc, bal)

    done = dict(zip(spaces, _each(screen, list(spaces))))
    screened = []
    for nme in setup.names:  # the log in library order
        setup.bar.update(1)
        if nme in done:
            s = done[nme]
            log[nme] = CandidateLog(nme, rnd, screening_score=s.screening.score, balance_score=s.balance)
            screened.append(s)
    screened.sort(key=lambda s: -s.screening.score)
    return screened, log


def _each(fn, items: list) -> list:
    """``[fn(i) for i in items]``, the items on ``fit.default_workers()`` threads (the candidates of a
    round are independent: each result is the one a serial loop gives)."""
    from concurrent.futures import ThreadPoolExecutor

    from ..identification.fit import default_workers

    n = min(default_workers(), len(items))
    if n <= 1:
        return [fn(i) for i in items]
    with ThreadPoolExecutor(max_workers=n, thread_name_prefix="diagnose-candidate") as pool:
        return list(pool.map(fn, items))


def _shortlist(screened: list[_Screened], keep: int) -> list[_Screened]:
    """The best ``keep`` by screening score, the look-alikes of each of them (screening
    by a linearised signature cannot rank effects that differ only far from
    "absent": a 30 Hz valve vs a delay; a heavier piston vs a softer oil column, the
    third-best on rigC of the evaluation with its 40 kg piston unscreened below it) and the
    best structural candidate of the balance-equation screen (if it explains more than 10 %)."""
    survivors = screened[:keep]
    have = {s.name for s in survivors}
    for top in list(survivors):
        for la in LIBRARY[top.name].look_alikes:
            extra = [s for s in screened if s.name == la and s.name not in have]
            survivors += extra
            have |= {s.name for s in extra}
    structural = [s for s in screened if s.balance is not None]
    if structural:
        best_bal = max(structural, key=lambda s: s.balance)
        if best_bal.name not in {s.name for s in survivors} and best_bal.balance > 0.1:
            survivors.append(best_bal)
    return survivors


def _confirm_all(setup: _Setup, state: _State, ctx: Context, survivors: list[_Screened], stats: dict,
                 log: dict) -> list[_Passing]:
    """Fits each shortlisted candidate (``confirm.confirm``), logs its tests and
    returns those that pass them all."""
    base_test = engine.channel_stats(state.sims, setup.cases, "test")
    g_nominal, floor, g_now = state.history[0][1], engine.floor_gap(setup.cases), engine.gap(state.sims, setup.cases)
    setup.bar.set_description_str(f"round {log[survivors[0].name].round}: fitting" if survivors else "")

    def fit_one(s: _Screened):
        t_fit = time.time()
        fit = confirm(s.space, s.screening.z0, setup.cases, state.x0, stats, base_test, state.tau, ctx,
                      setup.refit_interacting)
        return fit, time.time() - t_fit

    passing = []
    for s, (fit, seconds) in zip(survivors, _each(fit_one, survivors)):
        setup.bar.update(1)
        share = engine.share_closed(g_now, engine.gap(fit.sims, setup.cases), g_nominal, floor)
        reasons = _rejection(fit, share)
        log[s.name] = dataclasses.replace(
            log[s.name], score=fit.dbic, delta_bic=fit.dbic, heldout_improvement=fit.held,
            parameters=param_report(fit.space, fit.z, fit.lo, fit.hi), joint_p_absent=fit.joint_p, refit=fit.refit,
            fit_seconds=seconds, heldout_lr=fit.held_lr, rejection="; ".join(reasons) or None, share_closed=share)
        if not reasons:
            passing.append(_Passing(s.name, fit, s.screening))
    return passing


def _rejection(fit: Fit, share: float | None = None) -> list[str]:
    """The acceptance tests a confirmed candidate fails: BIC improvement,
    held-out improvement (SSR or -2 log L), "absent" excluded by one tested
    parameter's 95 % interval or (parameters that trade against each other)
    their joint 95 % region, and materiality: the fit closes at least ``engine.MATERIAL_MIN`` of the nominal
    model's gap above the noise floor (``share``, ``engine.share_closed``; None: not tested)."""
    space, nm = fit.space, fit.space.n_main
    tested = space.tests_absent[:nm]
    outside = (space.absent[:nm] < fit.lo[:nm]) | (space.absent[:nm] > fit.hi[:nm])
    excludes = bool(np.any(outside & tested)) or bool(fit.joint_excludes)
    reasons = []
    if fit.dbic < DELTA_BIC_MIN:
        reasons.append(f"BIC improvement {fit.dbic:.1f} < {DELTA_BIC_MIN:g}")
    if fit.held < HELDOUT_MIN and fit.held_lr < HELDOUT_LR_MIN:
        reasons.append(f"held-out error improves by {100 * fit.held:.1f} % < {100 * HELDOUT_MIN:g} % and its "
                       f"-2 log L by {fit.held_lr:.1f} < {HELDOUT_LR_MIN:g}")
    if not excludes:
        reasons.append("95 % interval (and joint region) includes 'absent'")
    if not reasons and share is not None and share < engine.MATERIAL_MIN:  # significant, but too small to name
        reasons.append(f"closes {100 * max(share, 0.0):.2f} % of the nominal model's gap above the noise floor on "
                       f"any channel < {100 * engine.MATERIAL_MIN:g} %: a correction too small to name")
    return reasons


def _decide(rnd: int, passing: list[_Passing], log: dict, stats: dict) -> Round:
    """Accept the best passing candidate, call the round ambiguous (the two best
    fit equally well and are not nested: nested candidates are decided by the
    BIC, never ambiguous) or stop (none passed)."""
    if not passing:
        return Round(rnd, "stop", tuple(log.values()), summary=(
            f"round {rnd}: no candidate passed (BIC, held-out error, interval and materiality tests); "
            + ("the residual is above the noise floor: the missing effect may not be in the library"
               if not engine.at_noise_floor(stats, 0.5) else "the residual is near the noise floor")))
    passing = sorted(passing, key=lambda p: -p.fit.dbic)
    fit_gap = None
    if len(passing) > 1:
        passing, fit_gap = _runner_up(passing)
        log[passing[0].name] = dataclasses.replace(log[passing[0].name], fit_gap_to_runner_up=fit_gap)
    best = passing[0]
    if fit_gap is not None and fit_gap < DELTA_FIT_AMBIGUOUS and not nested(best.name, passing[1].name):
        return _ambiguous(rnd, passing, log, fit_gap)
    log[best.name] = dataclasses.replace(log[best.name], accepted=True)
    for p in passing[1:]:
        log[p.name] = dataclasses.replace(log[p.name], rejection=_behind(p, best))
    return Round(rnd, "accept", tuple(log.values()), best=best.fit, best_name=best.name,
                 signature=best.screening.signature)


def _behind(p: _Passing, best: _Passing) -> str:
    """Why a passing candidate is not the one accepted.  Each BIC improvement is counted on the candidate's own
    effective sample sizes; where ``p``'s is the larger, ``best`` won the comparison on the sizes common to both
    (``_runner_up``), and the reason says that rather than claim an order the two numbers do not have."""
    if p.fit.dbic < best.fit.dbic:
        return f"passed, but BIC improvement {p.fit.dbic:.1f} < {best.name}'s {best.fit.dbic:.1f}"
    bic_p, bic_best = _common_bic(p.fit, best.fit)
    lower = bic_p - bic_best
    return (f"passed (BIC improvement {p.fit.dbic:.1f} on its own effective sample sizes, {best.name}'s "
            f"{best.fit.dbic:.1f} on its own), but on the effective sample sizes common to both {best.name}'s BIC "
            f"is lower by {lower:.1f}")


def _runner_up(passing: list[_Passing]) -> tuple[list[_Passing], float]:
    """The two best passing candidates compared on effective sample sizes common
    to both (per channel the smaller of the two): the runner-up goes first if it
    wins there; and their misfits' (-2 log L, no parameter penalty) difference."""
    a, b = passing[0].fit, passing[1].fit
    fa, fb = _common_bic(a, b, penalty=False)
    bic_a, bic_b = _common_bic(a, b)
    if bic_b < bic_a:
        passing = [passing[1], passing[0]] + passing[2:]
    return passing, abs(fb - fa)


def _common_bic(a: Fit, b: Fit, penalty: bool = True) -> tuple[float, float]:
    """The BICs of two fits on the effective sample sizes common to both (per channel the smaller), with each
    fit's parameter penalty or (``penalty`` False) its misfit alone."""
    ne = {k: min(a.neff[k], b.neff[k]) for k in a.neff}
    return (engine.bic(a.stats, a.z.size if penalty else 0, ne), engine.bic(b.stats, b.z.size if penalty else 0, ne))


def _ambiguous(rnd: int, passing: list[_Passing], log: dict, fit_gap: float) -> Round:
    """The round's outcome when the two best passing candidates fit equally well."""
    best, other = passing[0], passing[1]
    for p, q in ((best, other), (other, best)):
        log[p.name] = dataclasses.replace(log[p.name], rejection=(
            f"ambiguous with {q.name}: their fits differ by {fit_gap:.1f} < {DELTA_FIT_AMBIGUOUS:g} "
            "(-2 log likelihood)"))
    for p in passing[2:]:
        log[p.name] = dataclasses.replace(
            log[p.name], rejection=f"passed, but BIC improvement {p.fit.dbic:.1f} below {best.name}'s")
    return Round(rnd, "ambiguous", tuple(log.values()),
                 summary=f"round {rnd}: ambiguous: {best.name} or {other.name} explain the records equally well",
                 ambiguous_between=(best.name, other.name),
                 separating_experiment=separating_experiment(best.name, other.name))


# --- accepting an effect -------------------------------------------------------------------

def _accept(setup: _Setup, state: _State, outcome: Round) -> None:
    """Adds the round's best effect to the model (initial displacements re-fitted
    with it) and, from the second effect on, re-fits the accepted effects jointly."""
    fit, name, cases = outcome.best, outcome.best_name, setup.cases
    row = next(c for c in outcome.log if c.name == name)
    state.rig, state.tau = fit.rig, fit.tau
    state.x0 = engine.refine_x0(state.rig, cases, state.tau)
    state.sims = engine.simulate_all(state.rig, cases, state.tau, state.x0)
    g_after = engine.gap(state.sims, cases)
    state.history.append((name, g_after))
    state.signatures[name] = outcome.signature
    eff = {"name": name, "doc": LIBRARY[name].doc, "parameters": row.parameters, "delta_bic": fit.dbic,
           "heldout_improvement": fit.held, "gap_after": g_after, "round": outcome.number}
    if LIBRARY[name].delays_command:
        eff["note"] = ("command_delay is the rig's [delays] command_delay (rig_updated.toml carries it) for a value "
                       ">= 0")
    eff["inseparable"] = [[f"{name}: {k}" for k in g] for g in param_groups(fit.space, fit.corr)]
    state.effects.append(eff)
    state.accepted.append(Accepted(name, fit.space, np.asarray(fit.z, float).copy(),
                                   np.asarray(fit.lo, float).copy(), np.asarray(fit.hi, float).copy(), fit.corr))
    if setup.joint_refit and len(state.accepted) >= 2:
        _polish(setup, state, outcome.number)
    if setup.joint_refit:
        _polish_loop(setup, state, outcome.number)


def _polish(setup: _Setup, state: _State, rnd: int) -> None:
    """The joint re-fit of the accepted effects; its model replaces the greedy one if kept."""
    setup.bar.set_description_str(f"round {rnd}: joint re-fit")
    parameters = {e["name"]: e["parameters"] for e in state.effects}
    info, new = joint_refit(state.accepted, parameters, state.rig, state.tau, setup.cases, state.x0, state.sims,
                            rnd)
    _adopt(setup, state, info, new, "joint re-fit")


def _polish_loop(setup: _Setup, state: _State, rnd: int) -> None:
    """The loop re-fit (``joint.loop_refit``) once the effects have re-sized the actuator; its model replaces
    the current one if kept.  Where it was refused, the loop alone on the displacement channel
    (``joint.loop_refit_displacement``), kept on the evidence an effect needs (``DELTA_BIC_MIN``) with no
    channel worse, or where it brings every channel back to no worse than the nominal model's."""
    setup.bar.set_description_str(f"round {rnd}: loop re-fit")
    parameters = {e["name"]: e["parameters"] for e in state.effects}
    info, new = loop_refit(state.accepted, parameters, state.rig, setup.nominal, state.tau, setup.cases, state.x0,
                           state.sims, rnd, _context(setup, state))
    _adopt(setup, state, info, new, "loop re-fit")
    if info is not None and info.gap_joint is not None and not info.kept:  # tried, refused: the loop alone
        setup.bar.set_description_str(f"round {rnd}: loop re-fit on the displacement")
        k = int(sum(a.z.size for a in state.accepted))
        info, new = loop_refit_displacement(state.rig, setup.nominal, state.tau, setup.cases, state.x0, state.sims,
                                            k, rnd, _context(setup, state), DELTA_BIC_MIN, state.history[0][1])
        _adopt(setup, state, info, new, "loop re-fit (displacement)")


def _restore(setup: _Setup, state: _State, rnd: int) -> None:
    """After the last round: the restoring re-fit (``joint.restore_refit``) where the model tracks a channel
    worse than the nominal model; its model replaces the current one if kept."""
    if worse_than_nominal(engine.gap(state.sims, setup.cases), state.history[0][1], setup.mode):  # else not tried
        setup.bar.set_description_str(RESTORE_HEAD)
    parameters = {e["name"]: e["parameters"] for e in state.effects}
    info, new = restore_refit(state.accepted, parameters, state.rig, state.history[0][1], state.tau, setup.cases,
                              state.x0, state.sims, rnd, _context(setup, state))
    _adopt(setup, state, info, new, RESTORE_HEAD)


def _adopt(setup: _Setup, state: _State, info, new, label: str) -> None:
    """Logs a re-fit (``info``; None: not tried) and, if it was kept (``new``), makes its model the current one."""
    if info is None:
        return
    state.joint_log.append(info)
    if new is None:
        return
    state.rig, state.tau, state.sims = new.rig, new.tau, new.sims
    state.x0 = tuple(float(v) for v in new.x0)
    state.accepted = [new.accepted.get(a.name, a) for a in state.accepted]
    for e in state.effects:
        e["parameters"] = new.parameters.get(e["name"], e["parameters"])
    if new.groups is not None:  # the loop alone re-fitted on the displacement leaves the effects' groups
        state.joint_groups = new.groups
    state.effects[-1]["gap_after"] = engine.gap(state.sims, setup.cases)
    state.history.append((label, state.effects[-1]["gap_after"]))


# --- the result ------------------------------------------------------------------------------

def _alignment_notes(effects: list[dict[str, Any]]) -> None:
    """A fitted command delay < 0 is an acquisition misalignment, not a physical delay."""
    for eff in effects:
        tv = eff["parameters"].get("command_delay", {}).get("value") if LIBRARY[eff["name"]].delays_command else None
        if tv is not None and tv < 0.0:
            eff["note"] += (f"; here < 0: the response channels lead the command by {-1e3 * tv:.2f} ms, which no "
                            "physical delay does: check the acquisition's alignment (row k must be sampled before "
                            "the command of row k is sent); rig_updated.toml cannot hold it (the record's command "
                            "is shifted instead)")


def _gap_closed(before: dict, after: dict, floor: dict) -> dict:
    """Per channel the share of the gap above the noise floor that the effects closed."""
    closed = {}
    for c in before:
        den = before[c] - floor[c]
        closed[c] = float(np.clip((before[c] - after[c]) / den, 0.0, 1.0)) if den > 1e-12 else None
    return closed


def _summary(verdict: str, effects: list, last: Round | None, joint_log: list[JointRefit]) -> str:
    summary = last.summary if last is not None else ""
    if not summary:
        summary = f"stopped after {len(effects)} effect(s)"
    if joint_log:
        j = joint_log[-1]
        if j.effects == ("loop (displacement)",):  # its reason names it and says why kept or not
            summary += f"; re-fit of {j.reason}"
        elif j.reason and j.reason.startswith(RESTORE_HEAD):
            summary += f"; {j.reason}"
        else:
            summary += (f"; joint re-fit of {' + '.join(j.effects)}: "
                        + (f"kept (BIC better by {j.delta_bic:.1f})" if j.kept else j.reason))
    amb = list(last.ambiguous_between) if last is not None else []
    head = {"effect_found": "missing effect(s): " + ", ".join(e["name"] for e in effects),
            "no_effect": "no missing effect", "ambiguous": f"ambiguous: {' or '.join(amb)}"}[verdict]
    if verdict == "ambiguous" and effects:
        head = "found " + ", ".join(e["name"] for e in effects) + "; then " + head
    return f"{head}. {summary}"


def _determined(effects: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every parameter of the effects, from the best determined to the worst (``stats.precision_order``:
    identified ones by relative standard error, then those at a bound, then those not identified)."""
    rows = [{"effect": e["name"], "key": k, **{f: p.get(f) for f in ("value", "unit", "interval_95", "status",
                                                                       "relative_sd")}}
            for e in effects for k, p in e["parameters"].items()]
    rel = [r["relative_sd"] if r["relative_sd"] is not None else np.inf for r in rows]
    return [rows[i] for i in precision_order(rel, [r["status"] or "identified" for r in rows])]


def _result(setup: _Setup, state: _State, sims0: list, last: Round | None, runtime: float) -> Diagnosis:
    cases = setup.cases
    _alignment_notes(state.effects)
    gap_before, gap_after, floor = engine.gap(sims0, cases), engine.gap(state.sims, cases), engine.floor_gap(cases)
    ambiguous = last is not None and last.outcome == "ambiguous"
    verdict = "ambiguous" if ambiguous else ("effect_found" if state.effects else "no_effect")
    d = Diagnosis(verdict=verdict, effects=state.effects, gap_before=gap_before, gap_after=gap_after,
                  candidates=state.log, rig=state.rig, mode=setup.mode, records=[c.name for c in cases],
                  noise_floor=floor, gap_closed=_gap_closed(gap_before, gap_after, floor),
                  gap_where=gap_where(sims0, cases),
                  ambiguous_between=list(last.ambiguous_between) if ambiguous else [],
                  separating_experiment=last.separating_experiment if ambiguous else "",
                  joint_refit=state.joint_log, determined=_determined(state.effects),
                  inseparable=(state.joint_groups if state.joint_groups is not None
                               else [g for e in state.effects for g in e.get("inseparable", [])]),
                  command_delay=state.rig.command_delay + state.tau,
                  record_shift=state.tau,
                  summary=_summary(verdict, state.effects, last, state.joint_log), runtime_s=runtime)
    d.plots = {"cases": cases, "sims_before": sims0, "sims_after": state.sims, "history": state.history,
               "signatures": state.signatures}
    return d
