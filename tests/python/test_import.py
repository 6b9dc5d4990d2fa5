"""The package as imported: ``import servohydraulics`` loads the library only (no SciPy,
pandas, python-control or matplotlib: they arrive with the names that need them, PEP 562),
every public name resolves, functions do not shadow their modules, and the plotting
backend is left alone.  Import checks run in a fresh interpreter, since this test
session has long imported everything."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import types
from pathlib import Path

import servohydraulics as sh

HEAVY = ("scipy", "pandas", "control", "matplotlib")


def _python(code: str, tmp_path) -> str:
    """Runs ``code`` in a new interpreter that imports the package this session tests (the
    installed one, or a source tree with SERVOHYDRAULICS_CORE_DIR) and returns its stdout."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(sh.__file__).resolve().parent.parent),
                                         *filter(None, [env.get("PYTHONPATH")])])
    if env.get("SERVOHYDRAULICS_CORE_DIR"):
        env["SERVOHYDRAULICS_CORE_DIR"] = str(Path(env["SERVOHYDRAULICS_CORE_DIR"]).resolve())
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return res.stdout.strip()


def _loaded() -> str:
    """Code printing (as JSON) which of HEAVY the interpreter has loaded so far."""
    return f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))\n"


def test_import_loads_no_heavy_dependency(tmp_path):
    code = "import json, sys\nimport servohydraulics as sh\n" + _loaded() + "sh.analysis\n" + _loaded()
    first, after_analysis = (json.loads(line) for line in _python(code, tmp_path).splitlines())
    assert first == [], f"import servohydraulics loaded {first}"
    assert "control" in after_analysis  # the lazy name brings its dependency


def test_public_names_resolve_lazily(tmp_path):
    """Every name of ``__all__`` and every lazy submodule resolves in a fresh interpreter;
    ``sh.sweep`` brings pandas and stays the function after its module is imported."""
    code = ("import importlib, json, sys, types\nimport servohydraulics as sh\n"
            "sweep = sh.sweep\n" + _loaded() +
            "importlib.import_module('servohydraulics.parameter_sweep')\n"
            "print(json.dumps({'kinds': {n: type(getattr(sh, n)).__name__ for n in sh.__all__},\n"
            "                  'subs': {n: isinstance(getattr(sh, n), types.ModuleType) for n in sh._SUBMODULES},\n"
            "                  'sweep_kept': sh.sweep is sweep}))\n")
    after_sweep, names = (json.loads(line) for line in _python(code, tmp_path).splitlines())
    assert "pandas" in after_sweep
    assert names["sweep_kept"]
    assert all(names["subs"].values()), names["subs"]
    assert set(names["kinds"]) == set(sh.__all__)
    assert names["kinds"]["sweep"] == names["kinds"]["diagnose"] == names["kinds"]["reproduce"] == "function"


def test_functions_do_not_shadow_their_modules():
    """sh.sweep, sh.diagnose, sh.reproduce stay functions after their modules are imported."""
    for name in ("sweep", "diagnose", "reproduce"):
        assert callable(getattr(sh, name)) and not isinstance(getattr(sh, name), type(sh))
    for module in ("servohydraulics.parameter_sweep", "servohydraulics.analysis", "servohydraulics.loops"):
        assert importlib.import_module(module).__name__ == module
    assert callable(sh.sweep) and sh.sweep.__module__ == "servohydraulics.parameter_sweep"
    assert isinstance(sh.parameter_sweep, types.ModuleType) and sh.parameter_sweep.sweep is sh.sweep
    assert "_core" not in sh.__all__
    assert sh.linearize is importlib.import_module("servohydraulics.analysis").linearize


def test_import_leaves_the_plotting_backend_alone(tmp_path):
    code = ("import matplotlib\nmatplotlib.use('svg')\n"
            "import servohydraulics as sh\nimport servohydraulics.plots, servohydraulics.analysis\n"
            "fig, ax = servohydraulics.plots.new_figure('t')\n"
            "print(matplotlib.get_backend())")
    assert _python(code, tmp_path) == "svg"
