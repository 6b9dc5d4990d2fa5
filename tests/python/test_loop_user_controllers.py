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
