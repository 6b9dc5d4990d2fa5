"""Diagnose: the named rules of the workflow, alone, on synthetic inputs.

The decision of a round (``workflow._decide``) against its stated contract
(docs/diagnose.md, steps 4-5), the JSON row of a candidate (the keys written
before and after a fit), and the lag-1 autocorrelation behind the effective
sample sizes against an AR(1) process whose coefficient is known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.diagnosis import engine, workflow
from servohydraulics.diagnosis.types import CandidateLog, Fit, Refit, Screening

KEY = ("rec", "displacement")
N = 1000


def _passing(name: str, ssr: float, dbic: float) -> workflow._Passing:
    """A candidate that passed every test, with residual sum of squares ``ssr``
    over N samples (no autocorrelation: n_eff = N)."""
    stats = {KEY: {"ssr": ssr, "n": N, "rho": 0.0, "floor": 0.0}}
    z = np.zeros(1)
    fit = Fit(space=None, z=z, z_tr=z, lo=z - 1, hi=z + 1, rig=sh.zhao2003(), tau=0.0, x0=np.zeros(1),
              joint_excludes=True, joint_p=0.0, sims=[], stats=stats, neff={KEY: float(N)}, dbic=dbic, held=0.5,
              held_lr=50.0)
    return workflow._Passing(name, fit, Screening(0.5, z, None))


def _log(*names: str) -> dict:
    return {n: CandidateLog(n, 1, screening_score=0.5) for n in names}


def test_decide_two_equal_fits_are_ambiguous() -> None:
    # misfits differ by N log(100.2 / 100) = 2.0 < DELTA_FIT_AMBIGUOUS: neither is named
    a, b = _passing("viscous_damping", 100.0, 40.0), _passing("leakage", 100.2, 38.0)
    assert N * math.log(100.2 / 100.0) < workflow.DELTA_FIT_AMBIGUOUS
    rnd = workflow._decide(1, [b, a], _log("viscous_damping", "leakage"), {})
    assert rnd.outcome == "ambiguous" and rnd.best is None
    assert rnd.ambiguous_between == ("viscous_damping", "leakage")
    assert "viscous_damping" in rnd.separating_experiment and "leakage" in rnd.separating_experiment
    assert all(row.rejection.startswith("ambiguous with") and not row.accepted for row in rnd.log)


def test_decide_nested_candidates_are_never_ambiguous() -> None:
    # lugre_friction nests coulomb_friction: the same small misfit gap is decided by the BIC
    a, b = _passing("coulomb_friction", 100.0, 40.0), _passing("lugre_friction", 100.2, 38.0)
    rnd = workflow._decide(1, [a, b], _log("coulomb_friction", "lugre_friction"), {})
    assert rnd.outcome == "accept" and rnd.best_name == "coulomb_friction"
    rows = {row.name: row for row in rnd.log}
    assert rows["coulomb_friction"].accepted and rows["coulomb_friction"].rejection is None
    assert rows["coulomb_friction"].fit_gap_to_runner_up == pytest.approx(N * math.log(100.2 / 100.0))
    assert "passed, but BIC improvement" in rows["lugre_friction"].rejection


def test_decide_says_why_a_larger_bic_improvement_lost_on_common_sample_sizes() -> None:
    # a (smooth residual: n_eff 100) gains more on its own sample sizes than b (white: 1000), but b's misfit is
    # lower: on the common (smaller) sizes b wins, and a's reason must say so, not claim 60 < 40
    a, b = _passing("mr_damper", 100.0, 60.0), _passing("lugre_friction", 90.0, 40.0)
    a.fit.neff[KEY] = 100.0
    rnd = workflow._decide(1, [b, a], _log("mr_damper", "lugre_friction"), {})
    assert rnd.outcome == "accept" and rnd.best_name == "lugre_friction"
    reason = {row.name: row for row in rnd.log}["mr_damper"].rejection
    lower = 100.0 * math.log(100.0 / 90.0)  # the same k: the penalties cancel
    assert "common to both" in reason and f"lower by {lower:.1f}" in reason and "60.0" in reason
    assert "< lugre_friction" not in reason


def test_decide_clear_winner_and_nothing_passing() -> None:
    a, b = _passing("viscous_damping", 100.0, 40.0), _passing("leakage", 110.0, 20.0)
    rnd = workflow._decide(2, [b, a], _log("viscous_damping", "leakage"), {})
    assert rnd.outcome == "accept" and rnd.best is a.fit and rnd.number == 2
    stats = {KEY: {"ssr": 100.0, "n": N, "rho": 0.0, "floor": 10.0}}  # 10x the noise floor
    stop = workflow._decide(2, [], _log("leakage"), stats)
    assert stop.outcome == "stop" and "may not be in the library" in stop.summary


def test_candidate_log_keys() -> None:
    base = ["name", "round", "screening_score", "balance_score", "score", "delta_bic", "heldout_improvement",
            "parameters", "accepted", "rejection"]
    assert list(CandidateLog("leakage", 1, rejection="already added").to_dict()) == base
    fitted = CandidateLog("leakage", 1, delta_bic=12.0, joint_p_absent=0.01, refit=Refit(), fit_seconds=1.0,
                          heldout_lr=11.0).to_dict()
    assert list(fitted) == base + ["joint_p_absent", "refit", "fit_seconds", "heldout_lr"]
    assert fitted["refit"] == {"tried": False, "kept": False}


def test_ar1_coefficient_of_an_ar1_process() -> None:
    """The diagnosis's AR(1) coefficient is identify's lag-1 autocorrelation, clipped to [0, 0.999]."""
    from servohydraulics.identification.stats import ar1_coefficient, ar1_effective_n, lag1_autocorrelation

    rng = np.random.default_rng(5)
    phi, n = 0.6, 200_000
    w = rng.normal(size=n)
    e = np.empty(n)
    e[0] = w[0]
    for i in range(1, n):
        e[i] = phi * e[i - 1] + w[i]
    # the estimate's standard deviation is about sqrt((1 - phi^2) / n) = 0.0018
    assert abs(ar1_coefficient(e) - phi) < 0.01
    assert ar1_coefficient(e) == lag1_autocorrelation(e)
    assert ar1_coefficient(np.cumsum(w)) == 0.999  # a random walk: clipped below 1
    alternating = np.resize([1.0, -1.0], 100)
    assert lag1_autocorrelation(alternating) < -0.9 and ar1_coefficient(alternating) == 0.0  # clipped at 0
    assert ar1_effective_n(1000, 0.6) == pytest.approx(1000 * 0.4 / 1.6)


def test_balance_screen_has_the_stribeck_level() -> None:
    """The balance screen's structure forces are Eq (5)'s with the Stribeck level (the core's):
    a force record made by the closed form m a + k x + c v + g(v) tanh(v / v_stick), g(v) =
    F_c (1 + (r - 1) exp(-(v / v_s)^2)), plus a known extra force w leaves exactly w as the
    residual, so w's signature explains all of it (without the Stribeck level it would not)."""
    from types import SimpleNamespace

    rig = sh.zhao2003()
    rig.effects.coulomb_friction, rig.effects.lugre_friction, rig.effects.spring_softening = True, False, False
    rig.stribeck_ratio, rig.v_s, rig.F_c = 2.0, 0.01, 300.0
    t = np.arange(20000) * 5e-4
    w0 = 2 * math.pi * 1.0
    x, v, a = 0.01 * np.sin(w0 * t), 0.01 * w0 * np.cos(w0 * t), -0.01 * w0 ** 2 * np.sin(w0 * t)
    g = rig.F_c * (1.0 + (rig.stribeck_ratio - 1.0) * np.exp(-(v / rig.v_s) ** 2))
    extra = 50.0 * np.sin(3 * w0 * t) ** 3
    F = rig.m * a + rig.k * x + rig.c * v + g * np.tanh(v / rig.v_stick) + extra
    derived = {"displacement": x, "velocity": v, "acceleration": a, "force": F, "rms_v": float(np.std(v))}
    case = SimpleNamespace(derived=derived, mode="force")
    assert engine.balance_screen(rig, [case], lambda r, s: np.sin(3 * w0 * t) ** 3) > 1 - 1e-9
    stribeck_excess = (g - rig.F_c) * np.tanh(v / rig.v_stick)
    assert engine.balance_screen(rig, [case], lambda r, s: stribeck_excess) < 0.01
