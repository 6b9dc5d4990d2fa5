"""Energy balance of the structure on a run through the softening spring.

The structure (mass m, without the piston) obeys m x'' = F - c x' - F_c
tanh(x'/v_stick) - f_s(x), with F the load-cell force between piston and
structure.  Hence, over a run,

    integral F v dt = [1/2 m v^2 + U(x)] + integral (c v^2 + F_c tanh(v/v_stick) v) dt

with the piecewise potential of the springs, U = 1/2 k x^2 for |x| <= x_c and
1/2 k x_c^2 + k x_c (|x| - x_c) + 1/2 k_2 (|x| - x_c)^2 beyond.  Everything is
computed from the recorded channels (force, displacement, velocity), the
integrals with the trapezoidal rule on the 0.5 ms samples.

Tolerance: the residual must be below 2e-5 of the gross actuator work
integral |F v| dt and 1e-3 of the dissipated energy.  Sources: CVODE's error
(rtol 1e-6: state errors ~1e-5 relative) and the trapezoidal rule ((w dt)^2/12
~ 1e-6 for the 0.5 Hz motion, ~1e-4 for the small 13 Hz oil-column content of
F).  Measured: 1.5e-6 of the gross work (5 mJ of 140 J net work); 1.5e-7 with
rtol 1e-8, so the residual is the integration error, not a modelling term.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import trapezoid

import servohydraulics as sh


def spring_energy(rig: sh.Rig, x: np.ndarray) -> np.ndarray:
    """U(x) [J] of the nonlinear-elastic springs (k within +-x_contact, k_2 beyond)."""
    a, xc = np.abs(x), rig.x_contact
    return np.where(a <= xc, 0.5 * rig.k * a**2,
                    0.5 * rig.k * xc**2 + rig.k * xc * (a - xc) + 0.5 * rig.k_2 * (a - xc) ** 2)


def test_spring_energy_is_the_integral_of_the_spring_force(calibrated):
    """U(x) against the core's own spring force f_s, integrated numerically."""
    dyn = sh.Dynamics(calibrated, sh.ControlMode.Free)
    x = np.linspace(0.0, 0.05, 20001)
    fs = np.array([dyn.spring_force(v) for v in x])
    U = np.concatenate([[0.0], np.cumsum(0.5 * (fs[1:] + fs[:-1]) * np.diff(x))])
    np.testing.assert_allclose(U, spring_energy(calibrated, x), rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(fs, [dyn.spring_force(-v) * -1 for v in x])  # odd


@pytest.mark.parametrize("rtol", [1e-6, 1e-8])
def test_actuator_work_equals_stored_plus_dissipated(calibrated, dt, rtol):
    rig = calibrated  # every effect on: friction, piston mass, softening, load pressure, flow curve
    n = int(round(4.0 / dt)) + 1
    t = np.arange(n) * dt
    u = 0.04 * np.sin(2 * np.pi * 0.5 * t) * np.minimum(t / 0.5, 1.0)  # 4 cm at 0.5 Hz, ramped in
    res = sh.simulate(rig, mode="displacement", command=u, dt=dt, options=sh.solver_options(rtol=rtol))
    x, v, F = res.displacement, res.velocity, res.force
    assert np.abs(x).max() > rig.x_contact + 0.01  # well into the softened range
    assert not res.capacity_exceeded

    work = trapezoid(F * v, t)
    gross = trapezoid(np.abs(F * v), t)
    stored = 0.5 * rig.m * (v[-1] ** 2 - v[0] ** 2) + spring_energy(rig, x[-1]) - spring_energy(rig, x[0])
    dissipated = trapezoid(rig.c * v**2 + rig.F_c * np.tanh(v / rig.v_stick) * v, t)
    residual = work - stored - dissipated
    assert abs(residual) < 2e-5 * gross
    assert abs(residual) < 1e-3 * dissipated
    assert dissipated > 0.1 * work  # the balance is not dominated by one term
