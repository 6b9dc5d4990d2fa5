"""Lab records at any uniform rate: unit-suffixed columns, clear errors, the controller sample."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.identification import run


def _write(path, header, rows):
    path.write_text(header + "\n" + "\n".join(",".join(str(v) for v in r) for r in rows) + "\n")
    return path


def test_unit_suffixed_columns_read_as_channels(tmp_path):
    t = np.arange(50) * 0.004  # 250 Hz
    rows = np.column_stack([t, np.sin(t), 0.9 * np.sin(t), 100 * np.cos(t)])
    rec = sh.read_record(_write(tmp_path / "lab.csv", "time_s,command_m,displacement_m,force_N", rows))
    assert list(rec.channels) == ["time", "command", "displacement", "force"]
    assert rec.dt == pytest.approx(0.004)
    np.testing.assert_array_equal(rec.force, rows[:, 3])


@pytest.mark.parametrize("header, rows, words", [
    ("time_s,command_m,displacement_m,force_N", [[0, 0, 0, 0], [0.001, 0, 0, 0], [0.003, 0, 0, 0]],
     ["time must be uniform", "step"]),
    ("time_s,command_m,displacement_m,force_N", [[0, 0, 0, 0], [0.001, 0, "nan", 0], [0.002, 0, 0, 0]],
     ["'displacement'", "row 3"]),
    ("time,time_s,command,displacement,force", [[0, 0, 0, 0, 0], [1, 1, 0, 0, 0]], ["'time'", "twice"]),
    ("time_s,command_m,displacement_m", [[0, 0, 0], [1, 0, 0]], ["missing", "force"]),
])
def test_bad_files_name_file_and_column(tmp_path, header, rows, words):
    path = _write(tmp_path / "bad.csv", header, rows)
    with pytest.raises(ValueError) as e:
        sh.read_record(path)
    assert "bad.csv" in str(e.value)
    for w in words:
        assert w in str(e.value)


def _record(rig, u, dt):
    sim = sh.simulate(rig, "displacement", command=u, dt=dt)
    return sh.Response({"time": sim.time, "command": u, "displacement": sim.displacement, "force": sim.force})


def test_controller_sample_defaults_to_the_record_and_can_be_finer():
    """Contract: dt=None runs the controller at the record's dt (sample-for-sample the
    core's own run); a controller twice as fast gets the command interpolated and
    every second output kept (equal to simulating the interpolated command by hand)."""
    rig = sh.zhao2003()
    dt = 2e-3
    t = np.arange(400) * dt
    u = 0.002 * np.sin(2 * np.pi * 1.5 * t) * np.minimum(t / 0.2, 1)
    rec = _record(rig, u, dt)
    sim = run.simulate_record(rig, rec, "displacement", x0=0.0)
    np.testing.assert_array_equal(sim.displacement, rec.displacement)
    fine = run.simulate_record(rig, rec, "displacement", dt=dt / 2, x0=0.0)
    t2 = np.arange(2 * u.size - 1) * dt / 2
    by_hand = sh.simulate(rig, "displacement", command=np.interp(t2, t, u), dt=dt / 2)
    np.testing.assert_array_equal(fine.displacement, by_hand.displacement[::2])
    coarse = run.simulate_record(rig, rec, "displacement", dt=2 * dt, x0=0.0)
    assert coarse.displacement.size == u.size
    with pytest.raises(ValueError, match="invalid dt"):
        run.simulate_record(rig, rec, "displacement", dt=0.7 * dt)
