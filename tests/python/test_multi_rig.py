"""The coupled multi-actuator rig (issue 23) against its oracles, through the Python API.

- Energy balance: over a run with large rotations, friction, leakage and the pistons' inertia, the
  hydraulic power the valves deliver equals the rate of the oil's stored energy, the kinetic energy
  (node, fixture, pistons) and the specimen's potential energy plus the dissipation (specimen
  damping, leakage, piston friction), integrated from the channels (Simpson).
- Static equilibrium under held commands: the steady state of a run equals the solution of the
  equilibrium equations written here anew (servo controller, valve flow with the load pressure,
  leakage, the fixture's nonlinear strokes and J^T F = K q), solved by SciPy.
- Force fighting: zero for two actuators on (x, theta); |F1 - F2| / sqrt(2) for two actuators on a
  translating node; for three actuators on (x, theta) the null-space component of J^T, computed here.
- The benchmark's frame: the condensed stiffness is the scripts' own static condensation.
- Files and bad input: a multi-actuator rig file round trip, and errors naming the key and value.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.optimize import fsolve

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.multi_rig import MARTHS_ANGLES, MARTHS_ARM, MultiActuatorRig, node_specimen


def _two(rig_a: sh.Rig, rig_b: sh.Rig | None = None, specimen=None) -> MultiActuatorRig:
    return MultiActuatorRig([rig_a, rig_b or rig_a], [MARTHS_ARM] * 2, MARTHS_ANGLES,
                            specimen if specimen is not None else sh.marths_frame())


def _strokes(arms, angles, x, th):
    return np.array([x + d * (math.cos(th + a) - math.cos(a)) for d, a in zip(arms, angles)])


def test_energy_balance():
    a = sh.zhao2003()
    a.F_c, a.m_p = 300.0, 30.0
    b = sh.copy_rig(a)
    b.C_l, b.G_p, b.K_a = 2 * a.C_l, 1.3 * a.G_p, 0.7 * a.K_a
    sp = node_specimen(M=[[40.0, 3.0], [3.0, 6.0]], C=[[4e3, 200.0], [200.0, 600.0]],
                       K=[[2e6, 3e5], [3e5, 4e5]], fixture_mass=10.0, fixture_inertia=1.0)
    rig = MultiActuatorRig([a, b], [0.3, 0.5], [-0.4, 0.7], sp)
    dt = 1 / 8192
    t = np.arange(8193) * dt  # one second, an odd count for Simpson
    u = np.c_[0.01 * np.sin(2 * np.pi * 3 * t), -0.02 * np.sin(2 * np.pi * 2 * t) + 0.005]
    res = sh.simulate_multi(rig, u, dt, options=sh.solver_options(rtol=1e-11))
    assert np.max(np.abs(res["node.theta"])) > 0.02  # the geometry is well beyond linear
    ch = res.channels
    q = np.c_[ch["node.x"], ch["node.theta"]]
    qd = np.c_[ch["node.x_velocity"], ch["node.theta_velocity"]]
    M0 = np.reshape(sp.M, (2, 2)) + np.diag([sp.fixture_mass, sp.fixture_inertia])
    C, K = np.reshape(sp.C, (2, 2)), np.reshape(sp.K, (2, 2))
    power = np.zeros(len(res))
    dissipation = np.einsum("ki,ij,kj->k", qd, C, qd)
    stored = 0.5 * np.einsum("ki,ij,kj->k", qd, M0, qd) + 0.5 * np.einsum("ki,ij,kj->k", q, K, q)
    for i, r in enumerate(rig.rigs, start=1):
        p, Q, v = ch[f"actuator{i}.pressure"], ch[f"actuator{i}.flow"], ch[f"actuator{i}.velocity"]
        power += Q * p
        dissipation += r.C_l * p**2 + ch[f"actuator{i}.friction"] * v
        stored += 0.5 * r.K_a * p**2 + 0.5 * r.m_p * v**2
    supplied = simpson(power, x=res.time)
    balance = supplied - simpson(dissipation, x=res.time) - (stored[-1] - stored[0])
    scale = simpson(np.abs(power), x=res.time)
    assert scale > 10.0  # joules moved
    assert abs(balance) < 1e-6 * scale, (balance, scale)
    # The oracle sees a missing term: without the pistons' kinetic energy the balance is far off.
    piston = sum(0.5 * r.m_p * ch[f"actuator{i}.velocity"][-1] ** 2 for i, r in enumerate(rig.rigs, start=1))
    assert abs(piston) > 1e3 * abs(balance)


def test_static_equilibrium_under_held_commands():
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.C_l, b.G_p = 3 * a.C_l, 0.6 * a.G_p
    rig = _two(a, b)
    dt = 1 / 1024
    u0 = np.array([0.004, -0.002])
    u = np.tile(u0, (3 * 1024, 1))
    res = sh.simulate_multi(rig, u, dt)
    K = sh.marths_frame()["K"]
    arms, angles = rig.arms, rig.angles

    def flow(r: sh.Rig, xv: float, p: float) -> float:  # Eq (3), written here: the table curve, signed root
        g = math.copysign(np.interp(abs(xv), r.flow_curve.opening, r.flow_curve.flow), xv)
        return r.K_v * g * math.sqrt(1.0 - math.copysign(1.0, xv) * p / r.p_s)

    def residual(z):
        x, th, p1, p2 = z[0] * 1e-3, z[1] * 1e-3, z[2] * 1e6, z[3] * 1e6
        s = _strokes(arms, angles, x, th)
        Jth = [-d * math.sin(th + al) for d, al in zip(arms, angles)]
        F = np.array([rig.rigs[0].A * p1, rig.rigs[1].A * p2])
        node = K @ [x, th] - np.array([F.sum(), Jth[0] * F[0] + Jth[1] * F[1]])
        out = [node[0] / 1e3, node[1] / 1e3]
        for r, ui, si, p in zip(rig.rigs, u0, s, (p1, p2)):
            xv = r.K_s * r.C_F_disp * r.G_p * (ui - si)  # Eq (1) into the static valve: the spool at rest
            out.append((flow(r, xv, p) - r.C_l * p) * 1e6)  # the flow feeds the leakage
        return out

    z = fsolve(residual, [1.0, 1.0, 0.1, 0.1], xtol=1e-14)
    assert np.max(np.abs(residual(z))) < 1e-9
    s_eq = _strokes(arms, angles, z[0] * 1e-3, z[1] * 1e-3)
    s_sim = np.array([res["actuator1.stroke"][-1], res["actuator2.stroke"][-1]])
    assert np.all(np.abs(s_sim - u0) > 1e-5)  # leakage under load: the strokes miss the commands
    np.testing.assert_allclose(s_sim, s_eq, rtol=0, atol=1e-9)
    np.testing.assert_allclose([res["node.x"][-1], res["node.theta"][-1]], [z[0] * 1e-3, z[1] * 1e-3], atol=1e-9)
    np.testing.assert_allclose([res["actuator1.pressure"][-1], res["actuator2.pressure"][-1]],
                               [z[2] * 1e6, z[3] * 1e6], rtol=1e-6)


def test_force_fighting_measures():
    r = sh.zhao2003()
    dt = 1 / 1024
    t = np.arange(1024) * dt
    # Two actuators on (x, theta): J^T is invertible, no null space.
    res = sh.simulate_multi(_two(r), np.c_[0.003 * np.sin(2 * np.pi * t), -0.002 * np.sin(2 * np.pi * t)], dt)
    assert np.all(res["node.force_fighting"] == 0.0)
    f1, f2 = res["actuator1.force"], res["actuator2.force"]
    np.testing.assert_allclose(res["node.opposing_force"], 0.5 * (np.abs(f1) + np.abs(f2) - np.abs(f1 + f2)),
                               atol=1e-9 * np.max(np.abs(f1)))
    # Two actuators on a translating node commanded apart: they fight; the null space of J^T = [1, 1].
    sp = node_specimen(M=50.0, C=2e3, K=1e6, rotation=False)
    lock = MultiActuatorRig([r, r], [MARTHS_ARM] * 2, MARTHS_ANGLES, sp)
    res = sh.simulate_multi(lock, np.c_[0.002 * np.sin(2 * np.pi * t), -0.001 * np.sin(2 * np.pi * t)], dt)
    f1, f2 = res["actuator1.force"], res["actuator2.force"]
    np.testing.assert_allclose(res["node.force_fighting"], np.abs(f1 - f2) / math.sqrt(2), rtol=1e-12, atol=1e-9)
    assert np.max(res["node.force_fighting"]) > 1e4  # kN of fighting for a mm of mismatch
    # Three actuators on (x, theta): the component of F orthogonal to the columns of J.
    arms, angles = [0.3, 0.3, 0.4], [-0.5, 0.5, 0.1]
    three = MultiActuatorRig([r, r, r], arms, angles, sh.marths_frame())
    res = sh.simulate_multi(three, np.c_[0.002 * np.sin(2 * np.pi * t), 0.001 * np.sin(2 * np.pi * t),
                                         0.003 * np.sin(2 * np.pi * t)], dt)
    F = np.c_[res["actuator1.force"], res["actuator2.force"], res["actuator3.force"]]
    fight = []
    for k in range(len(res)):
        th = res["node.theta"][k]
        J = np.c_[np.ones(3), [-d * math.sin(th + a) for d, a in zip(arms, angles)]]
        P = J @ np.linalg.pinv(J)
        fight.append(np.linalg.norm(F[k] - P @ F[k]))
    np.testing.assert_allclose(res["node.force_fighting"], fight, rtol=1e-9, atol=1e-6)
    assert max(fight) > 1e3


def test_marths_frame_is_the_benchmark_condensation():
    # The scripts' 5-DOF stiffness, transcribed from physicalFrame_feedbackForce.m through its 6 x 6
    # element matrices and transformations, statically condensed.
    E, inch = 200e9, 0.0254
    Lb, Lc, Ic, Ib = 0.762, 0.64135, 0.7 * 2.520 * inch**4, 4.21372e-7

    def k6(I, L):  # noqa: E741
        k = np.zeros((6, 6))
        idx = [1, 2, 4, 5]
        k[np.ix_(idx, idx)] = E * I / L**3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                                       [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
        return k

    def T(a):
        c, s = math.cos(a), math.sin(a)
        R = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
        return np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]])

    Kc = T(math.pi / 2).T @ k6(Ic, Lc) @ T(math.pi / 2)
    Kb = k6(Ib, Lb)
    K = np.array([[2 * Kc[3, 3], Kc[3, 5], Kc[3, 5], Kc[3, 2], Kc[3, 2]],
                  [Kc[5, 3], Kc[5, 5] + Kb[5, 5], Kb[5, 2], 0, Kc[5, 2]],
                  [Kc[5, 3], Kb[2, 5], Kc[5, 5] + Kb[2, 2], Kc[5, 2], 0],
                  [Kc[2, 3], 0, Kc[2, 5], Kc[2, 2], 0],
                  [Kc[2, 3], Kc[2, 5], 0, 0, Kc[2, 2]]])
    Kred = K[:2, :2] - K[:2, 2:] @ np.linalg.solve(K[2:, 2:], K[2:, :2])
    for reduction in ("guyan", "static"):
        fr = sh.marths_frame(reduction)
        np.testing.assert_allclose(fr["K"], Kred, rtol=1e-12)
        for name in ("M", "C"):
            np.testing.assert_allclose(fr[name], fr[name].T, rtol=1e-12, atol=1e-12)
            assert np.all(np.linalg.eigvalsh(fr[name]) > 0)
    # The static model's mass is the scripts' diag(M1x, M12z) (no factor 1.1); Guyan adds the slaves' inertia.
    rho, Ab, Ac = 7850.0, 7.56e-4, 1.670 * inch**2
    mb, mc = rho * Ab * Lb, rho * Ac * Lc
    np.testing.assert_allclose(np.diag(sh.marths_frame("static")["M"]),
                               [(mb + 2 * mc) / 2, (mb / 2 * Lb**2 + mc / 2 * Lc**2) / 3], rtol=1e-12)
    assert sh.marths_frame()["M"][0, 0] > 1.1 * (mb + 2 * mc) / 2


def test_rig_file_round_trip_and_channels(tmp_path):
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.G_p = 1.7
    rig = _two(a, b)
    paths = sh.save_multi_rig(rig, tmp_path / "two.toml")
    assert [p.name for p in paths] == ["two.toml", "two_actuator1.toml", "two_actuator2.toml"]
    back = sh.load_multi_rig(tmp_path / "two.toml")
    assert back.rigs == rig.rigs and back.arms == rig.arms and back.angles == rig.angles
    np.testing.assert_array_equal(back.specimen.K, rig.specimen.K)
    # An override over a rig file, the frame by name, angles in degrees.
    (tmp_path / "three.toml").write_text(
        '[fixture]\narms = [0.3, 0.3, 0.4]\nangles_deg = [-30, 30, 5]\n[specimen]\nframe = "marths"\n'
        'fixture_mass = 5.0\n'
        '[[actuators]]\nrig = "two_actuator1.toml"\n[[actuators]]\nrig = "two_actuator2.toml"\n'
        '[[actuators]]\n[actuators.controller]\nG_p = 0.5\n')
    three = sh.load_multi_rig(tmp_path / "three.toml")
    assert three.actuators == 3 and three.rigs[1].G_p == 1.7 and three.rigs[2].G_p == 0.5
    assert three.angles[0] == pytest.approx(-math.radians(30))
    res = sh.simulate_multi(three, np.zeros((8, 3)), 1e-3)
    names = set(res.channels)
    for i in (1, 2, 3):
        for ch, unit in _core.ACTUATOR_CHANNELS:
            assert f"actuator{i}.{ch}" in names and res.units[f"actuator{i}.{ch}"] == unit
    for ch, unit in _core.NODE_CHANNELS:
        assert res.units[f"node.{ch}"] == unit
    assert res["actuator3.flags"].dtype == np.uint32
    out = res.to_csv(tmp_path / "run.csv")
    header = out.read_text().splitlines()[0].split(",")
    assert header[0] == "time" and "actuator3.force" in header


def test_warnings_name_the_actuator():
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.v_max = 0.5  # a drive limit the command reaches
    rig = _two(a, b)
    t = np.arange(512) / 1024
    res = sh.simulate_multi(rig, np.c_[0.0 * t, 0.02 * np.sin(2 * np.pi * 4 * t)], 1 / 1024)
    w = res.warnings()
    assert any(x.startswith("actuator2: servovalve drive saturated") for x in w)
    assert not any(x.startswith("actuator1: servovalve drive") for x in w)


def _multi_error(res, ref) -> float:
    """The largest error of any actuator's stroke or load-cell force, relative to its peak in ref."""
    err = 0.0
    for i in range(1, ref.actuators + 1):
        for ch in ("stroke", "force"):
            r, x = ref[f"actuator{i}.{ch}"], res[f"actuator{i}.{ch}"]
            err = max(err, float(np.max(np.abs(x - r)) / np.max(np.abs(r))))
    return err


def _stiff_friction_rig():
    """Sharp friction on light pistons (400 N, 5 kg) on a two-node specimen: the error-controlled pair turns
    stiff and CVODE takes samples.  Returns the rig, 600 samples of a two-sine command at 1024 Hz and CVODE's
    run of it at rtol 1e-10 (the reference)."""
    a = sh.zhao2003()
    a.F_c, a.m_p = 400.0, 5.0
    sp = node_specimen(M=[[8.0, 0.0], [0.0, 0.8]], K=[[2.3e6, 8.6e5], [8.6e5, 1.1e6]], C=[[500.0, 0.0], [0.0, 20.0]])
    rig = MultiActuatorRig([a, a], [MARTHS_ARM] * 2, MARTHS_ANGLES, sp)
    k = np.arange(600)
    u = np.c_[0.005 * np.sin(2 * np.pi * 2 * k / 1024), 0.004 * np.sin(2 * np.pi * 3 * k / 1024)]
    ref = sh.simulate_multi(rig, u, 1 / 1024, options=sh.solver_options("cvode", rtol=1e-10,
                                                                        max_steps_per_sample=1000000))
    return rig, u, ref


def test_accuracy_checks_measure_the_coupled_runs_error():
    """The integrators' accuracy checks on the coupled rig (output_gap.hpp over every actuator's
    stroke and force; work.error_estimate is the run's gap over the check's bound): against CVODE
    at rtol 1e-10, the gap is the run's own error.  The default's check of a run that turned stiff
    (a second dopri5 at rtol / 10, bound 0.5 x 1e-3) and RK4's companion at twice the substeps
    (bound rk4_flag_rtol) each measure it within a factor 3; RK4 past its bound flags and warns,
    at its automatic substeps it is silent."""
    rig, u, ref = _stiff_friction_rig()
    for rtol in (1e-5, 1e-4):
        res = sh.simulate_multi(rig, u, 1 / 1024, options=sh.solver_options(rtol=rtol))
        assert res.work.stiff_samples > 0
        assert 1 / 3 <= res.work.error_estimate * 0.5e-3 / _multi_error(res, ref) <= 3, rtol
    # RK4 on two rigs of different gains, a square wave on one, a coarse loop sample.
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.G_p = 1.5 * a.G_p
    rig, dt = _two(a, b), 1 / 256
    t = np.arange(256) * dt
    u = np.c_[0.01 * np.sin(2 * np.pi * 3 * t), 0.008 * np.sign(np.sin(2 * np.pi * 2 * t))]
    ref = sh.simulate_multi(rig, u, dt, options=sh.solver_options("cvode", rtol=1e-10, max_steps_per_sample=100000))
    for n in (2, 3):
        res = sh.simulate_multi(rig, u, dt, options=sh.solver_options("rk4", rk4_substeps=n, rk4_flag_rtol=2e-3))
        err = _multi_error(res, ref)
        assert 1 / 3 <= res.work.error_estimate * 2e-3 / err <= 3, n
        assert (res.work.error_estimate > 1) == (err > 2e-3), n  # errors 3.9e-3 and 1.4e-3 of the peaks
        assert any("twice the RK4 substeps" in w for w in res.warnings()) == (err > 2e-3), n
    auto = sh.simulate_multi(rig, u, dt, options=sh.solver_options("rk4"))
    assert _multi_error(auto, ref) <= 1e-4
    assert auto.work.error_estimate <= 1 and not any("twice the RK4 substeps" in w for w in auto.warnings())


@pytest.mark.parametrize("text, needle", [
    ('[fixture]\narms = [0.3]\nangles = [0.1]\n[specimen]\nM = 5.0\n[[actuators]]\n', "specimen.M shape"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\n[specimen]\nM = [[5, 0], [0, 1]]\n'
     'K = [[1, 2], [3, 4]]\n[[actuators]]\n[[actuators]]\n', "invalid specimen.K[1][0] = 3"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\n[specimen]\nframe = "marths"\n'
     '[[actuators]]\n[[actuators]]\n[actuators.servovalve]\nK_v = -1.0\n', "invalid actuators[1].K_v = -1"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\n[specimen]\nframe = "marths"\n[[actuators]]\n',
     "invalid [[actuators]] (count) = 1"),
    ('[fixture]\narms = [0.3, "a"]\nangles = [0.1, -0.1]\n[specimen]\nframe = "marths"\n[[actuators]]\n'
     '[[actuators]]\n', "invalid fixture.arms[1] = 'a'"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\n[specimen]\nframe = "nope"\n[[actuators]]\n'
     '[[actuators]]\n', "invalid specimen.frame = 'nope'"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\nwidth = 3\n', "unknown key fixture.width"),
    ('[fixture]\narms = [0.3, 0.3]\nangles = [0.1, -0.1]\n[specimen]\nframe = "marths"\n[[actuators]]\n'
     'rig = "missing.toml"\n[[actuators]]\n', "rig file not found"),
])
def test_bad_rig_files(tmp_path, text, needle):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises((ValueError, FileNotFoundError)) as e:
        sh.load_multi_rig(path)
    assert needle in str(e.value) and str(path) in str(e.value)


def test_bad_commands_and_plant_calls():
    rig = _two(sh.zhao2003())
    with pytest.raises(ValueError, match=r"invalid commands shape = \(10, 3\)"):
        sh.simulate_multi(rig, np.zeros((10, 3)), 1e-3)
    u = np.zeros((10, 2))
    u[4, 1] = np.nan
    with pytest.raises(ValueError, match=r"invalid commands\[4, 1\] = nan"):
        sh.simulate_multi(rig, u, 1e-3)
    with pytest.raises(ValueError, match="invalid dt"):
        sh.simulate_multi(rig, np.zeros((10, 2)), 0.0)
    plant = rig.make_plant(1e-3)
    with pytest.raises(ValueError, match=r"invalid u \(length\) = 3"):
        plant.step([0.0, 0.0, 0.0])
    assert plant.step([0.001, 0.0]).ok()
    np.testing.assert_allclose(plant.displacements(), [plant.observe()["actuator1.stroke"],
                                                       plant.observe()["actuator2.stroke"]])


def test_calibrated_marths_rig_follows_the_identified_plant():
    """The committed rig files (studies/marths_rig_calibration.py) against the benchmark's identified
    plant: the band errors docs/multi-actuator.md states, recomputed from the files."""
    import json

    from shared_data import shared_path

    ss = json.loads(shared_path("marths-data/ID_Control_plant_100Hz_plantFRAME_SS.json").read_text())
    A, B, C, D = (np.asarray(ss[k], dtype=float) for k in "ABCD")
    f = np.logspace(-1, np.log10(50.0), 80)
    H_id = np.stack([C @ np.linalg.solve(2j * np.pi * fk * np.eye(A.shape[0]) - A, B) + D for fk in f])
    rig = sh.marths_rig()
    assert rig.actuators == 2 and rig.frame == "marths" and all(r.effects.coulomb_friction for r in rig.rigs)
    H = rig.frequency_response(f)
    rms = np.sqrt(np.mean((np.abs(H - H_id) / np.abs(H_id)) ** 2, axis=0))
    assert rms[0, 0] < 0.03 and rms[1, 0] < 0.02  # column 1 followed closely
    assert rms[0, 1] < 0.1 and rms[1, 1] < 0.1    # column 2: the compromise the docs explain
    dc = rig.frequency_response([0.0])[0].real
    np.testing.assert_allclose(dc, [[0.835, 0.127], [0.139, 0.877]], atol=2e-3)


def test_replace_marked_keeps_the_rest(tmp_path):
    from servohydraulics.atomic import replace_marked

    page = tmp_path / "page.md"
    page.write_text("head\n<!-- t -->\nold\n<!-- /t -->\ntail\n")
    replace_marked(page, "t", "new\n")
    assert page.read_text() == "head\n<!-- t -->\nnew\n<!-- /t -->\ntail\n"
    with pytest.raises(ValueError, match="marker <!-- u -->"):
        replace_marked(page, "u", "x")


def test_ros2_on_the_coupled_rig_is_second_order_and_stable_where_rk4_is_not():
    """ROS2 (the linearly implicit fixed-step method) on the coupled rig.  Two actuators of different
    gains, sines, a 2,048 Hz loop: against CVODE at rtol 1e-12 its error over every actuator's
    stroke and force falls about fourfold per doubling of the substeps (second order; at a coarse
    loop sample the stiff modes make it fall more slowly first, the order reduction of any
    Rosenbrock method).  Light pistons with sharp friction (the pair turns stiff there): at four
    substeps ROS2 is more than three times closer to CVODE than RK4 at four."""
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.G_p = 1.5 * a.G_p
    rig, dt = _two(a, b), 1 / 2048
    t = np.arange(2048) * dt
    u = np.c_[0.01 * np.sin(2 * np.pi * 3 * t), 0.008 * np.sin(2 * np.pi * 2 * t)]
    ref = sh.simulate_multi(rig, u, dt, options=sh.solver_options("cvode", rtol=1e-12, max_steps_per_sample=1000000))
    errs = [_multi_error(sh.simulate_multi(rig, u, dt, options=sh.solver_options("ros2", ros2_substeps=n)), ref)
            for n in (16, 32, 64)]
    assert 3.3 < errs[0] / errs[1] < 4.7 and 3.3 < errs[1] / errs[2] < 4.7, errs

    rig, u, ref = _stiff_friction_rig()
    ros2 = _multi_error(sh.simulate_multi(rig, u, 1 / 1024, options=sh.solver_options("ros2", ros2_substeps=4)), ref)
    rk4 = _multi_error(sh.simulate_multi(rig, u, 1 / 1024, options=sh.solver_options("rk4", rk4_substeps=4,
                                                                                       rk4_flag_rtol=0.0)), ref)
    assert 3 * ros2 < rk4, (ros2, rk4)
