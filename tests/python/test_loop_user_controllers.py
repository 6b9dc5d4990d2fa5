"""A user's Python tracking controller in the paper's loops (EFT and RPsD), not only in the
RTHS benchmark: the same object protocol (reset(), command(...)), the same error path.

Oracle: a Python controller that passes the desired value through is the paper's loop with
its own compensation switched off (amplitude_T = 0 in RPsD, compensation "none" in EFT), to
the bit; a controller that raises stops the run with its error, naming the sample."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import rths


class PassThrough:
    """command = the desired value (displacement [m] in RPsD, force [N] in EFT)."""

    def __init__(self):
        self.calls = 0

    def reset(self):
        self.calls = 0

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        self.calls += 1
        return desired


class Subclassed(rths.TrackingController):
    def reset(self):
        pass

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        return desired


class Failing(PassThrough):
    def command(self, *args):
        if self.calls == 100:
            raise ZeroDivisionError("user bug")
        return super().command(*args)


def ground_motion(n=2000, dt=5e-4):
    t = np.arange(n) * dt
    return 0.5 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(t / 0.2, 1.0)


@pytest.mark.parametrize("controller", [PassThrough, Subclassed])
def test_rpsd_with_a_python_controller_is_the_loop_without_amplitude_compensation(controller):
    rig, ag = sh.zhao2003(), ground_motion()
    ref = sh.run_rpsd(rig, ag, amplitude_T=0.0)
    c = controller()
    res = sh.run_rpsd(rig, ag, amplitude_T=0.0, tracking=c)
    for ch in ("command", "displacement", "force", "calc_displacement"):
        np.testing.assert_array_equal(res.channels[ch], ref.channels[ch])
    if isinstance(c, PassThrough):
        assert c.calls == ag.size
    # and the paper's 68 ms lead is not a pass-through: the oracle can fail
    assert np.max(np.abs(sh.run_rpsd(rig, ag).channels["command"] - ref.channels["command"])) > 1e-6


def test_eft_with_a_python_controller_is_the_loop_without_compensation():
    rig, ag = sh.zhao2003(), ground_motion()
    ref = sh.run_eft(rig, ag, compensation="none")
    res = sh.run_eft(rig, ag, compensation="none", tracking=PassThrough())
    for ch in ("command", "force", "displacement"):
        np.testing.assert_array_equal(res.channels[ch], ref.channels[ch])
    assert np.max(np.abs(sh.run_eft(rig, ag).channels["command"] - ref.channels["command"])) > 1.0  # linear VFC differs


@pytest.mark.parametrize("run", [sh.run_rpsd, sh.run_eft])
def test_a_python_controller_error_stops_the_loop_naming_the_sample(run):
    with pytest.raises(RuntimeError, match=r"command\(\) raised at sample 100 \(t = 0\.05 s\): ZeroDivisionError") \
            as info:
        run(sh.zhao2003(), ground_motion(), tracking=Failing())
    assert isinstance(info.value.__cause__, ZeroDivisionError)
    assert info.value.sample == 100


def test_not_a_controller_is_named():
    with pytest.raises(ValueError, match="invalid tracking"):
        sh.run_rpsd(sh.zhao2003(), ground_motion(), tracking=object())


# ------------------------------------------------------------- the two optional inputs
class PaperVelocityFeedback:
    """The paper's linear velocity feedback compensation (Eqs 9-10) written in Python from the
    measured velocity: du = A H(v) / (K_v K_s C_F G_p), H the phase lead (T_d-hat = 5 ms,
    alpha = 0.1; its discrete coefficients from the core's PhaseLead), command = P_eff + du.
    It also keeps the measured pressures it was given."""

    def __init__(self, rig, dt):
        cfg = sh.loops.eft_config()
        lead = sh._core.PhaseLead(cfg.lead_T, cfg.alpha, dt)
        self.b0, self.b1, self.a1 = lead.b0, lead.b1, lead.a1
        self.A, self.Kf = rig.A, rig.K_v * (rig.K_s * rig.C_F_force * rig.G_p)
        self.pressures, self.velocities = [], []

    def reset(self):
        self.u1 = self.y1 = 0.0
        self.pressures, self.velocities = [], []

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force, *,
                measured_velocity, measured_pressure):
        v = self.b0 * measured_velocity + self.b1 * self.u1 - self.a1 * self.y1
        self.u1, self.y1 = measured_velocity, v
        self.velocities.append(measured_velocity)
        self.pressures.append(measured_pressure)
        return desired + self.A * v / self.Kf


class PaperVelocityFeedbackSubclass(rths.TrackingController):
    """The same through the TrackingController subclass (the trampoline), taking **kwargs."""

    def __init__(self, rig, dt):
        super().__init__()
        self.impl = PaperVelocityFeedback(rig, dt)

    def reset(self):
        self.impl.reset()

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force, **inputs):
        return self.impl.command(desired, desired_velocity, desired_acceleration, measured, measured_force, **inputs)


@pytest.mark.parametrize("controller", [PaperVelocityFeedback, PaperVelocityFeedbackSubclass])
def test_a_python_velocity_feedback_from_measured_velocity_is_the_builtin_eft(controller):
    """Oracle: the built-in VelocityFeedbackTracking (sh.run_eft's default, linear) to the bit; the
    measured velocity and pressure a controller receives are the rows' sensors to the bit."""
    rig, ag = sh.zhao2003(), ground_motion()
    ref = sh.run_eft(rig, ag)
    c = controller(rig, sh.loops.eft_config().dt)
    res = sh.run_eft(rig, ag, tracking=c)
    for ch in ("command", "force", "displacement", "velocity", "pressure"):
        np.testing.assert_array_equal(res.channels[ch], ref.channels[ch], err_msg=ch)
    impl = getattr(c, "impl", c)
    np.testing.assert_array_equal(impl.velocities, ref.channels["velocity"])
    np.testing.assert_array_equal(impl.pressures, ref.channels["pressure"])
    assert np.max(np.abs(ref.pressure)) > 1e5 and np.max(np.abs(ref.velocity)) > 1e-4  # inputs that matter
    # and the compensation is not a pass-through: the oracle can fail
    none = sh.run_eft(rig, ag, compensation="none")
    assert np.max(np.abs(none.channels["command"] - ref.channels["command"])) > 1.0


class OnlyVelocity:
    def reset(self):
        self.seen = []

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force,
                measured_velocity=None):
        self.seen.append(measured_velocity)
        return desired


class AnyKeywords:
    def reset(self):
        self.seen = []

    def command(self, *args, **kwargs):
        self.seen.append((len(args), sorted(kwargs)))
        return args[0]


@pytest.mark.parametrize("obj, keywords", [(PassThrough(), ()), (OnlyVelocity(), ("measured_velocity",)),
                                           (AnyKeywords(), ("measured_velocity", "measured_pressure")),
                                           (Failing(), ())])
def test_the_optional_inputs_follow_the_signature(obj, keywords):
    """Decided once from command()'s signature: the five positional inputs always, each optional
    input as a keyword only if command() names it or takes **kwargs (a five-argument or *args
    class gets five, as before)."""
    wrapped = sh._core.rths.PythonController(obj)
    assert wrapped.keywords == keywords
    if isinstance(obj, Failing):
        return
    res = sh.run_eft(sh.zhao2003(), ground_motion(200), compensation="none", tracking=obj)
    assert res.success
    if isinstance(obj, OnlyVelocity):
        np.testing.assert_array_equal(obj.seen, res.channels["velocity"])
    if isinstance(obj, AnyKeywords):
        assert obj.seen == [(5, ["measured_pressure", "measured_velocity"])] * 200
