"""Confirmation of a screened candidate by simulation-error fits: the start of
the fit, the train-segment fit (held-out improvement), the fit on all data (BIC
improvement, HAC 95 % intervals, joint test against "absent") and the bounded
re-fit of the interacting nominal parameters."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..identification.fit import best
from ..identification.stats import LEVEL, bound_status, inseparable_groups, quantile
from . import engine
from .effects import LOAD_TERMS, Context
from .types import Case, Fit, Refit


def param_report(space, z: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> dict:
    """The fitted parameters as diagnosis.json writes them: per key its value, unit, 95 % interval,
    value meaning "absent" (external units), rig key, ``status`` (``stats.bound_status``:
    "identified", "at bound" for a parameter that ended at a limit of its plausible range, its
    interval then that whole range, or "not identified", its interval null) and ``relative_sd``
    (the standard error over the value, in the fitting coordinates).  An identified parameter's
    interval is cut to the plausible range (a friction level's interval does not go below 0)."""
    z = np.asarray(z, float)
    n = space.lo.size
    z, lo, hi = z[:n], np.asarray(lo, float)[:n], np.asarray(hi, float)[:n]
    status = bound_status(z, space.lo, space.hi, np.isfinite(lo) & np.isfinite(hi), scale=space.scale[:n])
    q = quantile(LEVEL)
    ext = space.to_external(z)
    absent = space.to_external(space.absent)
    out = {}
    keys = [(p.key, p.unit, p.rig_key) for p in space.params] + \
           [(k, u, LOAD_TERMS[k].rig_key if k in LOAD_TERMS else "re-fitted nominal parameter")
            for k, u in space.interacting]
    for i, (key, unit, where) in enumerate(keys):
        if status[i] == "at bound":
            zl, zh = space.lo[i], space.hi[i]
        else:
            zl, zh = max(lo[i], space.lo[i]), min(hi[i], space.hi[i])
        a, b = space.coords.values_at(i, float(zl)), space.coords.values_at(i, float(zh))
        a, b = min(a, b), max(a, b)
        sd = (hi[i] - lo[i]) / (2 * q) if np.isfinite(hi[i] - lo[i]) else math.inf
        out[key] = {"value": _num(ext[i]), "unit": unit, "interval_95": [_num(a), _num(b)],
                    "absent": _num(absent[i]), "rig_key": where, "status": status[i],
                    "relative_sd": _num(sd / abs(z[i])) if z[i] != 0 else None}
        if status[i] == "not identified":
            out[key]["interval_95"] = [None, None]
        if key in LOAD_TERMS and not math.isfinite(ext[i]):
            out[key]["note"] = "infinite: the term is switched off"
    return out


def param_groups(space, corr: np.ndarray | None) -> list[list[str]]:
    """The groups of the space's parameters that the records cannot tell apart
    (``stats.inseparable_groups``), by key."""
    if corr is None:
        return []
    keys = [p.key for p in space.params] + [k for k, _ in space.interacting]
    return [[keys[i] for i in g] for g in inseparable_groups(corr)]


def _num(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _heldout(space, z_tr: np.ndarray, x0_tr: np.ndarray, cases: list[Case], base_test: dict,
             tau: float) -> tuple[float, float]:
    """The held-out (test-segment) SSR improvement of the train-segment fit
    (fraction) and of its -2 log likelihood (the held-out residual's effective
    sample sizes before the effect)."""
    rig_tr, tau_tr = space.rig_and_tau(z_tr, tau)
    test = engine.channel_stats(engine.simulate_all(rig_tr, cases, tau_tr, x0_tr), cases, "test")
    held = 1.0 - sum(s["ssr"] for s in test.values()) / sum(s["ssr"] for s in base_test.values())
    ne_test = engine.n_eff(base_test)
    held_lr = float(sum(ne_test[k] * math.log(max(base_test[k]["ssr"], 1e-300) / max(test[k]["ssr"], 1e-300))
                        for k in base_test))
    return held, held_lr


def _cost(space, z: np.ndarray, cases: list[Case], x0s, tau: float, which: str, weights: dict | None = None
          ) -> float:
    """Sum of squared normalised (and weighted) residuals of the model at ``z`` (fitting coordinates;
    the search's runs, ``engine.run_options``: it chooses the fits' starts)."""
    rig, t = space.rig_and_tau(z, tau)
    r = engine.residuals(engine.simulate_all(rig, cases, t, x0s, search=True), cases, which, weights)
    return float(r @ r)


def _ssr(stats: dict) -> float:
    return sum(s["ssr"] for s in stats.values())


#: least-squares evaluations of the fit repeated with the likelihood's channel weights (0: no such repeat)
WEIGHTED_NFEV = 20


def _judged(space, res, cases: list[Case], tau: float, stats: dict, neff_ref: dict | None):
    """The model of a fit (parameters, initial displacements, rig, delay, simulations), its channel
    statistics, the effective sample sizes for its BIC and whether it ends worse than the current model
    (``stats``) by the total SSR or by the BIC's -2 log L."""
    z, x0 = res.z, res.x0
    rig_c, tau_c = space.rig_and_tau(z, tau)
    sims_c = engine.simulate_all(rig_c, cases, tau_c, x0)
    st_c = engine.channel_stats(sims_c, cases)
    neff = neff_ref if neff_ref is not None else engine.n_eff(st_c)
    worse = _ssr(st_c) > _ssr(stats) or engine.bic(st_c, 0, neff) > engine.bic(stats, 0, neff)
    return z, x0, rig_c, tau_c, sims_c, st_c, neff, worse


def _absent_z(space) -> np.ndarray:
    """The candidate's "absent" value with the interacting parameters at their current values (fitting
    coordinates): the model of the previous round."""
    return np.asarray(space.absent, float).copy()


def fit_space(space, z0: np.ndarray, cases: list[Case], x0s, stats: dict, base_test: dict, tau: float,
              neff_ref: dict | None = None) -> Fit:
    """Train-segment fit (held-out improvement), then the fit on all data, its BIC
    improvement over the current model (``stats``: its channel statistics) and its
    HAC 95 % intervals.  ``x0s``: the current initial displacements (the fits'
    start for the co-fitted ones).

    The invariant: the fit never ends worse than the candidate's "absent" value
    (which reproduces the current model): the fit on all data starts from the
    better of the train-segment fit and "absent", and a result whose misfit (the
    total normalised SSR or the BIC's -2 log L) is above the current model's is
    replaced by "absent" itself (so that its BIC change is the parameter penalty
    alone, never a gain, and never a loss beyond it)."""
    absent = _absent_z(space)
    tr = engine.fit(space, cases, z0, tau, "train", x0s)
    z_tr = {"absent": absent, "train": tr.z}[best({"train": _cost(space, tr.z, cases, tr.x0, tau, "train"),
                                                    "absent": _cost(space, absent, cases, x0s, tau, "train")})]
    x0_tr = tr.x0 if z_tr is tr.z else np.asarray(x0s, float)
    held, held_lr = _heldout(space, z_tr, x0_tr, cases, base_test, tau)
    start = {"absent": absent, "train": z_tr}[best({"train": _cost(space, z_tr, cases, x0s, tau, "all"),
                                                     "absent": _cost(space, absent, cases, x0s, tau, "all")})]
    res = engine.fit(space, cases, start, tau, "all", x0s, max_nfev=12)
    z, x0, rig_c, tau_c, sims_c, st_c, neff, worse = _judged(space, res, cases, tau, stats, neff_ref)
    if worse and WEIGHTED_NFEV and _ssr(st_c) < _ssr(stats):
        # the records' error fell but the likelihood the decision reads did not: the channels differ in quality
        # (a force gap of 88 % beside a displacement gap of 2.7 %: the BIC weighs the displacement by its far
        # larger effective sample size), so the fit is repeated with the likelihood's own channel weights
        w = engine.likelihood_weights(stats)
        start_w = {"absent": absent, "fit": z}[best({"fit": _cost(space, z, cases, x0, tau, "all", w),
                                                    "absent": _cost(space, absent, cases, x0s, tau, "all", w)})]
        res_w = engine.fit(space, cases, start_w, tau, "all", x0s if start_w is absent else x0,
                           max_nfev=WEIGHTED_NFEV, weights=w)
        judged = _judged(space, res_w, cases, tau, stats, neff_ref)
        if not judged[-1]:
            res, (z, x0, rig_c, tau_c, sims_c, st_c, neff, worse) = res_w, judged
    if worse:  # the fit wandered off: the candidate at "absent", i.e. the current model itself
        z, x0 = absent, np.asarray(x0s, float)
        rig_c, tau_c = space.ctx.rig, tau
        sims_c = engine.simulate_all(rig_c, cases, tau_c, x0)
        st_c = engine.channel_stats(sims_c, cases)
        res = dataclasses.replace(res, z=z, x0=x0)
    dbic = engine.bic(stats, 0, neff) - engine.bic(st_c, z.size, neff)
    lengths = engine.series_lengths(cases)
    lo, hi, corr = engine.uncertainty(space, res, lengths)
    nm = space.n_main
    tested = np.concatenate([space.tests_absent[:nm], np.zeros(z.size - nm, bool)])
    joint, pval = engine.joint_excludes_absent(space, res, lengths, tested)
    if worse:
        joint, pval, lo, hi = False, 1.0, np.minimum(lo, z), np.maximum(hi, z)
    return Fit(space=space, z=z, z_tr=z_tr, lo=lo, hi=hi, corr=corr, rig=rig_c, tau=tau_c, x0=x0, joint_excludes=joint,
               joint_p=pval, sims=sims_c, stats=st_c, neff=neff, dbic=dbic, held=held, held_lr=held_lr,
               ended_at_absent=bool(worse))


def scan_start(space, z0: np.ndarray, cases: list[Case], x0s, tau: float, ctx: Context) -> np.ndarray:
    """The start of the fit (multi-start): the best (training-segment error) of
    the candidate's "absent" value (the current model), the screening estimate (a
    linear extrapolation of the signature, which can land far off for a strongly
    nonlinear parameter such as K_a), the probe value, and for an effect whose
    error is not smooth in its first parameter (``Candidate.scan``) the values of
    a coarse scan of it, the other parameters at the screening estimate (or the
    probe where that is "absent": a scan of a yield displacement at zero force
    sees nothing).  A least-squares fit started where a hard clip barely engages
    stops there; one started at "absent" cannot end worse than the current model."""
    n = space.n_main
    z0 = np.asarray(z0, float)[:n]
    other = np.where(z0 == space.absent[:n], space.probe[:n], z0)
    starts = [np.asarray(space.absent[:n], float), z0, np.asarray(space.probe[:n], float)]
    for v in (np.asarray(space.cand.scan(ctx), float) if space.cand.scan is not None else ()):
        z = other.copy()
        z[0] = np.clip(space.to_internal(np.concatenate([[v], space.to_external(z)[1:]]))[0], space.lo[0], space.hi[0])
        starts.append(z)
    cost = [_cost(space, np.concatenate([z, space.absent[n:]]), cases, x0s, tau, "train") for z in starts]
    return starts[int(np.argmin(cost))]


def confirm(space, z0: np.ndarray, cases: list[Case], x0s, stats: dict, base_test: dict, tau: float, ctx: Context,
            refit_interacting: bool) -> Fit:
    """Fits the candidate alone, then (if it has interacting nominal parameters and
    ``refit_interacting``) with the bounded +-25 % re-fit of them, started from the
    first fit; keeps the re-fit only if it improves the BIC (same effective sample
    sizes for both)."""
    alone = engine.Space(space.cand, ctx, ())
    z0 = scan_start(alone, z0[: alone.n_main], cases, x0s, tau, ctx)
    a = fit_space(alone, z0, cases, x0s, stats, base_test, tau)
    inter = space.interacting if refit_interacting else ()
    if not inter:
        return a
    z1 = np.concatenate([a.z_tr, space.absent[space.n_main:]])
    b = fit_space(space, z1, cases, x0s, stats, base_test, tau, neff_ref=a.neff)
    keep = b.dbic > a.dbic
    info = Refit(tried=True, kept=bool(keep), parameters=tuple(k for k, _ in inter), delta_bic_with=b.dbic,
                 delta_bic_without=a.dbic)
    return dataclasses.replace(b if keep else a, refit=info)
