"""One name table per enum and one field table for SolverOptions, in the C++ core
(enum_name.hpp, solver_options.hpp): the binding's enums, the Python layer's
dictionaries, ``solver_options``'s keywords and the CLI's choices all read them
(the FMU's items: test_fmu.py).  A name typed out a second time anywhere fails here."""

from __future__ import annotations

import argparse
import inspect

import numpy as np
import pytest

import servohydraulics as sh
from servohydraulics import _core, loops, rig
from servohydraulics.cli import build_parser
from servohydraulics.simulate import DEFAULT_METHOD, METHODS, MODES, RESTARTS

#: (Python dictionary, core table, the binding's enum type)
TABLES = {
    "modes": (MODES, _core.CONTROL_MODE_NAMES, _core.ControlMode),
    "methods": (METHODS, _core.METHOD_NAMES, _core.SolverOptions.Method),
    "restarts": (RESTARTS, _core.RESTART_NAMES, _core.SolverOptions.Restart),
    "compensation": (loops.COMPENSATION, _core.COMPENSATION_NAMES, _core.VelocityFeedbackCompensator.Kind),
    "schemes": (loops.STRUCTURAL_SCHEMES, _core.SCHEME_NAMES, _core.StructuralScheme),
    "restoring_force": (loops.RESTORING_FORCE, _core.RESTORING_FORCE_NAMES, _core.RestoringForce),
    "force_measurement": (loops.FORCE_MEASUREMENT, _core.FORCE_MEASUREMENT_NAMES, _core.ForceMeasurement),
    "flow_curve_kind": (rig.FLOW_CURVE_KINDS, _core.FLOW_CURVE_KIND_NAMES, _core.FlowCurve.Kind),
}


def test_eq15_schemes_are_the_first_rows_of_the_scheme_table():
    """run_rpsd's scheme= (Eq 15 itself) takes the first two structural schemes; the others need a
    LinearSubstructure, and Eq (15) refuses them by name."""
    assert list(loops.SCHEMES.items()) == list(_core.SCHEME_NAMES)[:2]
    with pytest.raises(Exception, match="scheme"):
        sh.run_rpsd(sh.zhao2003(), np.zeros(10), scheme="runge_kutta4")


@pytest.mark.parametrize("key", TABLES)
def test_python_names_are_the_core_table(key):
    names, table, enum = TABLES[key]
    assert list(names.items()) == list(table)
    # one row per enumerator, in the enum's order (the FMU stores the index)
    assert [int(value) for _, value in table] == list(range(len(enum.__members__)))
    assert {value for _, value in table} == set(enum.__members__.values())


def test_solver_option_fields_drive_the_binding_and_solver_options():
    fields = [f["name"] for f in _core.SOLVER_OPTION_FIELDS]
    o = _core.SolverOptions()
    assert repr(o).startswith("SolverOptions(" + fields[0] + "=")
    assert [part.split("=")[0] for part in repr(o)[len("SolverOptions("):-1].split(", ")] == fields
    assert set(inspect.signature(sh.solver_options).parameters) == set(fields)
    # solver_options() is the core's default, field by field; every keyword reaches its field
    assert sh.solver_options() == o
    changed = sh.solver_options(method="cvode", restart="never", rtol=1e-6, atol_fraction=0.1, max_order=3,
                                max_steps_per_sample=500, max_internal_step=1e-4, stiff_steps=10,
                                stiff_fallback=False, stiff_check=False, rk4_substeps=4, rk4_h_rho=0.5, rk4_v_ref=0.2,
                                rk4_flag_rtol=1e-4, rk4_max_refinements=2, ros2_substeps=8, stiff_rosenbrock=True,
                                rosenbrock_order=4, stiffness_test=True)
    assert all(getattr(changed, f) != getattr(o, f) for f in fields), changed


def test_default_method_is_the_cores():
    assert METHODS[DEFAULT_METHOD] == _core.SolverOptions().method
    assert inspect.signature(sh.solver_options).parameters["method"].default == DEFAULT_METHOD


def _option(command: str, flag: str) -> argparse.Action:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return next(a for a in sub.choices[command]._actions if flag in a.option_strings)


@pytest.mark.parametrize("command", ["compare", "fmu"])
def test_cli_method_choices_are_the_table(command):
    assert list(_option(command, "--method").choices) == [n for n, _ in _core.METHOD_NAMES]


def test_cli_defaults_and_modes():
    assert _option("fmu", "--method").default == DEFAULT_METHOD == "dopri5"
    assert tuple(_option("fmu", "--kind").choices) == _core.FMU_KINDS == ("plant", "eft", "rpsd")
    for command in ("simulate", "diagnose", "fmu"):
        assert list(_option(command, "--mode").choices) == [n for n, _ in _core.CONTROL_MODE_NAMES]


def test_cli_accepts_and_lists_every_method(capsys):
    for name, _ in _core.METHOD_NAMES:
        args = build_parser().parse_args(["compare", "r.csv", "--rig", "r.toml", "--mode", "force", "--out", "o",
                                          "--method", name])
        assert args.method == name
    with pytest.raises(SystemExit):
        build_parser().parse_args(["fmu", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert all(name in text for name, _ in _core.METHOD_NAMES)


# ----------------------------------------------------------------- the loop configs' field tables
#: (config class, its field table, the Python builder): the controllers' configs (controllers.hpp)
CONFIGS = {
    "eft": (_core.EftConfig, _core.EFT_CONFIG_FIELDS, loops.eft_config),
    "rpsd": (_core.RpsdConfig, _core.RPSD_CONFIG_FIELDS, loops.rpsd_config),
}
#: the simulated loops' own settings (loops.hpp), by the same kinds
LOOP_OPTIONS = {
    "eft": (_core.EftLoopOptions, _core.EFT_LOOP_OPTION_FIELDS, loops.eft_loop_options),
    "rpsd": (_core.RpsdLoopOptions, _core.RPSD_LOOP_OPTION_FIELDS, loops.rpsd_loop_options),
}
#: the Python keywords of a field whose keyword is not its name (the signatures predate the tables)
KEYWORDS = {"plant_options": ["solver_options"], "model": [n for n, _, _ in _core.MODEL_SDOF_FIELDS]}
assert {k: list(v) for k, v in loops.FIELD_KEYWORDS.items()} == KEYWORDS


def _writable(cls) -> list[str]:
    return sorted(n for n in dir(cls) if isinstance(getattr(cls, n), property) and getattr(cls, n).fset is not None)


def _keywords(table) -> list[str]:
    return [k for n, _, _ in table for k in KEYWORDS.get(n, [n])]


@pytest.mark.parametrize("kind", CONFIGS)
def test_config_table_is_the_bindings_attributes(kind):
    """Every field of kEftConfigFields / kRpsdConfigFields (and of the loops' kEftLoopOptionFields /
    kRpsdLoopOptionFields) is a read-write attribute of the binding's class, and the class has no
    other (the same for ModelSDOF's table)."""
    for cls, table, _ in (CONFIGS[kind], LOOP_OPTIONS[kind]):
        assert _writable(cls) == sorted(n for n, _, _ in table)
    assert _writable(_core.ModelSDOF) == sorted(n for n, _, _ in _core.MODEL_SDOF_FIELDS)


def test_a_controller_config_holds_no_simulation_field():
    """The controllers' configs and the simulated loops' options share no field: a plant's
    integrator or mass is not a real-time controller's setting."""
    for kind in CONFIGS:
        config = {n for n, _, _ in CONFIGS[kind][1]}
        options = {n for n, _, _ in LOOP_OPTIONS[kind][1]}
        assert not config & options, kind
        assert "plant_options" in options and "plant_options" not in config
    assert "physical_mass_fraction" in {n for n, _, _ in _core.RPSD_LOOP_OPTION_FIELDS}


def _fmu_parameters(kind: str) -> list[dict]:
    v = _core.fmu_variables(kind, "displacement", sh.zhao2003(), 5e-4, 0.0, _core.SolverOptions(),
                            _core.EftConfig(), _core.RpsdConfig())
    return [x for x in v if x["name"].startswith(kind + ".")]


@pytest.mark.parametrize("kind", CONFIGS)
def test_config_table_is_the_fmus_parameters(kind):
    """The controller FMU's "<kind>.*" parameters are the table's fields in table order (a nested
    struct's fields flattened: rpsd.m_m), with the table's unit and meaning, every field but dt,
    which is the FMU's own parameter "dt" (cpp/fmu/model.cpp add_field): no field is skipped."""
    _, table, _ = CONFIGS[kind]
    assert not hasattr(_core, "FMU_CONFIG_FIELDS_SKIPPED")  # no skip list
    expected = []
    for name, unit, meaning in table:
        if name == "dt":
            continue
        rows = _core.MODEL_SDOF_FIELDS if name == "model" else [(name, unit, meaning)]
        expected += [(f"{kind}.{n}", u, m) for n, u, m in rows]
    got = _fmu_parameters(kind)
    assert [x["name"] for x in got] == [n for n, _, _ in expected]
    for x, (name, unit, meaning) in zip(got, expected):
        assert x["causality"] == "parameter" and x["description"] == meaning, name
        assert x["unit"] == unit or x["type"] != "Real", name  # FMI 2 units are on Reals only
    # export_fmu's settings are the FMU's parameters (the keywords of their fields)
    from servohydraulics import fmu

    assert sorted(n.split(".", 1)[1] for n, _, _ in expected) == sorted(fmu.settings(kind))
    # dt: the FMU's own parameter, copied into the config
    assert "dt" in {x["name"] for x in _core.fmu_variables(kind, "displacement", sh.zhao2003(), 5e-4, 0.0,
                                                           _core.SolverOptions(), _core.EftConfig(),
                                                           _core.RpsdConfig())}


@pytest.mark.parametrize("kind", CONFIGS)
def test_config_table_is_the_python_keywords(kind):
    """eft_config / rpsd_config (and the controllers) take one keyword per field of the config's
    table, eft_loop_options / rpsd_loop_options one per field of the loop's; run_eft / run_rpsd
    take both; a keyword set to a non-default value changes exactly its field; a field added to a
    table and not to the builder fails every call."""
    run = {"eft": sh.run_eft, "rpsd": sh.run_rpsd}[kind]
    ctrl = {"eft": sh.EftController, "rpsd": sh.RpsdController}[kind]
    config_keywords = _keywords(CONFIGS[kind][1])
    assert sorted(set(inspect.signature(ctrl).parameters) - {"rig"}) == sorted(config_keywords)
    opts = _core.SolverOptions()
    opts.rtol = 1e-9
    changed = {"dt": 1e-3, "mass": 100.0, "compensation": "nonlinear", "lead_T": 0.01, "alpha": 0.2,
               "compute_delay": 1, "solver_options": opts, "m_m": 100.0, "c_m": 10.0, "k_m": 1e6,
               "scheme": "explicit_newmark", "restoring_force": "measured_force",
               "force_measurement": "actuator_pressure", "amplitude_T": 0.05, "delay_T": 0.01,
               "physical_mass_fraction": 0.5, "subtract_mass": 10.0, "subtract_damping": 5.0}
    for _, table, build in (CONFIGS[kind], LOOP_OPTIONS[kind]):
        keywords = _keywords(table)
        assert sorted(inspect.signature(build).parameters) == sorted(keywords)
        assert set(keywords) <= set(inspect.signature(run).parameters)
        for name, unit, _ in table:
            assert f"{name} [{unit}]" in build.__doc__ if unit else f"    {name}: " in build.__doc__
        default = build()
        for name, _, _ in table:
            cfg = build(**{k: changed[k] for k in KEYWORDS.get(name, [name])})
            differs = [n for n, _, _ in table if getattr(cfg, n) != getattr(default, n)]
            assert differs == [name], (name, differs)
    for name, _, _ in CONFIGS[kind][1]:
        assert f"    {name}" in ctrl.__doc__


def test_a_field_added_to_the_table_fails_the_python_builders(monkeypatch):
    extra = ("new_field", "s", "a field no builder knows")
    monkeypatch.setattr(_core, "EFT_CONFIG_FIELDS", [*_core.EFT_CONFIG_FIELDS, extra])
    with pytest.raises(TypeError, match="new_field"):
        loops.eft_config()
    monkeypatch.setattr(_core, "RPSD_CONFIG_FIELDS", [*_core.RPSD_CONFIG_FIELDS, extra])
    with pytest.raises(TypeError, match="new_field"):
        loops.rpsd_config()
    for table, build in (("EFT_LOOP_OPTION_FIELDS", loops.eft_loop_options),
                         ("RPSD_LOOP_OPTION_FIELDS", loops.rpsd_loop_options)):
        monkeypatch.setattr(_core, table, [*getattr(_core, table), extra])
        with pytest.raises(TypeError, match="new_field"):
            build()
