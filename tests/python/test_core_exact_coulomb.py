"""The exact Coulomb law (``v_stick = 0``): stick and slip, the switches located in time.

Oracles:
* the free vibration of a mass on a spring with Coulomb friction (closed form): every half-cycle
  is a sinusoid at sqrt(k/m) about +-F_c/k, so the turning points fall by 2 F_c/k, and the mass
  sticks at the first turning point where the spring force is within F_c, after that many half
  periods pi/w, and stays there;
* breakaway under a ramp force (closed form): stuck until the force reaches the static level
  F_s = stribeck_ratio F_c, at t = F_s / rate;
* an energy balance over a forced run with stick phases and the Stribeck peak: the work of the
  applied force equals the change of the kinetic and spring energies plus the friction's work,
  the integral of g(v) |v|;
* the regularised law g(v) tanh(v / v_stick) (an independent model, run by CVODE) converging to it
  as v_stick -> 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import servohydraulics as sh

M, K, F_C = 10.0, 1.0e5, 100.0
W = math.sqrt(K / M)
METHODS = [("dopri5", {}), ("cvode", {}), ("rk4", {"rk4_substeps": 4}), ("ros2", {"ros2_substeps": 16}),
           ("arkode_erk", {}), ("arkode_dirk", {})]


def _rig(v_stick: float = 0.0, ratio: float = 1.0) -> sh.Rig:
    """A mass on a linear spring with Coulomb friction and nothing else (free mode)."""
    r = sh.Rig()
    e = r.effects
    for name in dir(e):
        if not name.startswith("_") and isinstance(getattr(e, name), bool):
            setattr(e, name, False)
    e.coulomb_friction = True
    r.effects = e
    r.m, r.k, r.c, r.F_c, r.v_stick = M, K, 0.0, F_C, v_stick
    r.stribeck_ratio, r.v_s, r.x_contact = ratio, 0.02, 1.0
    return r


def _free_vibration(x0: float) -> tuple[float, int]:
    """Where the free vibration from x0 > 0 sticks, and after how many half-cycles (closed form)."""
    x, n = x0, 0
    while abs(K * x) > F_C:
        x = -x + math.copysign(2.0 * F_C / K, x)
        n += 1
    return x, n


@pytest.mark.parametrize("method,kw", METHODS, ids=[m for m, _ in METHODS])
def test_free_vibration_sticks_where_and_when_the_closed_form_says(method: str, kw: dict) -> None:
    x0, dt = 9.5e-3, 1e-3
    x_stop, halves = _free_vibration(x0)
    assert halves == 5 and x_stop == pytest.approx(5e-4)
    res = sh.simulate(_rig(), "free", command=np.zeros(400), dt=dt, x0=x0,
                      options=sh.solver_options(method=method, **kw))
    x, v, t = res.displacement, res.velocity, res.time
    t_stop = halves * math.pi / W
    moving = t[np.nonzero(v)[0]]
    assert moving.max() < t_stop <= moving.max() + dt  # the last sample before the stop still moves
    after = t > t_stop
    assert np.all(v[after] == 0.0)  # stuck for good: v is 0 exactly, not a creep
    assert np.ptp(x[after]) == 0.0
    # the whole run against the closed form: half-cycle j from its turning point x_j at j pi / w is
    # x_j - (x_j - c_j)(1 - cos w (t - j pi / w)) about the centre c_j = sgn(x_j) F_c / k
    turns = [x0]
    for _ in range(halves):
        turns.append(-turns[-1] + math.copysign(2.0 * F_C / K, turns[-1]))
    j = np.minimum(np.floor(t * W / math.pi).astype(int), halves)
    xj = np.asarray(turns)[j]
    c = np.sign(xj) * F_C / K
    closed = np.where(j < halves, c + (xj - c) * np.cos(W * (t - j * math.pi / W)), x_stop)
    # [m]: fixed steps locate the switches less well, and ARKODE's DIRK runs at a looser default
    tol = 2e-6 if method in ("rk4", "ros2", "arkode_dirk") else 1e-7
    err = np.max(np.abs(x - closed))
    assert err < tol, (method, err)


@pytest.mark.parametrize("method,kw", METHODS[:3], ids=[m for m, _ in METHODS[:3]])
def test_a_ramp_force_breaks_it_loose_at_the_static_level(method: str, kw: dict) -> None:
    ratio, rate, dt = 1.5, 1000.0, 1e-4  # the force reaches F_s = 150 N at 0.15 s
    r = _rig(ratio=ratio)
    r.k = 1.0  # nearly no spring: the ramp alone loads the friction
    n = 2500
    u = rate * (np.arange(n) + 0.5) * dt  # sample j holds u_j over [t_j, t_j+1): 0.05 N past F_s at j = 1500
    res = sh.simulate(r, "free", command=u, dt=dt, x0=0.0, options=sh.solver_options(method=method, **kw))
    v = res.velocity
    j = int(math.ceil(ratio * F_C / (rate * dt) - 0.5))  # the first sample whose held force exceeds F_s
    assert j == 1500
    first = int(np.nonzero(v)[0][0])  # the first row that ends moving: the end of sample j
    assert res.time[first] == pytest.approx((j + 1) * dt)
    assert np.all(v[:first] == 0.0) and np.all(v[first:] > 0.0)


def test_energy_balance_of_a_forced_run_with_stick_phases() -> None:
    ratio, dt, n = 1.3, 2e-5, 50000  # 1 s at 50 kHz: the trapezoid rule's error is far below the tolerance
    r = _rig(ratio=ratio)
    t = np.arange(n) * dt
    u = 180.0 * np.sin(2 * math.pi * 3.0 * t)  # above F_s = 130 N at the peaks only: long stuck stretches
    res = sh.simulate(r, "free", command=u, dt=dt, x0=0.0, options=sh.solver_options(rtol=1e-10))
    x, v = res.displacement, res.velocity
    stuck = np.mean(v == 0.0)
    assert 0.2 < stuck < 0.9, stuck
    # the force held over each sample is u_k (zero-order hold): its work is u_k (x_k+1 - x_k), exact
    work_in = float(np.sum(u[:-1] * np.diff(x)))
    g = F_C * (1.0 + (ratio - 1.0) * np.exp(-(v / r.v_s) ** 2))
    p = g * np.abs(v)
    work_friction = float(np.sum(0.5 * (p[1:] + p[:-1]) * dt))
    energy = 0.5 * M * v[-1] ** 2 + 0.5 * K * x[-1] ** 2
    assert work_friction > 0.5 * work_in  # the friction takes a good part of it: the balance tests it
    assert work_in == pytest.approx(energy + work_friction, rel=2e-4)


def test_the_regularised_law_converges_to_it() -> None:
    x0, dt = 9.5e-3, 1e-3
    t_stop = 5 * math.pi / W
    exact = sh.simulate(_rig(), "free", command=np.zeros(400), dt=dt, x0=x0)
    k = np.searchsorted(exact.time, t_stop)  # the first sample after the stop
    errors = []
    for v_stick in (1e-3, 1e-4, 1e-5):
        reg = sh.simulate(_rig(v_stick), "free", command=np.zeros(400), dt=dt, x0=x0,
                          options=sh.solver_options(method="cvode", rtol=1e-9))
        errors.append(float(np.max(np.abs(reg.displacement[: k + 1] - exact.displacement[: k + 1]))))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 2e-6  # [m], 0.02 % of x0


def test_a_negative_v_stick_names_the_field() -> None:
    r = _rig()
    r.v_stick = -1e-4
    with pytest.raises(ValueError, match="v_stick"):
        sh.simulate(r, "free", command=np.zeros(10), dt=1e-3)


def test_a_stick_slip_chatter_is_an_error_with_its_time() -> None:
    # a 1 g mass on a 1e9 N/m spring from 1 mm: k x0 / (2 F_c) = 500 half-cycles of 3 us before it sticks,
    # all in the first 1 ms sample: more switches than Status::kMaxSwitches (64) in one sample
    r = _rig()
    r.m, r.k, r.F_c = 1e-3, 1e9, 1e3
    with pytest.raises(sh.SimulationError, match=r"at t = 0\.000\d+ s: the exact Coulomb law .* more than 64 times"):
        sh.simulate(r, "free", command=np.zeros(5), dt=1e-3, x0=1e-3, options=sh.solver_options(method="rk4"))


def test_the_coupled_rig_refuses_it_by_name() -> None:
    from servohydraulics.multi_rig import MARTHS_ANGLES, MARTHS_ARM, MultiActuatorRig

    exact = sh.zhao2003()
    exact.effects.coulomb_friction = True
    exact.v_stick = 0.0
    with pytest.raises(ValueError, match=r"actuators\[1\]\.v_stick = 0: the exact Coulomb law"):
        MultiActuatorRig([sh.zhao2003(), exact], [MARTHS_ARM] * 2, MARTHS_ANGLES, sh.marths_frame())
