"""``diagnose --dt`` (issue 25, item 4): a 1 kHz record of a 2 kHz rig.

The record is the nominal rig's own run at a 2 kHz controller, kept at every second
sample (a 1 kHz acquisition).  Simulated at the record's 1 ms the controller holds each
command twice as long (a zero-order hold of 1 ms lags 0.25 ms more than one of 0.5 ms),
so without the controller's sample the diagnosis names a ``command_delay`` (negative:
the record leads the model) that is not in the rig; with ``dt=5e-4`` (the command
interpolated onto the controller's grid, the same helper as ``compare`` and
``identify``) it names nothing.  The oracle: the record is the nominal rig's.  Sensor noise
as on the UTFSM frame's quieter campaign (2 um, 20 N): the linear interpolation of the 1 kHz
command misses the 2 kHz one by about 1 um at the chirp's top (8.5 Hz), below that noise."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.identification.run import controller_ratio

DELAYS = ["command_delay", "loop_delay", "servovalve_dynamics"]


@pytest.fixture(scope="module")
def decimated():
    rig = sh.zhao2003()
    dt = 5e-4
    t = np.arange(int(4.0 / dt) + 1) * dt
    f = 0.5 + 2.0 * t  # a chirp 0.5 -> 8.5 Hz over 4 s
    u = 0.003 * np.sin(2 * np.pi * np.cumsum(f) * dt) * np.minimum(t / 0.2, 1.0)
    res = sh.simulate(rig, "displacement", command=u, dt=dt)
    rng = np.random.default_rng(3)
    keep = slice(None, None, 2)
    rec = sh.Response({"time": t[keep], "command": u[keep],
                       "displacement": np.asarray(res.displacement)[keep] + 2e-6 * rng.standard_normal(t[keep].size),
                       "force": np.asarray(res.force)[keep] + 20.0 * rng.standard_normal(t[keep].size)},
                      kind="record")
    return rig, rec


def test_the_controller_sample_is_shared_with_compare_and_identify():
    assert controller_ratio(1e-3, 100, 5e-4) == (2, True)
    with pytest.raises(ValueError, match="invalid dt = 0.0007"):
        controller_ratio(1e-3, 100, 7e-4)


def test_a_1khz_record_of_a_2khz_rig_has_no_delay_with_dt(decimated):
    rig, rec = decimated
    without = sh.diagnose([rec], rig, mode="displacement", progress=False, candidates=DELAYS)
    names = [e["name"] for e in without.effects]
    assert "command_delay" in names, without.summary
    tau = without.effects[names.index("command_delay")]["parameters"]["command_delay"]["value"]
    assert -0.5e-3 < tau < -0.1e-3, tau  # the extra half sample of hold: about -0.25 ms
    fixed = sh.diagnose([rec], rig, mode="displacement", progress=False, candidates=DELAYS, dt=5e-4)
    assert fixed.verdict == "no_effect", fixed.summary
    assert fixed.to_dict()["controller_dt_s"] == 5e-4
    # the model at the right controller rate: its gap a quarter of the other (0.17 % against 0.64 %, the rest noise)
    assert fixed.gap_before["displacement"] < 0.5 * without.gap_before["displacement"]


def test_diagnose_refuses_a_dt_that_does_not_fit_the_record(decimated, tmp_path):
    rig, rec = decimated
    with pytest.raises(ValueError, match=r"invalid dt = 0.0007"):
        sh.diagnose([rec], rig, mode="displacement", progress=False, dt=7e-4)
