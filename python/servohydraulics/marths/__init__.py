"""The virtual multi-axial RTHS benchmark (maRTHS; Condori Uribe, Salmeron, Patino, Montoya, Dyke, Silva,
Maghareh, Najarian, Montoya, Front. Built Environ. 2023) with the RoDeAC compensator (Quiroz, Galmez,
Fermandois, Front. Built Environ. 2024), on the C++ core.

    from servohydraulics import marths
    data = marths.load_data("../shared/marths-data")        # validated
    rec = marths.load_record("../shared/marths-data", "elcentro")
    trial = marths.run_trial(data, rec, "rodeac")           # J1-J10, peak voltages, realizable
    out = marths.run_benchmark("../shared/marths-data", "elcentro", "rodeac", perturbed=20)
    trial = marths.run_trial(data, rec, MyController())     # your own: reset() and command(desired, measured)
    trial = marths.run_trial(data, rec, "rodeac", plant=my_rig)  # any MultiActuatorSystem
    trial = marths.run_trial(data, rec, "rodeac", plant=sh.marths_rig(), keep_signals=True)  # the nonlinear
    trial.rig["actuator1.spool"]                             # rig; its channels, replayed (rig_summary)

The C++ blocks (plant, structures, controllers, loop) are ``servohydraulics._core.marths``; the seam
(``MultiActuatorSystem``, ``MultiTrackingController``, ``Coupler``) is in ``servohydraulics._core``.
"""

from .. import _core
from .benchmark import (
    CONTROLLERS,
    NOMINAL_SEED,
    PLANTS,
    STABLE_J2_PCT,
    Trial,
    applied_commands,
    as_controller,
    benchmark_rig,
    controller_label,
    loop_config,
    make_controller,
    mimo_feedforward_config,
    noise_seed,
    nominal_plant,
    perturbed_model,
    perturbed_plant,
    plant_label,
    plant_model,
    replay_on_rig,
    rig_summary,
    rodeac_config,
    run_trial,
    samples,
    structures,
)
from .data import DT, EQ_INTENSITY, FILES, FS, RECORDS, MarthsData, load_data, load_record
from .evaluation import J_COMPONENTS, J_TITLES, J_UNITS, SATURATION_LIMIT, evaluate, finddelay, realizable
from .report import Setup, check_perturbed, execute, j_table, prepare, rig_figure, run_benchmark, write_outputs

core = _core.marths
#: The multi-actuator controller interface: subclass it in Python (super().__init__(2)), or give any object
#: with reset() and command(desired, measured, [desired_velocity=, desired_acceleration=]).
MultiTrackingController = _core.MultiTrackingController
#: What stands behind the actuators' sensors (C++ subclasses run without the GIL; a Python object with
#: actuators, dt, reset(), displacements(), step(u) runs through PythonMultiActuatorSystem).
MultiActuatorSystem = _core.MultiActuatorSystem

__all__ = [
    "CONTROLLERS", "NOMINAL_SEED", "STABLE_J2_PCT", "Trial", "as_controller", "controller_label", "loop_config",
    "make_controller",
    "mimo_feedforward_config", "nominal_plant", "noise_seed", "perturbed_model", "perturbed_plant", "plant_model",
    "rodeac_config", "run_trial", "samples", "structures", "DT", "EQ_INTENSITY", "FILES", "FS", "RECORDS",
    "MarthsData", "load_data", "load_record", "J_COMPONENTS", "J_TITLES", "J_UNITS", "SATURATION_LIMIT", "evaluate",
    "finddelay", "realizable", "check_perturbed", "j_table", "run_benchmark", "write_outputs", "core", "Setup",
    "prepare", "execute",
    "MultiTrackingController", "MultiActuatorSystem", "PLANTS", "applied_commands", "benchmark_rig", "plant_label",
    "replay_on_rig", "rig_summary", "rig_figure",
]
