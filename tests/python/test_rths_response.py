"""An RTHS trial's record is a Response of kind "rths", one shape with the EFT/RPsD runs:
its channels and units are the core's table (_core.rths.RTHS_CHANNELS, from
kRthsChannels in rths/loop.hpp), ``Trial.signals`` reads the same data, and
``to_pandas`` writes it.  Oracles: the loop's own output (RthsLoop.run) bit for bit, the
sample grid, the ground motion and the sensor noise's sigma."""

from __future__ import annotations

import math

import numpy as np
import pytest

from servohydraulics import _core, rths
from servohydraulics.response import Response, channel_units

R = rths.core


@pytest.fixture(scope="module")
def short():
    case, rec = rths.embedded_case(1), rths.synthetic_record(duration=3.0)
    return case, rec, rths.run_trial(case, rec, "sample", seed=3, keep_signals=True, timing=True)


def test_the_table_is_exported_with_units():
    table = dict(map(tuple, R.RTHS_CHANNELS))
    assert list(table) == ["time", "ground_acceleration", "measured", "displacement", "actuator_force", "command",
                           "feedback_force"]
    assert table["time"] == "s" and table["actuator_force"] == "N" and table["measured"] == "m"
    assert table["ground_acceleration"] == "m/s^2"
    assert channel_units("rths") == {**table, "step_seconds": "s"}
    assert R.RTHS_CHANNELS is _core.rths.RTHS_CHANNELS


def test_the_response_channels_and_units_are_the_table(short):
    case, rec, t = short
    res = t.response
    assert isinstance(res, Response) and res.kind == "rths" and res.success and res.status == "ok"
    n, dofs = rec.samples(), t.signals["numerical"].shape[1]
    table = dict(map(tuple, R.RTHS_CHANNELS))
    per_dof = [f"{p}_{i}" for p in ("numerical", "reference") for i in range(dofs)]
    assert list(res.channels) == list(table) + ["step_seconds"] + per_dof
    assert res.units == {**table, "step_seconds": "s", **{c: "m" for c in per_dof}}
    assert len(res) == n and res.dt == rths.DT and res.work.rows == n
    assert res.work.peak_force == t.max_force_N == float(np.max(np.abs(res.actuator_force)))


def test_the_response_is_the_loops_output_to_the_bit(short):
    """The same run through RthsLoop.run directly: every column identical; the grid, the
    ground motion and the noise as configured."""
    case, rec, t = short
    exp = R.BenchmarkPlant(rths.nominal_plant(), rths.DT)
    num = R.LinearSubstructure(rths.partition(case, exp.specimen()), rths.DT, R.SubstructureScheme.RungeKutta4)
    cfg = R.RthsLoopConfig()
    cfg.seed, cfg.generator = 3, R.NoiseGenerator.SimulinkRandomNumber
    out, summary = R.RthsLoop(exp, num, rths.make_controller("sample"), cfg).run(
        num, R.GroundMotion(rec.time, rec.acceleration, rths.EQ_INTENSITY), rec.samples(), False)
    assert isinstance(summary, _core.RunSummary) and summary.ok() and summary.rows == rec.samples()
    res = t.response
    for name, _ in R.RTHS_CHANNELS:
        np.testing.assert_array_equal(res.channels[name], out[name], err_msg=name)
        assert t.signals[name] is res.channels[name]
    np.testing.assert_array_equal(t.signals["numerical"], out["numerical"])
    np.testing.assert_array_equal(t.signals["reference"], rths.case_reference(case, rec))
    n = rec.samples()
    np.testing.assert_array_equal(res.time, np.arange(n) * rths.DT)
    np.testing.assert_allclose(res.ground_acceleration,
                               rths.EQ_INTENSITY * np.interp(res.time, rec.time, rec.acceleration), rtol=0,
                               atol=1e-12 * np.max(np.abs(rec.acceleration)))
    noise = res.measured - res.displacement  # sigma = 1.6e-5 m (F1 L169), one draw a sample
    assert np.std(noise) == pytest.approx(cfg.displacement_noise.sigma, rel=0.02)
    assert np.all(res.step_seconds >= 0.0) and res.step_seconds.size == n


def test_to_pandas_and_the_signals_mapping(short):
    _, rec, t = short
    df = t.response.to_pandas()
    assert list(df.columns) == list(t.response.channels) and len(df) == rec.samples()
    assert df.attrs["units"]["feedback_force"] == "N" and df.attrs["units"]["numerical_0"] == "m"
    np.testing.assert_array_equal(df["command"].to_numpy(), t.signals["command"])
    assert set(t.signals) == set(t.response.channels) | {"numerical", "reference"}
    with pytest.raises(KeyError):
        t.signals["nope"]
    with pytest.raises(AttributeError, match="read-only"):
        t.response.channels.command = None


def test_without_keep_signals_there_is_no_response_and_a_failure_is_said():
    case, rec = rths.embedded_case(1), rths.synthetic_record(duration=1.0)
    t = rths.run_trial(case, rec, "sample", seed=3)
    assert t.response is None and len(t.signals) == 0 and dict(t.signals) == {}

    class NanAt5:
        def reset(self):
            self.k = 0

        def command(self, *args):
            self.k += 1
            return math.nan if self.k == 6 else 0.0

    bad = rths.run_trial(case, rec, NanAt5(), keep_signals=True)
    res = bad.response
    assert not bad.ok and not res.success and res.status == "non_finite" and len(res) == 6
    assert res.message.startswith(f"RTHS failed at t = {5 * rths.DT:.6g} s")
    assert res.to_pandas().shape[0] == 6 and res.work.failure_time == 5 * rths.DT
    # the core's RunSummary, as every loop's (test_run_summary.py): the failure at the loop's sample time
    assert not res.work.ok and res.work.status.t == res.work.failure_time and res.work.rows == 6
    assert bad.failure_time == res.work.failure_time and bad.max_force_N == res.work.peak_force
