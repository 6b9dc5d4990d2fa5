"""Diagnose: the contract (API, CLI, files, JSON) and hidden-effect cases end to end.

Records are made by the independent plain-Python simulator of the evaluation
(evaluation/diagnose_eval/independent_plant.py), not by the core the workflow uses,
with measurement noise; the workflow sees only the record, mode and nominal rig.
The full evaluation (many records, graded strengths, other forms) is
evaluation/diagnose_eval/evaluate.py, reported in docs/diagnose_eval.md.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics.cli import main
from servohydraulics.diagnosis import NAMES, engine
from servohydraulics.records import Record

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "evaluation" / "diagnose_eval"))
import independent_plant as ip  # noqa: E402

DT = 5e-4


def _noisy(ch: dict, snr_db: float, seed: int, free: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    rec = {"time": ch["time"], "command": ch["command"]}
    for c in ("displacement", "force"):
        y = ch[c]
        rms = float(np.sqrt(np.mean(y ** 2)))
        rec[c] = y + (0 if (free and c == "force") else rng.normal(0, rms * 10 ** (-snr_db / 20), y.size))
    return rec


def _free_rig() -> sh.Rig:
    rig = sh.zhao2003(actuator_attached=False)
    rig.effects.coulomb_friction = False
    return rig


def _linear_rig() -> sh.Rig:
    rig = sh.zhao2003()
    for e in ("coulomb_friction", "spring_softening", "load_pressure", "flow_nonlinearity"):
        setattr(rig.effects, e, False)
    return rig


def _free_record(F_c: float, seed: int = 1) -> dict:
    n = int(3.0 / DT) + 1
    tr = replace(ip.Truth(c=1.1e3), friction="coulomb" if F_c > 0 else "none", F_c=F_c)
    ch = ip.simulate(tr, "free", np.zeros(n), DT, x0=0.013, substeps=4)
    return _noisy(ch, 30, seed, free=True)


def _displacement_record(seed: int = 2, snr: float = 30, duration: float = 2.0, **truth) -> dict:
    t = np.arange(int(duration / DT) + 1) * DT
    u = np.minimum(t / 0.25, 1) * (0.02 * np.sin(2 * np.pi * 0.8 * t) + 0.004 * np.sin(2 * np.pi * (1 + t) * t))
    ch = ip.simulate(replace(ip.Truth(), **truth), "displacement", u, DT, substeps=4)
    return _noisy(ch, snr, seed)


@pytest.fixture(scope="module")
def free_friction(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("rec") / "free.csv"
    sh.write_record(path, _free_record(95.7))
    return path


def test_free_vibration_friction_is_named_and_fitted(free_friction: Path, tmp_path: Path) -> None:
    """Fig 2(b): free vibration from 1.3 cm, friction 95.7 N hidden; the model
    has only viscous damping.  coulomb_friction must be named, F_c within 20 %,
    the gap must close to near the noise floor, and the files must follow the contract."""
    d = sh.diagnose([free_friction], _free_rig(), mode="free", progress=False)
    assert d.verdict == "effect_found"
    assert d.effects[0]["name"] == "coulomb_friction"
    p = d.effects[0]["parameters"]["F_c"]
    assert p["unit"] == "N"
    assert abs(p["value"] - 95.7) / 95.7 < 0.2
    assert p["interval_95"][0] < p["value"] < p["interval_95"][1]
    assert p["interval_95"][0] > 0.0  # excludes "absent"
    assert d.gap_after["displacement"] < 0.5 * d.gap_before["displacement"]
    assert d.gap_after["displacement"] < 1.3 * d.noise_floor["displacement"]
    assert d.rig.effects.coulomb_friction and abs(d.rig.F_c - p["value"]) < 1e-9

    d.write(tmp_path)
    js = json.loads((tmp_path / "diagnosis.json").read_text())
    for k in ("verdict", "effects", "gap_before", "gap_after", "candidates"):
        assert k in js
    assert {c["name"] for c in js["candidates"]} == set(NAMES)
    for c in js["candidates"]:
        assert "score" in c and "rejection" in c
        assert c["accepted"] == (c["rejection"] is None)
    assert js["effects"][0]["parameters"]["F_c"]["interval_95"][0] is not None
    rig = sh.load_rig(tmp_path / "rig_updated.toml")
    assert rig.effects.coulomb_friction and rig.F_c == pytest.approx(p["value"])
    report = (tmp_path / "report.md").read_text()
    assert "coulomb_friction" in report and "| share closed |" in report
    accepted = next(c for c in js["candidates"] if c["accepted"])
    assert accepted["share_closed"] > 0.5  # the friction closes most of the free vibration's gap
    for png in ("residual_before_after.png", "signature.png", "gap_closing.png"):
        assert (tmp_path / png).stat().st_size > 1000


def test_flow_gain_nonlinearity_hidden_in_displacement_record() -> None:
    """A rational flow curve with b = 1.5 hidden (the model's flow gain is linear):
    the library's family (knee x_k, full-opening flow ratio g_1) contains it at
    x_k = 0, g_1 = 1 / (1 + b) = 0.4."""
    rec = Record({k: np.asarray(v) for k, v in _displacement_record(flow="rational", b=1.5).items()})
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "effect_found"
    assert d.effects[0]["name"] == "flow_gain_nonlinearity"
    p = d.effects[0]["parameters"]["g_1"]
    assert p["unit"] == "-"
    assert abs(p["value"] - 1 / 2.5) / 0.4 < 0.2
    assert d.gap_after["force"] < 0.5 * d.gap_before["force"]


def test_lugre_friction_is_named_with_its_presliding_stiffness() -> None:
    """LuGre friction (bristle stiffness 5e5 N/m: 0.5 mm of presliding travel, and a
    Stribeck peak F_s = 1.3 F_c the library's LuGre does not have) hidden in a
    displacement record: named lugre_friction, sigma_0 and the sliding level F_c
    within 20 %, and Coulomb friction, the same F_c, not screened after it.  The same
    record with Coulomb friction is named coulomb_friction: lugre_friction nests it
    (sigma_0 -> infinity) and the BIC prefers the simpler law, never "ambiguous"."""
    rec = Record({k: np.asarray(v) for k, v in _displacement_record(
        friction="lugre", F_c=250.0, F_s=325.0, v_s=0.01, sigma_0=5e5).items()})
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "effect_found"
    assert d.effects[0]["name"] == "lugre_friction"
    p = d.effects[0]["parameters"]
    assert p["sigma_0"]["unit"] == "N/m" and abs(p["sigma_0"]["value"] - 5e5) / 5e5 < 0.2
    assert abs(p["F_c"]["value"] - 250.0) / 250.0 < 0.2
    assert d.rig.effects.lugre_friction and d.rig.sigma_0 == pytest.approx(p["sigma_0"]["value"])
    # after it, coulomb_friction (its limit, the same F_c) is not screened again: a re-fit of an added parameter
    later = [c for c in d.candidates if c.name == "coulomb_friction" and c.round > 1]
    assert later and all(c.rejection.startswith("already in the model: a limit of lugre_friction")
                         and c.screening_score is None and c.delta_bic is None for c in later)

    rec = Record({k: np.asarray(v) for k, v in _displacement_record(friction="coulomb", F_c=250.0).items()})
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "effect_found"
    assert d.effects[0]["name"] == "coulomb_friction"
    assert not d.rig.effects.lugre_friction


def test_weak_effect_under_the_noise_floor_is_found_at_20db() -> None:
    """150 N of Coulomb friction at SNR 20 dB changes the force by less than the
    noise floor's own uncertainty (the nominal residual passes the noise-floor test:
    a square wave of 150 N under about 1.6 kN of noise), yet its structured signature
    is significant (about n (F_c / sigma)^2 in -2 log L): named, F_c within 20 %.  The
    same noise on a record with nothing hidden gives no_effect."""
    rec = Record({k: np.asarray(v) for k, v in _displacement_record(
        snr=20, duration=4.0, friction="coulomb", F_c=150.0).items()})
    case = engine.make_case(rec, "displacement", "weak")
    stats = engine.channel_stats(engine.simulate_all(_linear_rig(), [case], 0.0, [case.x0_data]), [case])
    assert engine.at_noise_floor(stats)  # the variance test alone cannot see it
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "effect_found"
    assert d.effects[0]["name"] == "coulomb_friction"
    assert abs(d.effects[0]["parameters"]["F_c"]["value"] - 150.0) / 150.0 < 0.2

    rec = Record({k: np.asarray(v) for k, v in _displacement_record(snr=20, duration=4.0, seed=9).items()})
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "no_effect"


@pytest.mark.slow  # minutes: excluded from scripts/run.sh test, run by scripts/run.sh test-all
def test_record_logged_one_sample_late_is_an_alignment_not_an_effect() -> None:
    """A lab whose acquisition logs each response sample one sample later than the
    record convention (row k sampled before command k is sent) makes the response
    lead the command by dt.  Without a negative delay in the library that reads as
    a valve, piston mass and friction together; it must be named command_delay with
    tau = -dt and a note about the acquisition's alignment.  The opposite shift is a
    plain +dt delay."""
    base = _displacement_record(snr=40, duration=3.0, seed=4)
    for shift in (1, -1):
        rec = dict(base)
        for c in ("displacement", "force"):
            y = np.asarray(rec[c])
            rec[c] = np.concatenate([y[1:], y[-1:]]) if shift == 1 else np.concatenate([y[:1], y[:-1]])
        d = sh.diagnose(Record({k: np.asarray(v) for k, v in rec.items()}), _linear_rig(), mode="displacement",
                        progress=False)
        assert [e["name"] for e in d.effects] == ["command_delay"]
        tau = d.effects[0]["parameters"]["command_delay"]["value"]
        assert abs(tau - (-DT if shift == 1 else DT)) < 0.05 * DT
        assert ("alignment" in d.effects[0]["note"]) == (shift == 1)


def test_no_effect_record_gives_no_effect() -> None:
    rec = Record({k: np.asarray(v) for k, v in _displacement_record(seed=5).items()})
    d = sh.diagnose(rec, _linear_rig(), mode="displacement", progress=False)
    assert d.verdict == "no_effect"
    assert d.effects == []
    assert d.gap_after == d.gap_before


def test_cli_end_to_end(free_friction: Path, tmp_path: Path, capsys) -> None:
    rig = tmp_path / "nominal.toml"
    sh.save_rig(_free_rig(), rig)
    out = tmp_path / "out"
    rc = main(["diagnose", str(free_friction), "--rig", str(rig), "--mode", "free", "--out", str(out), "--quiet"])
    assert rc == 0
    assert "coulomb_friction" in capsys.readouterr().out
    js = json.loads((out / "diagnosis.json").read_text())
    assert js["verdict"] == "effect_found" and js["effects"][0]["name"] == "coulomb_friction"


def test_csv_errors(tmp_path: Path, capsys) -> None:
    rig = tmp_path / "nominal.toml"
    sh.save_rig(_free_rig(), rig)
    bad = tmp_path / "nonuniform.csv"
    bad.write_text("time,command,displacement,force\n0,0,0.01,0\n0.0005,0,0.01,0\n0.0015,0,0.01,0\n"
                   "0.002,0,0.01,0\n")
    rc = main(["diagnose", str(bad), "--rig", str(rig), "--mode", "free", "--out", str(tmp_path / "o"), "--quiet"])
    assert rc == 2
    assert "uniform" in capsys.readouterr().err
    missing = tmp_path / "missing.csv"
    missing.write_text("time,command,displacement\n0,0,0\n0.0005,0,0\n")
    with pytest.raises(ValueError, match="force"):
        sh.diagnose([missing], _free_rig(), mode="free", progress=False)
    with pytest.raises(FileNotFoundError):
        sh.diagnose([tmp_path / "nope.csv"], _free_rig(), mode="free", progress=False)
    ok = tmp_path / "ok.csv"
    sh.write_record(ok, _free_record(0.0))
    with pytest.raises(ValueError, match="mode"):
        sh.diagnose([ok], _free_rig(), mode="velocity", progress=False)
    with pytest.raises(ValueError, match="candidate"):
        sh.diagnose([ok], _free_rig(), mode="free", candidates=["magic"], progress=False)


@pytest.mark.slow  # minutes: excluded from scripts/run.sh test, run by scripts/run.sh test-all
def test_ambiguous_valve_or_leakage_then_resolved_by_a_sweep() -> None:
    """A slower servovalve (f_v = 50 Hz instead of the nominal 70.7 Hz) seen through one
    4 Hz, 2 mm sine at 20 dB: at a single frequency the valve's extra lag and a larger
    leakage coefficient perturb the loop alike (each fits the one amplitude ratio and
    phase per channel), so the two fits are within the ambiguity threshold and the
    report must say "ambiguous" naming both and a separating experiment.  A second
    record, a 1-15 Hz sweep, shows the valve's frequency dependence: it is then named,
    with f_v near the truth."""
    n = int(2.0 / DT)
    t = np.arange(n) * DT
    env = np.sin(0.5 * np.pi * np.minimum(t / 0.5, 1.0)) ** 2  # smooth start from rest
    tr = ip.Truth(f_v=50.0)
    sine = _noisy(ip.simulate(tr, "displacement", env * 0.002 * np.sin(2 * np.pi * 4.0 * t), DT, substeps=4), 20, 1)
    u2 = env * 0.0005 * np.sin(2 * np.pi * (1.0 * t + 0.5 * 14.0 / 2.0 * t ** 2))
    sweep = _noisy(ip.simulate(tr, "displacement", u2, DT, substeps=4), 20, 2)
    rig = _linear_rig()
    one = sh.diagnose([Record(sine)], rig, mode="displacement", progress=False)
    assert one.verdict == "ambiguous", one.summary
    assert set(one.ambiguous_between) == {"servovalve_dynamics", "leakage"}, one.ambiguous_between
    assert "servovalve_dynamics" in one.separating_experiment and "sweep" in one.separating_experiment
    assert one.to_dict()["ambiguous_between"] == one.ambiguous_between
    both = sh.diagnose([Record(sine), Record(sweep)], rig, mode="displacement", progress=False)
    assert both.verdict == "effect_found", both.summary
    assert both.effects[0]["name"] == "servovalve_dynamics"
    assert abs(both.effects[0]["parameters"]["f_v"]["value"] - 50.0) < 0.2 * 50.0
