"""The RTHS benchmark control problem (Silva, Gomez, Maghareh, Dyke, Spencer,
Mech. Syst. Signal Process. 135 (2020) 106381) on the C++ core.

    from servohydraulics import rths
    case = rths.load_case(DATA, 1)                 # or rths.embedded_case(1)
    rec = rths.load_record(DATA, "elcentro")       # or rths.synthetic_record()
    trial = rths.run_trial(case, rec, "sample")    # J1-J9, max force, ...
    out = rths.run_case(case, rec, "model", perturbed=20, seed=1)  # through sh.sweep
    trial = rths.run_trial(case, rec, MyController())  # your own: reset() and command(...)

The C++ blocks (plants, converters, substructures, controllers, the loop) are
``servohydraulics._core.rths``.
"""

from .. import _core
from .benchmark import (
    CONTROLLERS,
    FORCE_LIMIT,
    NOISE_GENERATORS,
    Trial,
    as_controller,
    case_psi,
    case_reference,
    controller_label,
    load_controller,
    make_controller,
    nominal_plant,
    partition,
    perturbed_plant,
    run_case,
    run_trial,
    trial_seed,
)
from .data import (
    CASES,
    DT,
    EQ_INTENSITY,
    FS,
    RECORDS,
    BenchmarkCase,
    Record,
    chirp_record,
    embedded_case,
    load_case,
    load_record,
    modal_damping,
    reference_stiffness,
    shear_building,
    synthetic_record,
)
from .evaluation import J_LABELS, J_NAMES, criteria, critical_delay, evaluate, matlab_round, psi, reference_response
from .opensees import OpenSeesSubstructure, spring_model

core = _core.rths
#: The tracking-controller interface: subclass it in Python (or give any object with reset() and command(...)).
TrackingController = core.TrackingController
#: Wraps any object with reset() and command(...) as a TrackingController (rths.as_controller does it).
PythonController = core.PythonController

__all__ = [
    "CONTROLLERS", "FORCE_LIMIT", "Trial", "case_psi", "case_reference", "make_controller", "load_controller",
    "as_controller", "controller_label", "TrackingController", "PythonController", "J_LABELS", "criteria",
    "nominal_plant", "partition", "perturbed_plant", "run_case", "run_trial", "trial_seed", "NOISE_GENERATORS",
    "CASES", "DT", "EQ_INTENSITY", "FS", "RECORDS", "BenchmarkCase", "Record", "embedded_case", "load_case",
    "load_record", "modal_damping", "reference_stiffness", "shear_building", "synthetic_record", "chirp_record",
    "J_NAMES", "critical_delay", "evaluate", "matlab_round", "psi", "reference_response", "core",
    "OpenSeesSubstructure", "spring_model",
]
