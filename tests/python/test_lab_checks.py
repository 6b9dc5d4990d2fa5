"""Records that cannot be misread (issue 25, item 4): the plausibility checks of
``compare``, ``identify`` and ``diagnose``, on the screen and in their JSON.

The oracle of each case is the rig itself: a record the rig simulated is read right
(NRMSE ~0) once its units are given, and refused or flagged as written wrong (a record
in millimetres read as metres compared at a 278 % NRMSE with exit 0 before)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_cases import run_case

import servohydraulics as sh
from servohydraulics.identification.checks import CODES, Check, CheckError, record_checks

DT = 1e-3
N = 3000


def _record(amplitude: float = 0.002, f: float = 2.0, rig=None) -> dict[str, np.ndarray]:
    """A 3 s sine of ``amplitude`` [m] through the preset (a record the rig itself made)."""
    rig = rig or sh.zhao2003()
    t = np.arange(N) * DT
    u = amplitude * np.sin(2 * np.pi * f * t) * np.minimum(t / 0.3, 1.0)
    res = sh.simulate(rig, "displacement", command=u, dt=DT)
    return {"time": t, "command": u, "displacement": np.asarray(res.displacement), "force": np.asarray(res.force)}


def _csv(path, cols: dict, header=None, factors=None):
    names = header or list(cols)
    f = factors or {}
    data = np.column_stack([cols[k] * f.get(k, 1.0) for k in cols])
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("checks")
    rec = _record()
    sh.save_rig(sh.zhao2003(), d / "rig.toml")
    return {"dir": d, "rec": rec, "rig": d / "rig.toml",
            "m": _csv(d / "rec_m.csv", rec),
            "mm": _csv(d / "rec_mm.csv", rec, factors={"command": 1e3, "displacement": 1e3})}


def test_a_millimetre_record_read_as_metres_is_refused_and_read_right_with_units(files, tmp_path):
    """Before, ``compare`` of such a record exited 0 with a number and no word (the shared sweep in
    mm: 142.67 %, docs/lab-records.md, 'Checks').  Now: exit 2 naming the file, the channel, the
    value, the rig's stroke and the flag that reads it right; with ``--units`` it compares at ~0."""
    out = tmp_path / "cmp"
    outcome, code, err = run_case(["compare", str(files["mm"]), "--rig", str(files["rig"]), "--mode", "displacement",
                                   "--out", str(out)])
    assert code == 2, err
    line = err.strip().splitlines()[-1]
    for w in ("error:", "rec_mm.csv", "[displacement_outside_stroke]", "invalid displacement = 1.496 m",
              "times the rig's stroke", "--units command=mm,displacement=mm"):
        assert w in line, line
    assert not out.exists() or not any(out.iterdir())
    outcome, code, err = run_case(["compare", str(files["mm"]), "--rig", str(files["rig"]), "--mode", "displacement",
                                   "--out", str(out), "--units", "command=mm,displacement=mm"])
    assert code == 0, err
    data = json.loads((out / "comparison.json").read_text())
    assert data["channels"]["displacement"]["nrmse_pct"] < 0.1
    assert data["checks"] == []
    for name in ("overlay.png", "frf.png", "loops.png"):
        assert (out / name).is_file()


def test_identify_and_diagnose_refuse_the_millimetre_record_too(files, tmp_path):
    """Without a start rig (the generic start scales itself from the record): the absolute
    check (a 2 m half-stroke, 25 m/s) still refuses it; with the rig, the stroke check."""
    for argv in (["identify", str(files["mm"]), "--mode", "displacement", "--quiet"],
                 ["diagnose", str(files["mm"]), "--rig", str(files["rig"]), "--mode", "displacement", "--quiet"]):
        outcome, code, err = run_case(argv + ["--out", str(tmp_path / argv[0])])
        assert code == 2, err
        assert "rec_mm.csv" in err, err
        assert "[displacement_implausible]" in err or "[displacement_outside_stroke]" in err, err
        assert not (tmp_path / argv[0]).exists() or not any((tmp_path / argv[0]).iterdir())


def test_time_in_milliseconds_read_as_seconds(files, tmp_path):
    rec = files["rec"]
    path = _csv(tmp_path / "rec_ms.csv", rec, factors={"time": 1e3})
    with pytest.raises(CheckError, match=r"rec_ms.csv: \[time_step\] invalid time step = 1 s.*--units time=ms"):
        sh.identification.compare(sh.read_record(path), sh.zhao2003(), "displacement")
    c = sh.identification.compare(sh.read_record(path, units={"time": "ms"}), sh.zhao2003(), "displacement")
    assert c.nrmse("displacement") < 0.1


def test_channels_in_different_units_and_a_force_unit_command(files, tmp_path):
    rec = files["rec"]
    mixed = _csv(tmp_path / "rec_mixed.csv", rec, factors={"displacement": 1e3})
    found = record_checks(sh.read_record(mixed), None, "displacement")
    assert [c.code for c in found if c.level == "error"][:1] == ["channel_units"], found
    newton = _csv(tmp_path / "rec_n.csv", rec, header=["time", "command_N", "displacement", "force"])
    with pytest.raises(CheckError, match=r"\[command_unit\] invalid command unit = 'N'"):
        sh.identification.compare(sh.read_record(newton), sh.zhao2003(), "displacement")


def test_a_record_flat_at_a_stop_warns_and_can_be_acknowledged(files, tmp_path):
    """The measured displacement clipped at 1 mm while the command goes to 2 mm (an end
    stop): a warning with the level and the time, exit 0; acknowledged, it leaves the screen
    and stays in the JSON."""
    rec = dict(files["rec"])
    rec["displacement"] = np.minimum(rec["displacement"], 0.001)
    path = _csv(tmp_path / "rec_stop.csv", rec)
    argv = ["compare", str(path), "--rig", str(files["rig"]), "--mode", "displacement"]
    outcome, code, err = run_case(argv + ["--out", str(tmp_path / "a")])
    assert code == 0, err
    assert "warning:" in err and "[flat_at_limit] displacement sits flat at 1 mm" in err, err
    data = json.loads((tmp_path / "a" / "comparison.json").read_text())
    flat = [c for c in data["checks"] if c["code"] == "flat_at_limit"]
    assert flat and flat[0]["level"] == "warning" and flat[0]["channel"] == "displacement"
    assert flat[0]["values"]["level"] == pytest.approx(0.001, rel=1e-6) and not flat[0]["acknowledged"]
    outcome, code, err = run_case(argv + ["--out", str(tmp_path / "b"), "--accept", "flat_at_limit"])
    assert code == 0 and "flat_at_limit" not in err, err
    data = json.loads((tmp_path / "b" / "comparison.json").read_text())
    assert [c["acknowledged"] for c in data["checks"] if c["code"] == "flat_at_limit"] == [True]


def test_a_clean_sine_peak_is_not_flat(files):
    """The slow sine's own peaks (the command does not go beyond them) raise nothing."""
    rec = sh.Response(files["rec"], kind="record")
    assert record_checks(rec, sh.zhao2003(), "displacement") == []


def test_the_simulated_runs_limits_are_checks(files, tmp_path):
    """A rig whose spool saturates on this record (its limit at 0.3 of the 0.0094 peak opening
    the preset needs): ``run_spool`` in the JSON and on the screen, with the time."""
    rig = sh.zhao2003()
    rig.x_v_max = 0.003
    rig.effects.spool_saturation = True
    sh.save_rig(rig, tmp_path / "rig_small.toml")
    outcome, code, err = run_case(["compare", str(files["m"]), "--rig", str(tmp_path / "rig_small.toml"),
                                   "--mode", "displacement", "--out", str(tmp_path / "o")])
    assert code == 0, err
    data = json.loads((tmp_path / "o" / "comparison.json").read_text())
    spool = [c for c in data["checks"] if c["code"] == "run_spool"]
    assert spool and "servovalve spool saturated" in spool[0]["message"], data["checks"]
    assert "[run_spool]" in err


def test_diagnose_reports_the_nominal_runs_limits(files, tmp_path):
    """Issue 25, item 4, for ``diagnose``: the same small-spool rig's nominal run saturates the
    spool on this record, and the diagnosis says so (``run_spool`` in its checks, with the time),
    as ``compare`` does; the preset's own run hits nothing."""
    rig = sh.zhao2003()
    rig.x_v_max = 0.003
    rig.effects.spool_saturation = True
    d = sh.diagnose([files["m"]], rig, "displacement", progress=False, max_effects=1, candidates=["leakage"])
    spool = [c for c in d.checks if c.code == "run_spool"]
    assert spool and "servovalve spool saturated" in spool[0].message, d.checks
    clean = sh.diagnose([files["m"]], sh.zhao2003(), "displacement", progress=False, max_effects=1,
                        candidates=["leakage"])
    assert not [c for c in clean.checks if c.code.startswith("run_")], clean.checks


@pytest.mark.parametrize("accept, words", [
    ("bogus", ["invalid accept = 'bogus'", "not a check"]),
    ("displacement_outside_stroke", ["invalid accept = 'displacement_outside_stroke'", "cannot be acknowledged"]),
])
def test_accept_refuses_unknown_and_error_codes(files, tmp_path, accept, words):
    outcome, code, err = run_case(["compare", str(files["m"]), "--rig", str(files["rig"]), "--mode", "displacement",
                                   "--out", str(tmp_path / "x"), "--accept", accept])
    assert code == 2
    for w in words:
        assert w in err, err


def test_every_code_has_a_level_and_a_meaning():
    assert set(CODES) >= {"time_step", "displacement_outside_stroke", "flat_at_limit", "run_spool", "run_drive",
                          "run_stroke"}
    for code, (level, why) in CODES.items():
        assert level in ("error", "warning") and why, code
    c = Check("flat_at_limit", "f.csv", "force", "m", {"a": 1.0})
    assert c.to_dict()["level"] == "warning" and c.line() == "f.csv: [flat_at_limit] m"
