"""Bad input: a clear error naming the field and the value, before any
integration; failed or diverging runs: SimulationError naming the time and the
cause (or, for a run that stays bounded, a result that says what went wrong)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.records import read_record, write_record

BAD_POSITIVE = [0.0, -1.0, math.nan, math.inf, -math.inf]


def _value(v: float) -> str:
    """How the error message prints a value: 0, -1, nan, inf, -inf."""
    return {0.0: "0", -1.0: "-1"}.get(v, repr(v))


@pytest.mark.parametrize("field", ["m", "A", "p_s"])
@pytest.mark.parametrize("value", BAD_POSITIVE, ids=_value)
def test_rig_parameter_must_be_positive_and_finite(calibrated, field, value):
    setattr(calibrated, field, value)
    message = rf"invalid {field} = {re.escape(_value(value))}\b"
    with pytest.raises(ValueError, match=message):
        sh.simulate(calibrated, mode="force", duration=0.01)
    with pytest.raises(ValueError, match=message):
        calibrated.validate()
    with pytest.raises(ValueError, match=rf"invalid ([a-z]+\.)?{field} = {re.escape(_value(value))}\b"):
        sh.rig_from_dict({"structure" if field == "m" else "actuator": {field: value}})


@pytest.mark.parametrize("dt", BAD_POSITIVE, ids=_value)
def test_time_step_must_be_positive_and_finite(calibrated, dt):
    with pytest.raises(ValueError, match=rf"invalid dt = {re.escape(_value(dt))}\b"):
        sh.simulate(calibrated, mode="displacement", duration=0.01, dt=dt)
    if math.isfinite(dt):  # the C++ constructor checks it too
        with pytest.raises(ValueError, match=rf"invalid dt = {re.escape(_value(dt))}\b"):
            sh.Plant(calibrated, sh.ControlMode.Displacement, dt)


def test_unknown_toml_keys_are_errors(tmp_path):
    cases = {
        "[structure]\nmass = 7084.0\n": r"unknown rig key structure\.mass",
        "[bogus]\nm = 1.0\n": r"unknown rig section \[bogus\]",
        "m = 7084.0\n": r"unknown rig section \[m\]",
        "[servovalve.flow_curve]\nkind = 'rational'\nbeta = 0.5\n": r"unknown rig key servovalve\.flow_curve\.beta",
        "[effects]\ngravity = true\n": r"unknown rig key effects\.gravity",
    }
    for i, (text, message) in enumerate(cases.items()):
        path = tmp_path / f"rig{i}.toml"
        path.write_text(text)
        with pytest.raises(ValueError, match=message) as info:
            sh.load_rig(path)
        assert str(path) in str(info.value)  # the message names the file


def test_rig_file_bad_values(tmp_path):
    path = tmp_path / "rig.toml"
    path.write_text("[structure]\nm = -5.0\n")
    with pytest.raises(ValueError, match=r"invalid m = -5\b"):
        sh.load_rig(path)
    path.write_text("[structure]\nm = 'heavy'\n")
    with pytest.raises(ValueError, match=r"invalid structure\.m = 'heavy'"):
        sh.load_rig(path)
    path.write_text("[effects]\ncoulomb_friction = 1\n")
    with pytest.raises(ValueError, match=r"invalid effects\.coulomb_friction = 1"):
        sh.load_rig(path)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_command_must_be_finite(calibrated, bad):
    u = np.zeros(100)
    u[37] = bad
    with pytest.raises(ValueError, match=rf"invalid command\[37\] = {re.escape(repr(bad))}"):
        sh.simulate(calibrated, mode="displacement", command=u)


def test_command_length_must_match_duration(calibrated):
    with pytest.raises(ValueError, match=r"invalid command length = 100: duration = 0\.1 s .* needs 201 samples"):
        sh.simulate(calibrated, mode="force", command=np.zeros(100), duration=0.1, dt=5e-4)
    with pytest.raises(ValueError, match=r"invalid command shape = \(10, 2\)"):
        sh.simulate(calibrated, mode="force", command=np.zeros((10, 2)))


def test_invalid_mode(calibrated):
    with pytest.raises(ValueError, match=r"invalid mode = 'position'"):
        sh.simulate(calibrated, mode="position", duration=0.01)


def _record(t: np.ndarray) -> dict:
    return {"time": t, "command": np.zeros_like(t), "displacement": np.zeros_like(t), "force": np.zeros_like(t)}


def test_record_time_must_be_uniform_and_increasing(tmp_path):
    path = tmp_path / "rec.csv"
    good = np.arange(10) * 5e-4
    write_record(path, _record(good))
    assert len(read_record(path)) == 10

    uneven = good.copy()
    uneven[5:] += 1e-4
    lines = ["time,command,displacement,force"] + [f"{v:.10g},0,0,0" for v in uneven]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"time must be uniform; step 4 is"):
        read_record(path)
    with pytest.raises(ValueError, match=r"time must be uniform"):
        write_record(tmp_path / "out.csv", _record(uneven))

    backwards = good.copy()
    backwards[6] = backwards[4]
    lines = ["time,command,displacement,force"] + [f"{v:.10g},0,0,0" for v in backwards]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"time must be increasing; time\[6\] = 0\.002 <= time\[5\] = 0\.0025"):
        read_record(path)


def test_record_bad_columns(tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("time,command,displacement\n0,0,0\n0.0005,0,0\n")
    with pytest.raises(ValueError, match=r"missing column\(s\) \['force'\]"):
        read_record(path)
    path.write_text("time,command,displacement,force,temperature\n0,0,0,0,20\n0.0005,0,0,0,20\n")
    with pytest.raises(ValueError, match=r"unknown column\(s\) \['temperature'\]"):
        read_record(path)
    path.write_text("time,command,displacement,force\n0,0,0,0\n0.0005,0,nan,0\n")
    with pytest.raises(ValueError, match=r"column 'displacement' row 3 is nan"):
        read_record(path)


def test_diverging_run_raises_with_time_and_cause(calibrated):
    """An absurd ideal force (1e9 N) on the free structure passes the 100 m
    divergence guard at t = sqrt(2 * 100 m * 7084 kg / 1e9 N) = 37.6 ms (the
    spring is negligible there); the error names the sample time and the cause."""
    with pytest.raises(sh.SimulationError, match=r"failed at t = 0\.038 s: .*diverged"):
        sh.simulate(calibrated, mode="free", command=np.full(400, 1e9))
    partial = sh.simulate(calibrated, mode="free", command=np.full(400, 1e9), raise_on_failure=False)
    assert not partial.success and partial.status == "non_finite"
    assert partial.work.status.t == pytest.approx(0.038)
    assert len(partial.time) == 76  # rows up to the failed sample (t = 0 ... 0.0375 s)
    assert np.all(np.isfinite(partial.displacement))


def test_solver_overrun_raises_with_time_and_cvode_flag(calibrated):
    opts = sh.solver_options(method="cvode", max_steps_per_sample=1)
    with pytest.raises(sh.SimulationError, match=r"failed at t = [0-9.e-]+ s: overrun.*\(CVODE flag -1\)"):
        sh.simulate(calibrated, mode="displacement", command=np.full(10, 1e-3), options=opts)


def test_printed_table_one_runs_into_the_supply_pressure(make_rig, dt):
    """Table I as printed is unstable in displacement control (Eq 12 has a
    right-half-plane pair).  The nonlinear run does not blow up numerically:
    the oil-column oscillation grows until the load pressure reaches the
    supply pressure, which bounds it.  The run completes and says so; the
    displacement then oscillates far beyond the 1 mm command."""
    rig = make_rig("printed")
    n = int(round(1.0 / dt)) + 1
    res = sh.simulate(rig, mode="displacement", command=np.full(n, 1e-3), dt=dt)
    assert res.success
    assert res.supply_limited
    assert any("supply pressure" in w and "t = " in w for w in res.warnings())
    late = res.displacement[res.time > 0.5]
    assert late.max() - late.min() > 5e-3  # a limit cycle of more than 5 mm peak to peak
    # The calibrated preset holds the same command quietly.
    ok = sh.simulate(make_rig(), mode="displacement", command=np.full(n, 1e-3), dt=dt)
    assert not ok.warnings()
    assert np.ptp(ok.displacement[ok.time > 0.5]) < 1e-5


def test_stroke_exceeded_is_reported():
    """A command past the +-127 mm stroke (10 V at C_F = 78.74 V/m) is flagged and warned about,
    with the time the displacement first crossed the stroke; within the stroke nothing is."""
    dt = 5e-4
    t = np.arange(0, 4.0, dt)
    ramp = 0.15 * np.minimum(t / 3.0, 1.0)  # 0 -> 150 mm, slow enough to track
    rig = sh.zhao2003()
    res = sh.simulate(rig, "displacement", ramp, dt)
    crossed = res.time[np.argmax(np.abs(res.displacement) > rig.stroke)]
    notes = [w for w in res.warnings(rig) if "stroke" in w]
    assert len(notes) == 1 and "127 mm" in notes[0] and f"t = {crossed:.3f} s" in notes[0]
    inside = sh.simulate(rig, "displacement", 0.1 / 0.15 * ramp, dt)
    assert not any("stroke" in w for w in inside.warnings(rig))
