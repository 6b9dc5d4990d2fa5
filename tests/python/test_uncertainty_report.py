"""Uncertainty that means what it says (issue 25, item 3): the coverage of the one covariance
rule on a model whose covariance is known, parameters that collapsed to a bound or to zero
reported as "at bound / not identified" (never with a falsely precise interval), parameters the
records cannot tell apart grouped, and the reports listing the best determined first.  The
helpers live in ``identification/stats.py`` and serve both ``sh.identify``'s report and
``sh.diagnose``'s."""

from __future__ import annotations

import types

import numpy as np
import pytest
from scipy import signal

import servohydraulics as sh
from servohydraulics.diagnosis import LIBRARY, engine
from servohydraulics.diagnosis.confirm import param_report
from servohydraulics.diagnosis.effects import Context
from servohydraulics.identification import stats
from servohydraulics.identification.coordinates import Coordinates
from servohydraulics.identification.fit import StageResult
from servohydraulics.identification.records import CHI2_1_95, removal_statistics, uncertainty
from servohydraulics.identification.report import identification_markdown


@pytest.mark.parametrize("phi, lowest, var_rtol", [(0.6, 0.923, 0.15), (0.95, 0.90, 0.25)])
def test_hac_intervals_cover_the_truth_of_a_regression_with_known_covariance(phi, lowest, var_rtol):
    """Oracle: y = X beta + e with AR(1) noise and known beta.  The least-squares estimate's
    95 % intervals from ``stats.covariance`` (the rule both reports use) cover beta in 95 % of
    400 replications for each of the two parameters: within the binomial spread (down to 92.3 %)
    at phi = 0.6, at least 90 % at phi = 0.95 (about 40 effective samples in 1500); their mean
    variance is the exact one, (X'X)^-1 X' S X (X'X)^-1 with S the AR(1) covariance, within 15 %
    (25 %).  The white-noise rule s^2 (X'X)^-1 covers 85 % or less.  (Without the prewhitening of
    the scores the sandwich covered 92 % at phi = 0.6 and 84-88 % at 0.95.)"""
    n, reps = 1500, 400
    rng = np.random.default_rng(25)
    t = np.arange(n) / n
    X = np.column_stack([np.sin(2 * np.pi * 3 * t), t - 0.5])
    beta = np.array([1.0, -2.0])
    q = stats.quantile()
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    S = phi ** lag / (1 - phi ** 2)  # AR(1) with unit innovations
    XtXi = np.linalg.inv(X.T @ X)
    exact = XtXi @ X.T @ S @ X @ XtXi
    hits, white, var = np.zeros(2), np.zeros(2), np.zeros(2)
    for _ in range(reps):
        e = signal.lfilter([1.0], [1.0, -phi], rng.standard_normal(n + 200))[200:]
        y = X @ beta + e
        b = XtXi @ X.T @ y
        r = y - X @ b
        sd = stats.covariance(X, r).sd  # the residual's Jacobian in b is -X: the sign does not matter
        hits += np.abs(b - beta) <= q * sd
        white += np.abs(b - beta) <= q * np.sqrt(float(r @ r) / n * np.diag(XtXi))
        var += sd ** 2 / reps
    cover = hits / reps
    assert np.all((cover >= lowest) & (cover <= 0.977)), cover
    np.testing.assert_allclose(var, np.diag(exact), rtol=var_rtol)
    assert np.all(white / reps < 0.85), white / reps


@pytest.mark.parametrize("m, p, L", [(2, 1, 1), (9, 3, 4), (400, 5, 60), (1200, 10, 599)])
def test_the_bartlett_sum_is_the_weighted_sum_of_the_lagged_cross_products(m, p, L):
    """Oracle: the definition, sum over |l| <= L of (1 - |l| / (L + 1)) Gamma_l with
    Gamma_l = sum_t S_t+l S_t' summed lag by lag, on persistent (random-walk) scores: the
    filtered-columns form ``stats._bartlett`` computes agrees to rounding, and it is symmetric (to rounding)."""
    S = np.random.default_rng(m + p + L).standard_normal((m, p)).cumsum(axis=0)
    want = S.T @ S
    for lag in range(1, L + 1):
        g = S[lag:].T @ S[:-lag]
        want += (1.0 - lag / (L + 1)) * (g + g.T)
    got = stats._bartlett(S, L)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))
    np.testing.assert_allclose(got, got.T, rtol=0, atol=1e-13 * np.max(np.abs(want)))


def test_inseparable_groups_are_the_connected_pairs():
    """a-b and b-c correlated beyond 0.95 make one group {a, b, c} even though a-c is 0.9; d-e is
    a second group; f is alone; NaN entries (a parameter without a finite variance) link nothing."""
    c = np.eye(6)
    for i, j, v in ((0, 1, 0.97), (1, 2, -0.96), (0, 2, 0.9), (3, 4, 0.99), (2, 5, np.nan)):
        c[i, j] = c[j, i] = v
    assert stats.inseparable_groups(c) == [[0, 1, 2], [3, 4]]
    assert stats.inseparable_groups(np.eye(3)) == []


def test_precision_order_lists_the_best_determined_first():
    order = stats.precision_order([0.1, 0.001, np.inf, 0.02, 0.0005],
                                  ["identified", "identified", "not identified", "identified", "at bound"])
    assert order == [1, 3, 0, 4, 2]


def test_bound_status():
    st = stats.bound_status([0.0, 0.5, 1.0, 0.3, 2.0], [0.0, 0.0, 0.0, 0.0, -np.inf], [1.0, 1.0, 1.0, 1.0, np.inf],
                            [True, True, True, False, True])
    assert st == ["at bound", "identified", "at bound", "not identified", "identified"]


def test_a_key_whose_removal_changes_nothing_is_at_bound_not_falsely_precise():
    """Two log keys of a model r(z) = v_a(z) g - y + noise: key a acts (its value a fifth of the
    signal), key b does nothing, yet its Jacobian column is large (as the column of a damper mass
    collapsed to 3.6e-11 kg came out of the integrator's noise), so the sandwich gives b a tiny
    interval.  The removal statistic (a simulation with the key at the bottom of its range) is the
    Wald statistic for a (within 1 %) and zero for b: b is "at bound" with its whole range, a keeps
    its finite interval."""
    rng = np.random.default_rng(7)
    n = 4000
    g = np.sin(np.linspace(0, 40, n))
    noise = 0.01 * rng.standard_normal(n)
    coords = Coordinates(("a", "b"), np.array([0.2, 3.6e-11]), ("log", "log"), np.array([0.2, 3.6e-11]))

    def residual(z):
        v = coords.values(z)
        return v[0] * g - 0.2 * g + noise  # the data: a = 0.2; b has no effect at all

    z = np.zeros(2)
    f = residual(z)
    J = np.column_stack([0.2 * g, 0.5 * rng.standard_normal(n)])  # b's column: spurious, not the model's
    stage = StageResult(z, 0.5 * float(f @ f), 1, f, J)
    cov = stats.covariance(J, f)
    w = removal_statistics(stage, coords, cov, residual)
    assert w[0] == pytest.approx(1.0 / cov.sd[0] ** 2, rel=0.01)
    assert w[1] < 1e-6 < CHI2_1_95
    u = uncertainty(stage, coords, [n], residual=residual)
    assert u["status"] == {"a": "identified", "b": "at bound"}
    assert u["intervals"]["b"] == (0.0, np.inf)
    assert 0.19 < u["intervals"]["a"][0] < 0.2 < u["intervals"]["a"][1] < 0.21


def test_removals_on_the_fits_own_runs_compare_with_the_cost_on_the_same_runs():
    """``removal_statistics`` with ``fast`` (the fit's own, cheaper runs; None where they cannot stand for
    the whole runs): each removal is compared with the cost at the fit on the runs it was made on.  A
    fast residual that differs from the whole runs' by an integrator's error (a fixed 2 % of the signal,
    the same at every point) gives the whole runs' statistics; where ``fast`` gives None (key b, a removal
    the fit's runs cannot make), the whole runs decide, compared with their own cost."""
    rng = np.random.default_rng(11)
    n = 4000
    g = np.sin(np.linspace(0, 40, n))
    noise = 0.01 * rng.standard_normal(n)
    coords = Coordinates(("a", "b"), np.array([0.2, 0.1]), ("log", "log"), np.array([0.2, 0.1]))

    def residual(z):  # both keys act: a on g, b on a second signal
        v = coords.values(z)
        return v[0] * g - 0.2 * g + (v[1] - 0.1) * np.cos(np.linspace(0, 25, n)) + noise

    calls = []

    def fast(points):
        calls.append(len(points))
        out = []
        for z in points:
            v = coords.values(z)
            out.append(None if v[1] < 0.05 else residual(z) + 0.02 * 0.2 * g)  # b removed: not on these runs
        return out

    z = np.zeros(2)
    f = residual(z)
    J = np.column_stack([0.2 * g, 0.1 * np.cos(np.linspace(0, 25, n))])
    stage = StageResult(z, 0.5 * float(f @ f), 1, f, J)
    cov = stats.covariance(J, f)
    whole = removal_statistics(stage, coords, cov, residual)
    both = removal_statistics(stage, coords, cov, residual, fast)
    assert calls == [3]  # the fit's point and the two removals, run together
    assert both[0] == pytest.approx(whole[0], rel=0.05) and both[0] != whole[0]  # a on the fast runs
    assert both[1] == whole[1]  # b on the whole runs, to the bit
    assert both[0] > CHI2_1_95 and both[1] > CHI2_1_95
    assert removal_statistics(stage, coords, cov, residual, lambda pts: [None] * len(pts)) == whole


def _context(rig: sh.Rig) -> Context:
    return Context(rig=rig, nominal=rig, mode="displacement", peak_spool=0.1, peak_pressure=5e6, peak_x=0.03,
                   rms_v=0.05, peak_force=3e4)


def test_diagnosis_reports_a_parameter_at_its_bound_as_at_bound_with_its_whole_range():
    """A Coulomb fit that collapsed to F_c = 0 (the bottom of its plausible range) with a
    sandwich interval of +-1e-3 N is reported "at bound" with the whole range [0, 5 kN], not the
    falsely precise interval; a friction level well inside its range keeps its interval, cut at 0
    where the sandwich interval crosses it; the report says "at bound / not identified"."""
    rig = sh.zhao2003()
    rig.effects.coulomb_friction = False
    space = engine.Space(LIBRARY["coulomb_friction"], _context(rig), ())
    hi_range = float(space.hi[0])
    collapsed = param_report(space, np.array([0.0]), np.array([-1e-3]), np.array([1e-3]))["F_c"]
    assert collapsed["status"] == "at bound"
    assert collapsed["interval_95"] == [0.0, hi_range]
    inside = param_report(space, np.array([40.0]), np.array([-10.0]), np.array([90.0]))["F_c"]
    assert inside["status"] == "identified" and inside["interval_95"] == [0.0, 90.0]
    assert inside["relative_sd"] == pytest.approx(100.0 / (2 * stats.quantile()) / 40.0)
    unknown = param_report(space, np.array([40.0]), np.array([-np.inf]), np.array([np.inf]))["F_c"]
    assert unknown["status"] == "not identified" and unknown["interval_95"] == [None, None]

    from servohydraulics.diagnosis.report import _markdown
    from servohydraulics.diagnosis.workflow import Diagnosis, _determined

    effects = [{"name": "coulomb_friction", "doc": "friction", "parameters": {"F_c": collapsed},
                "delta_bic": 12.0, "heldout_improvement": 0.1, "gap_after": {}, "round": 1},
               {"name": "viscous_damping", "doc": "damping", "parameters": {
                   "c": {**inside, "unit": "N s/m", "relative_sd": 0.01}}, "delta_bic": 30.0,
                "heldout_improvement": 0.2, "gap_after": {}, "round": 2}]
    d = Diagnosis(verdict="effect_found", effects=effects, gap_before={}, gap_after={}, candidates=[], rig=rig,
                  mode="displacement", records=["r"], determined=_determined(effects),
                  inseparable=[["coulomb_friction: F_c", "viscous_damping: c"]])
    assert [r["effect"] for r in d.determined] == ["viscous_damping", "coulomb_friction"]  # best first
    md = _markdown(d, {})
    assert "at bound / not identified" in md
    assert "{coulomb_friction: F_c, viscous_damping: c}" in md
    assert md.index("| viscous_damping | c |") < md.index("| coulomb_friction | F_c |")


def test_identify_report_lists_the_best_determined_first_and_groups_what_it_cannot_separate():
    """``identification_markdown`` orders the keys by relative standard error (at-bound and
    unidentified ones last) and names the group of keys whose correlations exceed 0.95."""
    params = {"G_p": {"value": 0.8, "unit": "-", "start": 1.0, "stage1": 0.9, "std": 0.08, "status": "identified",
                      "interval": [0.64, 0.96]},
              "f_v": {"value": 60.0, "unit": "Hz", "start": 70.0, "stage1": None, "std": 0.6, "status": "identified",
                      "interval": [58.8, 61.2]},
              "m": {"value": 3.6e-11, "unit": "kg", "start": 0.1, "stage1": None, "std": np.inf,
                    "status": "at bound", "interval": [0.0, np.inf]},
              "zeta_v": {"value": 0.6, "unit": "-", "start": 0.7, "stage1": None, "std": 0.03,
                         "status": "identified", "interval": [0.54, 0.66]}}
    corr = np.array([[1, 0.2, np.nan, 0.1], [0.2, 1, np.nan, 0.97], [np.nan] * 4, [0.1, 0.97, np.nan, 1]], float)
    ident = types.SimpleNamespace(
        to_dict=lambda: {"level": 0.95, "parameters": params, "derived": {}, "field": None}, generic_start=True,
        mode="displacement", kept="time", rho1=0.9, n_eff=100.0, keys=tuple(params), correlation=corr, flags=[],
        before=[], after=[], field_input=None, checks=[], runtime_s={}, nfev={})
    md = identification_markdown(ident)
    rows = [ln for ln in md.splitlines() if ln.startswith("| `")][:4]
    assert [r.split("`")[1] for r in rows] == ["f_v", "zeta_v", "G_p", "m"]
    assert "at bound / not identified" in rows[3]
    assert "{`f_v`, `zeta_v`}" in md
