"""An MR damper's field law identified across records at different currents (issue 25, item 1):
the core's law (the thesis' against an independent transcription), the multi-record fit of a
known law from simulated records and its prediction at a third current against the simulator's
truth, the bad input, and the UTFSM acceptance (0.5 A held out, no worse than the thesis)."""

from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy import signal
from shared_data import shared_path
from spencer_oracle import spencer_force_rk4

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.identification import baselines, generic, law

DT = 1e-3
ROOT = Path(__file__).resolve().parents[2]


# ---- the law in the core ------------------------------------------------------------------------


def thesis_rig(current: float) -> sh.Rig:
    """The thesis' whole current law (``baselines.thesis_law_keys``) at ``current`` [A]."""
    rig = sh.rig_from_dict({"specimen": {**baselines.thesis_law_keys(), "mr_current": current}})
    rig.effects.mr_damper = True
    return rig


@pytest.mark.parametrize("current", [0.0, 0.25, 0.5, 0.8, 1.0])
def test_thesis_law_values_follow_the_thesis(current):
    """The core's law (``mr_damper_law``, mr_law = quiroz2022 in the current) equals the thesis'
    current-dependent parameters (``baselines.thesis_mr_parameters``, the README's forms) in SI."""
    v = _core.mr_damper_law(thesis_rig(current))
    p = baselines.thesis_mr_parameters(current)
    assert v["u"] == current
    for key, expected in (("alpha", 1e3 * p.alpha), ("c0", 1e3 * p.c0), ("c1", 1e3 * p.c1),
                          ("beta", 1e6 * p.beta), ("gamma", 1e6 * p.gamma)):
        assert v[key] == pytest.approx(expected, rel=1e-13), key


@pytest.mark.parametrize("current", [0.0, 0.5, 1.0])
def test_thesis_law_element_matches_an_independent_transcription(current):
    """The core's MR element under the thesis' law at a current, driven by a motion (the kinematic
    driver, RK4), against the NumPy transcription of the thesis' equations (spencer_oracle.py, in
    N, mm, s, at ``thesis_mr_parameters(current)``) and against ``baselines.spencer_force`` (the
    element at the same parameters folded into Spencer's constant terms): to 1e-9 of the peak."""
    t = np.arange(3001) * DT
    x = 2e-3 * signal.chirp(t, 0.5, t[-1], 12.0) * np.minimum(t / 0.3, 1.0)
    v = np.gradient(x, DT)
    dyn = _core.Dynamics(thesis_rig(current), _core.ControlMode.Free)
    core = dyn.specimen_forces(x, v, DT, 10)
    p = baselines.thesis_mr_parameters(current)
    oracle = spencer_force_rk4(x, v, DT, p, substeps=10)
    scale = np.max(np.abs(oracle))
    assert scale > 100.0
    assert np.max(np.abs(core - oracle)) < 1e-9 * scale
    folded = baselines.spencer_force(x, DT, p, cutoff_hz=1e9)  # no smoothing: the same x and v
    assert np.max(np.abs(core - folded)) < 1e-9 * scale


def test_spencer_law_in_volts_is_unchanged_and_in_amperes_the_same():
    """Spencer's linear law reads the voltage by default; the same coefficients read from a current
    give the same parameters (the field input only names the unit)."""
    r = sh.zhao2003()
    r.mr_voltage = 1.5
    v = _core.mr_damper_law(r)
    assert v["alpha"] == r.mr_alpha_a + r.mr_alpha_b * 1.5 and v["beta"] == r.mr_beta
    a = sh.zhao2003()
    a.mr_input, a.mr_current = law.MR_INPUTS["current"], 1.5
    a.validate()
    assert _core.mr_damper_law(a) == v


@pytest.mark.parametrize(("change", "message"), [
    (dict(mr_current=0.5), r"invalid mr_current = 0.5: must be 0 when mr_input = \"voltage\""),
    (dict(mr_input="current", mr_voltage=1.0), r"invalid mr_voltage = 1: must be 0 when mr_input = \"current\""),
    (dict(mr_alpha_c=-5.0), r"invalid mr_alpha_c = -5: must be 0 under mr_law = \"spencer\""),
    (dict(mr_bw_decay=1.0), r"invalid mr_bw_decay = 1: must be 0 under mr_law = \"spencer\""),
    (dict(mr_law_min=2.0, mr_law_max=1.0), r"invalid mr_law_min = 2: must be <= mr_law_max = 1"),
    (dict(mr_law="quiroz2022", mr_voltage=2.0, mr_alpha_c=-1e5),
     r"invalid mr_alpha_c = -100000: gives alpha = .* at the field input u = 2 V \(mr_law = \"quiroz2022\"\)"),
    (dict(mr_law="quiroz2022", mr_voltage=1.0, mr_bw_decay=-1e3), r"invalid mr_bw_decay = -1000: gives beta = inf"),
    (dict(mr_current=math.nan), r"invalid specimen.mr_current = nan"),
    (dict(mr_input="amperes"), r"invalid specimen.mr_input = 'amperes': expected one of \['voltage', 'current'\]"),
    (dict(mr_law=2), r"invalid specimen.mr_law = 2: expected one of \['spencer', 'quiroz2022'\]"),
])
def test_bad_law_keys_name_the_field(change, message):
    with pytest.raises(ValueError, match=message):
        sh.rig_from_dict({"specimen": change})


def test_rig_file_round_trip_of_the_law(tmp_path):
    rig = thesis_rig(0.5)
    back = sh.load_rig(sh.save_rig(rig, tmp_path / "rig.toml"))
    assert back == rig
    text = (tmp_path / "rig.toml").read_text()
    assert 'mr_input = "current"' in text and 'mr_law = "quiroz2022"' in text


def test_extrapolation_is_reported():
    """A run outside the range the law was identified on says so (Response.warnings)."""
    rig = copy.copy(thesis_rig(0.5))
    rig.A = 1e-3  # a strong actuator for the damper
    u = 1e-3 * np.sin(2 * np.pi * 2.0 * np.arange(400) * DT)
    assert not any("extrapolates" in w for w in sh.simulate(rig, "displacement", command=u, dt=DT).warnings())
    rig.mr_current = 1.2  # (the thesis' quadratic alpha turns negative above 1.36 A: an error, not a run)
    w = sh.simulate(rig, "displacement", command=u, dt=DT).warnings()
    assert any("MR damper current 1.2 A is outside the range its law was identified on (0 ... 1 A" in x for x in w)


# ---- identification of a known law from simulated records ------------------------------------------

TRUTH = {"mr_alpha_a": 2.0e4, "mr_alpha_b": 4.0e4, "mr_c0_a": 1.0e3, "mr_c0_b": 4.0e3, "mr_c1_a": 1.0e4,
         "mr_c1_b": 6.0e4}


def chirp(duration=5.0, f1=8.0, amp=2e-3):
    t = np.arange(int(round(duration / DT)) + 1) * DT
    return t, amp * signal.chirp(t, 0.3, t[-1], f1) * np.minimum(t / 0.5, 1.0)


def truth_rig() -> sh.Rig:
    """A small lab actuator (the generic rig of a +-2 mm, 1 kN record) with an MR damper whose
    Spencer law in the coil current is known."""
    t, u = chirp()
    scale = sh.Response({"time": t, "command": u, "displacement": u, "force": 1e3 * u / 2e-3})
    r = generic.generic_rig(scale)
    r.effects.mr_damper = True
    r.effects.load_pressure = False
    r.k, r.c, r.m = 1.0, 0.0, 2.0
    r.mr_input = law.MR_INPUTS["current"]
    for k, v in TRUTH.items():
        setattr(r, k, v)
    r.mr_A, r.mr_n, r.mr_beta, r.mr_gamma, r.mr_k0, r.mr_k1, r.mr_x0 = 300.0, 2.0, 3.0e6, 3.0e6, 0.0, 1.0e3, 0.0
    r.mr_law_min, r.mr_law_max = 0.0, 1.0
    r.validate()
    return r


def record_at(rig: sh.Rig, current: float, seed: int) -> sh.Response:
    """The truth simulated (CVODE, rtol 1e-8) at ``current``, noise 3 um and 1 % of the force's std."""
    t, u = chirp()
    r = copy.copy(rig)
    r.mr_current = current
    sim = sh.simulate(r, "displacement", command=u, dt=DT, options=sh.solver_options(method="cvode", rtol=1e-8))
    rng = np.random.default_rng(seed)
    return sh.Response({"time": t, "command": u, "displacement": sim.displacement + 3e-6 * rng.standard_normal(t.size),
                        "force": sim.force + 0.01 * np.std(sim.force) * rng.standard_normal(t.size)})


def test_identifies_a_known_current_law_and_predicts_a_third_current():
    """Records at 0 A and 1 A of a known Spencer law; the start 30-50 % off the law's keys; the
    joint fit recovers alpha_a, alpha_b, c0_a, c0_b within their 95 % intervals (or 3 %), and the
    identified rig predicts a record at 0.5 A (no record fitted there) to the noise's level
    against the simulator's truth."""
    truth = truth_rig()
    recs = [record_at(truth, 0.0, 1), record_at(truth, 1.0, 2)]
    start = copy.copy(truth)
    for k, f in zip(TRUTH, (1.4, 0.6, 1.5, 0.7, 1.3, 0.65)):
        setattr(start, k, TRUTH[k] * f)
    start.G_p *= 1.2
    fit = ["G_p", *TRUTH]
    ident = sh.identify(recs, rig=start, fit=fit, mode="displacement", currents=[0.0, 1.0], progress=False)
    assert ident.field_input.values == (0.0, 1.0) and ident.law == "spencer"
    assert ident.rig.mr_law_min == 0.0 and ident.rig.mr_law_max == 1.0
    d = ident.to_dict()
    assert d["field"] == {"input": "current", "unit": "A", "values": [0.0, 1.0], "range": [0.0, 1.0], "law": "spencer"}
    assert [r["current"] for r in d["records"]] == [0.0, 1.0]
    assert "fitted across the records at currents 0, 1 A" in ident.markdown()
    for k in ("mr_alpha_a", "mr_alpha_b", "mr_c0_a", "mr_c0_b"):
        lo, hi = ident.intervals[k]
        v = TRUTH[k]
        assert lo <= v <= hi or abs(ident.values[k] / v - 1) < 0.03, (k, v, ident.values[k], (lo, hi))
    for a in ident.after:
        assert a.nrmse("force") < 2.0
    held = record_at(truth, 0.5, 3)
    c = sh.identification.compare(held, ident.rig, "displacement", current=0.5)
    assert c.nrmse("force") < 2.0 and c.nrmse("displacement") < 1.0
    assert not any("extrapolates" in w for w in c.warnings)
    # without the law (the 0 A rig at its own current), the 0.5 A force is far off: the test can fail
    zero = copy.copy(ident.rig)
    zero.mr_alpha_b = zero.mr_c0_b = zero.mr_c1_b = 0.0
    assert sh.identification.compare(held, zero, "displacement", current=0.5).nrmse("force") > 20.0
    # outside the identified range: the prediction says it extrapolates
    far = sh.identification.compare(held, ident.rig, "displacement", current=1.5)
    assert any("extrapolates" in w for w in far.warnings)


def voltage_truth() -> sh.Rig:
    """The truth rig with its law in the coil voltage [V] (the same coefficients, per volt)."""
    truth = truth_rig()
    truth.mr_input, truth.mr_current = law.MR_INPUTS["voltage"], 0.0
    return truth


@pytest.fixture(scope="module")
def voltage_records():
    """The voltage truth simulated (CVODE, rtol 1e-8, no noise) at 0 V and 2 V, the 5 s chirps."""
    truth, recs = voltage_truth(), []
    for volts in (0.0, 2.0):
        r = copy.copy(truth)
        r.mr_voltage = volts
        t, u = chirp()
        sim = sh.simulate(r, "displacement", command=u, dt=DT, options=sh.solver_options(method="cvode", rtol=1e-8))
        recs.append(sh.Response({"time": t, "command": u, "displacement": sim.displacement, "force": sim.force}))
    return recs


def test_voltage_driven_records_run_at_their_own_voltage(voltage_records):
    """``voltages=``: the rig's field input becomes the voltage, each record runs at its own (the
    truth as the start reproduces both records to the noise, one short fit step), and the law's
    range is the records'."""
    truth, recs = voltage_truth(), voltage_records
    ident = sh.identify(recs, rig=truth, fit=["mr_alpha_b"], mode="displacement", voltages=[0, 2], max_nfev=1,
                        frequency_stage=False, progress=False)
    assert law.rig_field(ident.rig)[0] == "voltage" and (ident.rig.mr_law_min, ident.rig.mr_law_max) == (0.0, 2.0)
    assert [a.nrmse("force") for a in ident.before] == pytest.approx([0.0, 0.0], abs=0.05)
    # the same records at the wrong voltage are far off: the field per record is what runs
    wrong = sh.identification.compare(recs[1], truth, "displacement", voltage=0.0)
    assert wrong.nrmse("force") > 20.0


def test_law_keys_follow_the_field_levels():
    keys, notes = law.law_keys("spencer", 2)
    assert keys == ("mr_alpha_a", "mr_alpha_b", "mr_c0_a", "mr_c0_b", "mr_c1_a", "mr_c1_b", *law.FIELD_FREE_KEYS)
    assert not notes
    keys, notes = law.law_keys("quiroz2022", 2)
    assert "mr_bw_decay" in keys and "mr_alpha_c" not in keys and any("mr_alpha_c is held" in n for n in notes)
    assert "mr_alpha_c" in law.law_keys("quiroz2022", 3)[0]
    keys, notes = law.law_keys("spencer", 1)
    assert "mr_alpha_b" not in keys and notes


# ---- bad input -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def two_records():
    truth = truth_rig()
    return [record_at(truth, 0.0, 1), record_at(truth, 1.0, 2)]


@pytest.mark.parametrize(("kwargs", "message"), [
    (dict(currents=[0.0]), r"invalid currents = \[0.0\]: 1 value\(s\) for 2 record\(s\)"),
    (dict(currents=[0.0, -1.0]), r"invalid current of record 2 = -1.0: must be finite and >= 0"),
    (dict(currents=[0.0, "one"]), r"invalid current of record 2 = 'one': expected a number"),
    (dict(currents=[0.0, math.inf]), r"invalid current of record 2 = inf"),
    (dict(currents=[math.nan, 1.0]), r"invalid current of record 1 = nan: must be finite and >= 0"),
    (dict(voltages=[0.0]), r"invalid voltages = \[0.0\]: 1 value\(s\) for 2 record\(s\)"),
    (dict(voltages=[0.0, -2.0]), r"invalid voltage of record 2 = -2.0: must be finite and >= 0"),
    (dict(currents=[0, 1], voltages=[0, 1]), r"currents and voltages both given"),
    (dict(currents=[0, 1], specimen="bouc_wen"), r"invalid specimen = 'bouc_wen' with currents"),
    (dict(law="quiroz2022"), r"invalid law = 'quiroz2022': a field law needs the records' field values"),
    (dict(currents=[0, 1], law="cubic"), r"invalid law = 'cubic'"),
])
def test_identify_bad_field_input(two_records, kwargs, message):
    with pytest.raises(ValueError, match=message):
        sh.identify(two_records, mode="displacement", progress=False, **kwargs)


def test_compare_bad_field_input(two_records):
    rig = truth_rig()
    rec = two_records[0]
    with pytest.raises(ValueError, match=r"invalid --voltage = 1.0: the rig's MR damper law reads a current"):
        sh.identification.compare(rec, rig, "displacement", voltage=1.0)
    with pytest.raises(ValueError, match=r"invalid --current = -0.5: must be finite and >= 0"):
        sh.identification.compare(rec, rig, "displacement", current=-0.5)
    plain = copy.copy(rig)
    plain.effects.mr_damper = False
    with pytest.raises(ValueError, match=r"invalid --current = 0.5: the rig has no MR damper"):
        sh.identification.compare(rec, plain, "displacement", current=0.5)
    with pytest.raises(ValueError, match=r"--current and --voltage both given"):
        sh.identification.compare(rec, rig, "displacement", current=0.5, voltage=1.0)


def _cli(capsys, *argv) -> tuple[int, str, str]:
    from servohydraulics.cli import main

    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize(("flags", "message"), [
    (("--current", "0"), r"error: invalid currents = \[0.0\]: 1 value\(s\) for 2 record\(s\) \(r0.csv, r1.csv\)"),
    (("--current", "0,-1"), r"error: invalid --current value 2 = '-1': must be finite and >= 0"),
    (("--current", "0,x"), r"error: invalid --current value 2 = 'x': expected a number"),
    (("--current", "0,,1"), r"error: invalid --current = '0,,1': expected comma-separated numbers"),
    (("--current", "0,1", "--voltage", "0,1"), r"error: invalid --current and --voltage together"),
    (("--current", "0,nan"), r"error: invalid --current value 2 = 'nan': must be finite and >= 0"),
    (("--voltage", "0,1,2"), r"error: invalid voltages = \[0.0, 1.0, 2.0\]: 3 value\(s\) for 2 record\(s\)"),
    (("--voltage", "0,-2"), r"error: invalid --voltage value 2 = '-2': must be finite and >= 0"),
    (("--voltage", "one,2"), r"error: invalid --voltage value 1 = 'one': expected a number"),
])
def test_cli_identify_bad_field_input(tmp_path, capsys, two_records, flags, message):
    paths = [r.to_csv(tmp_path / f"r{i}.csv") for i, r in enumerate(two_records)]
    out = tmp_path / "out"
    code, _, err = _cli(capsys, "identify", *paths, "--mode", "displacement", *flags, "--out", out, "--quiet")
    assert code == 2, err
    assert "Traceback" not in err
    assert re.search(message, err), err
    assert not out.exists()


def test_cli_compare_field_input(tmp_path, capsys, two_records):
    """``compare --current`` predicts at the current (an extrapolation is a warning, in the JSON as
    well); a rig without the damper, a negative current, both flags: error, exit 2, nothing written."""
    rig = truth_rig()
    rig_path = sh.save_rig(rig, tmp_path / "rig.toml")
    rec = two_records[1].to_csv(tmp_path / "rec.csv")
    out = tmp_path / "cmp"
    code, _, err = _cli(capsys, "compare", rec, "--rig", rig_path, "--mode", "displacement", "--current", "1.5",
                        "--out", out)
    assert code == 0, err
    assert "[run_mr_law] simulated run: MR damper current 1.5 A is outside the range its law was identified on " \
        "(0 ... 1 A" in err
    assert any("extrapolates" in w for w in json.loads((out / "comparison.json").read_text())["warnings"])
    plain = copy.copy(rig)
    plain.effects.mr_damper = False
    plain_path = sh.save_rig(plain, tmp_path / "plain.toml")
    for rig_file, flags, message in ((plain_path, ("--current", "0.5"), "the rig has no MR damper"),
                                     (rig_path, ("--current", "-1"), "invalid --current = '-1': must be finite"),
                                     (rig_path, ("--voltage", "1"), "the rig's MR damper law reads a current"),
                                     (rig_path, ("--current", "1", "--voltage", "1"), "--current and --voltage")):
        bad = tmp_path / "bad"
        code, _, err = _cli(capsys, "compare", rec, "--rig", rig_file, "--mode", "displacement", *flags, "--out", bad)
        assert code == 2 and message in err and "Traceback" not in err, err
        assert not bad.exists()


def test_cli_identify_and_compare_by_voltage(tmp_path, capsys, voltage_records):
    """``identify --voltage 0,2`` then ``compare --voltage 1``: the identified rig reads a voltage
    over 0 ... 2 V, and predicts a third voltage's record (the truth simulated at 1 V) to the
    truth's own accuracy; ``--current`` against that rig is refused (exit 2, nothing written)."""
    truth = voltage_truth()
    start = sh.save_rig(truth, tmp_path / "start.toml")
    paths = [r.to_csv(tmp_path / f"v{i}.csv") for i, r in enumerate(voltage_records)]
    out = tmp_path / "law"
    code, _, err = _cli(capsys, "identify", *paths, "--mode", "displacement", "--voltage", "0,2", "--rig", start,
                        "--fit", "mr_alpha_b", "--max-nfev", "1", "--out", out, "--quiet")
    assert code == 0, err
    rig = sh.load_rig(out / "rig_identified.toml")
    assert law.rig_field(rig)[0] == "voltage" and (rig.mr_law_min, rig.mr_law_max) == (0.0, 2.0)
    assert json.loads((out / "identification.json").read_text())["field"]["values"] == [0.0, 2.0]
    at_one = copy.copy(truth)
    at_one.mr_voltage = 1.0
    t, u = chirp()
    sim = sh.simulate(at_one, "displacement", command=u, dt=DT, options=sh.solver_options(method="cvode", rtol=1e-8))
    rec = sh.Response({"time": t, "command": u, "displacement": sim.displacement, "force": sim.force})
    rec_path = rec.to_csv(tmp_path / "v_half.csv")
    code, _, err = _cli(capsys, "compare", rec_path, "--rig", out / "rig_identified.toml", "--mode", "displacement",
                        "--voltage", "1", "--out", tmp_path / "cmp")
    assert code == 0, err
    c = json.loads((tmp_path / "cmp" / "comparison.json").read_text())
    assert c["channels"]["force"]["nrmse_pct"] < 2.0 and not any("extrapolates" in w for w in c["warnings"]), c
    assert c["field"] == {"input": "voltage", "value": 1.0, "unit": "V", "law": "spencer", "given": True}
    # the same record at 0 V (what a forgotten --voltage would give) is far off: the flag is what runs
    code, _, err = _cli(capsys, "compare", rec_path, "--rig", out / "rig_identified.toml", "--mode", "displacement",
                        "--voltage", "0", "--out", tmp_path / "cmp0")
    zero = json.loads((tmp_path / "cmp0" / "comparison.json").read_text())
    assert code == 0 and zero["channels"]["force"]["nrmse_pct"] > 20.0, err
    code, _, err = _cli(capsys, "compare", rec_path, "--rig", out / "rig_identified.toml", "--mode", "displacement",
                        "--current", "1", "--out", tmp_path / "bad")
    assert code == 2 and "the rig's MR damper law reads a voltage" in err and "Traceback" not in err, err
    assert not (tmp_path / "bad").exists()


# ---- the UTFSM records: 0 A + 1 A -> the held-out 0.5 A sweep --------------------------------------

UTFSM = "real-data/utfsm-mts-mrdamper"


def _thesis_on_half_amp(rec):
    from servohydraulics.identification import nrmse_pct

    x = baselines.thesis_displacement(rec.time, rec.command)
    f = baselines.thesis_mr_force(rec.displacement, rec.dt, 0.5)
    return nrmse_pct(x, rec.displacement), nrmse_pct(f, rec.force)


@pytest.mark.parametrize("law_name", [
    "spencer",
    pytest.param("quiroz2022", marks=pytest.mark.xfail(strict=True, reason=(
        "known loss on the force (docs/lab-records.md): from two currents the thesis' law makes the yield force "
        "alpha(i) sqrt(A / gamma(i)) convex in i (linear alpha, exponential gamma; alpha's curvature needs a "
        "third current), 1.6 times too weak at 0.5 A"))),
])
def test_utfsm_half_amp_predicted_no_worse_than_the_thesis(law_name):
    """The committed rig identified on the May 0 A and 1 A sweeps (evaluation/utfsm_current_law.py)
    predicts the held-out 0.5 A sweep from its command alone no worse than the thesis' models on
    that record (its G(s) from the command, its Bouc-Wen from the measured displacement).  The
    thesis' law loses on the force (a strict xfail: a win fails until the table is updated)."""
    from servohydraulics.identification import compare, simulate_record
    from servohydraulics.identification.fit import fit_options

    rec = sh.read_record(shared_path(f"{UTFSM}/sweep15Hz_0p5A.csv"))
    rig = law.predict_at(sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"law_may_{law_name}.toml"), current=0.5)
    c = compare(rec, rig, "displacement",
                simulated=simulate_record(rig, rec, "displacement", options=fit_options(rig, [rec], "displacement")))
    thesis_x, thesis_f = _thesis_on_half_amp(rec)
    assert (rig.mr_law_min, rig.mr_law_max) == (0.0, 1.0) and not c.warnings  # 0.5 A: inside the fitted range
    assert c.nrmse("displacement") <= thesis_x, (c.nrmse("displacement"), thesis_x)
    assert c.nrmse("force") <= thesis_f, (c.nrmse("force"), thesis_f)


@pytest.mark.slow
def test_utfsm_identify_on_zero_and_one_amp_predicts_half_amp():
    """The whole workflow from the records (a few minutes): identify on the May 0 A and 1 A sweeps
    together (generic start, Spencer's law), predict the 0.5 A sweep at --current 0.5."""
    recs = [sh.read_record(shared_path(f"{UTFSM}/sweep15Hz_{n}.csv")) for n in ("0A", "1A")]
    ident = sh.identify(recs, mode="displacement", currents=[0.0, 1.0], progress=False)
    rec = sh.read_record(shared_path(f"{UTFSM}/sweep15Hz_0p5A.csv"))
    c = sh.identification.compare(rec, ident.rig, "displacement", current=0.5,
                                  options=sh.solver_options(method="dopri5", rtol=1e-6))
    thesis_x, thesis_f = _thesis_on_half_amp(rec)
    assert c.nrmse("displacement") <= thesis_x and c.nrmse("force") <= thesis_f
