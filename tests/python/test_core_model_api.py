"""The core's model numerics that Python uses instead of re-deriving them
(`Dynamics.operating_point`, `Dynamics.structure_forces`,
`rk4_automatic_substeps`, the channel and state tables, `linearize_dynamics`),
checked against contracts: the plant held at the operating point stays at rest,
the structure force is what the equation of motion subtracts, the RK4 rule is
the one the plant applies, and the tables name what the record holds."""

from __future__ import annotations

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core

MODES = {"displacement": _core.ControlMode.Displacement, "force": _core.ControlMode.Force,
         "free": _core.ControlMode.Free}


@pytest.mark.parametrize("mode", list(MODES))
@pytest.mark.parametrize("x0", [0.0, 0.008, -0.025])
def test_operating_point_holds_the_plant_at_rest(mode: str, x0: float, dt: float) -> None:
    plant = _core.Plant(sh.zhao2003(), MODES[mode], dt)
    y0, u0 = plant.dynamics.operating_point(x0)
    assert isinstance(y0, np.ndarray) and y0.shape == (_core.NUM_STATES,)
    np.testing.assert_array_equal(y0, plant.dynamics.equilibrium(x0))
    plant.reset_state(y0)
    for _ in range(200):
        status, out = plant.step(u0)
        assert status.ok()
    assert out.displacement == pytest.approx(x0, abs=1e-6 * max(abs(x0), 1e-3))
    assert abs(out.velocity) < 1e-6


def test_structure_forces_is_the_force_the_equation_of_motion_subtracts(make_rig) -> None:
    rig = make_rig(stribeck_ratio=1.5)
    rig.effects.lugre_friction = True
    dyn = _core.Dynamics(rig, _core.ControlMode.Free)
    rng = np.random.default_rng(7)
    x, v = rng.uniform(-0.03, 0.03, 50), rng.uniform(-0.3, 0.3, 50)
    z = rng.uniform(-1, 1, 50) * rig.F_c / rig.sigma_0
    u = rng.uniform(-2e4, 2e4, 50)
    F = dyn.structure_forces(x, v, z)
    assert F.shape == x.shape
    a = np.array([dyn.rhs([xi, vi, 0, 0, 0, zi], ui)[1] for xi, vi, zi, ui in zip(x, v, z, u)])
    np.testing.assert_allclose(dyn.moving_mass * a, u - F, rtol=1e-12, atol=1e-9)
    # Broadcasting: a scalar x against an array of velocities; z defaults to 0.
    assert dyn.structure_forces(0.01, v).shape == v.shape
    assert isinstance(dyn.structure_forces(0.01, 0.1), float)


@pytest.mark.parametrize("lugre", [False, True])
@pytest.mark.parametrize("mode", list(MODES))
def test_rk4_automatic_substeps_is_the_rule_the_plant_applies(mode: str, lugre: bool, dt: float) -> None:
    rig = sh.zhao2003()
    rig.effects.lugre_friction = lugre
    opt = _core.SolverOptions()
    opt.method = _core.SolverOptions.Method.Rk4
    plant = _core.Plant(rig, MODES[mode], dt, opt)
    assert _core.rk4_automatic_substeps(plant.dynamics, dt, opt) == plant.rk4_substeps
    opt.rk4_v_ref = 40.0
    faster = _core.rk4_automatic_substeps(plant.dynamics, dt, opt)
    assert faster > plant.rk4_substeps if lugre else faster == plant.rk4_substeps
    opt.rk4_v_ref = -1.0
    with pytest.raises(ValueError, match="rk4_v_ref = -1"):
        _core.rk4_automatic_substeps(plant.dynamics, dt, opt)


def test_channel_and_state_tables_name_what_the_core_returns(dt: float) -> None:
    names = [name for name, _ in _core.PLANT_CHANNELS]
    assert names[0] == "time" and dict(_core.PLANT_CHANNELS)["force"] == "N"
    plant = _core.Plant(sh.zhao2003(), _core.ControlMode.Displacement, dt)
    channels, summary = _core.run_record(plant, np.full(10, 1e-3))
    assert list(channels) == names + ["flags", "internal_steps", "rhs_evals"]
    out = plant.observe()
    assert [getattr(out, n) for n in names[1:]] == [channels[n][-1] for n in names[1:]]
    assert out.time == channels["time"][-1] and not hasattr(out, "t")  # Output.t was renamed time
    states = [name for name, _ in _core.STATES]
    assert states == list(_core.StateIndex.__members__)
    assert [int(_core.StateIndex.__members__[s]) for s in states] == list(range(_core.NUM_STATES))


def test_linearize_dynamics_is_the_core_linearization() -> None:
    dyn = _core.Dynamics(sh.zhao2003(), _core.ControlMode.Displacement)
    y0, u0 = dyn.operating_point(0.004)
    a = _core.linearize_dynamics(dyn, y0, u0)
    assert not hasattr(_core, "linearize")  # one name: sh.linearize is the analysis one (StateSpace)
    J = np.array(dyn.jacobian(list(y0), u0))
    np.testing.assert_array_equal(a.A, J)  # A is the analytic Jacobian at the operating point
    f0 = np.array(dyn.rhs(list(y0), u0))
    f1 = np.array(dyn.rhs(list(y0), u0 + 1e-6))
    np.testing.assert_allclose((f1 - f0) / 1e-6, a.B, rtol=1e-5, atol=1e-6 * np.abs(a.B).max())
