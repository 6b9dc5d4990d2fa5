"""The object protocol of the parameter aggregates, from the binding
(bindings/protocol.hpp): repr, ==, copy, deepcopy, pickle; and the parameter
table (parameters.hpp) that drives Rig.validate(), the binding and rig.PARAMETERS."""

from __future__ import annotations

import copy
import math
import pickle
from concurrent.futures import ProcessPoolExecutor

import pytest

import servohydraulics as sh
from servohydraulics import _core


def changed_rig() -> sh.Rig:
    r = sh.zhao2003()
    r.k = 6.5e5
    r.effects.lugre_friction = True
    fc = r.flow_curve
    fc.flow = [0.0, 0.1, 0.2, 0.28, 0.35, 0.4, 0.5, 0.6]
    r.flow_curve = fc
    return r


def configs():
    e = _core.EftConfig()
    e.mass = 140.0
    e.compensation = _core.VelocityFeedbackCompensator.Kind.Nonlinear
    r = _core.RpsdConfig()
    r.k_m = 6e5
    r.scheme = _core.IntegrationScheme.ExplicitNewmark
    r.model = _core.ModelSDOF(140.0, 100.0)
    o = _core.RpsdLoopOptions()
    o.plant_options.method = _core.SolverOptions.Method.Rk4
    o.physical_mass_fraction = 0.02
    eo = _core.EftLoopOptions()
    eo.plant_options.rtol = 1e-9
    return [changed_rig(), changed_rig().effects, changed_rig().flow_curve, e, r, _core.ModelSDOF(1.0, 2.0),
            o.plant_options, o, eo]


@pytest.mark.parametrize("obj", configs(), ids=lambda o: type(o).__name__)
def test_round_trips_are_equal_and_independent(obj):
    for clone in (copy.copy(obj), copy.deepcopy(obj), pickle.loads(pickle.dumps(obj))):
        assert clone == obj and not (clone != obj)
        assert clone is not obj
        assert type(clone) is type(obj)
        assert repr(clone) == repr(obj)


def test_equality_detects_every_changed_field():
    base = sh.zhao2003()
    for p in sh.PARAMETERS:
        r = copy.copy(base)
        setattr(r, p.key, getattr(r, p.key) * 1.5 + 1.0)
        assert r != base, p.key
    for name in sh.rig.EFFECTS:
        r = copy.deepcopy(base)
        setattr(r.effects, name, not getattr(r.effects, name))
        assert r != base, name
    assert changed_rig() != base
    r = copy.copy(base)
    r.flow_curve = _core.FlowCurve()  # the rational curve
    assert r != base
    assert base != "a rig" and base == sh.zhao2003()
    c = _core.RpsdConfig()
    d = copy.copy(c)
    d.subtract_mass = 0.0  # given (0) is not none
    assert c != d and c.subtract_mass is None


def test_copy_is_independent():
    a = sh.zhao2003()
    b = sh.copy_rig(a)
    b.m = 1.0
    b.effects.coulomb_friction = False
    assert a.m == 7084.0 and a.effects.coulomb_friction


def test_repr_names_fields_and_values():
    r = repr(sh.zhao2003())
    assert r.startswith("Rig(m=7084.0, c=2100.0") and "effects=Effects(servovalve_dynamics=True" in r
    assert "k_m=None" in repr(_core.RpsdConfig())


def _k_of(rig: sh.Rig) -> float:
    return rig.k


def test_rigs_cross_a_process_pool():
    rigs = [changed_rig(), sh.zhao2003(actuator_attached=False)]
    with ProcessPoolExecutor(max_workers=1) as pool:
        assert list(pool.map(_k_of, rigs)) == [r.k for r in rigs]


def test_parameter_table_drives_validation_and_binding():
    rows = _core.RIG_PARAMETERS
    default = sh.Rig()
    assert [p.key for p in sh.PARAMETERS] == [row["key"] for row in rows]
    for row in rows:
        assert getattr(default, row["key"]) == row["default"]
        bad = {"finite and > 0": (0.0,), "finite and >= 0": (-1.0,), "finite and >= 1": (0.5,),
               "an integer in 1..6": (0.0, 2.5, 7.0), "finite": ()}[row["bound"]]
        for value in (*bad, math.nan, math.inf):
            r = sh.Rig()
            setattr(r, row["key"], value)
            with pytest.raises(ValueError, match=rf"invalid {row['key']} = .*must be {row['bound']} \["):
                r.validate()
    assert [e["key"] for e in _core.EFFECTS] == list(sh.rig.EFFECTS)
    assert all(getattr(default.effects, e["key"]) == e["default"] for e in _core.EFFECTS)


@pytest.mark.parametrize("obj", configs(), ids=lambda o: type(o).__name__)
def test_protocol_covers_every_writable_field(obj):
    """The protocol's hand-written field list names every settable attribute of the binding
    (a field added to the struct and bound but left out of add_protocol would fail here)."""
    cls = type(obj)
    writable = [n for n in dir(cls) if isinstance(getattr(cls, n), property) and getattr(cls, n).fset is not None]
    assert writable
    state = obj.__getstate__()
    assert sorted(state) == sorted(writable)
    text = repr(obj)
    assert all(f"{n}=" in text for n in writable)


def test_config_field_tables_drive_the_loop_configs():
    """kEftConfigFields / kRpsdConfigFields (controllers.hpp) are the configs' attributes, in the
    order the protocol's repr uses, each with a unit and a meaning; pickling keeps every one."""
    for cls, table in ((_core.EftConfig, _core.EFT_CONFIG_FIELDS), (_core.RpsdConfig, _core.RPSD_CONFIG_FIELDS)):
        names = [name for name, _, _ in table]
        obj = cls()
        assert all(hasattr(obj, n) for n in names)
        assert all(isinstance(unit, str) and meaning for _, unit, meaning in table)
        text = repr(obj)
        assert text.startswith(f"{cls.__name__}({names[0]}=")
        positions = [text.index(f"{n}=") for n in names]
        assert positions == sorted(positions)
        assert pickle.loads(pickle.dumps(obj)) == obj
    assert [n for n, _, _ in _core.RPSD_CONFIG_FIELDS][:4] == ["dt", "model", "k_m", "scheme"]
