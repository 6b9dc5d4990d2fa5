"""Numerical integration: tightening CVODE's tolerance, RK4 against CVODE.

Representative runs (1.5 s, every effect on, 2 Hz sine: 1 cm in displacement
control, 20 kN in force control, 20 kN ideal force on the free structure).
Differences are max |a - b| over the run divided by the peak of the reference
channel.

Bounds (measured values in brackets):
 - rtol 1e-6 -> 1e-9 moves displacement and force by < 1e-4 in the closed
   loops [displacement mode: x 3.8e-6, F 3.1e-5; force mode: x 1.6e-6,
   F 1.1e-5]: the loops
   are dissipative, local errors do not accumulate.
 - Free structure near resonance (2 Hz forcing, 1.58 Hz, 1.5 % damping):
   < 5e-3 [1.8e-3].  A lightly damped oscillator accumulates the local errors
   (phase) over its cycles: at the default rtol = 1e-6 the free-mode result is
   good to ~0.2 %, use rtol <= 1e-8 or RK4 when that matters.
 - RK4 (4 substeps of 0.125 ms) against CVODE at rtol 1e-10: < 1e-5 of the
   peak in every mode [displacement mode: x 2.5e-9, F 6.5e-8; force mode:
   x 5.2e-8, F 3.8e-7; free: x 5.5e-7].  RK4's local error at this step is
   ~(h w)^5 with h w = 0.06 for the 70.7 Hz valve; at the default rtol the
   fixed-step RK4 is the more accurate of the two.
"""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh

DURATION = 1.5  #: [s]


def _command(mode: str, dt: float) -> np.ndarray:
    t = np.arange(int(round(DURATION / dt)) + 1) * dt
    amp = 0.01 if mode == "displacement" else 2e4
    return amp * np.sin(2 * np.pi * 2.0 * t)


def _rel(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(a - ref)) / np.max(np.abs(ref)))


@pytest.mark.parametrize(("mode", "bound"), [("displacement", 1e-4), ("force", 1e-4), ("free", 5e-3)])
def test_tightening_cvode_tolerance(calibrated, dt, mode, bound):
    u = _command(mode, dt)
    loose = sh.simulate(calibrated, mode, u, dt=dt, options=sh.solver_options(rtol=1e-6))
    tight = sh.simulate(calibrated, mode, u, dt=dt, options=sh.solver_options(rtol=1e-9))
    assert _rel(loose.displacement, tight.displacement) < bound
    if mode != "free":
        assert _rel(loose.force, tight.force) < bound
        assert _rel(loose.pressure, tight.pressure) < bound


@pytest.mark.parametrize("mode", ["displacement", "force", "free"])
def test_rk4_agrees_with_cvode(calibrated, dt, mode):
    u = _command(mode, dt)
    rk4 = sh.simulate(calibrated, mode, u, dt=dt, options=sh.solver_options("rk4", rk4_substeps=4))
    ref = sh.simulate(calibrated, mode, u, dt=dt, options=sh.solver_options(rtol=1e-10))
    assert _rel(rk4.displacement, ref.displacement) < 1e-5
    if mode != "free":
        assert _rel(rk4.force, ref.force) < 1e-5


def test_restart_policies_agree(calibrated, dt):
    """Keeping CVODE's history across samples (restart="never") and restarting
    at every input change integrate the same trajectory (to 1e-4 of the peak,
    both at rtol 1e-6; measured 3e-6 / 2e-5)."""
    u = _command("displacement", dt)
    a = sh.simulate(calibrated, "displacement", u, dt=dt, options=sh.solver_options(restart="never"))
    b = sh.simulate(calibrated, "displacement", u, dt=dt)
    assert _rel(a.displacement, b.displacement) < 1e-4
    assert _rel(a.force, b.force) < 1e-4


def test_rk4_automatic_substeps_follow_the_stiffness():
    """rk4_substeps = 0 picks the fewest substeps with h * rho(J) <= 1 over the operating states
    (the equilibrium, where friction is steepest, and the pressure and spool envelope).
    The preset (fastest mode: the 70.7 Hz critically damped valve, 444 rad/s; h rho = 0.22)
    needs one.  A piston-only installed mass (54 kg) with the free-structure friction (95.7 N
    over v_stick = 1e-4 m/s) has a friction mode at -8.8e3 rad/s: h lambda = -4.4 at 2 kHz,
    outside RK4's stability interval (-2.79, 0).  After a 2 mm step the structure settles at
    rest, where that mode is live: the automatic choice (5 substeps) matches CVODE at
    rtol 1e-9, one substep does not (measured velocity errors 2e-8 vs 7e-5 m/s, the latter
    bounded only because tanh saturates past v_stick)."""
    dt = 5e-4
    preset = sh.make_plant(sh.zhao2003(), "displacement", dt, sh.solver_options(method="rk4"))
    assert preset.rk4_substeps == 1

    stiff = sh.zhao2003(actuator_attached=False)
    stiff.m = 54.0
    jac = np.array(sh.Dynamics(stiff, sh.ControlMode.Displacement).jacobian(
        sh.Dynamics(stiff, sh.ControlMode.Displacement).equilibrium(0.0), 0.0))
    rho = np.max(np.abs(np.linalg.eigvals(jac)))
    auto = sh.make_plant(stiff, "displacement", dt, sh.solver_options(method="rk4"))
    assert auto.rk4_substeps >= int(np.ceil(dt * rho))  # at least the equilibrium's rate
    u = np.full(2000, 0.002)
    ref = sh.simulate(stiff, "displacement", u, dt, options=sh.solver_options(method="cvode", rtol=1e-9))
    v_scale = np.max(np.abs(ref.velocity))
    rk = sh.simulate(stiff, "displacement", u, dt, options=sh.solver_options(method="rk4"))
    one = sh.simulate(stiff, "displacement", u, dt, options=sh.solver_options(method="rk4", rk4_substeps=1))
    assert np.max(np.abs(rk.velocity - ref.velocity)) < 1e-5 * v_scale
    assert np.max(np.abs(one.velocity - ref.velocity)) > 100 * np.max(np.abs(rk.velocity - ref.velocity))


def test_ros2_is_l_stable_where_one_rk4_substep_is_not():
    """ROS2 (method="ros2", Verwer's linearly implicit second-order method) on the stiff rig of the
    test above.  At rest after the step (from 0.5 s) the friction mode is live, h lambda = -4.4 a
    sample, outside RK4's stability interval: RK4 at one substep rings there (bounded by tanh's
    saturation), ROS2 at one substep (L-stable) settles with CVODE at rtol 1e-9, a thousand times
    closer.  In the step's transient ROS2 is second order: its error falls about fourfold per
    doubling of the substeps (the C++ test measures 4.01-4.04 on the preset): 4 substeps miss 1e-2
    of the peak force, 8 meet it, where RK4 at its automatic 5 is within 1e-5 (the test above)."""
    dt = 5e-4
    stiff = sh.zhao2003(actuator_attached=False)
    stiff.m = 54.0
    u = np.full(2000, 0.002)
    ref = sh.simulate(stiff, "displacement", u, dt, options=sh.solver_options(method="cvode", rtol=1e-9))
    v_scale, f_scale = np.max(np.abs(ref.velocity)), np.max(np.abs(ref.force))

    def errors(**kw):
        r = sh.simulate(stiff, "displacement", u, dt, options=sh.solver_options(**kw))
        ev, ef = np.abs(r.velocity - ref.velocity) / v_scale, np.abs(r.force - ref.force) / f_scale
        return float(ev[1000:].max()), float(ef.max())  # at rest; the force over the whole run

    rest_ros2, _ = errors(method="ros2", ros2_substeps=1)
    rest_rk4, _ = errors(method="rk4", rk4_substeps=1, rk4_flag_rtol=0.0)
    assert rest_ros2 < 1e-5 and rest_ros2 < rest_rk4 / 1000
    e4, e8, e16, e32 = (errors(method="ros2", ros2_substeps=n)[1] for n in (4, 8, 16, 32))
    assert 3 < e8 / e16 < 5 and 3 < e16 / e32 < 5
    assert e8 < 1e-2 < e4
    with pytest.raises(ValueError, match="ros2_substeps"):
        sh.solver_options(method="ros2", ros2_substeps=0)


def test_the_rosenbrock_order_is_2_or_4():
    """``rosenbrock_order`` names one of the two methods the pair has for its stiff samples; another value is an
    error naming the field and the value."""
    assert sh.solver_options().rosenbrock_order == 2 and not sh.solver_options().stiffness_test
    assert sh.solver_options(stiff_rosenbrock=True, rosenbrock_order=4, stiffness_test=True).rosenbrock_order == 4
    with pytest.raises(ValueError, match="rosenbrock_order.*3"):
        sh.solver_options(stiff_rosenbrock=True, rosenbrock_order=3)
