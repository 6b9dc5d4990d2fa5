"""Delays inside the loop (docs/specimens.md): the digital command delay against the
exact discretisation of a linear plant across the fractional switch; the EFT and RPsD
loops' plant transfer turned by exactly e^{-j w tau}; the Pade loop delay's realisation
against control.pade and the linearised loop against its closed form; bad delays."""

from __future__ import annotations

import control as ct
import numpy as np
import pytest
from scipy.linalg import expm

import servohydraulics as sh
from servohydraulics import _core

DT = 1.0 / 1024.0


def _linear_rig() -> sh.Rig:
    """The paper's rig with every nonlinearity off: an LTI plant (Eqs 6-8 with valve dynamics)."""
    r = sh.zhao2003()
    e = r.effects
    e.load_pressure = e.flow_nonlinearity = e.coulomb_friction = e.spring_softening = False
    e.drive_saturation = e.spool_saturation = False
    return r


def _hold(A, B, h):
    """(Phi, Gamma) of x' = A x + B u over h with u held: the exact zero-order-hold map."""
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A * h, B.ravel() * h
    E = expm(M)
    return E[:n, :n], E[:n, n]


@pytest.mark.parametrize("samples", [1.0, 0.3, 2.75])
def test_command_delay_is_exact_across_the_fractional_switch(samples):
    """A linear plant (sh.linearize is exact for it) under a command delayed by (D + f) samples:
    over sample k the held command is u[k-D-1] for f dt, then u[k-D].  Its exact discretisation
    (matrix exponentials of the two parts) against the simulated plant, CVODE at rtol 1e-10."""
    r = _linear_rig()
    r.command_delay = samples * DT
    rng = np.random.default_rng(12)
    u = np.concatenate([np.zeros(5), 0.004 * rng.standard_normal(300)])
    opts = sh.solver_options(rtol=1e-10)
    res = sh.simulate(r, "displacement", u, dt=DT, options=opts)
    lin = sh.linearize(_linear_rig(), "displacement", outputs=("displacement",))
    A, B, C = np.asarray(lin.A), np.asarray(lin.B), np.asarray(lin.C)
    D_, f = int(np.floor(samples + 1e-9)), samples - np.floor(samples + 1e-9)
    Pa, Ga = _hold(A, B, f * DT)
    Pb, Gb = _hold(A, B, (1 - f) * DT)
    cmd = lambda j: u[max(j, 0)]  # noqa: E731  (held at its first value before the run)
    x = np.zeros(A.shape[0])
    exact = [0.0]  # row k of a Response is the state at t_k (row 0: the start)
    for k in range(len(u) - 1):
        x = Pa @ x + Ga * cmd(k - D_ - 1)
        x = Pb @ x + Gb * cmd(k - D_)
        exact.append((C @ x).item())
    err = np.max(np.abs(res.displacement - np.array(exact)))
    assert err < 1e-8 * np.max(np.abs(exact)), f"max error {err:.3g} m"
    # holding the command for the whole sample instead would miss by far more:
    assert np.max(np.abs(np.diff(exact))) * min(f, 1 - f) > 1e3 * err or f == 0.0


def _phasor(y: np.ndarray, t: np.ndarray, w: float) -> complex:
    """Least-squares a + b cos + c sin at w over whole cycles: the complex amplitude b - j c."""
    M = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
    a, b, c = np.linalg.lstsq(M, y, rcond=None)[0]
    return complex(b, -c)


def _plant_transfer(res, out: str, w: float, t0: float) -> complex:
    t = res.time
    keep = t >= t0
    return _phasor(getattr(res, out)[keep], t[keep], w) / _phasor(res.command[keep], t[keep], w)


@pytest.mark.parametrize("samples", [2.0, 2.5])
def test_eft_loop_sees_the_plant_turned_by_the_delay(samples):
    """EFT (force control) of a linear, well-damped rig at 2 Hz: the transfer from the loop's
    force command to the measured force is the undelayed one times e^{-j w tau} (tau = the
    command delay), whatever the loop does with it."""
    w, dt = 2 * np.pi * 2.0, 5e-4
    r = _linear_rig()
    r.c = 60e3  # ~40 % damping: the free transient is gone after 4 s
    t = np.arange(int(6.0 / dt)) * dt
    ag = 1.0 * np.sin(w * t)
    H0 = _plant_transfer(sh.run_eft(r, ground_acceleration=ag, dt=dt), "force", w, 4.0)
    r.command_delay = samples * dt
    H = _plant_transfer(sh.run_eft(r, ground_acceleration=ag, dt=dt), "force", w, 4.0)
    expected = np.exp(-1j * w * samples * dt)
    assert abs(H / H0 - expected) < 1e-5, (H / H0, expected)


@pytest.mark.parametrize("samples", [1.0, 1.5])
def test_rpsd_loop_sees_the_plant_turned_by_the_delay(samples):
    """RPsD (displacement control) at 2 Hz: displacement / command is turned by e^{-j w tau}."""
    w, dt = 2 * np.pi * 2.0, 5e-4
    r = _linear_rig()
    r.c = 60e3
    t = np.arange(int(6.0 / dt)) * dt
    ag = 0.5 * np.sin(w * t)
    kw = dict(ground_acceleration=ag, dt=dt, c_m=60e3, restoring_force="calculated_displacement")
    H0 = _plant_transfer(sh.run_rpsd(r, **kw), "displacement", w, 4.0)
    r.command_delay = samples * dt
    H = _plant_transfer(sh.run_rpsd(r, **kw), "displacement", w, 4.0)
    expected = np.exp(-1j * w * samples * dt)
    assert abs(H / H0 - expected) < 1e-5, (H / H0, expected)


@pytest.mark.parametrize("order", range(1, _core.MAX_PADE_ORDER + 1))
def test_pade_realisation_is_control_pade(order):
    """The core's state-space realisation of the loop delay has the transfer function of
    control.pade(tau, order) (the same (N, N) approximant of e^{-s tau})."""
    r = sh.zhao2003()
    r.effects.loop_delay = True
    r.loop_delay, r.loop_delay_order = 3e-3, order
    P = _core.Dynamics(r, _core.ControlMode.Displacement).pade
    N, tau = P["order"], P["tau"]
    A = np.diag(np.ones(N - 1), 1) / tau
    A[-1, :] = -np.asarray(P["a"]) / tau
    B = np.zeros((N, 1))
    B[-1, 0] = 1.0 / tau
    sys = ct.ss(A, B, np.asarray(P["c"]).reshape(1, -1), [[P["d"]]])
    num, den = ct.pade(tau, order)
    ref = ct.tf(num, den)
    w = np.logspace(0, np.log10(2 * np.pi * 300), 40)
    Hs = np.array([sys(1j * wi) for wi in w]).ravel()
    Hr = np.array([ref(1j * wi) for wi in w]).ravel()
    assert np.max(np.abs(Hs - Hr)) < 1e-9
    assert np.max(np.abs(np.abs(Hs) - 1.0)) < 1e-9  # all-pass


@pytest.mark.parametrize("mode,out", [("displacement", "displacement"), ("force", "force")])
def test_linearised_loop_with_the_pade_delay_matches_its_closed_form(mode, out):
    """The delay sits on the valve drive, inside the analog loop: with L0 = T0 / (1 - T0) the
    undelayed loop gain (T0 the linearised closed loop), the delayed closed loop is
    L0 P / (1 + L0 P) with P = control.pade(tau, N).  Up to 30 Hz."""
    r = _linear_rig()
    T0 = sh.linearize(r, mode, outputs=(out,))
    r.effects.loop_delay = True
    r.loop_delay, r.loop_delay_order = 4e-3, 3
    T = sh.linearize(r, mode, outputs=(out,))
    assert T.nstates == T0.nstates + 3
    P = ct.tf(*ct.pade(4e-3, 3))
    for f in [0.5, 2.0, 8.0, 20.0, 30.0]:
        s = 2j * np.pi * f
        t0, p = complex(T0(s)), complex(P(s))
        L0 = t0 / (1 - t0)
        expected = L0 * p / (1 + L0 * p)
        assert abs(complex(T(s)) - expected) < 1e-9 * abs(expected), f


def test_c2d_of_the_linearised_delay_is_the_simulated_plant():
    """The linearised plant with the Pade delay, discretised by c2d (zoh), against the simulated
    plant (tiny steps about the equilibrium of a linear rig: the model is exact there)."""
    r = _linear_rig()
    r.effects.loop_delay = True
    r.loop_delay, r.loop_delay_order = 2e-3, 2
    lin = ct.c2d(sh.linearize(r, "displacement", outputs=("displacement",)), DT, method="zoh")
    u = 1e-3 * np.sin(2 * np.pi * 5 * np.arange(400) * DT)
    res = sh.simulate(r, "displacement", u, dt=DT, options=sh.solver_options(rtol=1e-10))
    _, y = ct.forced_response(lin, U=u)
    # both are the state at t_k = k dt, before input k is applied
    err = np.max(np.abs(res.displacement - np.ravel(y)))
    assert err < 1e-7 * np.max(np.abs(y))


@pytest.mark.parametrize("order", [1, 3, 6])
def test_default_integrator_with_the_pade_delay_against_tight_cvode(order):
    """The nonlinear paper plant with a 2 ms Pade loop delay: the default integrator at its
    default tolerance against an independent solver run, CVODE at rtol 1e-11 (the delay
    states' tolerances follow the drive they make, Dynamics::state_scale)."""
    r = sh.zhao2003()
    r.effects.loop_delay = True
    r.loop_delay, r.loop_delay_order = 2e-3, order
    t = np.arange(1500) * 5e-4
    u = 0.01 * np.sin(2 * np.pi * t) + 0.003 * np.sin(2 * np.pi * 7 * t)
    ref = sh.simulate(r, "displacement", u, dt=5e-4, options=sh.solver_options("cvode", rtol=1e-11))
    res = sh.simulate(r, "displacement", u, dt=5e-4)
    assert res.success, res.message
    for ch in ("displacement", "force", "spool"):
        a, b = getattr(res, ch), getattr(ref, ch)
        assert np.max(np.abs(a - b)) < 1e-6 * np.max(np.abs(b)), ch


@pytest.mark.parametrize("key", ["command_delay", "measurement_delay_displacement", "measurement_delay_force"])
def test_delays_beyond_the_maximum_name_the_field(key):
    r = sh.zhao2003()
    setattr(r, key, 65 * DT)
    with pytest.raises(ValueError, match=rf"invalid {key} = 0.0634765625: must be at most 64 samples"):
        sh.simulate(r, "displacement", np.zeros(4), dt=DT)
    setattr(r, key, 64 * DT)
    assert sh.simulate(r, "displacement", np.zeros(4), dt=DT).work.status.ok


def test_measurement_delay_interpolates_the_measured_channels():
    """A displacement delayed 1.5 samples reads the mean of the true values 1 and 2 samples back;
    the force channel is untouched (its own delay is 0)."""
    u = 0.01 * np.sin(2 * np.pi * 3 * np.arange(300) * DT)
    r = sh.zhao2003()
    a = sh.simulate(r, "displacement", u, dt=DT)
    r.measurement_delay_displacement = 1.5 * DT
    b = sh.simulate(r, "displacement", u, dt=DT)
    x = a.displacement
    np.testing.assert_array_equal(b.force, a.force)
    np.testing.assert_allclose(b.displacement[2:], 0.5 * (x[1:-1] + x[:-2]), rtol=0, atol=1e-15)
