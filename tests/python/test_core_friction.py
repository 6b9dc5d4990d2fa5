"""Friction beyond Coulomb: the Stribeck peak and LuGre presliding friction.

Oracles:
* presliding (LuGre with a sliding level far above any force in the test):
  the bristles are a spring sigma_0 and a damper sigma_1 in parallel with the
  structure, so a free vibration is the closed-form damped oscillation at
  sqrt((k + sigma_0)/m) about x_eq = sigma_0 x0 / (k + sigma_0);
* steady sliding: a constant force F0 drives the free structure to the terminal
  velocity v* with F0 = c v* + g(v*) (LuGre's steady state is the static law);
* the independent plain-Python simulator of the diagnose evaluation
  (evaluation/diagnose_eval/independent_plant.py), which has its own LuGre model.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import servohydraulics as sh

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation" / "diagnose_eval"))
import independent_plant as ip  # noqa: E402

DT = 5e-4


def _free_rig(**kw) -> sh.Rig:
    r = sh.zhao2003(actuator_attached=False)
    for k, v in kw.items():
        setattr(r, k, v)
    return r


@pytest.mark.parametrize("sigma_1", [0.0, 3.0e4])
def test_presliding_is_a_spring_and_damper(sigma_1: float) -> None:
    k, m, c, s0, x0 = 700.8e3, 7084.0, 1.1e3, 5.0e5, 2e-3
    r = _free_rig(F_c=1e9, sigma_0=s0, sigma_1=sigma_1, k=k, m=m, c=c)
    r.effects.spring_softening = False
    r.effects.lugre_friction = True
    res = sh.simulate(r, "free", duration=3.0, dt=DT, x0=x0,
                      options=sh.solver_options(rtol=1e-10))
    t = res.time
    wn = math.sqrt((k + s0) / m)
    zeta = (c + sigma_1) / (2.0 * math.sqrt((k + s0) * m))
    wd = wn * math.sqrt(1.0 - zeta * zeta)
    x_eq = s0 * x0 / (k + s0)
    exact = x_eq + (x0 - x_eq) * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2)
                                                           * np.sin(wd * t))
    err = np.max(np.abs(res.displacement - exact)) / (x0 - x_eq)
    assert err < 1e-4, err
    # the static law with the same level would not move at all from its own x0 spring balance: the
    # frequency must be the combined one, not sqrt(k/m)
    assert wn / math.sqrt(k / m) > 1.3


@pytest.mark.parametrize("lugre", [False, True])
def test_terminal_velocity_on_the_stribeck_curve(lugre: bool) -> None:
    F_c, ratio, v_s, c, v_star = 250.0, 1.5, 0.01, 1.0e4, 0.02
    r = _free_rig(F_c=F_c, stribeck_ratio=ratio, v_s=v_s, c=c, k=1.0, sigma_0=5e5)
    r.effects.spring_softening = False
    r.effects.lugre_friction = lugre
    g = F_c * (1.0 + (ratio - 1.0) * math.exp(-(v_star / v_s) ** 2))
    F0 = c * v_star + g
    assert F0 > ratio * F_c  # breaks away from rest (else it sticks: the Stribeck peak holds it)
    n = int(12.0 / DT)
    res = sh.simulate(r, "free", command=np.full(n, F0), dt=DT)
    v_end = res.velocity[-1]
    # the 1 N/m spring holds back k x(t_end) (about 0.2 N) and the slow deceleration it causes m a:
    # solve F0 - k x - m a = c v + g(v) for v
    g_of = lambda v: F_c * (1.0 + (ratio - 1.0) * math.exp(-(v / v_s) ** 2))  # noqa: E731
    held_back = r.k * res.displacement[-1] + r.m * res.acceleration[-1]
    v_star = brentq(lambda v: c * v + g_of(v) - (F0 - held_back), 0.015, 0.025)
    # closed-form sensitivity: the Stribeck term moves v* by (g - F_c) / (c + g'), about 0.25 mm/s here;
    # the simulated terminal velocity must match v* far more closely than that
    assert abs(v_end - v_star) < 1e-7, (v_end, v_star)
    # and the friction the structure feels is g(v*), not the sliding level F_c
    assert g - F_c > 2.0


def test_lugre_agrees_with_the_independent_simulator() -> None:
    t = np.arange(int(1.5 / DT)) * DT
    u = 0.004 * np.sin(2 * math.pi * 1.5 * t)
    tr = ip.Truth(friction="lugre", F_c=250.0, F_s=325.0, v_s=0.01, sigma_0=5e5)
    ref = ip.simulate(tr, "displacement", u, DT, substeps=8)
    r = sh.zhao2003()
    r.effects.load_pressure = False
    r.effects.flow_nonlinearity = False
    r.effects.spring_softening = False
    r.effects.lugre_friction = True
    r.F_c, r.stribeck_ratio, r.v_s, r.sigma_0, r.sigma_1 = 250.0, 1.3, 0.01, 5e5, 0.0
    res = sh.simulate(r, "displacement", u, DT, options=sh.solver_options(rtol=1e-9))
    for ch in ("displacement", "force"):
        e = np.sqrt(np.mean((getattr(res, ch) - ref[ch]) ** 2)) / np.sqrt(np.mean(ref[ch] ** 2))
        assert e < 2e-4, (ch, e)
    # the LuGre force is not the Coulomb one: the same rig with the static law differs by far more
    r.effects.lugre_friction = False
    res_c = sh.simulate(r, "displacement", u, DT, options=sh.solver_options(rtol=1e-9))
    e_c = np.sqrt(np.mean((res_c.force - ref["force"]) ** 2)) / np.sqrt(np.mean(ref["force"] ** 2))
    assert e_c > 20 * 2e-4


def test_lugre_rk4_substeps_follow_the_bristle_rate() -> None:
    r = sh.zhao2003()
    plain = sh.make_plant(r, "displacement", DT, sh.solver_options(method="rk4"))
    r.effects.lugre_friction = True
    r.F_c, r.sigma_0 = 250.0, 5e6
    stiff = sh.make_plant(r, "displacement", DT, sh.solver_options(method="rk4"))
    v_ref = r.K_v * r.flow_curve.eval(1.0) / r.A
    assert stiff.rk4_substeps >= math.ceil(DT * r.sigma_0 * v_ref / r.F_c)
    assert stiff.rk4_substeps > plain.rk4_substeps


def test_bad_friction_parameters_name_the_field() -> None:
    r = sh.zhao2003()
    r.stribeck_ratio = 0.5
    with pytest.raises(ValueError, match="stribeck_ratio"):
        sh.simulate(r, "displacement", duration=0.01)
    r = sh.zhao2003()
    r.sigma_0 = -1.0
    with pytest.raises(ValueError, match="sigma_0"):
        sh.simulate(r, "displacement", duration=0.01)
