"""The paper's experiments (servohydraulics.paper.experiments) checked against closed forms and
independent solvers, without drawing a figure or building the table."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

import servohydraulics as sh
from servohydraulics.paper import experiments as xp


@pytest.fixture(scope="module")
def rig():
    return sh.zhao2003()


def test_constants_are_the_core_defaults():
    """68 ms / 11.2 ms / 5 ms leads, alpha 0.1, 2 kHz, the solver's 7084 kg, 3.5 kN s/m (Table I)."""
    assert (xp.T_AMP, xp.T_LD, xp.T_EFT, xp.ALPHA, xp.DT) == pytest.approx((0.068, 0.0112, 0.005, 0.1, 5e-4))
    assert (xp.M_M, xp.C_M) == pytest.approx((7084.0, 3.5e3))


def test_lead_is_the_tustin_lead_prewarped_at_its_centre_frequency():
    """Oracle: scipy's bilinear transform of (T s + 1)/(alpha T s + 1) with the frequency warping
    matched at w0 = 1/(T sqrt(alpha)), the lead's maximum-phase frequency."""
    T, a, dt = xp.T_AMP, xp.ALPHA, xp.DT
    u = np.sin(2 * np.pi * 3.0 * np.arange(4000) * dt) + 0.3 * np.random.default_rng(1).standard_normal(4000)
    w0 = 1.0 / (T * math.sqrt(a))
    b, den = signal.bilinear([T, 1.0], [a * T, 1.0], fs=w0 / (2.0 * math.tan(w0 * dt / 2.0)))
    assert np.max(np.abs(xp.lead(u, T) - signal.lfilter(b, den, u))) < 1e-9 * np.max(np.abs(u))


def test_eq13_eq11_eq14_closed_forms(rig):
    d = xp.fig6a_amplitude_compensation(rig)
    assert d.omega_c == pytest.approx(rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p / rig.A, rel=1e-12)
    M = rig.m + rig.m_p
    assert d.oil_column_hz == pytest.approx(math.sqrt(rig.A**2 / (M * rig.K_a)) / (2 * math.pi), rel=1e-12)
    f = xp.eq11_force_loop(rig)
    kf = rig.A * rig.K_v * rig.C_F_force * rig.K_s
    assert 2 * math.pi * f.rolloff_hz == pytest.approx((kf * rig.G_p + rig.C_l) / rig.K_a, rel=1e-12)
    # the force-loop gain that would put Eq (11) at 120 Hz does so
    assert (kf * f.gain_for_120hz + rig.C_l) / rig.K_a == pytest.approx(2 * math.pi * 120.0, rel=1e-12)
    assert f.piston_fraction == pytest.approx(54.0 / (rig.m + 54.0), rel=1e-12)


def test_equivalent_damping_is_jacobsen(rig):
    """zeta_eq = zeta + 2 F_c / (pi k X) (energy per cycle of Coulomb friction), X fixed by the free
    structure's 1.1 %."""
    free = sh.zhao2003(actuator_attached=False)
    z_free = free.c / (2 * math.sqrt(free.k * free.m))
    X = 2 * free.F_c / (math.pi * free.k * (0.011 - z_free))
    z_att = rig.c / (2 * math.sqrt(rig.k * rig.m)) + 2 * rig.F_c / (math.pi * rig.k * X)
    e = xp.equivalent_damping(rig)
    assert e.amplitude == pytest.approx(X, rel=1e-12)
    assert e.zeta_attached == pytest.approx(z_att, rel=1e-12)


def test_free_vibration_frequency_and_identification(rig):
    fv = xp.fig2b_free_vibration(rig, quick=True)
    assert fv.natural_frequency == pytest.approx(math.sqrt(rig.k / rig.m) / (2 * math.pi), rel=1e-12)
    free = sh.zhao2003(actuator_attached=False)
    f_d = math.sqrt(free.k / free.m) / (2 * math.pi) * math.sqrt(1 - fv.zeta_table**2)
    # Coulomb friction does not change the period of a linear spring-mass: zero crossings at f_d
    assert fv.crossing_frequency == pytest.approx(f_d, rel=5e-3)
    # the identification recovers the values the record was simulated with
    assert fv.estimate.F_c == pytest.approx(free.F_c, rel=0.05)
    assert fv.estimate.zeta == pytest.approx(fv.zeta_table, abs=1e-3)


def test_direct_eft_drops_at_the_structure_poles(rig):
    """Eq (9): the structure's poles are zeros of G_fu, so |F/u| is smallest at its damped frequency."""
    d = xp.fig3a_direct_eft(rig, quick=True)
    z = rig.c / (2 * math.sqrt(rig.k * rig.m))
    f_d = math.sqrt(rig.k / rig.m) / (2 * math.pi) * math.sqrt(1 - z**2)
    assert d.min_frequency_eq9 == pytest.approx(f_d, abs=0.01)
    assert abs(d.min_frequency - f_d) < 0.1 and d.min_gain < 0.1


def test_displacement_sweep_follows_the_linear_model_at_low_frequency(rig):
    """Independent solvers: the nonlinear CVODE sweep against the linear G_xu (python-control) below
    0.5 Hz, where the 1.27 cm motion keeps the spool in its linear range."""
    s = xp.fig5_displacement_sweeps(rig, quick=True)
    d = xp.fig6a_amplitude_compensation(rig)
    fo = s.first_order
    sel = fo.excited & (fo.frequency > 0.2) & (fo.frequency < 0.5)
    model = np.abs(np.asarray(d.g_lin(2j * np.pi * fo.frequency[sel])))
    assert np.max(np.abs(np.abs(fo.response[sel]) / model - 1)) < 0.03
    assert fo.roll_off_hz == pytest.approx(d.omega_c / (2 * math.pi), rel=0.1)


def test_paper_delay_estimate_is_total_minus_amplitude_lead(rig):
    d = xp.fig10_pole_zero(rig)
    assert d.T_estimate == pytest.approx(rig.A / (rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p) - 0.068, rel=1e-12)
    assert d.zeta_model == pytest.approx(3.5e3 / (2 * math.sqrt(rig.k * 7084.0)), rel=1e-12)
    # zero residual phase at 1.58 Hz: the lead's phase cancels the compensated loop's lag there
    w = 2 * math.pi * 1.58
    T = d.T_zero_phase
    lag = -np.angle(complex(xp.compensated_loop(rig)(1j * w)))
    assert math.atan(w * T) - math.atan(0.1 * w * T) == pytest.approx(lag, abs=1e-9)


def test_rpsd_with_calculated_displacements_is_the_solver_sdof(rig):
    """With calculated displacements the RPsD solver runs open loop: its free vibration is the damped
    SDOF of (m_m, c_m, k) in closed form."""
    r = xp.rpsd_release(rig, xp.Release(free=4.0, fit=4.0), restoring_force="calculated_displacement")
    z = xp.C_M / (2 * math.sqrt(rig.k * xp.M_M))
    assert r.fit.damping_ratio == pytest.approx(z, abs=5e-4)
    assert r.fit.frequency == pytest.approx(math.sqrt(rig.k / xp.M_M) * math.sqrt(1 - z**2) / (2 * math.pi),
                                            rel=2e-3)


def test_with_effects_copies(rig):
    r = xp.linear_effects(rig)
    assert not (r.effects.flow_nonlinearity or r.effects.load_pressure or r.effects.coulomb_friction
                or r.effects.spring_softening)
    assert rig.effects.flow_nonlinearity and rig.effects.coulomb_friction  # the original is untouched
