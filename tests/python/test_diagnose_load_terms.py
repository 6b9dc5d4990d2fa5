"""The diagnosis' actuator-size load term and the MR damper's yield displacement (issue 25, item 2).

Oracles: first-order perturbation theory of the actuator's continuity equation (what a load
costs the displacement scales as 1 / A when A, K_v, K_a and C_l scale together), and the
closed-form Bouc-Wen yield displacement (A / (beta + gamma))^(1/n).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.diagnosis import LIBRARY
from servohydraulics.diagnosis.effects import apply_area


def _rig(k: float, m: float, m_p: float) -> sh.Rig:
    r = sh.zhao2003()
    r.k, r.k_2, r.m, r.m_p = k, k, m, m_p
    r.effects.coulomb_friction = False
    r.effects.spring_softening = False
    return r


def _displacement(rig: sh.Rig) -> np.ndarray:
    dt = 5e-4
    t = np.arange(0.0, 1.0, dt)
    cmd = 2e-3 * np.sin(2 * np.pi * 3.0 * t) * np.minimum(t / 0.2, 1.0)
    return np.asarray(sh.simulate(rig, "displacement", cmd, dt=dt).displacement)


def test_actuator_size_keeps_the_no_load_response_and_scales_the_load_cost_as_one_over_A() -> None:
    """With A, K_v, K_a, C_l (and F_cap) scaled by q, the loop's no-load response is the same, and the
    displacement a load takes away (loaded run minus a run with the load ~1000 times smaller) falls as 1 / q
    to first order: the compliance flow K_a F' / A^2, the leakage C_l F / A^2 and the load pressure F / A all
    scale as 1 / q."""
    loaded, light = _rig(1.0e7, 1000.0, 200.0), _rig(1.0e4, 1.0, 0.2)
    costs = []
    for q in (1.0, 4.0, 16.0):
        a, b = apply_area(loaded, loaded.A * q), apply_area(light, light.A * q)
        assert a.K_v / a.A == pytest.approx(loaded.K_v / loaded.A, rel=1e-12)
        assert a.K_a / a.A == pytest.approx(loaded.K_a / loaded.A, rel=1e-12)
        assert a.F_cap / a.A == pytest.approx(loaded.F_cap / loaded.A, rel=1e-12)
        x_light = _displacement(b)
        costs.append(float(np.sqrt(np.mean((_displacement(a) - x_light) ** 2))))
        if q == 1.0:
            x_light_1 = x_light
        else:  # the no-load response is the same (to a few per cent of the load's cost: the light load's own)
            assert np.sqrt(np.mean((x_light - x_light_1) ** 2)) < 0.03 * costs[0]
    assert costs[0] > 1e-4  # the load costs the q = 1 loop a visible part of its 2 mm
    assert costs[1] / costs[0] == pytest.approx(1 / 4, rel=0.25)
    assert costs[2] / costs[0] == pytest.approx(1 / 16, rel=0.35)


def test_apply_area_returns_a_copy() -> None:
    r = sh.zhao2003()
    before = copy.deepcopy(r)
    out = apply_area(r, 3.0 * r.A)
    assert r == before and out.A == pytest.approx(3.0 * r.A)


@pytest.mark.parametrize("law", ["spencer", "quiroz2022"])
def test_mr_damper_candidate_sets_the_yield_displacement_in_closed_form(law: str) -> None:
    """The candidate's fourth parameter z_y: the rig it builds has (mr_A / (beta + gamma))^(1/mr_n) = z_y at the
    record's field input, beta / gamma kept; with three parameters (no z_y) beta and gamma are untouched."""
    r = sh.zhao2003()
    r.effects.mr_damper = True
    r.mr_A, r.mr_beta, r.mr_gamma, r.mr_n = 300.0, 4e-6, 7e4, 2.0
    r.mr_law = _core.MrLaw.Quiroz2022 if law == "quiroz2022" else _core.MrLaw.Spencer
    r.mr_bw_decay = 3.6561 if law == "quiroz2022" else 0.0
    r.mr_input, r.mr_current = _core.MrInput.Current, 1.0
    cand = LIBRARY["mr_damper"]
    law0 = _core.mr_damper_law(r)
    for z_y in (1e-3, 4e-3, 2e-2):
        out = cand.apply(r, np.array([law0["alpha"], law0["c0"], law0["c1"], z_y]))
        got = _core.mr_damper_law(out)
        assert (out.mr_A / (got["beta"] + got["gamma"])) ** (1.0 / out.mr_n) == pytest.approx(z_y, rel=1e-9)
        assert got["beta"] / got["gamma"] == pytest.approx(law0["beta"] / law0["gamma"], rel=1e-9)
        assert got["alpha"] == pytest.approx(law0["alpha"], rel=1e-9)
    out = cand.apply(r, np.array([law0["alpha"], law0["c0"], law0["c1"]]))
    assert (out.mr_beta, out.mr_gamma) == (r.mr_beta, r.mr_gamma)


def test_the_rigs_own_values_back_from_fitting_coordinates_rebuild_it_exactly() -> None:
    """The joint and loop re-fits start by rebuilding the current model from the effects' fitted values and
    refuse to run if it differs: a value that comes back from fitting coordinates with round-off (1/(1/A), a
    yield displacement through its power law) must rebuild the rig bit for bit (the whole-record UTFSM runs
    logged "the model cannot be rebuilt" before)."""
    from servohydraulics.diagnosis.effects import set_nominal

    r = sh.zhao2003()
    r.effects.mr_damper = True
    r.mr_A, r.mr_beta, r.mr_gamma, r.mr_n = 300.0, 4.459093676526806e-09, 3583307.673100985, 2.0
    law = _core.mr_damper_law(r)
    z_y = (r.mr_A / (law["beta"] + law["gamma"])) ** (1.0 / r.mr_n)
    for eps in (0.0, 1e-16, -3e-16, 1e-15):
        assert LIBRARY["mr_damper"].apply(r, np.array([law["alpha"], law["c0"], law["c1"], z_y * (1 + eps)])) == r
        assert set_nominal(r, "A", 1.0 / (1.0 / (r.A * (1 + eps)))) == r
    assert set_nominal(r, "A", 1.001 * r.A) != r
