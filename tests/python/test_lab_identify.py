"""Identification recovers known parameters from records the core simulates with a
known rig plus noise; its outputs, the generic start and the specimen table."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy import signal

import servohydraulics as sh
from servohydraulics import identification as lab
from servohydraulics.identification import coordinates as keys
from servohydraulics.identification import generic
from servohydraulics.rig import rig_to_dict

DT = 1e-3
TRUE = {"G_p": 0.9, "f_v": 60.0, "zeta_v": 0.8, "k": 2.0e4, "c": 4.0e3}


def chirp(duration=12.0, f1=15.0, amp=2e-3):
    t = np.arange(int(round(duration / DT)) + 1) * DT
    return t, amp * signal.chirp(t, 0.2, t[-1], f1) * np.minimum(t / 0.5, 1.0)


def truth_rig() -> sh.Rig:
    """A small lab actuator (the generic rig of a +-2 mm, 0.5 kN record) with known loop and specimen keys."""
    t, u = chirp()
    scale = sh.Response({"time": t, "command": u, "displacement": u, "force": 100 * u / 2e-3 + 1e4 * u})
    r = generic.generic_rig(scale)
    for k, v in TRUE.items():
        setattr(r, k, v)
    return r


def noisy_record(rig, seed=0, sigma_x=3e-6, sigma_f=3.0):
    t, u = chirp()
    sim = sh.simulate(rig, "displacement", command=u, dt=DT, options=sh.solver_options(rtol=1e-8))
    rng = np.random.default_rng(seed)
    return sh.Response({"time": t, "command": u,
                        "displacement": sim.displacement + sigma_x * rng.standard_normal(t.size),
                        "force": sim.force + sigma_f * rng.standard_normal(t.size)})


def test_recovers_known_rig_within_intervals():
    """Start 20-50 % off every key; each true value lies inside the reported 95 %
    interval or within 1 % (the RK4 fit of a CVODE record has a small model error)."""
    rig = truth_rig()
    rec = noisy_record(rig)
    start = copy.copy(rig)
    for k, f in zip(TRUE, (1.3, 0.7, 1.4, 0.6, 1.5)):
        setattr(start, k, TRUE[k] * f)
    ident = sh.identify([rec], rig=start, mode="displacement", progress=False)
    assert ident.keys == tuple(TRUE)
    for k, v in TRUE.items():
        lo, hi = ident.intervals[k]
        assert lo <= v <= hi or abs(ident.values[k] / v - 1) < 0.01, (k, v, ident.values[k], (lo, hi))
        assert lo <= ident.values[k] <= hi
    assert ident.after[0].nrmse("displacement") < 0.5  # the noise is 0.2 % of the record's std
    assert ident.after[0].nrmse("displacement") < ident.before[0].nrmse("displacement")


def test_unseparable_keys_are_flagged():
    """K_a and C_l of a stiff oil column barely change a slow displacement loop: the report says so."""
    rig = truth_rig()
    rec = noisy_record(rig, seed=3)
    ident = lab.identify(rec, rig=rig, fit=["G_p", "C_l"], channels=["displacement"], frequency_stage=False,
                         max_nfev=5, progress=False)
    assert any("C_l" in f for f in ident.flags)
    assert not any(f.startswith("G_p is poorly") for f in ident.flags)
    assert ident.correlation.shape == (2, 2)
    assert ident.correlation[0, 0] == pytest.approx(1.0)


def test_writes_rig_report_and_plots(tmp_path):
    rig = truth_rig()
    rec = noisy_record(rig, seed=1)
    path = tmp_path / "rec.csv"
    sh.write_record(path, rec)
    rig_path = sh.save_rig(rig, tmp_path / "start.toml")
    from servohydraulics.cli import main

    assert main(["identify", str(path), "--mode", "displacement", "--rig", str(rig_path), "--fit", "G_p,c",
                 "--max-nfev", "8", "--quiet", "--out", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    for name in ("rig_identified.toml", "identification.json", "report.md", "overlay_rec.png", "frf_rec.png"):
        assert (out / name).stat().st_size > 0, name
    back = sh.load_rig(out / "rig_identified.toml")
    assert back.G_p == pytest.approx(TRUE["G_p"], rel=0.02)
    assert "95 % interval" in (out / "report.md").read_text()


def test_generic_rig_follows_its_documented_scaling():
    """The generic start: A = F_cap / p_s, C_F = 10 V / stroke, stroke = 5 x_pk, and the loop's
    closed-loop corner G_p C_F K_s K_v / A = 2 pi max(f_99 / 2, 1 Hz)."""
    t, u = chirp(f1=10.0)
    f = 300.0 * np.sin(np.arange(t.size) * 0.01)
    rec = sh.Response({"time": t, "command": u, "displacement": u, "force": f})
    r = generic.generic_rig(rec)
    s = generic.record_scales(rec)
    assert r.F_cap == pytest.approx(10 * 300.0, rel=1e-3)
    assert r.A == pytest.approx(r.F_cap / 21e6)
    assert r.stroke == pytest.approx(max(5 * s["x_pk"], 0.01))
    assert r.C_F_disp == pytest.approx(10.0 / r.stroke)
    corner = r.G_p * r.C_F_disp * r.K_s * r.K_v / r.A
    assert corner == pytest.approx(2 * math.pi * max(s["f_99"] / 2, 1.0))
    assert 9.0 < s["f_99"] <= 10.5


def test_specimen_table():
    """Every specimen kind names numeric Rig fields and turns on a switch the rig has."""
    assert keys.SPECIMEN_KEYS["linear"] == ("k", "c")
    assert set(keys.SPECIMEN_KEYS["mr_damper"]) - {"m"} <= set(keys.MR_DAMPER_FIELDS)
    rig = sh.zhao2003()
    for spec, ks in keys.SPECIMEN_KEYS.items():
        assert keys.specimen_keys(spec) == ks
        assert keys.check_keys(rig, ks) == ks
        if keys.SPECIMEN_EFFECT[spec] is not None:
            assert hasattr(rig.effects, keys.SPECIMEN_EFFECT[spec])
        assert set(ks) <= keys.FORCE_KEYS
    with pytest.raises(ValueError, match="invalid specimen = 'rubber'"):
        keys.specimen_keys("rubber")


def bingham_record(f_y=150.0, c=2.0e3, k=5.0e3):
    t, u = chirp(duration=20.0, f1=8.0)
    x = u
    v = np.gradient(x, DT)
    f = f_y * np.tanh(v / (0.02 * np.max(np.abs(v)))) + c * v + k * x
    return sh.Response({"time": t, "command": u, "displacement": x, "force": f})


def test_mr_damper_start_reproduces_the_bingham_fit():
    """The generic MR start: the Bingham fit recovers a Bingham record's f_y, c, k; the
    Spencer start's high-velocity force c1/(c0+c1) (alpha z_u + c0 v) is f_y + c v
    (closed form of the mapping, z_u = (A / (beta + gamma))^(1/n)), z_u = A x 5 % x_pk."""
    rec = bingham_record()
    b = generic.bingham_fit(rec)
    assert b["f_y"] == pytest.approx(150.0, rel=0.02)
    assert b["c"] == pytest.approx(2.0e3, rel=0.02)
    assert b["k"] == pytest.approx(5.0e3, rel=0.02)
    r = generic.generic_rig(rec)
    generic.specimen_start(r, rec, "mr_damper")
    z_u = (r.mr_A / (r.mr_beta + r.mr_gamma)) ** (1.0 / r.mr_n)
    assert z_u == pytest.approx(r.mr_A * 0.05 * generic.record_scales(rec)["x_pk"], rel=1e-12)
    for v in (0.05, 0.2):
        high = r.mr_c1_a / (r.mr_c0_a + r.mr_c1_a) * (r.mr_alpha_a * z_u + r.mr_c0_a * v)
        assert high == pytest.approx(b["f_y"] + b["c"] * v, rel=1e-12)
    assert r.mr_k1 == pytest.approx(b["k"]) and r.mr_k0 == 0.0 and r.mr_voltage == 0.0


def test_time_blocks():
    """Displacement control with both channels: loop keys on the displacement, then the
    specimen's on the force; otherwise one block of every key and channel."""
    ks = ("G_p", "f_v", "mr_alpha_a", "m")
    (a1, c1), (a2, c2) = lab.records.time_blocks(ks, ("displacement", "force"), "displacement")
    assert list(a1) == [True, True, False, False] and c1 == ("displacement",)
    assert list(a2) == [False, False, True, True] and c2 == ("force",)
    for chans, mode in ((("displacement",), "displacement"), (("displacement", "force"), "force")):
        (a, c), = lab.records.time_blocks(ks, chans, mode)
        assert a.all() and c == chans


def test_threaded_jacobian_equals_serial_and_the_derivative():
    """Forward differences on 2 threads equal the serial ones bit for bit, and a smooth
    function's derivative to the step's order (backward at an upper bound)."""
    from servohydraulics.identification.fit import DIFF_STEP, forward_jacobian

    t = np.linspace(0.0, 1.0, 50)

    def fun(z):
        return np.sin(z[0] * t) + z[1] ** 2 * t + np.exp(z[2] * t)

    z = np.array([0.3, -0.7, 0.2])
    hi = np.array([np.inf, np.inf, 0.2])
    J1 = forward_jacobian(fun, z, fun(z), hi, 1)
    J2 = forward_jacobian(fun, z, fun(z), hi, 2)
    np.testing.assert_array_equal(J1, J2)
    exact = np.column_stack([t * np.cos(z[0] * t), 2 * z[1] * t, t * np.exp(z[2] * t)])
    np.testing.assert_allclose(J1, exact, atol=5 * DIFF_STEP)


def mr_truth():
    """The small lab actuator with an MR damper (Spencer) of known keys."""
    r = truth_rig()
    r.effects.mr_damper = True
    r.k, r.c = 1.0, 0.0
    r.mr_alpha_a, r.mr_c0_a, r.mr_c1_a, r.mr_k1 = 4.0e4, 1.5e3, 2.0e4, 1.0e3
    r.mr_A, r.mr_n, r.mr_beta, r.mr_gamma, r.mr_k0, r.mr_x0, r.mr_voltage = 300.0, 2.0, 3.0e6, 3.0e6, 0.0, 0.0, 0.0
    return r


def test_recovers_an_mr_damper():
    """A core-simulated record (CVODE, noise 0.2 % / 1 %) of a known MR damper; the
    specimen keys start 30-50 % off: the fit brings the force NRMSE to the noise's
    level and the main keys (alpha, c0) within 5 % or their 95 % intervals."""
    truth = mr_truth()
    t, u = chirp(duration=6.0, f1=8.0)
    sim = sh.simulate(truth, "displacement", command=u, dt=DT, options=sh.solver_options(rtol=1e-8))
    rng = np.random.default_rng(5)
    sf = 0.01 * np.std(sim.force)
    rec = sh.Response({"time": t, "command": u, "displacement": sim.displacement + 3e-6 * rng.standard_normal(t.size),
                       "force": sim.force + sf * rng.standard_normal(t.size)})
    start = copy.copy(truth)
    for k, f in (("mr_alpha_a", 1.4), ("mr_c0_a", 0.6), ("mr_c1_a", 1.5), ("mr_k1", 0.7), ("G_p", 1.2)):
        setattr(start, k, getattr(truth, k) * f)
    fit = ["G_p", "mr_alpha_a", "mr_c0_a", "mr_c1_a", "mr_k1"]
    ident = sh.identify([rec], rig=start, fit=fit, mode="displacement", specimen="mr_damper", progress=False)
    assert ident.before[0].nrmse("force") > 10.0
    assert ident.after[0].nrmse("force") < 1.5
    assert ident.after[0].nrmse("displacement") < 0.5
    for k in ("G_p", "mr_alpha_a", "mr_c0_a"):
        lo, hi = ident.intervals[k]
        v = getattr(truth, k)
        assert lo <= v <= hi or abs(ident.values[k] / v - 1) < 0.05, (k, v, ident.values[k], (lo, hi))


def test_bad_arguments():
    rig = truth_rig()
    rec = noisy_record(rig)
    with pytest.raises(ValueError, match="invalid fit key = 'nope'"):
        lab.identify(rec, rig=rig, fit=["nope"], progress=False)
    with pytest.raises(ValueError, match="given twice"):
        lab.identify(rec, rig=rig, fit=["G_p", "G_p"], progress=False)
    with pytest.raises(ValueError, match="invalid mode"):
        lab.identify(rec, rig=rig, mode="free", progress=False)


def test_identify_is_a_plain_function():
    """``sh.identify`` is the function of the identification package (no callable module); the
    rig dict still carries the structure's keys."""
    import types

    from servohydraulics import identification

    assert isinstance(sh.identify, types.FunctionType) and sh.identify is identification.identify
    assert "k" in rig_to_dict(truth_rig())["structure"]


def test_cli_bouc_wen_from_the_generic_start(tmp_path):
    """`identify --specimen bouc_wen` from the generic start on a record of a Bouc-Wen
    specimen: the element is switched on in the written rig, both channels improve
    within 3 evaluations, and keys the short record cannot pin down have null
    (not infinite) interval ends or a flag in the JSON."""
    import json

    from servohydraulics.cli import main

    r = truth_rig()
    r.effects.bouc_wen_hysteresis = True
    r.bw_k, r.bw_beta, r.bw_gamma = 2e5, 500.0, 500.0
    t, u = chirp(duration=4.0)
    sim = sh.simulate(r, "displacement", command=u, dt=DT)
    path = tmp_path / "bw.csv"
    sh.write_record(path, sh.Response({"time": t, "command": u, "displacement": sim.displacement, "force": sim.force}))
    out = tmp_path / "out"
    assert main(["identify", str(path), "--mode", "displacement", "--specimen", "bouc_wen", "--max-nfev", "3",
                 "--quiet", "--out", str(out)]) == 0
    back = sh.load_rig(out / "rig_identified.toml")
    assert back.effects.bouc_wen_hysteresis and not back.effects.mr_damper
    data = json.loads((out / "identification.json").read_text())
    assert set(data["parameters"]) == {"G_p", "f_v", "zeta_v", "bw_k", "bw_beta", "bw_gamma", "c", "m"}
    rec = data["records"][0]
    for ch in ("displacement", "force"):
        assert rec["after"][ch] < rec["before"][ch]


@pytest.mark.parametrize("current", [0.0, 1.0])
def test_thesis_parameters_in_si_drive_the_core_like_the_baseline(current):
    """The thesis' Spencer parameters (N, mm, s) converted by ``spencer_rig_keys`` into the
    core's MR element: its specimen force in a displacement-controlled run equals the
    independent NumPy baseline driven by the same displacement, within 1 % of the force's std."""
    from servohydraulics.identification import baselines as b

    r = truth_rig()
    r.k, r.c = 1.0, 0.0
    r.effects.mr_damper = True
    for k, v in b.spencer_rig_keys(b.thesis_mr_parameters(current)).items():
        setattr(r, k, v)
    t = np.arange(3001) * DT
    u = 2e-3 * np.sin(2 * np.pi * 3.0 * t) * np.minimum(t / 0.3, 1.0)
    sim = sh.simulate(r, "displacement", command=u, dt=DT, options=sh.solver_options(rtol=1e-8))
    ref = b.spencer_force(sim.displacement, DT, b.thesis_mr_parameters(current), cutoff_hz=400.0)
    F = np.asarray(sim.specimen_force)
    assert np.max(np.abs(F - ref)[100:]) < 0.01 * np.std(ref)
