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
                                stiff_fallback=False, rk4_substeps=4, rk4_h_rho=0.5, rk4_v_ref=0.2,
                                rk4_flag_rtol=1e-4, rk4_max_refinements=2)
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
