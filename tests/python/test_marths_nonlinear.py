"""The maRTHS benchmark loop on the nonlinear two-actuator rig (``--plant nonlinear | RIG.toml``, issue 23
item 5), on the synthetic data folder (marths_support.py; no shared data needed).

Oracles:
* the rig's own linearisation (the analytic Jacobian about rest), discretised exactly (zero-order hold,
  SciPy's matrix exponential) and stepped in Python behind the same loop: at a small ground-motion scale
  and without sensor noise the nonlinear rig's J1-J10 and signals equal it (the J are ratios, so the
  scale cancels for a linear plant);
* the loop's commands replayed on the rig by ``simulate_multi`` give its strokes row by row (the loop holds
  exactly the commands it logs, in the record convention);
* bad ``--plant`` values: ``error:`` naming the value or the file and key, exit 2, nothing written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from marths_support import assert_refused, run_cli, write_folder
from scipy.linalg import expm

import servohydraulics as sh
from servohydraulics import marths
from servohydraulics.multi_rig import MultiActuatorRig


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    return write_folder(tmp_path_factory.mktemp("marths-nl") / "data", duration=1.0)


@pytest.fixture(scope="module")
def data(pristine):
    return marths.load_data(pristine)


@pytest.fixture(scope="module")
def record(pristine):
    return marths.load_record(pristine, "elcentro")


def _linear_rig() -> MultiActuatorRig:
    """The calibrated rig with the amplitude-dependent effects off (friction's regularised slope, the load
    pressure's root, the flow curve, the limits): linear but for the fixture's kinematics."""
    base = sh.marths_rig()
    rigs = [sh.copy_rig(r) for r in base.rigs]
    for r in rigs:
        for name in ("load_pressure", "flow_nonlinearity", "coulomb_friction", "spool_saturation",
                     "drive_saturation"):
            setattr(r.effects, name, False)
    return MultiActuatorRig(rigs, base.arms, base.angles, base.specimen)


class ZohLinearization:
    """The rig's linearisation about rest, dy/dt = A dy + B du, strokes = C dy, discretised exactly for a held
    command (expm of the augmented matrix), stepped through the MultiActuatorSystem protocol (SI)."""

    def __init__(self, rig: MultiActuatorRig, dt: float):
        A, B, C = rig.linearize()
        n, m = A.shape[0], B.shape[1]
        aug = np.zeros((n + m, n + m))
        aug[:n, :n], aug[:n, n:] = A, B
        E = expm(aug * dt)
        self.Phi, self.Gam, self.C = E[:n, :n], E[:n, n:], C
        self.actuators, self.dt = m, dt
        self.x = np.zeros(n)

    def reset(self):
        self.x[:] = 0.0

    def displacements(self):
        return self.C @ self.x

    def step(self, u):
        self.x = self.Phi @ self.x + self.Gam @ np.asarray(u, dtype=float)


def _quiet_config():
    c = marths.loop_config()
    c.noise_power = 0.0
    return c


def test_the_nonlinear_loop_equals_the_rigs_linearisation_at_small_amplitude(data, record):
    rig = _linear_rig()
    scale = 0.04  # strokes of ~0.1 mm: the kinematics' quadratic terms are 1e-4 of them
    a = marths.run_trial(data, record, "rodeac_fixed", plant=rig, scale=scale, config=_quiet_config(),
                         keep_signals=True)
    b = marths.run_trial(data, record, "rodeac_fixed", plant=ZohLinearization(rig, marths.DT), scale=scale,
                         config=_quiet_config(), keep_signals=True)
    assert a.ok and b.ok
    sa, sb = a.response.channels, b.response.channels
    peak = np.max(np.abs(sb["displacement_1"]))
    assert 2e-5 < peak < 1e-3
    for ch in ("displacement_1", "displacement_2", "x_estimate"):
        assert np.max(np.abs(sa[ch] - sb[ch])) < 2e-3 * np.max(np.abs(sb[ch])), ch
    for j in marths.J_COMPONENTS:
        np.testing.assert_allclose(a.J[j], b.J[j], rtol=2e-3, atol=2e-3, err_msg=j)
    # The rig's channels come with the trial: the replay's strokes are the loop's, sample by sample.
    assert a.rig is not None and b.rig is None
    summary = marths.rig_summary(a.rig, sa)
    assert summary["replay_stroke_difference_m"] == 0.0
    assert summary["actuators"][0]["peak_force_N"] > 0


def test_the_replay_is_the_loops_run_with_every_effect_and_the_daq(data, record):
    rig = sh.marths_rig()
    cfg = marths.loop_config(daq_quantizer=True, daq_saturation=True)
    t = marths.run_trial(data, record, "rodeac", plant=rig, config=cfg, keep_signals=True)
    assert t.ok and t.stable
    s = t.response.channels
    u = marths.applied_commands(s, cfg)
    # the D/A's commands differ from the controller's by its quantum, and the plant held those
    assert 0 < np.max(np.abs(u[:, 0] - s["command_1"])) < 1e-5
    assert marths.rig_summary(t.rig, s)["replay_stroke_difference_m"] == 0.0
    np.testing.assert_array_equal(t.rig["actuator1.command"], u[:, 0])



def test_the_command_on_the_nonlinear_rig(pristine, tmp_path, capsys):
    out = tmp_path / "out"
    code, stdout, err = run_cli(capsys, "marths-benchmark", "--data", pristine, "--plant", "nonlinear", "--quiet",
                             "--out", out)
    assert code == 0, err
    res = json.loads((out / "results.json").read_text())
    assert res["meta"]["plant"] == "nonlinear"
    nom = res["runs"]["nominal"]
    assert nom["ok"] and nom["stable"]
    rig = nom["rig"]
    assert rig["replay_stroke_difference_m"] == 0.0 and len(rig["actuators"]) == 2
    assert rig["peak_opposing_force_N"] <= max(a["peak_force_N"] for a in rig["actuators"])
    report = (out / "report.md").read_text()
    assert "- plant: nonlinear:" in report and "What the nonlinear rig shows" in report
    assert (out / "rig.png").stat().st_size > 1000 and "](rig.png)" in report
    # The same run through the Python API gives the same J (the rig by name or as an object).
    direct = marths.run_trial(marths.load_data(pristine), marths.load_record(pristine, "elcentro"), "rodeac",
                              plant=sh.marths_rig())
    assert nom["J"] == direct.J


def test_a_rig_file_as_the_plant(pristine, tmp_path, capsys):
    rig = sh.marths_rig()
    sh.save_multi_rig(rig, tmp_path / "mine.toml")
    out = tmp_path / "out"
    code, _, err = run_cli(capsys, "marths-benchmark", "--data", pristine, "--plant", tmp_path / "mine.toml",
                        "--quiet", "--out", out)
    assert code == 0, err
    res = json.loads((out / "results.json").read_text())
    assert res["meta"]["plant"] == str(tmp_path / "mine.toml")
    assert "rig" in res["runs"]["nominal"]



def test_bad_plants_are_named(pristine, tmp_path, capsys):
    d = ["--data", pristine]
    assert_refused(capsys, tmp_path, [*d, "--plant", "linear"], ["invalid plant = 'linear'", "identified | nonlinear"])
    assert_refused(capsys, tmp_path, [*d, "--plant", tmp_path / "none.toml"], ["invalid plant = ", "none.toml",
                                                                          "no such file"])
    assert_refused(capsys, tmp_path, [*d, "--plant", "nonlinear", "--perturbed", "3"],
             ["invalid perturbed = 3 with plant = 'nonlinear'", "identified plant's uncertainty"])
    bad = tmp_path / "bad.toml"
    bad.write_text("[fixture\narms = [0.3]\n")
    assert_refused(capsys, tmp_path, [*d, "--plant", bad], ["bad.toml", "is not valid TOML"])
    # a valid rig file with three actuators: the benchmark's coupler drives two
    three = tmp_path / "three.toml"
    three.write_text('[fixture]\narms = [0.3, 0.3, 0.4]\nangles_deg = [-30, 30, 5]\n[specimen]\nframe = "marths"\n'
                     "[[actuators]]\n[[actuators]]\n[[actuators]]\n")
    assert_refused(capsys, tmp_path, [*d, "--plant", three], ["three.toml", "(count) = 3", "drives 2 actuators"])
    # a bad value inside a rig file: the file, the key and the value
    sh.save_multi_rig(sh.marths_rig(), tmp_path / "k.toml")
    text = (tmp_path / "k_actuator2.toml").read_text().replace("K_v = 0.016", "K_v = -0.016")
    (tmp_path / "k_actuator2.toml").write_text(text)
    assert_refused(capsys, tmp_path, [*d, "--plant", tmp_path / "k.toml"], ["k.toml", "K_v", "-0.016"])


def test_a_missing_actuator_file_is_named(pristine, tmp_path, capsys):
    sh.save_multi_rig(sh.marths_rig(), tmp_path / "m.toml")
    (tmp_path / "m_actuator1.toml").unlink()
    assert_refused(capsys, tmp_path, ["--data", pristine, "--plant", tmp_path / "m.toml"], ["m_actuator1.toml"])


def test_the_frame_has_one_home():
    # marths_frame is the core's CondensedFrame: its Guyan stiffness is the loop's physical frame's, condensed
    R = sh._core.marths
    f = R.PhysicalFrame.from_parameters()
    T = np.vstack([np.eye(2), np.asarray(f.G)])
    fr = sh.marths_frame()
    np.testing.assert_allclose(fr["K"], T.T @ np.asarray(f.K) @ T, rtol=1e-12)
    np.testing.assert_allclose(fr["M"], T.T @ np.asarray(f.M) @ T, rtol=1e-12)
    np.testing.assert_allclose(fr["C"], T.T @ np.asarray(f.C) @ T, rtol=1e-12)


def test_the_study_variants():
    # the study's plants are the ones it documents: rig-small-valve has the calibrated linearisation
    import importlib.util

    path = Path(__file__).resolve().parents[2] / "studies" / "marths_linear_vs_nonlinear.py"
    spec = importlib.util.spec_from_file_location("marths_lvn", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    ps = mod.plants()
    assert list(ps) == list(mod.PLANTS)
    f = np.array([0.5, 5.0, 20.0])
    np.testing.assert_allclose(ps["rig-small-valve"].frequency_response(f), ps["rig"].frequency_response(f),
                               rtol=1e-9, atol=1e-12)
    k = mod.SMALL_VALVE_ACTUATOR
    assert ps["rig-small-valve"].rigs[k].K_v == pytest.approx(ps["rig"].rigs[k].K_v / mod.VALVE_FACTOR)
    assert ps["rig-small-valve"].rigs[k].G_p == pytest.approx(ps["rig"].rigs[k].G_p * mod.VALVE_FACTOR)
