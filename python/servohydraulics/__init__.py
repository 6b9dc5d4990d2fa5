"""servohydraulics: servo-hydraulic actuators for real-time dynamic testing.

A C++17 core (SUNDIALS CVODE, Eigen) with a thin Python layer, after
Zhao, French, Shield, Posbergh (2003), Earthquake Engng Struct. Dyn. 32:1773-1794.

    import servohydraulics as sh
    rig = sh.zhao2003()
    res = sh.simulate(rig, mode="displacement", command=u, dt=0.0005)
    res.displacement, res.units["displacement"], res.warnings(), res.to_pandas()

Importing the package loads the library (model, integration, control loops,
records) only, and no SciPy.  The heavier parts load on first use (PEP 562): ``analysis``
(python-control), ``sweep`` (pandas; the module is ``parameter_sweep``, so the
name ``sweep`` is only ever the function), the diagnosis and the paper's
reproduction (matplotlib).  Importing the package never touches matplotlib's
backend.
"""

import importlib as _importlib
import os as _os

# Development hook: SERVOHYDRAULICS_CORE_DIR names a CMake build directory whose
# _core module is used instead of an installed one (scripts/dev-build.sh).
if _os.environ.get("SERVOHYDRAULICS_CORE_DIR"):
    __path__.insert(0, _os.environ["SERVOHYDRAULICS_CORE_DIR"])

try:
    from . import _core  # noqa: E402, F401 - fails here, with the message below, when the core is not built
except ImportError as e:  # pragma: no cover - only without a built core
    raise ImportError(
        "the servohydraulics C++ core (_core) is not built here: install the package "
        "(pip install . or bash scripts/run.sh test), or point SERVOHYDRAULICS_CORE_DIR at a "
        f"build directory made by scripts/dev-build.sh ({e})"
    ) from e

from ._core import ConcurrentUseError, ControlMode, Dynamics, FlowCurve, Plant, SolverOptions  # noqa: E402
from .controllers import EftController, RpsdController  # noqa: E402
from .loops import linear_substructure, loop_converters, run_eft, run_rpsd, run_tracking, sensor_channel  # noqa: E402
from .records import read_record, write_record  # noqa: E402
from .response import Response, SimulationError  # noqa: E402
from .rig import (  # noqa: E402
    PARAMETERS,
    Error,
    Rig,
    copy_rig,
    load_rig,
    rig_from_dict,
    rig_to_dict,
    save_rig,
    zhao2003,
)
from .simulate import make_plant, simulate, solver_options  # noqa: E402

__version__ = "0.1.0"

#: Lazily imported submodules (first attribute access imports them).
_SUBMODULES = ("analysis", "identification", "excitations", "parameter_sweep", "plots", "diagnosis", "paper")

#: Lazily resolved names: name -> (module, attribute).
_LAZY = {
    "linearize": (".analysis", "linearize"),
    "identify": (".identification", "identify"),
    "sweep": (".parameter_sweep", "sweep"),
    "summary_run": (".parameter_sweep", "summary_run"),
    "diagnose": (".diagnosis", "diagnose"),
    "Diagnosis": (".diagnosis", "Diagnosis"),
    "reproduce": (".paper.reproduce", "reproduce"),
    "export_fmu": (".fmu", "export_fmu"),
    "MultiActuatorRig": (".multi_rig", "MultiActuatorRig"),
    "load_multi_rig": (".multi_rig", "load_multi_rig"),
    "save_multi_rig": (".multi_rig", "save_multi_rig"),
    "simulate_multi": (".multi_rig", "simulate_multi"),
    "marths_rig": (".multi_rig", "marths_rig"),
    "marths_frame": (".multi_rig", "marths_frame"),
    "node_specimen": (".multi_rig", "node_specimen"),
}

#: Deprecated names, kept for one release: name -> (replacement, object).
_DEPRECATED = {
    "TestMethodError": ("SimulationError", SimulationError),
    "SimulationResult": ("Response", Response),
    "MethodResult": ("Response", Response),
}


def _resolve(name: str):
    module, attr = _LAZY[name]
    return getattr(_importlib.import_module(module, __name__), attr)


def __getattr__(name: str):
    if name in _LAZY:
        return _resolve(name)
    if name in _SUBMODULES:
        return _importlib.import_module(f".{name}", __name__)
    if name in _DEPRECATED:
        import warnings

        new, obj = _DEPRECATED[name]
        warnings.warn(f"servohydraulics.{name} is deprecated; use servohydraulics.{new}", DeprecationWarning,
                      stacklevel=2)
        return obj
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | set(_SUBMODULES))


__all__ = [
    "PARAMETERS",
    "ConcurrentUseError",
    "ControlMode",
    "Diagnosis",
    "Dynamics",
    "EftController",
    "Error",
    "FlowCurve",
    "Plant",
    "Response",
    "Rig",
    "RpsdController",
    "SimulationError",
    "SolverOptions",
    "copy_rig",
    "diagnose",
    "export_fmu",
    "identify",
    "linearize",
    "load_rig",
    "make_plant",
    "read_record",
    "reproduce",
    "rig_from_dict",
    "rig_to_dict",
    "run_eft",
    "run_rpsd",
    "linear_substructure",
    "run_tracking",
    "save_rig",
    "simulate",
    "solver_options",
    "summary_run",
    "sweep",
    "write_record",
    "zhao2003",
    "loop_converters",
    "sensor_channel",
    "MultiActuatorRig",
    "load_multi_rig",
    "marths_frame",
    "marths_rig",
    "node_specimen",
    "save_multi_rig",
    "simulate_multi",
]
