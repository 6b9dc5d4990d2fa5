"""The diagnosis workflow: nominal gap, screening, confirmation by simulation-error
fits, acceptance by BIC (effective sample size), held-out error and intervals,
greedy for a second and third effect, a joint re-fit of the accepted effects
after each one from the second on, verdict."""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..records import Record, read_record
from ..rig import Rig, rig_to_dict
from ..simulate import MODES
from . import engine as E
from .effects import LIBRARY, Context, _copy, nested, separating_experiment

#: acceptance thresholds (documented in docs/diagnose.md)
DELTA_BIC_MIN = 10.0  #: "very strong" evidence on the Kass-Raftery scale
DELTA_FIT_AMBIGUOUS = 6.0  #: two passing candidates whose fits (-2 log L) differ by less are "equally good"
HELDOUT_MIN = 0.02  #: held-out SSR must fall by at least 2 % ...
#: ... or, for effects small against the noise, significantly: the held-out -2 log likelihood (effective
#: sample sizes of the held-out residual before the effect) must fall by at least this much
HELDOUT_LR_MIN = 10.0
KEEP = 3  #: candidates kept by screening for the full fit
MAX_EFFECTS = 3
JOINT_MAX_NFEV = 30  #: most least-squares iterations of the joint re-fit


@dataclass
class Diagnosis:
    """What ``diagnose`` found; ``to_dict()`` is the content of diagnosis.json."""

    verdict: str
    effects: list
    gap_before: dict
    gap_after: dict
    candidates: list
    rig: Rig
    mode: str
    records: list
    noise_floor: dict = field(default_factory=dict)
    gap_closed: dict = field(default_factory=dict)
    gap_where: dict = field(default_factory=dict)
    ambiguous_between: list = field(default_factory=list)
    separating_experiment: str = ""
    #: the joint re-fits of the accepted effects (one per round from the second effect on; the last is the final one)
    joint_refit: list = field(default_factory=list)
    command_delay: float = 0.0
    summary: str = ""
    runtime_s: float = 0.0
    #: arrays for the report (not in the JSON)
    plots: dict = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "verdict": self.verdict,
            "summary": self.summary,
            "mode": self.mode,
            "records": self.records,
            "effects": self.effects,
            "joint_refit": self.joint_refit,
            "gap_before": self.gap_before,
            "gap_after": self.gap_after,
            "noise_floor": self.noise_floor,
            "gap_closed": self.gap_closed,
            "gap_where": self.gap_where,
            "candidates": self.candidates,
            "ambiguous_between": self.ambiguous_between,
            "separating_experiment": self.separating_experiment,
            "command_delay_s": self.command_delay,
            "rig_updated": rig_to_dict(self.rig),
            "runtime_s": self.runtime_s,
        }

    def write(self, out: str | Path) -> Path:
        """Writes diagnosis.json, rig_updated.toml and report.md (with plots) to ``out``."""
        from .report import write_outputs

        return write_outputs(self, Path(out))


def _as_records(records) -> list[Record]:
    if isinstance(records, (str, Path, Record)):
        records = [records]
    out = []
    for r in records:
        out.append(r if isinstance(r, Record) else read_record(r))
    if not out:
        raise ValueError("invalid records = []: give at least one record")
    return out


def _progress(total: int, enabled: bool, desc: str):
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, disable=not enabled, file=sys.stderr, leave=False,
                bar_format="{desc}: {n_fmt}/{total_fmt} {bar} {elapsed} {postfix}")


def gap_where(sims: list, cases: list[E.Case]) -> dict:
    """Where the gap sits, for the channel with the largest normalised gap:
    residual rms by time segment, frequency band, |displacement| quartile,
    velocity sign and |velocity| (reversals vs. motion)."""
    g = E.gap(sims, cases)
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


def _param_report(space: E.Space, z: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> dict:
    ext = space.to_external(z)
    elo, ehi = space.to_external(lo), space.to_external(hi)
    absent = space.to_external(space.absent)
    out = {}
    keys = [(p.key, p.unit, p.rig_key) for p in space.params] + \
           [(k, u, "re-fitted nominal parameter") for k, u in space.interacting]
    for i, (key, unit, where) in enumerate(keys):
        a, b = (ehi[i], elo[i]) if space.rec[i] else (elo[i], ehi[i])
        a, b = min(a, b), max(a, b)
        out[key] = {"value": _num(ext[i]), "unit": unit, "interval_95": [_num(a), _num(b)],
                    "absent": _num(absent[i]), "rig_key": where}
    return out


def _num(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _fit_space(space: E.Space, z0: np.ndarray, cases: list, stats: dict, base_test: dict, tau: float,
               neff_ref: dict | None = None) -> dict:
    """Train-segment fit (held-out improvement), then the fit on all data, its BIC
    improvement over the current model and its HAC 95 % intervals."""
    z_tr, res_tr = E.fit(space, cases, z0, tau, "train")
    rig_tr, tau_tr = space.rig_and_tau(z_tr, tau)
    old = E.with_x0(cases, res_tr.x0)
    test = E.channel_stats(E.simulate_all(rig_tr, cases, tau_tr), cases, "test")
    E.with_x0(cases, old)
    held = 1.0 - sum(s["ssr"] for s in test.values()) / sum(s["ssr"] for s in base_test.values())
    ne_test = E.n_eff(base_test)
    held_lr = float(sum(ne_test[k] * math.log(max(base_test[k]["ssr"], 1e-300) / max(test[k]["ssr"], 1e-300))
                        for k in base_test))
    z, res = E.fit(space, cases, z_tr, tau, "all", max_nfev=12)
    rig_c, tau_c = space.rig_and_tau(z, tau)
    old = E.with_x0(cases, res.x0)
    sims_c = E.simulate_all(rig_c, cases, tau_c)
    E.with_x0(cases, old)
    st_c = E.channel_stats(sims_c, cases)
    neff = neff_ref if neff_ref is not None else E.n_eff(st_c)
    dbic = E.bic(stats, 0, neff) - E.bic(st_c, z.size, neff)
    lengths = E.series_lengths(cases)
    lo, hi = E.intervals(space, res, lengths)
    nm = space.n_main
    tested = np.concatenate([space.tests_absent[:nm], np.zeros(z.size - nm, bool)])
    joint, pval = E.joint_excludes_absent(space, res, lengths, tested)
    return {"space": space, "z": z, "z_tr": z_tr, "lo": lo, "hi": hi, "rig": rig_c, "tau": tau_c,
            "joint_excludes": joint, "joint_p": pval,
            "sims": sims_c, "stats": st_c, "neff": neff, "dbic": dbic, "held": held, "held_lr": held_lr}


def _scan_start(space: E.Space, z0: np.ndarray, cases: list, tau: float, ctx: Context) -> np.ndarray:
    """The start of the fit: the better (training-segment error) of the screening
    estimate (a linear extrapolation of the signature, which can land far off for
    a strongly nonlinear parameter such as K_a) and the probe value, and for an
    effect whose error is not smooth in its first parameter (``Candidate.scan``)
    the values of a coarse scan of it (a least-squares fit started where a hard
    clip barely engages stops there)."""
    starts = [np.asarray(z0, float), np.asarray(space.probe[: space.n_main], float)]
    for v in (np.asarray(space.cand.scan(ctx), float) if space.cand.scan is not None else ()):
        z = np.asarray(z0, float).copy()
        z[0] = np.clip(space.to_internal(np.concatenate([[v], space.to_external(z)[1:]]))[0], space.lo[0], space.hi[0])
        starts.append(z)
    cost = []
    for z in starts:
        rig, t = space.rig_and_tau(z, tau)
        r = E.residuals(E.simulate_all(rig, cases, t), cases, "train")
        cost.append(float(r @ r))
    return starts[int(np.argmin(cost))]


def _confirm(space: E.Space, z0: np.ndarray, cases: list, stats: dict, base_test: dict, tau: float, ctx: Context,
             refit_interacting: bool, current: Rig) -> dict:
    """Fits the candidate alone, then (if it has interacting nominal parameters and
    ``refit_interacting``) with the bounded +-25 % re-fit of them, started from the
    first fit; keeps the re-fit only if it improves the BIC (same effective sample
    sizes for both)."""
    alone = E.Space(space.cand, ctx, ())
    z0 = _scan_start(alone, z0[: alone.n_main], cases, tau, ctx)
    a = _fit_space(alone, z0, cases, stats, base_test, tau)
    a["refit"] = {"tried": False, "kept": False}
    inter = space.interacting if refit_interacting else ()
    if not inter:
        return a
    z1 = np.concatenate([a["z_tr"], space.absent[space.n_main:]])
    b = _fit_space(space, z1, cases, stats, base_test, tau, neff_ref=a["neff"])
    keep = b["dbic"] > a["dbic"]
    info = {"tried": True, "kept": bool(keep), "parameters": [k for k, _ in inter],
            "delta_bic_with": b["dbic"], "delta_bic_without": a["dbic"]}
    out = b if keep else a
    out["refit"] = info
    return out


def _joint_refit(accepted: list[dict], current: Rig, tau: float, cases: list, sims: list,
                 rnd: int) -> tuple[dict, tuple | None]:
    """The joint re-fit ("polish") of the accepted effects.  Each effect was
    fitted with the ones before it held at their values, so an earlier effect's
    parameter absorbs part of a later one (a fitted delay takes up part of a
    missing damping, and the damping fitted after it is biased the other way).
    Here all accepted effects' own parameters (the command delay among them) and
    the nominal parameters their kept interacting re-fits moved are fitted
    together by simulation error (``E.JointSpace``), started from the greedy
    model's values, each within its candidate's bounds; the HAC 95 % intervals
    come from the joint fit, so each effect's interval accounts for the others.
    The joint fit is kept if its BIC (same parameters, the greedy model's
    effective sample sizes) is not worse than the greedy model's.

    An effect whose every own parameter a later effect also fits
    (coulomb_friction's F_c under lugre_friction) is superseded: it stays as the
    later effect left it.  Effects that share only part of their parameters, or
    whose greedy model cannot be rebuilt from their parameters, are not re-fitted.

    ``accepted``: per effect in the order added, ``space`` (its ``Space``), ``z``,
    ``lo``, ``hi`` (fitting coordinates) and ``eff`` (its entry in the diagnosis).
    Returns the record for diagnosis.json and, if the joint fit is kept,
    (rig, tau, fitted initial displacements, simulations); the accepted
    entries' ``z``, ``lo``, ``hi`` and ``eff["parameters"]`` are then updated."""
    t0 = time.time()
    k = int(sum(a["z"].size for a in accepted))  # the model's fitted parameters (the BIC penalty, both fits)
    keys = [{prm.key for prm in a["space"].params} for a in accepted]
    later = [set().union(*keys[i + 1:]) for i in range(len(keys))]
    held = [a["name"] for a, ks, lt in zip(accepted, keys, later) if ks <= lt]
    shared = sorted({kk for ks, lt in zip(keys, later) if not ks <= lt for kk in ks & lt})
    accepted = [a for a, ks, lt in zip(accepted, keys, later) if not ks <= lt]
    info: dict[str, Any] = {"round": rnd, "effects": [a["name"] for a in accepted], "kept": False}
    if held:
        info["superseded"] = held
    if shared or len(accepted) < 2:
        info["reason"] = ("not tried: " + (f"effects share the parameter(s) {shared}" if shared
                                           else "fewer than two effects to re-fit"))
        return info, None
    js = E.JointSpace([a["space"] for a in accepted], current)
    # start: the greedy values; a nominal parameter (or an effect's own parameter) that a later interacting
    # re-fit moved starts from the model's value
    z0 = np.concatenate([a["z"][: a["space"].n_main] for a in accepted]
                        + [np.array([float(getattr(current, kk)) for kk, _ in js.interacting])])
    inter = [{kk for kk, _ in a["space"].interacting} for a in accepted]
    for i, (a, blk) in enumerate(zip(accepted, js.blocks)):
        moved = set().union(*inter[i + 1:])
        for j, prm in enumerate(a["space"].params):
            if prm.key in moved and not prm.reciprocal and hasattr(current, prm.key):
                z0[blk.start + j] = float(getattr(current, prm.key))
    delay = sum(float(a["space"].to_external(a["z"])[0]) for a in accepted if a["space"].cand.delays_command)
    base_tau = tau - delay
    rig0, tau0 = js.rig_and_tau(z0, base_tau)
    if not E.same_rig(rig0, current) or not math.isclose(tau0, tau, rel_tol=1e-9, abs_tol=1e-12):
        info["reason"] = "not tried: the greedy model cannot be rebuilt from the effects' parameters"
        return info, None
    stats0 = E.channel_stats(sims, cases)
    neff = E.n_eff(stats0)
    z, res = E.fit(js, cases, z0, base_tau, "all", max_nfev=JOINT_MAX_NFEV)
    rig1, tau1 = js.rig_and_tau(z, base_tau)
    old = E.with_x0(cases, res.x0)
    sims1 = E.simulate_all(rig1, cases, tau1)
    E.with_x0(cases, old)
    info["parameters_fitted"] = [prm.key for prm in js.params] + [kk for kk, _ in js.interacting]
    info["nfev"] = int(res.nfev)
    if any(s is None for s in sims1):
        info["reason"] = "the jointly fitted model's simulation fails: kept the greedy fit"
        info["seconds"] = time.time() - t0
        return info, None
    stats1 = E.channel_stats(sims1, cases)
    b0, b1 = E.bic(stats0, k, neff), E.bic(stats1, k, neff)
    lengths = E.series_lengths(cases)
    lo, hi = E.intervals(js, res, lengths)
    before, after, excl, reports = {}, {}, {}, []
    for a, blk in zip(accepted, js.blocks):
        sp, nm = a["space"], a["space"].n_main
        zf, lof, hif = a["z"].copy(), a["lo"].copy(), a["hi"].copy()
        zf[:nm], lof[:nm], hif[:nm] = z[blk], lo[blk], hi[blk]
        for jj, (kk, _) in enumerate(sp.interacting):
            idx = js.index_of(kk)
            if idx is not None:
                zf[nm + jj], lof[nm + jj], hif[nm + jj] = z[idx], lo[idx], hi[idx]
        rep = _param_report(sp, zf, lof, hif)
        before[a["name"]] = {kk: {"value": v["value"], "interval_95": v["interval_95"]}
                             for kk, v in a["eff"]["parameters"].items()}
        after[a["name"]] = {kk: {"value": v["value"], "interval_95": v["interval_95"]} for kk, v in rep.items()}
        tested = sp.tests_absent[:nm]
        outside = (sp.absent[:nm] < lo[blk]) | (sp.absent[:nm] > hi[blk])
        mask = np.zeros(z.size, bool)
        mask[blk] = tested
        excl[a["name"]] = bool(np.any(outside & tested)) or E.joint_excludes_absent(js, res, lengths, mask)[0]
        reports.append((zf, lof, hif, rep))
    keep = b1 <= b0
    info.update({"kept": bool(keep), "bic_greedy": b0, "bic_joint": b1, "delta_bic": b0 - b1,
                 "gap_greedy": E.gap(sims, cases), "gap_joint": E.gap(sims1, cases),
                 "parameters_greedy": before, "parameters_joint": after, "excludes_absent_joint": excl,
                 "reason": ("joint BIC not worse than the greedy one: kept the joint fit" if keep
                            else "joint BIC worse than the greedy one: kept the greedy fit"),
                 "seconds": time.time() - t0})
    if not keep:
        return info, None
    for a, (zf, lof, hif, rep) in zip(accepted, reports):
        a["z"], a["lo"], a["hi"] = zf, lof, hif
        a["eff"]["parameters"] = rep
    return info, (rig1, tau1, res.x0, sims1)


def diagnose(records, rig: Rig, mode: str = "displacement", progress: bool = True,
             keep: int = KEEP, max_effects: int = MAX_EFFECTS, candidates: Sequence[str] | None = None,
             refit_interacting: bool = True, joint_refit: bool = True) -> Diagnosis:
    """Finds the effect the model ``rig`` is missing in lab ``records``.

    Args:
        records: one or more records of the same rig (paths to CSV files or
            ``Record`` objects, read with ``read_record``: uniform time).
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
            accepted effects' parameters together (``_joint_refit``); kept only
            if its BIC is not worse than the greedy fit's.

    Returns:
        A ``Diagnosis`` (``.write(dir)`` writes diagnosis.json, rig_updated.toml, report.md).
    """
    t_start = time.time()
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    names = list(candidates) if candidates is not None else list(LIBRARY)
    for nme in names:
        if nme not in LIBRARY:
            raise ValueError(f"unknown candidate {nme!r}: expected one of {list(LIBRARY)}")
    recs = _as_records(records)
    rig.validate()
    cases = [E.make_case(r, mode, str(r.path) if r.path else f"record{i}") for i, r in enumerate(recs)]
    for i, c in enumerate(cases):
        if any(c.name == o.name for o in cases[:i]):
            c.name = f"{c.name}#{i}"

    current, tau = _copy(rig), 0.0
    E.refine_x0(current, cases, tau)
    sims0 = E.simulate_all(current, cases, tau)
    if any(s is None for s in sims0):
        raise ValueError("the nominal rig's simulation fails on this record: check the rig and --mode")
    gap_before = E.gap(sims0, cases)
    floor = E.floor_gap(cases)
    where = gap_where(sims0, cases)
    effects: list = []
    cand_log: list = []
    verdict, summary = None, ""
    amb: list = []
    sep = ""
    history = [("nominal", gap_before)]
    signatures: dict = {}
    sims = sims0
    accepted: list = []  #: per accepted effect: its fit space and values (for the joint re-fit)
    joint_log: list = []
    bar = _progress(max_effects * (len(names) + keep), progress, "diagnose")

    for rnd in range(1, max_effects + 1):
        stats = E.channel_stats(sims, cases)
        # no stop at the noise floor: an effect whose share of the variance is below the floor estimate's own
        # uncertainty (a 150 N Coulomb term under 1.6 kN of noise) is still found by its structured signature
        # (a fit gains about n (F_c / sigma)^2 in -2 log L); the search stops when no candidate passes
        x_peak = max(float(np.max(np.abs(c.meas["displacement"]))) for c in cases)
        ctx = Context(rig=current, nominal=rig, mode=mode,
                      peak_spool=max(float(np.max(np.abs(s["spool"]))) for s in sims),
                      peak_pressure=max(float(np.max(np.abs(s["pressure"]))) for s in sims),
                      peak_x=x_peak, rms_v=float(np.mean([c.derived["rms_v"] for c in cases])),
                      dt=min(c.dt for c in cases))
        r0 = E.residuals(sims, cases)
        base_test = E.channel_stats(sims, cases, "test")
        bar.set_description_str(f"round {rnd}: screening")
        screened = []
        added = {e["name"] for e in effects}
        for nme in names:
            bar.update(1)
            cand = LIBRARY[nme]
            entry = {"name": nme, "round": rnd, "screening_score": None, "balance_score": None,
                     "score": None, "delta_bic": None, "heldout_improvement": None, "parameters": None,
                     "accepted": False, "rejection": None}
            cand_log.append(entry)
            if nme in added:
                entry["rejection"] = "already added"
                continue
            if mode not in cand.modes:
                entry["rejection"] = f"cannot act in {mode} mode"
                continue
            why = cand.exercised(ctx)
            if why:
                entry["rejection"] = why
                continue
            inter = cand.interacts if refit_interacting else ()
            inter = tuple((k, u) for k, u in inter if getattr(current, k) > 0
                          and (k != "F_c" or current.effects.coulomb_friction))
            space = E.Space(cand, ctx, inter)
            sc = E.secant_screen(space, cases, sims, r0, tau)
            entry["screening_score"] = sc["score"]
            if cand.structural_signature is not None:
                entry["balance_score"] = E.balance_screen(current, cases, cand.structural_signature)
            screened.append((nme, space, sc, entry))
        screened.sort(key=lambda s: -s[2]["score"])
        survivors = screened[:keep]
        # the look-alikes of the best-screened candidate are confirmed too: screening by a linearised
        # signature cannot rank effects that differ only far from "absent" (a 30 Hz valve vs a delay)
        if screened:
            have = {s[0] for s in survivors}
            for la in LIBRARY[screened[0][0]].look_alikes:
                extra = [s for s in screened if s[0] == la and s[0] not in have]
                survivors += extra
                have |= {s[0] for s in extra}
        # the best structural candidate of the balance-equation screen also goes on
        structural = [s for s in screened if s[3]["balance_score"] is not None]
        if structural:
            best_bal = max(structural, key=lambda s: s[3]["balance_score"])
            if best_bal[0] not in {s[0] for s in survivors} and best_bal[3]["balance_score"] > 0.1:
                survivors.append(best_bal)
        kept = {s[0] for s in survivors}
        for rank, (nme, _space, sc, entry) in enumerate(screened):
            if nme not in kept:
                entry["rejection"] = (f"screening: its signature explains {100 * sc['score']:.1f} % of the residual "
                                      f"(rank {rank + 1}; kept the best {keep})")
        passing = []
        for nme, space, sc, entry in survivors:
            bar.set_description_str(f"round {rnd}: fitting {nme}")
            bar.update(1)
            t_fit = time.time()
            c = _confirm(space, sc["z0"], cases, stats, base_test, tau, ctx, refit_interacting, current)
            lo, hi, z, space = c["lo"], c["hi"], c["z"], c["space"]
            dbic, held = c["dbic"], c["held"]
            nm = space.n_main
            tested = space.tests_absent[:nm]
            outside = (space.absent[:nm] < lo[:nm]) | (space.absent[:nm] > hi[:nm])
            # present if one tested parameter's interval excludes "absent", or (parameters that trade against
            # each other) their joint 95 % region does
            excludes = bool(np.any(outside & tested)) or bool(c["joint_excludes"])
            entry["joint_p_absent"] = c["joint_p"]
            entry.update({"score": dbic, "delta_bic": dbic, "heldout_improvement": held,
                          "parameters": _param_report(space, z, lo, hi), "refit": c["refit"]})
            entry["fit_seconds"] = time.time() - t_fit
            reasons = []
            if dbic < DELTA_BIC_MIN:
                reasons.append(f"BIC improvement {dbic:.1f} < {DELTA_BIC_MIN:g}")
            entry["heldout_lr"] = c["held_lr"]
            if held < HELDOUT_MIN and c["held_lr"] < HELDOUT_LR_MIN:
                reasons.append(f"held-out error improves by {100 * held:.1f} % < {100 * HELDOUT_MIN:g} % and its "
                               f"-2 log L by {c['held_lr']:.1f} < {HELDOUT_LR_MIN:g}")
            if not excludes:
                reasons.append("95 % interval (and joint region) includes 'absent'")
            if reasons:
                entry["rejection"] = "; ".join(reasons)
            else:
                passing.append({"name": nme, "space": space, "z": z, "lo": lo, "hi": hi, "rig": c["rig"],
                                "tau": c["tau"], "sims": c["sims"], "dbic": dbic, "entry": entry, "sc": sc,
                                "stats": c["stats"], "neff": c["neff"], "held": held})
        if not passing:
            summary = (f"round {rnd}: no candidate passed (BIC, held-out error and interval tests); "
                       + ("the residual is above the noise floor: the missing effect may not be in the library"
                          if not E.at_noise_floor(stats, 0.5) else "the residual is near the noise floor"))
            break
        passing.sort(key=lambda p: -p["dbic"])
        best = passing[0]
        # "equally well": the two best fits' misfits (-2 log likelihood) differ by < DELTA_FIT_AMBIGUOUS on effective
        # sizes common to both (per channel the smaller of the two), without the parameter penalty
        fit_gap = None
        if len(passing) > 1:
            a, b = passing[0], passing[1]
            ne = {k: min(a["neff"][k], b["neff"][k]) for k in a["neff"]}
            fa, fb = E.bic(a["stats"], 0, ne), E.bic(b["stats"], 0, ne)
            ka, kb = a["z"].size, b["z"].size
            if E.bic(b["stats"], kb, ne) < E.bic(a["stats"], ka, ne):  # on the common scale the runner-up wins
                passing[0], passing[1] = b, a
                best = b
            fit_gap = abs(fb - fa)
            best["entry"]["fit_gap_to_runner_up"] = fit_gap
        # nested candidates (one is a limit of the other) are decided by the BIC above, never ambiguous
        if fit_gap is not None and fit_gap < DELTA_FIT_AMBIGUOUS and not nested(passing[0]["name"],
                                                                                passing[1]["name"]):
            other = passing[1]
            amb = [best["name"], other["name"]]
            sep = separating_experiment(best["name"], other["name"])
            for p in passing[:2]:
                p["entry"]["rejection"] = (f"ambiguous with {other['name'] if p is best else best['name']}: "
                                           f"their fits differ by {fit_gap:.1f} < {DELTA_FIT_AMBIGUOUS:g} "
                                           "(-2 log likelihood)")
            for p in passing[2:]:
                p["entry"]["rejection"] = f"passed, but BIC improvement {p['dbic']:.1f} below {best['name']}'s"
            verdict = "ambiguous"
            summary = f"round {rnd}: ambiguous: {amb[0]} or {amb[1]} explain the records equally well"
            break
        best["entry"]["accepted"] = True
        for p in passing[1:]:
            p["entry"]["rejection"] = (f"passed, but BIC improvement {p['dbic']:.1f} < {best['name']}'s "
                                       f"{best['dbic']:.1f}")
        current, tau = best["rig"], best["tau"]
        E.refine_x0(current, cases, tau)
        sims = E.simulate_all(current, cases, tau)
        g_after = E.gap(sims, cases)
        history.append((best["name"], g_after))
        signatures[best["name"]] = best["sc"]["signature"]
        eff = {"name": best["name"], "doc": LIBRARY[best["name"]].doc,
               "parameters": best["entry"]["parameters"], "delta_bic": best["dbic"],
               "heldout_improvement": best["held"], "gap_after": g_after, "round": rnd}
        if LIBRARY[best["name"]].delays_command:
            eff["note"] = ("time_delay is not a rig parameter: delay the command by tau (integer + fractional "
                           "samples) before simulating; rig_updated.toml cannot hold it")
        effects.append(eff)
        accepted.append({"name": best["name"], "space": best["space"], "z": np.asarray(best["z"], float).copy(),
                         "lo": np.asarray(best["lo"], float).copy(), "hi": np.asarray(best["hi"], float).copy(),
                         "eff": eff})
        if joint_refit and len(accepted) >= 2:
            bar.set_description_str(f"round {rnd}: joint re-fit")
            info, new = _joint_refit(accepted, current, tau, cases, sims, rnd)
            joint_log.append(info)
            if new is not None:
                current, tau, x0s, sims = new
                E.with_x0(cases, x0s)
                eff["gap_after"] = E.gap(sims, cases)
                history.append(("joint re-fit", eff["gap_after"]))
    bar.close()
    for eff in effects:
        tv = eff["parameters"].get("tau", {}).get("value") if LIBRARY[eff["name"]].delays_command else None
        if tv is not None and tv < 0.0:
            eff["note"] += (f"; tau < 0: the response channels lead the command by {-1e3 * tv:.2f} ms, which no "
                            "physical delay does: check the acquisition's alignment (row k must be sampled before "
                            "the command of row k is sent)")

    gap_after = E.gap(sims, cases)
    closed = {}
    for c in gap_before:
        den = gap_before[c] - floor[c]
        closed[c] = float(np.clip((gap_before[c] - gap_after[c]) / den, 0.0, 1.0)) if den > 1e-12 else None
    if verdict is None:
        verdict = "effect_found" if effects else "no_effect"
    if not summary:
        summary = f"stopped after {len(effects)} effect(s)"
    if joint_log:
        j = joint_log[-1]
        summary += (f"; joint re-fit of {' + '.join(j['effects'])}: "
                    + (f"kept (BIC better by {j['delta_bic']:.1f})" if j["kept"] else j["reason"]))
    head = {"effect_found": "missing effect(s): " + ", ".join(e["name"] for e in effects),
            "no_effect": "no missing effect", "ambiguous": f"ambiguous: {' or '.join(amb)}"}[verdict]
    if verdict == "ambiguous" and effects:
        head = "found " + ", ".join(e["name"] for e in effects) + "; then " + head
    d = Diagnosis(verdict=verdict, effects=effects, gap_before=gap_before, gap_after=gap_after,
                  candidates=cand_log, rig=current, mode=mode,
                  records=[c.name for c in cases], noise_floor=floor, gap_closed=closed, gap_where=where,
                  ambiguous_between=amb, separating_experiment=sep, joint_refit=joint_log, command_delay=tau,
                  summary=f"{head}. {summary}", runtime_s=time.time() - t_start)
    d.plots = {"cases": cases, "sims_before": sims0, "sims_after": sims, "history": history,
               "signatures": signatures}
    return d
