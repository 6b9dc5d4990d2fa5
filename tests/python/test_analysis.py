"""Linear analysis against closed forms (Eqs 9-14), Routh against eigenvalues."""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import analysis as an

F = np.array([0.3, 1.0, 1.58, 2.0, 5.0, 10.0, 30.0])  # [Hz]


def linear_rig(valve: bool) -> sh.Rig:
    """Calibrated preset with the effects the closed forms leave out switched off."""
    r = an.linear_analysis_rig(sh.zhao2003())
    r.effects.servovalve_dynamics = valve
    r.effects.piston_mass = False
    return r


def resp(sys_, f=F):
    return np.asarray(sys_(1j * 2 * np.pi * f)).ravel()


@pytest.mark.parametrize("valve", [False, True])
def test_linearisation_matches_eq12_and_eq9(valve):
    r = linear_rig(valve)
    np.testing.assert_allclose(resp(an.linearize(r, "displacement")), resp(an.G_xu(r)), rtol=1e-7)
    np.testing.assert_allclose(resp(an.linearize(r, "force", outputs=("force",))), resp(an.G_fu(r)), rtol=1e-7)
    np.testing.assert_allclose(np.sort_complex(an.linearize(r).poles()), np.sort_complex(an.G_xu(r).poles()),
                               rtol=1e-7)


def test_piston_mass_in_closed_forms():
    r = an.linear_analysis_rig(sh.zhao2003())  # piston mass and valve on
    np.testing.assert_allclose(resp(an.linearize(r, "force", outputs=("force",))), resp(an.G_fu(r)), rtol=1e-7)
    np.testing.assert_allclose(resp(an.linearize(r)), resp(an.G_xu(r)), rtol=1e-7)


def test_velocity_feedback_compensation_gives_eq10():
    r = linear_rig(False)
    lc = an.linearize(r, "force", outputs=("force",), compensators=an.Compensation(velocity_feedback=True))
    np.testing.assert_allclose(resp(lc), resp(an.G_fu_compensated(r)), rtol=1e-7)
    # Eq (10) is first order with roll-off Eq (11): |G| = 1/sqrt(2) times its DC gain there.
    g = an.G_fu_compensated(r)
    w = an.omega_cEFT(r)
    assert abs(abs(complex(g(1j * w))) / abs(complex(g(0))) - 1 / math.sqrt(2)) < 1e-9


def test_amplitude_lead_in_series():
    r = linear_rig(True)
    lc = an.linearize(r, compensators=an.Compensation(amplitude_T=0.068))
    np.testing.assert_allclose(resp(lc), resp(an.phase_lead(0.068) * an.G_xu(r)), rtol=1e-7)


def test_structure_zeros_of_direct_eft():
    """Eq (9): the structure's poles are zeros of G_fu (force drop at f_n)."""
    r = linear_rig(False)
    z = np.sort_complex(ct.zeros(an.G_fu(r)))
    s = np.sort_complex(np.roots([r.m, r.c, r.k]))
    np.testing.assert_allclose(z, s, rtol=1e-6)


def test_closed_form_frequencies_paper_numbers():
    rig = sh.zhao2003()
    assert abs(an.omega_cRPD(rig) / (2 * np.pi) - 1.96) < 0.02  # Eq (13), paper 1.96 Hz
    assert abs(1 / an.omega_cRPD(rig) - 0.081) < 0.001  # 81 ms
    assert abs(an.natural_frequency(rig) / (2 * np.pi) - 1.58) < 0.01
    # Eq (14) from its definition, and the closed-loop oil-column mode near it.
    w14 = math.sqrt(rig.A**2 / ((rig.m + rig.m_p) * rig.K_a))
    assert an.omega_oil_column(rig) == pytest.approx(w14)
    f_cl, z_cl = an.dominant_modes(an.G_xu(linear_rig(False)))[-1]
    assert abs(f_cl - w14 / (2 * np.pi)) / f_cl < 0.05 and 0 < z_cl < 0.2


def test_friction_treatments():
    rig = sh.zhao2003()
    tangent = an.linearize(rig, friction="tangent", outputs=("displacement",))
    # Tangent friction F_c/v_stick dominates the damping: the structure is stuck.
    a_vv = tangent.A[1, 1]
    assert a_vv == pytest.approx(-(rig.c + rig.F_c / rig.v_stick) / (rig.m + rig.m_p))
    eq = an.linearize(rig, friction="equivalent", friction_amplitude=0.01)
    c_eq = rig.c + 4 * rig.F_c / (math.pi * math.sqrt(rig.k / rig.m) * 0.01)
    assert eq.A[1, 1] == pytest.approx(-c_eq / (rig.m + rig.m_p))
    with pytest.raises(ValueError, match="friction"):
        an.linearize(rig, friction="bogus")


def test_operating_point_is_equilibrium():
    rig = sh.zhao2003()
    for mode in ("displacement", "force"):
        sys_ = an.linearize(rig, mode, x0=0.01)
        assert np.all(np.isfinite(sys_.A))
        assert np.max(np.real(sys_.poles())) < 0


def test_routh_bound_matches_eigenvalue_crossing():
    rig = an.linear_analysis_rig(sh.zhao2003())
    for mass in (54.0, 1000.0, 7138.0):
        r = an.rig_with_mass(rig, mass)
        for valve in (False, True):
            r.effects.servovalve_dynamics = valve
            gmax = an.max_p_gain(r, servovalve_on=valve)
            for fac, stable in ((0.995, True), (1.005, False)):
                r.G_p = fac * gmax
                assert (np.max(np.real(np.linalg.eigvals(an.linearize(r).A))) < 0) == stable
            r.G_p = rig.G_p
    # Static valve: the cubic's closed-form Routh bound a2 a1 > a3 a0.
    M = 7138.0
    a3, a2, a1 = rig.K_a * M, rig.K_a * rig.c + rig.C_l * M, rig.K_a * rig.k + rig.C_l * rig.c + rig.A**2
    L1 = rig.A * rig.K_v * rig.C_F_disp * rig.K_s
    g_cubic = (a2 * a1 / a3 - rig.C_l * rig.k) / L1
    assert an.max_p_gain(rig, M, servovalve_on=False) == pytest.approx(g_cubic, rel=1e-7)


def test_max_gain_falls_with_mass_and_printed_table_is_unstable():
    rig = an.linear_analysis_rig(sh.zhao2003())
    g = an.max_p_gain_curve(rig, np.geomspace(54, 7138, 8))
    assert np.all(np.diff(g) < 0)
    assert g[-1] > rig.G_p  # the paper's gain ran stably
    printed = an.linear_analysis_rig(sh.zhao2003("printed"))
    assert an.max_p_gain(printed) < printed.G_p  # Table I as printed: unstable (docs/calibration.md)
    assert not an.routh_stable(an.characteristic_polynomial(printed))


def test_routh_array_known_polynomial():
    # (s+1)(s+2)(s+3) stable; s^3 + s^2 + 2 s + 8 has two RHP roots.
    assert an.routh_stable(np.poly([-1, -2, -3]))
    R = an.routh_array([1, 1, 2, 8])
    assert np.sum(np.diff(np.sign(R[:, 0])) != 0) == 2


def test_amplitude_compensation_design():
    rig = an.linear_analysis_rig(sh.zhao2003())
    g = an.G_xu(rig) * an.zoh_delay(5e-4)
    T, dev = an.amplitude_compensation_T(g, (0.0, 5.0))
    assert abs(T - 0.068) < 0.003  # paper: 68 ms (Fig 6a)
    band = an.acceptable_band(g, T, 0.05)
    assert 5.0 <= band <= 6.0  # acceptable to 5 Hz, not to 6 Hz
    # A pure first order is compensated exactly by T = tau with alpha -> 0: check the helper's optimum.
    tau = 0.08
    T1, dev1 = an.amplitude_compensation_T(ct.tf([1], [tau, 1]), (0.0, 2.0), alpha=1e-4)
    assert T1 == pytest.approx(tau, rel=1e-3) and dev1 < 1e-3


def test_delay_compensation_design():
    assert an.delay_compensation_T(0.081, 0.068) == pytest.approx(0.013)
    # The lead found cancels the residual phase at that frequency.
    rig = an.linear_analysis_rig(sh.zhao2003())
    comp = an.phase_lead(0.068) * an.G_xu(rig)
    T = an.delay_compensation_T(0.0, 0.068, comp, 1.58)
    assert abs(np.angle(complex((an.phase_lead(T) * comp)(1j * 2 * np.pi * 1.58)))) < 1e-9


def test_rpsd_loop_delay_trend():
    """More delay compensation, more damping (Figs 8a, 8b); calculated vs measured."""
    rig = an.linear_analysis_rig(sh.zhao2003())
    wn = an.natural_frequency(rig)
    z = [an.structural_mode(an.rpsd_loop(rig, delay_T=T), wn)[1] for T in (0.006, 0.0112, 0.016)]
    assert z[0] < 0 and z[0] < z[1] < z[2]
    # The net damping change equals Im(H)/2 of the displacement loop at w_n to first order.
    h = complex((an.phase_lead(0.0112) * an.phase_lead(0.068) * an.G_xu(rig) * an.zoh_delay(5e-4))(1j * wn))
    assert z[1] == pytest.approx(3.5e3 / (2 * math.sqrt(rig.k * 7084)) + h.imag / 2, abs=0.003)


def test_bad_input():
    rig = sh.zhao2003()
    with pytest.raises(ValueError, match="mode"):
        an.linearize(rig, "torque")
    with pytest.raises(ValueError, match="output"):
        an.linearize(rig, outputs=("temperature",))
    with pytest.raises(ValueError, match="velocity_feedback"):
        an.linearize(rig, compensators=an.Compensation(velocity_feedback=True))
    with pytest.raises(ValueError, match="T"):
        an.phase_lead(-1.0)
