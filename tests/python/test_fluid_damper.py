"""The nonlinear viscous fluid damper (effects.fluid_damper): F = c |u'|^alpha sign(u') in series
with a Maxwell stiffness k_d, F = k_d (x - u).  Energy dissipated per cycle of x = X sin(w t)
against the closed forms, through the kinematic driver (Dynamics.specimen_forces) and inside
the plant:

* alpha = 1 (a linear Maxwell element): the complex stiffness k_d i w c / (k_d + i w c) gives
  E = pi X^2 Im = pi w c k_d^2 X^2 / (k_d^2 + (c w)^2).
* a rigid series stiffness (k_d -> oo), any alpha: E = int_0^T c |v|^(1+alpha) dt
  = 4 c X^(1+alpha) w^alpha 2^alpha Gamma(1 + alpha/2)^2 / Gamma(2 + alpha)
  (4 int_0^(pi/2) cos^(1+alpha) by the Beta function and Legendre's duplication formula).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core

C = 20e3  # [N (s/m)^alpha]
X, FREQ = 0.01, 2.0
W = 2.0 * math.pi * FREQ


def maxwell_energy(c: float, k: float, X: float, w: float) -> float:
    return math.pi * w * c * k**2 * X**2 / (k**2 + (c * w) ** 2)


def rigid_energy(c: float, alpha: float, X: float, w: float) -> float:
    return 4.0 * c * X ** (1 + alpha) * w**alpha * 2**alpha * math.gamma(1 + alpha / 2) ** 2 / math.gamma(2 + alpha)


def _rig(alpha: float, k: float) -> sh.Rig:
    r = sh.zhao2003()
    r.effects.fluid_damper = True
    r.fd_c, r.fd_alpha, r.fd_k = C, alpha, k
    return r


def _last_cycle_energy(F: np.ndarray, v: np.ndarray, dt: float, n_per: int) -> float:
    p = F[-n_per - 1:] * v[-n_per - 1:]
    return float(np.sum(0.5 * (p[1:] + p[:-1])) * dt)  # trapezoid of F v over the last period


def _driver_energy(alpha: float, k: float, cycles: int = 8, n_per: int = 4000) -> float:
    dt = 1.0 / (FREQ * n_per)
    t = np.arange(cycles * n_per + 1) * dt
    x, v = X * np.sin(W * t), X * W * np.cos(W * t)
    F = _core.Dynamics(_rig(alpha, k), _core.ControlMode.Free).specimen_forces(x, v, dt)
    return _last_cycle_energy(F, v, dt, n_per)


def test_closed_forms_agree_at_alpha_one_and_rigid():
    """The two closed forms are one at alpha = 1, k_d -> oo: pi c w X^2."""
    assert rigid_energy(C, 1.0, X, W) == pytest.approx(math.pi * C * W * X**2, rel=1e-14)
    assert maxwell_energy(C, 1e15, X, W) == pytest.approx(math.pi * C * W * X**2, rel=1e-12)


@pytest.mark.parametrize("k", [250e3, 2.5e6])  # c w = 251 kN/m: the Maxwell roll-off matters
def test_maxwell_energy_per_cycle(k):
    assert _driver_energy(1.0, k) == pytest.approx(maxwell_energy(C, k, X, W), rel=1e-6)


@pytest.mark.parametrize("alpha", [0.5, 0.3])
def test_nonlinear_energy_per_cycle_with_a_stiff_series_spring(alpha):
    """k_d = 1e9 N/m: the series spring takes ~1e-5 of the stroke; a softer one dissipates less,
    converging on the rigid closed form from below."""
    E_cf = rigid_energy(C, alpha, X, W)
    E_stiff, E_soft = _driver_energy(alpha, 1e9), _driver_energy(alpha, 1e8)
    assert E_stiff == pytest.approx(E_cf, rel=2e-4)
    assert E_soft < E_stiff < E_cf


@pytest.mark.parametrize(("alpha", "k", "rel_cf"), [(1.0, 2.5e6, 2e-4), (0.5, 1e9, 5e-3)])
def test_energy_inside_the_plant(alpha, k, rel_cf):
    """The plant tracking 10 mm at 2 Hz (the damper in parallel with the structure): the energy the
    damper takes over the last cycle, int F_sp v dt from the plant's own channels, equals the
    kinematic driver's along the recorded motion and the closed form at the motion's fundamental
    amplitude (the actuator's harmonic distortion, ~0.3 %, bounds the nonlinear case)."""
    dt, n_per, cycles = 5e-4, 1000, 6
    t = np.arange(cycles * n_per + 1) * dt
    r = _rig(alpha, k)
    res = sh.simulate(r, "displacement", 0.01 * np.sin(W * t), dt=dt)
    x, v, F = res.displacement, res.velocity, res.specimen_force
    E_plant = _last_cycle_energy(F, v, dt, n_per)
    F_driver = _core.Dynamics(r, _core.ControlMode.Displacement).specimen_forces(x, v, dt)
    assert E_plant == pytest.approx(_last_cycle_energy(F_driver, v, dt, n_per), rel=2e-5)
    tt = t[-n_per - 1:]
    basis = np.column_stack([np.sin(W * tt), np.cos(W * tt), np.ones_like(tt)])
    coef = np.linalg.lstsq(basis, x[-n_per - 1:], rcond=None)[0]
    Xf = math.hypot(coef[0], coef[1])
    E_cf = maxwell_energy(C, k, Xf, W) if alpha == 1.0 else rigid_energy(C, alpha, Xf, W)
    assert E_plant == pytest.approx(E_cf, rel=rel_cf)


def test_state_rest_and_bad_input():
    r = _rig(0.5, 1e7)
    dyn = _core.Dynamics(r, _core.ControlMode.Displacement)
    assert dyn.layout["fluid_damper"] == 6 and dyn.layout["fd_u"] == 6
    assert dyn.equilibrium(0.01)[6] == 0.01  # no force at rest: u = x
    assert dyn.specimen_force(dyn.equilibrium(0.01)) == 0.0
    r.fd_alpha = 1.5
    with pytest.raises(ValueError, match=r"invalid fd_alpha = 1.5: must be in \(0, 1\]"):
        _core.Dynamics(r, _core.ControlMode.Displacement)
    with pytest.raises(ValueError, match="invalid x, v"):
        dyn.specimen_forces(np.zeros(3), np.zeros(4), 1e-3)
    with pytest.raises(ValueError, match="invalid dt = 0"):
        dyn.specimen_forces(np.zeros(3), np.zeros(3), 0.0)
