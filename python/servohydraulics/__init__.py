"""servohydraulics: servo-hydraulic actuators for real-time dynamic testing.

A C++17 core (SUNDIALS CVODE, Eigen) with a thin Python layer, after
Zhao, French, Shield, Posbergh (2003), Earthquake Engng Struct. Dyn. 32:1773-1794.

    import servohydraulics as sh
    rig = sh.zhao2003()
    res = sh.simulate(rig, mode="displacement", command=u, dt=0.0005)
"""

import os as _os

# Development hook: SERVOHYDRAULICS_CORE_DIR names a CMake build directory whose
# _core module is used instead of an installed one (scripts/dev-build.sh).
if _os.environ.get("SERVOHYDRAULICS_CORE_DIR"):
    __path__.insert(0, _os.environ["SERVOHYDRAULICS_CORE_DIR"])

try:
    from . import _core  # noqa: E402
except ImportError as e:  # pragma: no cover - only without a built core
    raise ImportError(
        "the servohydraulics C++ core (_core) is not built here: install the package "
        "(pip install . or bash scripts/run.sh test), or point SERVOHYDRAULICS_CORE_DIR at a "
        f"build directory made by scripts/dev-build.sh ({e})"
    ) from e

from . import analysis, identify  # noqa: E402
from ._core import ControlMode, Dynamics, FlowCurve, Plant, SolverOptions, linearize
from .controllers import EftController, RpsdController
from .diagnose import Diagnosis, diagnose  # the function shadows the subpackage name
from .methods import MethodResult, TestMethodError, run_eft, run_rpsd, run_tracking
from .records import read_record, write_record
from .reproduce import reproduce  # the function shadows the module name
from .rig import PARAMETERS, Error, Rig, copy_rig, load_rig, rig_from_dict, rig_to_dict, save_rig, zhao2003
from .simulate import SimulationError, SimulationResult, make_plant, simulate, solver_options
from .sweep import summary_run, sweep

__version__ = "0.1.0"

__all__ = [
    "PARAMETERS",
    "ControlMode",
    "Diagnosis",
    "Dynamics",
    "EftController",
    "Error",
    "FlowCurve",
    "MethodResult",
    "Plant",
    "Rig",
    "RpsdController",
    "SimulationError",
    "SimulationResult",
    "SolverOptions",
    "TestMethodError",
    "_core",
    "copy_rig",
    "diagnose",
    "linearize",
    "load_rig",
    "make_plant",
    "read_record",
    "rig_from_dict",
    "rig_to_dict",
    "run_eft",
    "run_rpsd",
    "run_tracking",
    "save_rig",
    "simulate",
    "solver_options",
    "summary_run",
    "sweep",
    "write_record",
    "analysis",
    "identify",
    "reproduce",
    "zhao2003",
]
