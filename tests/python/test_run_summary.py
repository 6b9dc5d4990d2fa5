"""One run summary: every loop (the plant's record, EFT, RPsD and the RTHS benchmark loop) returns
the core's RunSummary (record.hpp), read as ``Response.work``.  Oracle: the peaks are the largest
|value| of the run's own channels, bit for bit; a failure's time is the failed row's time."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import rths

SUMMARY = {"ok", "status", "rows", "internal_steps", "rhs_evals", "restarts", "max_internal_steps",
           "stiff_samples", "inaccurate_samples", "error_estimate", "max_sample_error_estimate", "flags_any",
           "peak_force", "peak_displacement", "peak_velocity", "failure_time", "first_capacity_time"}


def _ag(n=1000, dt=5e-4):
    t = np.arange(n) * dt
    return 0.5 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(t / 0.2, 1.0)


def _runs():
    rig = sh.zhao2003()
    t = np.arange(1000) * 5e-4
    yield "plant", sh.simulate(rig, "displacement", 2e-3 * np.sin(2 * np.pi * 3.0 * t)), "force"
    yield "eft", sh.run_eft(rig, _ag()), "force"
    yield "rpsd", sh.run_rpsd(rig, _ag(), physical_mass_fraction=0.02), "force"
    case, rec = rths.embedded_case(1), rths.synthetic_record(duration=1.0)
    yield "rths", rths.run_trial(case, rec, "sample", keep_signals=True).response, "actuator_force"


@pytest.mark.parametrize("kind, res, force", list(_runs()), ids=lambda x: x if isinstance(x, str) else "")
def test_every_loop_returns_the_same_summary(kind, res, force):
    assert set(vars(res.work)) == SUMMARY and res.kind == kind
    w = res.work
    assert w.ok and w.status.ok and w.failure_time == -1.0 and w.rows == len(res)
    assert w.peak_force == float(np.max(np.abs(res.channels[force]))) > 0.0
    assert w.peak_displacement == float(np.max(np.abs(res.displacement))) > 0.0
    if "velocity" in res.channels:  # the RTHS rows carry no velocity: the specimen's own, checked below
        assert w.peak_velocity == float(np.max(np.abs(res.velocity))) > 0.0
    else:
        x = res.displacement
        assert w.peak_velocity == pytest.approx(np.max(np.abs(np.diff(x))) / res.dt, rel=0.05)


@pytest.mark.parametrize("kind", ["plant", "eft"])
def test_a_failed_sample_gives_its_row_time(kind):
    """A stiff sample (Dopri5 without its CVODE fallback, stiff_steps 2) after a step at row 100
    stops the run there: failure_time is the time of that row, the last one written."""
    rig, opts = sh.zhao2003(), sh.solver_options("dopri5")
    opts.stiff_fallback, opts.stiff_steps = False, 2
    if kind == "plant":
        res = sh.simulate(rig, "displacement", np.r_[np.zeros(100), np.full(100, 5e-3)], options=opts,
                          raise_on_failure=False)
    else:
        res = sh.run_eft(rig, np.r_[np.zeros(100), np.full(100, 5.0)], solver_options=opts, raise_on_failure=False)
    w = res.work
    assert not w.ok and res.status == "stiff" and len(res) == w.rows == 101
    assert w.failure_time == float(res.time[-1]) == 100 * res.dt
