"""The controller/plant seam: sh.make_plant and a controller stepped by hand
(sensors at t_k, then command, then plant step), as a laboratory wires a
controller to its rig's I/O, reproduce sh.run_eft / sh.run_rpsd sample for
sample (the same C++ arithmetic in the same order: equal to round-off, in fact
bit for bit)."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

import servohydraulics as sh

DT = 5e-4
N = 2000  # 1 s at 2 kHz
PLANT_CHANNELS = tuple(name for name, _ in sh._core.PLANT_CHANNELS)


def ground_motion(amplitude: float, f: float) -> np.ndarray:
    t = np.arange(N) * DT
    return amplitude * np.sin(2 * np.pi * f * t) * np.minimum(1.0, t)


def by_hand(plant, command) -> dict:
    """Steps the plant under command(k, sensors); returns the sensors and commands per row."""
    rows = {name: np.empty(N) for name in (*PLANT_CHANNELS, "command")}
    sensors = plant.observe()
    for k in range(N):
        u = command(k, sensors)
        for name in PLANT_CHANNELS:
            rows[name][k] = getattr(sensors, name)
        rows["command"][k] = u
        status, sensors = plant.step(u)
        assert status.ok(), status.message
    return rows


def assert_same(rows: dict, res) -> None:
    for name, x in rows.items():
        np.testing.assert_allclose(x, res.channels[name], rtol=1e-12, atol=1e-15, err_msg=name)


@pytest.mark.parametrize("compensation", ["linear", "nonlinear"])
@pytest.mark.parametrize("other_model", [False, True])
def test_eft_controller_reproduces_run_eft(compensation, other_model):
    rig = sh.zhao2003()
    model = sh.zhao2003()
    if other_model:  # the controller's knowledge differs from the plant
        model.K_v *= 1.2
        model.A *= 0.95
        model.m *= 1.1
    ag = ground_motion(2.0, 1.3)
    kw = {"compensation": compensation, "compute_delay": int(other_model)}
    res = sh.run_eft(rig, ground_acceleration=ag, model=model if other_model else None, **kw)
    # run_eft's P_eff uses the plant's mass; the controller knows only its model: say so.
    ctrl = sh.EftController(model if other_model else rig, mass=rig.m, **kw)
    plant = sh.make_plant(rig, "force", DT)
    rows = by_hand(plant, lambda k, s: ctrl.command(s, ground_acceleration=ag[k]))
    assert_same(rows, res)
    assert np.max(np.abs(res.compensation)) > 100.0  # the compensation did act


@pytest.mark.parametrize("scheme", ["central_difference", "explicit_newmark"])
@pytest.mark.parametrize("restoring_force", ["calculated_displacement", "measured_displacement", "measured_force",
                                             "measured_force_corrected"])
def test_rpsd_controller_reproduces_run_rpsd(scheme, restoring_force):
    rig = sh.zhao2003()
    ag = ground_motion(1.0, 1.1)
    pe = 2e3 * np.minimum(1.0, np.arange(N) * DT)
    fe = 50.0 * np.cos(0.01 * np.arange(N))
    kw = {"scheme": scheme, "restoring_force": restoring_force}
    res = sh.run_rpsd(rig, ground_acceleration=ag, external_force=pe, restoring_force_error=fe, **kw)
    ctrl = sh.RpsdController(rig, **kw)
    plant = sh.make_plant(rig, "displacement", DT)
    calc = np.empty(N)

    def command(k, s):
        out = ctrl.command_output(s, ground_acceleration=ag[k], external_force=pe[k], restoring_force_error=fe[k])
        calc[k] = out.calc_displacement
        return out.command

    assert_same(by_hand(plant, command), res)
    np.testing.assert_allclose(calc, res.calc_displacement, rtol=1e-12, atol=1e-15)


def test_rpsd_substructured_pressure_option_through_the_seam():
    """Option (d) on p A with 2 % physical mass: the controller is given the physical rig."""
    rig = sh.zhao2003()
    pe = 1e4 * np.minimum(1.0, np.arange(N) * DT)
    kw = {"scheme": "explicit_newmark", "restoring_force": "measured_force_corrected",
          "force_measurement": "actuator_pressure"}
    res = sh.run_rpsd(rig, external_force=pe, physical_mass_fraction=0.02, **kw)
    physical = copy.copy(rig)
    physical.m = 0.02 * 7084.0
    ctrl = sh.RpsdController(physical, **kw)
    assert ctrl.subtract_mass == pytest.approx(physical.m + physical.m_p)
    plant = sh.make_plant(physical, "displacement", DT)
    assert_same(by_hand(plant, lambda k, s: ctrl.command(s, external_force=pe[k])), res)


def test_reset_restarts_the_controller():
    rig = sh.zhao2003()
    ctrl = sh.RpsdController(rig, restoring_force="calculated_displacement")
    s = sh.make_plant(rig, "displacement").observe()
    first = [ctrl.command(s, external_force=1e3) for _ in range(5)]
    ctrl.reset()
    again = [ctrl.command(s, external_force=1e3) for _ in range(5)]
    assert first == again and first[-1] > 0.0


def test_none_means_the_rigs_value_and_bad_values_name_the_field():
    rig = sh.zhao2003()
    ctrl = sh.RpsdController(rig, k_m=None, subtract_mass=None, subtract_damping=None)
    assert (ctrl.k_m, ctrl.subtract_mass, ctrl.subtract_damping) == (rig.k, rig.m, rig.c)
    assert ctrl.config.k_m is None
    assert sh.EftController(rig).mass == rig.m
    with pytest.raises(ValueError, match="k_m = -1"):
        sh.RpsdController(rig, k_m=-1.0)
    with pytest.raises(ValueError, match="mass = 0"):
        sh.EftController(rig, mass=0.0)


def test_defaults_are_the_cores_constants():
    tm = sh._core.ZHAO2003_TEST_METHODS
    assert (tm.dt, tm.eft_lead_T, tm.amplitude_T, tm.delay_T, tm.alpha) == (5e-4, 5e-3, 68e-3, 11.2e-3, 0.1)
    assert (tm.model.m_m, tm.model.c_m) == (7084.0, 3.5e3)
    cfg = sh._core.RpsdConfig()
    assert (cfg.amplitude_T, cfg.delay_T, cfg.model.m_m) == (tm.amplitude_T, tm.delay_T, tm.model.m_m)
    assert sh._core.EftConfig().lead_T == tm.eft_lead_T
    names = [n for n, _ in sh._core.RPSD_CHANNELS]
    res = sh.run_rpsd(sh.zhao2003(), external_force=np.ones(10))
    assert set(names) <= set(res.channels)


def test_renamed_keywords_warn_and_agree():
    rig = sh.zhao2003()
    pe = np.ones(200) * 1e3
    new = sh.run_rpsd(rig, external_force=pe, scheme="explicit_newmark", solver_options=sh.solver_options())
    with pytest.warns(DeprecationWarning, match="solver= is deprecated"):
        old = sh.run_rpsd(rig, external_force=pe, solver="explicit_newmark")
    with pytest.warns(DeprecationWarning, match="options= is deprecated"):
        sh.run_eft(rig, ground_acceleration=np.zeros(10), options=sh.solver_options())
    np.testing.assert_array_equal(new.calc_displacement, old.calc_displacement)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        with pytest.raises(ValueError, match="not both"):
            sh.run_rpsd(rig, external_force=pe, scheme="central_difference", solver="explicit_newmark")
