"""The RTHS benchmark (Silva et al. 2020, MSSP 135:106381) against its published
numbers and independent oracles.  The official files are read from
../shared/rths-data (never copied into the repository)."""

from __future__ import annotations

import json
import math
from functools import partial

import numpy as np
import pytest
from shared_data import shared_path

from servohydraulics import rths
from servohydraulics.cli import main

#: Published Table 3, case 1, El Centro x 0.4, sample controller, nominal plant
#: (paper p. 30; the code's J order, BENCHMARK.md 10).
PUBLISHED_CASE1 = [4.6, 10.4, 11.5, 36.1, 19.0, 32.3, 32.4, 14.8, 14.8]


@pytest.fixture(scope="module")
def data():
    return shared_path("rths-data/mat")


def test_published_case1_row(data):
    """The published row with the official run's noise realisation: the Simulink
    generator of the SENSORS subsystem at seed 0 (BENCHMARK.md 3.2), every J to the
    acceptance tolerance (J1 to 0.1 ms, J2-J9 to 0.5 percentage points)."""
    case, rec = rths.load_case(data, 1), rths.load_record(data, "elcentro")
    J = rths.run_trial(case, rec, "sample", seed=0, noise="simulink").J
    assert J[0] == pytest.approx(PUBLISHED_CASE1[0], abs=0.1)
    for i in range(1, 9):
        assert J[i] == pytest.approx(PUBLISHED_CASE1[i], abs=0.5), f"J{i + 1} = {J[i]}"
    # The peak criteria J3 and J5 hang on single noise samples (seed-to-seed sd ~0.19 pp,
    # below): they land on the published value rounded to 0.1 only with the official noise.
    assert round(J[2], 1) == PUBLISHED_CASE1[2] and round(J[4], 1) == PUBLISHED_CASE1[4]


def test_published_case1_row_over_noise_seeds(data):
    """BENCHMARK.md 10's comparison for a generator that is not the official one:
    the seed mean of the noise-insensitive J to 0.5 pp, the single-sample peaks (J3,
    J5) to the seed-to-seed spread."""
    case, rec = rths.load_case(data, 1), rths.load_record(data, "elcentro")
    ref = rths.case_reference(case, rec)
    Js = np.array([rths.run_trial(case, rec, "sample", seed=s, reference=ref, noise="mersenne").J
                   for s in range(16)])
    J, sd = Js.mean(axis=0), Js.std(axis=0, ddof=1)
    assert J[0] == pytest.approx(PUBLISHED_CASE1[0], abs=0.1)  # J1 to 0.1 ms
    for i in (1, 3, 5, 6, 7, 8):  # J2, J4, J6-J9: noise-insensitive (seed sd < 0.03), to 0.5 pp
        assert sd[i] < 0.05 and J[i] == pytest.approx(PUBLISHED_CASE1[i], abs=0.5), f"J{i + 1}"
    for i in (2, 4):  # J3, J5: single-sample peaks (seed sd ~0.19 pp)
        assert 0.1 < sd[i] < 0.4, f"J{i + 1} sd {sd[i]}"
        assert abs(J[i] - PUBLISHED_CASE1[i]) <= max(0.5, 3.0 * sd[i]), f"J{i + 1} {J[i]} +- {sd[i]}"


def _minimal_standard(state: int):
    """Park and Miller's minimal standard generator in exact integer arithmetic."""
    while True:
        state = 16807 * state % 2147483647
        yield state


def test_simulink_noise_generator_against_an_independent_implementation():
    """The core's Simulink generator against this file's own: exact-integer minimal
    standard (checked by Park and Miller's value 1043618065 after 10000 draws from 1),
    the Random Number block's polar method keeping one variate per accepted pair."""
    g = _minimal_standard(1)
    for _ in range(9999):
        next(g)
    assert next(g) == 1043618065
    assert rths.core.GaussianSequence.simulink_state(0) == 1144108930  # the block's state for a zero seed
    uni = _minimal_standard(1144108930)
    want = []
    while len(want) < 5000:
        sr = 2.0 * (next(uni) * 4.6566128752457969e-10) - 1.0
        si = 2.0 * (next(uni) * 4.6566128752457969e-10) - 1.0
        s = sr * sr + si * si
        if 0.0 < s <= 1.0:
            want.append(math.sqrt(-2.0 * math.log(s) / s) * sr)
    seq = rths.core.GaussianSequence(0, rths.core.NoiseGenerator.SimulinkRandomNumber)
    got = [seq.next() for _ in range(5000)]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="noise"):
        rths.run_trial(rths.embedded_case(1), rths.synthetic_record(duration=0.1), noise="gauss")


def test_embedded_structure_matches_official_files(data):
    for n in (1, 2, 3, 4):
        off, emb = rths.load_case(data, n), rths.embedded_case(n)
        np.testing.assert_allclose(emb.M, off.M, rtol=0, atol=0)
        np.testing.assert_allclose(emb.K, off.K, rtol=1e-12)
        np.testing.assert_allclose(emb.C, off.C, rtol=1e-9, atol=1e-9 * np.abs(off.C).max())


def test_plant_transfer_function_and_controller_coefficients():
    p = rths.nominal_plant()
    assert p.c_e == pytest.approx(114.22086714782024, rel=1e-15)  # BENCHMARK.md 2.2
    den = p.denominator()  # BENCHMARK.md 2.3, from the F1 parameters
    np.testing.assert_allclose(den, [29.13, 12590.599867147821, 8421776.502399411, 2328489633.084145,
                                     543546586039.86615, 21675605752000], rtol=1e-12)
    assert p.numerator() / den[-1] == pytest.approx(1.007514, abs=1e-6)
    c = rths.core.SampleController()
    np.testing.assert_allclose(c.lead_coefficients, (25.353362720558675, -24.330788542666237, 0.022574177892434395),
                               rtol=1e-12)
    np.testing.assert_allclose(c.pi_coefficients, (2.0115966796875, -1.9884033203125, -1.0), rtol=1e-15)


def _rhp_zeros(case, tau):
    """RHP roots of det A(s) + exp(-s tau) b(s) cof11(A(s)) by the argument principle
    along the imaginary axis (an oracle independent of the crossing-frequency route)."""
    sp = rths.nominal_plant().specimen()
    Mn, Cn, Kn = case.M.copy(), case.C.copy(), case.K.copy()
    Mn[0, 0] -= sp.m
    Cn[0, 0] -= sp.c
    Kn[0, 0] -= sp.k
    w = np.linspace(0.0, 2e4, 2_000_001)
    s = 1j * w
    A = Mn[None] * s[:, None, None] ** 2 + Cn[None] * s[:, None, None] + Kn[None]
    b = sp.m * s**2 + sp.c * s + sp.k
    F = np.linalg.det(A) + np.exp(-s * tau) * b * np.linalg.det(A[:, 1:, 1:])
    F = F / (s + 1.0) ** 6  # -> a nonzero constant at infinity (neutral, me/(m - me) < 1)
    darg = np.sum(np.angle(F[1:] / F[:-1]))  # 0 .. +inf; the other half mirrors
    return round((-2 * darg) / (2 * math.pi) + 0.0)


def test_psi_critical_delay_is_a_stability_switch(data):
    case = rths.load_case(data, 1)
    sp = rths.nominal_plant().specimen()
    tau = rths.critical_delay(case.M, case.C, case.K, sp.m, sp.c, sp.k)
    assert _rhp_zeros(case, 0.95 * tau) == 0
    assert _rhp_zeros(case, 1.05 * tau) >= 2
    assert rths.case_psi(case) == pytest.approx(math.log10(1000 * tau))


def test_compensators_improve_j1_j2_on_all_cases(data):
    rec = rths.load_record(data, "elcentro")
    for n in (1, 2, 3, 4):
        case = rths.load_case(data, n)
        base = rths.run_trial(case, rec, "sample", seed=1).J
        for name in ("polynomial", "ats", "model"):
            J = rths.run_trial(case, rec, name, seed=1).J
            assert J[0] < base[0] and J[1] < base[1], (n, name, J[:2], base[:2])


def test_perturbed_trials_stable_and_reproducible(data):
    case, rec = rths.load_case(data, 2), rths.load_record(data, "elcentro")
    a = rths.run_case(case, rec, "sample", perturbed=3, seed=7, max_workers=2, progress=False)
    b = rths.run_case(case, rec, "sample", perturbed=3, seed=7, max_workers=2, progress=False)
    assert a["perturbed"]["stable"] == 3 and a["perturbed"]["ran_to_end"] == 3
    assert a["perturbed"]["J_mean"] == b["perturbed"]["J_mean"]
    t = a["table"]
    np.testing.assert_allclose(t["k_e"].to_numpy() != 1190e3, True)


def test_a_diverging_trial_is_not_stable(data, monkeypatch):
    """The quadratic extrapolation loses perturbed plant 20 of case 4 (seed-0 draws) at
    59 Hz (studies/rths_polynomial_study.py): it runs to the end in floating point,
    so only the stability test can say so; the first-order default keeps it."""
    from servohydraulics.rths import benchmark as B
    case, rec = rths.load_case(data, 4), rths.load_record(data, "elcentro")
    plant = B.perturbed_plant(0, 4, 20)

    good = rths.run_trial(case, rec, "polynomial", plant=plant)
    assert good.ok and good.stable and good.J[1] < 5.0
    monkeypatch.setitem(B.CONTROLLERS, "polynomial", (partial(B.polynomial_controller, order=2), "quadratic"))
    bad = rths.run_trial(case, rec, "polynomial", plant=plant)
    assert bad.ok and not bad.stable and bad.max_force_N > 100 * B.FORCE_LIMIT


def test_integration_schemes_agree(data):
    case, rec = rths.load_case(data, 1), rths.load_record(data, "elcentro")
    rk4 = rths.run_trial(case, rec, "sample", seed=1).J
    for scheme in ("CentralDifference", "ExplicitNewmark"):
        J = rths.run_trial(case, rec, "sample", seed=1, scheme=scheme).J
        # second-order schemes: their period error moves the floor criteria by ~1 pp at h = 1/4096
        np.testing.assert_allclose(J[1:], rk4[1:], atol=1.5)


def test_cli_embedded_default_is_labelled(tmp_path, capsys):
    assert main(["rths-benchmark", "--cases", "1", "--controller", "model", "--quiet", "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "results.json").read_text())
    nom = res["cases"]["1"]["nominal"]
    assert set(nom) == {"J", "criteria", "max_force_N", "max_displacement_m", "PSI"} and len(nom["J"]) == 9
    assert list(nom["criteria"]) == list(rths.J_NAMES) == res["meta"]["J_names"]  # the J list, by name
    assert list(nom["criteria"].values()) == nom["J"] and "J1_delay_ms" in rths.J_NAMES
    assert "| J1_delay_ms | J2_rms_tracking_error_pct |" in (tmp_path / "report.md").read_text()
    assert res["meta"]["synthetic"] is True
    assert "NOT the benchmark" in (tmp_path / "report.md").read_text()
    assert (tmp_path / "tracking.png").is_file() and (tmp_path / "criteria.png").is_file()
    assert res["meta"]["noise"] == "simulink" and "official run's realisation" in (tmp_path / "report.md").read_text()
    other = tmp_path / "mersenne"
    assert main(["rths-benchmark", "--cases", "1", "--controller", "model", "--noise", "mersenne", "--quiet",
                 "--out", str(other)]) == 0
    res2 = json.loads((other / "results.json").read_text())
    assert res2["meta"]["noise"] == "mersenne" and res2["cases"]["1"]["nominal"]["J"] != nom["J"]


def test_cli_bad_input_names_the_field(tmp_path, capsys):
    assert main(["rths-benchmark", "--cases", "5", "--quiet", "--out", str(tmp_path)]) == 2
    assert "cases" in capsys.readouterr().err


def test_nonlinear_plant_as_experimental_substructure():
    """Our nonlinear servo-hydraulic Plant behind the same interface in the same loop.
    The sample controller is tuned for the benchmark plant, not for this rig, so the
    test checks only that the loop runs and that the specimen follows the command
    (J2 < 60 %, J1 at most the 12 ms search limit). It does not check the benchmark's accuracy."""
    import servohydraulics as sh
    rig = sh.zhao2003()
    rig.m, rig.k, rig.c = 100.0, 1.0e6, 200.0  # a small specimen, so that Mr - Me stays positive definite
    rec = rths.synthetic_record(duration=4.0)
    rec.time, rec.acceleration = rec.time[400:] - 4.0, rec.acceleration[400:]
    exp = rths.core.ServoHydraulicSubstructure(rig, rths.DT)
    t = rths.run_trial(rths.embedded_case(1), rec, "sample", experimental=exp, seed=1)
    assert t.ok and all(math.isfinite(j) for j in t.J)
    assert t.J[1] < 60.0 and t.J[0] <= 12.0


def test_chirp_is_the_specified_sweep_and_runs(tmp_path):
    """BENCHMARK.md 6: sin(2 pi (f1 t + (f2 - f1) t^2 / 2T)), 0.1-40 Hz over 90 s, 368,641 samples
    at 4096 Hz; the loop's interpolation at the RK4 mid-stage returns the exact sine."""
    rec = rths.chirp_record()
    assert rec.samples() == 368_641 and rec.end_time == 90.0
    gm = rths.core.GroundMotion(rec.time, rec.acceleration, 1.0)
    for t in (0.3, 44.5, 89.7):
        for tk in (t, t + rths.DT / 2):
            tk = round(tk * 8192) / 8192
            assert gm(tk) == pytest.approx(math.sin(2 * math.pi * (0.1 * tk + 39.9 * tk * tk / 180.0)), abs=1e-9)
    # instantaneous frequency from the zero crossings: f1 + (f2 - f1) t / T
    a, t = rec.acceleration, rec.time
    i = np.nonzero(np.diff(np.signbit(a)))[0]
    z = t[i] - a[i] * (t[i + 1] - t[i]) / (a[i + 1] - a[i])  # crossings, linearly interpolated
    mid, f = 0.5 * (z[2:] + z[:-2]), 1.0 / (z[2:] - z[:-2])
    np.testing.assert_allclose(f[mid > 5.0], 0.1 + 39.9 * mid[mid > 5.0] / 90.0, rtol=1e-4)
    assert main(["rths-benchmark", "--record", "chirp", "--cases", "1", "--quiet", "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["meta"]["record"] == "chirp" and all(math.isfinite(j) for j in res["cases"]["1"]["nominal"]["J"])
    assert "chirp" in (tmp_path / "report.md").read_text()


def test_cli_csi_derivative_block_option(data, tmp_path):
    """--csi derivative-block: the official code's Derivative block on the CSI (BENCHMARK.md 2.1);
    it moves the noise-insensitive J4 of case 1 by +0.05 pp (docs, "The J5 gap")."""
    outs = {}
    for csi in ("exact", "derivative-block"):
        out = tmp_path / csi
        assert main(["rths-benchmark", "--data", str(data), "--cases", "1", "--csi", csi, "--perturbed", "1",
                     "--workers", "1", "--quiet", "--out", str(out)]) == 0
        outs[csi] = json.loads((out / "results.json").read_text())
        assert outs[csi]["meta"]["csi"] == csi
    J0, J1 = outs["exact"]["cases"]["1"]["nominal"]["J"], outs["derivative-block"]["cases"]["1"]["nominal"]["J"]
    assert J1[3] - J0[3] == pytest.approx(0.05, abs=0.02)
    exact, block = outs["exact"]["cases"]["1"], outs["derivative-block"]["cases"]["1"]
    assert exact["perturbed"]["J_mean"] != block["perturbed"]["J_mean"]
