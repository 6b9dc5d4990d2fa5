"""Running the maRTHS benchmark: the model from the data, one trial in the C++ loop
(``_core.marths.MarthsLoop``), J1-J10, and the perturbed trials through ``sh.sweep``."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .. import _core
from ..multi_rig import MultiActuatorRig, MultiResponse, load_multi_rig, marths_rig, simulate_multi
from ..response import Response, Work
from ..rths.benchmark import build_user_object, trial_seed
from ..rths.data import Record
from .data import DT, EQ_INTENSITY, FS, MarthsData
from .evaluation import J_COMPONENTS, evaluate, realizable

R = _core.marths
TC = _core.rths  # the single-actuator compensators (tracking.hpp)

__all__ = ["CONTROLLERS", "NOMINAL_SEED", "Trial", "structures", "plant_model", "nominal_plant", "perturbed_model",
           "perturbed_plant", "make_controller", "as_controller", "controller_label", "rodeac_config",
           "mimo_feedforward_config", "run_trial", "loop_config", "PLANTS", "benchmark_rig", "plant_label",
           "applied_commands", "replay_on_rig", "rig_summary"]

#: The noise seed of the nominal trial (S1_Input_Data.m: rng(123)).
NOMINAL_SEED = 123
#: A trial is stable when it ran to the end with J2 below this on both actuators [%] (Trial.stable).
STABLE_J2_PCT = 100.0


# ----------------------------------------------------------------------------- the model

def structures(data: MarthsData) -> Any:
    """The reference structure, the numerical substructure and the physical frame (``MarthsStructures``)."""
    return R.MarthsStructures.build(data.K, data.M, data.influence)


def plant_model(data: MarthsData) -> Any:
    """The identified plant's state space (``plantFRAME_SS``; input and output in mm)."""
    return R.StateSpace(data.A, data.B, data.C, data.D)


def nominal_plant(data: MarthsData, dt: float = DT) -> Any:
    """The nominal identified plant as a ``MultiActuatorSystem`` (SI at the seam)."""
    return R.IdentifiedPlant(plant_model(data), dt)


def perturbed_model(seed: int, trial: int) -> Any:
    """Trial ``trial`` >= 1's perturbed transfer matrix (``TransferMatrix``): the nine draws of
    fcn_build_uncert_plant.m from a sequence seeded by (seed, trial), the gains rescaled."""
    return R.PlantUncertainty().draw(R.BenchmarkPlantModel(), trial_seed(seed, "marths-plant", trial))


def perturbed_plant(seed: int, trial: int, dt: float = DT) -> Any:
    """The perturbed plant of ``trial`` as a ``MultiActuatorSystem`` (its own modal realisation)."""
    return R.IdentifiedPlant(perturbed_model(seed, trial).realize(), dt)


#: The plants behind the actuators by name (besides a multi-actuator rig file): name -> description.
PLANTS = {
    "identified": "the benchmark's identified linear MIMO plant (plantFRAME_SS, BENCHMARK.md section 4)",
    "nonlinear": "the nonlinear two-actuator rig calibrated to the identified plant (sh.marths_rig(), "
                 "docs/multi-actuator.md): two of the paper's servo-hydraulic actuators on the benchmark's coupler "
                 "and physical frame",
}


def benchmark_rig(plant: Any) -> MultiActuatorRig | None:
    """The nonlinear rig a benchmark runs on: None for ``"identified"`` (the identified plant), the calibrated
    two-actuator rig for ``"nonlinear"``, a :class:`MultiActuatorRig` as it is, or a multi-actuator rig file
    (TOML, :func:`servohydraulics.load_multi_rig`).  ValueError naming the value (or the file, key and value)
    otherwise; the rig must have two actuators (the benchmark's coupler)."""
    if plant is None or (isinstance(plant, str) and plant == "identified"):
        return None
    if isinstance(plant, str) and plant == "nonlinear":
        return marths_rig()
    if isinstance(plant, MultiActuatorRig):
        rig = plant
    elif isinstance(plant, (str, Path)):
        path = Path(plant)
        if not path.is_file():
            raise ValueError(f"invalid plant = {str(plant)!r}: expected {' | '.join(PLANTS)} or a multi-actuator rig "
                             "file (TOML; no such file)")
        try:
            rig = load_multi_rig(path)
        except FileNotFoundError as e:  # an actuator's rig file it names
            raise ValueError(str(e)) from None
        if rig.actuators != 2:
            raise ValueError(f"{path}: invalid [[actuators]] (count) = {rig.actuators}: the benchmark's coupler "
                             "drives 2 actuators")
        return rig
    else:
        raise ValueError(f"invalid plant = {plant!r}: expected {' | '.join(PLANTS)}, a rig file or a MultiActuatorRig")
    if rig.actuators != 2:
        raise ValueError(f"invalid plant actuators = {rig.actuators}: the benchmark's coupler drives 2 actuators")
    return rig


def plant_label(plant: Any) -> tuple[str, str]:
    """(name, description) of a plant for reports."""
    if plant is None or (isinstance(plant, str) and plant in PLANTS):
        name = plant or "identified"
        return name, PLANTS[name]
    if isinstance(plant, MultiActuatorRig):
        return "rig", f"a nonlinear multi-actuator rig ({plant!r})"
    return str(plant), "a nonlinear two-actuator rig from this file (docs/multi-actuator.md)"


def noise_seed(seed: int, trial: int) -> int:
    """The sensor-noise seed of a trial: ``seed`` itself on the nominal trial (0), a 32-bit number drawn from
    (seed, trial) on the perturbed ones (the scripts use a clock-based one there)."""
    return int(seed) if trial == 0 else trial_seed(seed, "marths-noise", trial) & 0xFFFFFFFF


def loop_config(seed: int = NOMINAL_SEED, daq_quantizer: bool = False, daq_saturation: bool = False,
                exact_kinematics: bool = False, independent_noise: bool = False) -> Any:
    """The loop's settings: the model's (fs = 1024 Hz, noise power 1.5e-7 mm^2 s through Simulink's Random
    Number block with ``seed``, identical on both channels, no DAQ blocks) unless changed."""
    c = R.MarthsLoopConfig()
    c.seed = int(seed) & (2**64 - 1)
    c.generator = _core.NoiseGenerator.SimulinkRandomNumber
    c.daq_quantizer = bool(daq_quantizer)
    c.daq_saturation = bool(daq_saturation)
    c.exact_kinematics = bool(exact_kinematics)
    c.independent_noise = bool(independent_noise)
    return c


# ----------------------------------------------------------------------------- controllers

def rodeac_config(data: MarthsData, adaptive: bool = True) -> Any:
    """RoDeAC as S3_Controller.m sets it: theta0 and P0 of Initial_parameters.mat (P0 = 0: non-adaptive),
    lambda = 1, the 4th-order 20 Hz Butterworth noise filter at 1024 Hz, signals in mm."""
    c = R.RodeacConfig()
    c.channels = [R.RodeacChannel(th, P if adaptive else np.zeros_like(P)) for th, P in zip(data.theta0, data.P0)]
    c.forgetting = 1.0
    c.filter = _core.butterworth_lowpass(4, 20.0, FS)
    c.unit = 1e-3
    c.validate()
    return c


def _ideal_converters(cfg) -> None:
    """The maRTHS model has no quantiser and no active saturation: the compensators' converters pass through."""
    cfg.converters.ad = _core.ideal_converter(_core.Converter.Kind.AnalogToDigital)
    cfg.converters.da = _core.ideal_converter(_core.Converter.Kind.DigitalToAnalog)


def _inverse_series(data: MarthsData, i: int, order: int) -> list[float]:
    """The Taylor coefficients c_0 .. c_order of 1 / H_ii(s) at s = 0 [s^m] (H_ii: actuator i's own element of
    the identified plant; mm/mm)."""
    H = [float(h[i, i]) for h in plant_model(data).taylor_coefficients(order)]
    c: list[float] = []
    for m in range(order + 1):
        acc = (1.0 if m == 0 else 0.0) - sum(H[j] * c[m - j] for j in range(1, m + 1))
        c.append(acc / H[0])
    return c


def _decentralized(data: MarthsData, make_one: Callable[[MarthsData, int], Any]) -> Any:
    return R.DecentralizedController([make_one(data, i) for i in range(2)], DT)


def _channel_sample(data: MarthsData, i: int) -> Any:
    cfg = TC.SampleControllerConfig()
    cfg.dt = DT
    _ideal_converters(cfg)
    return TC.SampleController(cfg)


def _channel_polynomial(data: MarthsData, i: int) -> Any:
    c0, c1 = _inverse_series(data, i, 1)
    cfg = TC.PolynomialConfig()
    cfg.dt = DT
    cfg.tau = c1 / c0            # the low-frequency delay of H_ii: -H'(0)/H(0) = c1/c0
    cfg.static_gain = 1.0 / c0   # H_ii(0)
    cfg.pi = TC.PiGains(0.0, 0.0)
    _ideal_converters(cfg)
    return TC.PolynomialExtrapolation(cfg)


def _channel_model(data: MarthsData, i: int) -> Any:
    cfg = TC.ModelBasedConfig()
    cfg.dt = DT
    cfg.coefficients = _inverse_series(data, i, 2) + [0.0]  # the jerk term destabilises the loop
    cfg.pi = TC.PiGains(0.0, 0.0)
    _ideal_converters(cfg)
    return TC.ModelBasedCompensator(cfg)


def _channel_ats(data: MarthsData, i: int) -> Any:
    c = _inverse_series(data, i, 2)
    cfg = TC.AtsConfig()
    cfg.dt = DT
    cfg.initial = c
    cfg.lower = [0.5 * c[0], 0.0, -4.0 * abs(c[2]) - 1e-4]
    cfg.upper = [2.0 * c[0], 4.0 * c[1], 4.0 * abs(c[2]) + 1e-4]
    cfg.pi = TC.PiGains(0.0, 0.0)
    _ideal_converters(cfg)
    return TC.AdaptiveTimeSeries(cfg)


def mimo_feedforward_config(data: MarthsData, order: int = 2) -> Any:
    """The MIMO model-based feedforward on the identified plant: u = sum_m E_m r^(m), E(s) the Taylor series
    of H(s)^-1 at s = 0 up to ``order`` (MimoFeedforwardConfig.from_plant), no feedback."""
    return R.MimoFeedforwardConfig.from_plant(plant_model(data), order, DT)


#: name -> (factory(data) -> MultiTrackingController, description)
CONTROLLERS: dict[str, tuple[Callable[[MarthsData], Any], str]] = {
    "rodeac": (lambda d: R.RodeacController(rodeac_config(d, True)),
               "RoDeAC: RLS-adaptive FIR compensator per actuator (Quiroz, Galmez, Fermandois 2024), "
               "as S3_Controller.m"),
    "rodeac_fixed": (lambda d: R.RodeacController(rodeac_config(d, False)),
                     "RoDeAC with P0 = 0: the fixed FIR compensator of Initial_parameters.mat (non-adaptive)"),
    "none": (lambda d: R.PassThrough(2), "no compensation: the command is the target"),
    "decentralized": (lambda d: _decentralized(d, _channel_model),
                      "decentralized model-based feedforward: per actuator, the 2nd-order series of 1/H_ii(s)"),
    "decentralized-model": (lambda d: _decentralized(d, _channel_model),
                            "decentralized model-based feedforward: per actuator, the 2nd-order series of 1/H_ii(s)"),
    "decentralized-polynomial": (lambda d: _decentralized(d, _channel_polynomial),
                                 "decentralized polynomial extrapolation (Horiuchi et al. 1999) over H_ii's delay"),
    "decentralized-ats": (lambda d: _decentralized(d, _channel_ats),
                          "decentralized adaptive time series (Chae et al. 2013) from 1/H_ii(s)"),
    "decentralized-sample": (lambda d: _decentralized(d, _channel_sample),
                             "decentralized PI + phase lead of the RTHS benchmark (Silva et al. 2020), as published"),
    "mimo-feedforward": (lambda d: R.MimoFeedforward(mimo_feedforward_config(d)),
                         "MIMO model-based feedforward: the 2nd-order series of H(s)^-1 of the identified plant"),
}


def make_controller(name: str, data: MarthsData) -> Any:
    """A built-in multi-actuator controller by name (CONTROLLERS) designed on the NOMINAL plant, or a user's
    ``"module:Class"`` (imported from PYTHONPATH, built with no arguments)."""
    if isinstance(name, str) and ":" in name:
        obj = build_user_object(name, sorted(CONTROLLERS))
        try:
            return as_controller(obj, data)
        except TypeError as e:
            raise ValueError(f"invalid controller = {name!r}: {e}") from e
    if name not in CONTROLLERS:
        raise ValueError(f"invalid controller = {name!r}: expected one of {sorted(CONTROLLERS)} or 'module:Class'")
    return CONTROLLERS[name][0](data)


def as_controller(controller: Any, data: MarthsData | None = None) -> Any:
    """The loop's controller: a name or ``"module:Class"`` (needs ``data``), a ``MultiTrackingController``
    (a built-in or a Python subclass) as it is, or any object with ``reset()`` and ``command(desired,
    measured, [desired_velocity=, desired_acceleration=])`` wrapped (``actuators`` attribute, default 2)."""
    if isinstance(controller, str):
        if data is None:
            raise ValueError("a controller given by name needs the benchmark's data")
        return make_controller(controller, data)
    if isinstance(controller, _core.MultiTrackingController):
        return controller
    return _core.PythonMultiController(controller, int(getattr(controller, "actuators", 2)))


def controller_label(controller: Any) -> tuple[str, str]:
    """(name, description) of a controller for reports."""
    if isinstance(controller, str) and controller in CONTROLLERS:
        return controller, CONTROLLERS[controller][1]
    if isinstance(controller, str):
        return controller, "user controller"
    obj = controller.controller if isinstance(controller, _core.PythonMultiController) else controller
    cls = type(obj)
    doc = (cls.__doc__ or "").strip().splitlines()
    return f"{cls.__module__}:{cls.__qualname__}", (doc[0].strip() if doc else "user controller")


def _plant(plant: Any, data: MarthsData) -> Any:
    if plant is None:
        return nominal_plant(data)
    if isinstance(plant, _core.MultiActuatorSystem):
        return plant
    if isinstance(plant, MultiActuatorRig):
        return plant.make_plant(DT)
    if isinstance(plant, R.TransferMatrix):
        return R.IdentifiedPlant(plant.realize(), DT)
    if isinstance(plant, R.StateSpace):
        return R.IdentifiedPlant(plant, DT)
    return _core.PythonMultiActuatorSystem(plant)


# ----------------------------------------------------------------------------- one trial

@dataclass
class Trial:
    """One maRTHS trial: J1-J10 (BENCHMARK.md's units and order, unrounded), the peak command voltages and
    the realizability, plus (``keep_signals``) the run's record as ``response`` (a :class:`Response` of kind
    ``"marths"``: ``_core.marths.MARTHS_CHANNELS`` in SI)."""
    J: dict[str, list[float]]
    peak_voltage: list[float]   #: max |v1|, max |v2| [V]
    ok: bool
    failure_time: float
    wall_time: float
    work: Work
    response: Response | None = None
    #: on a nonlinear rig (``plant`` a MultiActuatorRig, ``keep_signals``): every rig channel, from
    #: :func:`replay_on_rig` (the same commands on the same rig, run anew: identical strokes)
    rig: MultiResponse | None = None

    @property
    def realizable(self) -> bool:
        """S5's rule on this trial's peak voltages."""
        return realizable(self.peak_voltage)

    @property
    def stable(self) -> bool:
        """Ran to the end with both actuators' tracking errors smaller than their targets (J2 < 100 %): a loop that
        diverges can still run to the end in floating point (the 3rd-order MIMO feedforward did, at 1e4 %)."""
        return self.ok and all(math.isfinite(v) and v < STABLE_J2_PCT for v in self.J["J2"])


def samples(record: Record) -> int:
    """N = floor(t_end fs) + 1 samples t_k = k/fs (BENCHMARK.md section 1)."""
    return record.samples(FS)


def run_trial(data: MarthsData, record: Record, controller: Any = "rodeac", plant: Any = None,
              seed: int = NOMINAL_SEED, scale: float = EQ_INTENSITY, config: Any = None, structures_: Any = None,
              keep_signals: bool = False, timing: bool = False) -> Trial:
    """One vmaRTHS run on the 1024 Hz grid of the record, then J1-J10.

    Args:
        controller: a built-in name (CONTROLLERS) or ``"module:Class"`` (built anew), or a controller object
            (``MultiTrackingController``, or any object with ``reset()`` and ``command(...)``); the loop resets it.
        plant: None (the nominal identified plant), a ``MultiActuatorSystem`` (e.g. ``perturbed_plant(...)``, or
            a rig of nonlinear actuators bound from C++), a :class:`MultiActuatorRig` (stepped by its default
            integrator; with ``keep_signals`` its channels are in ``Trial.rig``), a ``TransferMatrix`` or
            ``StateSpace`` (mm in and out), or a Python object with the protocol of
            ``_core.PythonMultiActuatorSystem``.
        seed: the sensor-noise seed (Simulink's Random Number block; 123: the benchmark's nominal trial).
        config: a ``MarthsLoopConfig`` (its seed is replaced by ``seed``); None: :func:`loop_config`.
    """
    st = structures_ if structures_ is not None else structures(data)
    p = _plant(plant, data)
    ctrl = as_controller(controller, data)
    cfg = config if config is not None else loop_config()
    cfg.seed = int(seed) & (2**64 - 1)
    loop = R.MarthsLoop(p, ctrl, st, cfg)
    gm = _core.GroundMotion(record.time, record.acceleration, scale)
    n = samples(record)
    t0 = time.perf_counter()
    out, summary = loop.run(gm, n, timing)
    wall = time.perf_counter() - t0
    work = Work.from_core(summary)
    if work.ok:
        J = evaluate(out, FS)
    else:
        J = {j: [math.nan] * len(c) for j, c in J_COMPONENTS.items()}
    volts = [float(np.max(np.abs(out[f"voltage_{i}"]))) if len(out[f"voltage_{i}"]) else math.nan for i in (1, 2)]
    trial = Trial(J, volts, work.ok, work.failure_time, wall, work)
    if keep_signals:
        trial.response = Response(out, kind="marths", dt=DT, work=work)
        if isinstance(plant, MultiActuatorRig):
            trial.rig = replay_on_rig(plant, out, cfg)
    return trial


def applied_commands(rows: dict[str, np.ndarray], config: Any) -> np.ndarray:
    """The commands the plant held, (n, 2) [m]: the controller's, or with the DAQ blocks on, the D/A's output
    converted back (``CommandVoltage.millimetres`` of the logged voltage)."""
    if not (config.daq_quantizer or config.daq_saturation):
        return np.column_stack([rows["command_1"], rows["command_2"]])
    return np.column_stack([[config.voltage[i].millimetres(v) * config.sensor_unit for v in rows[f"voltage_{i + 1}"]]
                            for i in range(2)])


def replay_on_rig(rig: MultiActuatorRig, rows: dict[str, np.ndarray], config: Any) -> MultiResponse | None:
    """Every channel of the rig (forces, pressures, spools, friction, the node) during a loop run: the commands
    the loop applied, run again from rest on the same rig by :func:`simulate_multi` (the same integrator on the
    same inputs: the strokes equal the loop's ``displacement_1/2`` row by row).  None when the loop logged fewer
    than two rows."""
    u = applied_commands(rows, config)
    if u.shape[0] < 2:
        return None
    return simulate_multi(rig, u, DT, raise_on_failure=False)


def rig_summary(res: MultiResponse, rows: dict[str, np.ndarray] | None = None) -> dict[str, Any]:
    """What the nonlinear rig shows and the linear plant cannot (SI): per actuator the peak load-cell force [N],
    spool opening [-] (and its limit), valve drive [V] and friction [N], the share of samples with the spool
    beyond 90 % of its limit; the force difference F1 - F2 and the opposing force (the force that cancels in the
    x resultant) [N]; the limit warnings; with the loop's ``rows``, the largest stroke difference between the
    loop and the replay [m] (0: the replay is the loop's run)."""
    out: dict[str, Any] = {"actuators": []}
    for i, r in enumerate(res.multi_rig.rigs, start=1):
        spool = res[f"actuator{i}.spool"]
        lim = float(r.x_v_max) if r.effects.spool_saturation else math.inf
        out["actuators"].append({
            "peak_force_N": float(np.max(np.abs(res[f"actuator{i}.force"]))),
            "peak_spool": float(np.max(np.abs(spool))), "spool_limit": lim,
            "spool_above_90pct_share": float(np.mean(np.abs(spool) > 0.9 * lim)) if math.isfinite(lim) else 0.0,
            "peak_drive_V": float(np.max(np.abs(res[f"actuator{i}.drive"]))),
            "peak_friction_N": float(np.max(np.abs(res[f"actuator{i}.friction"]))),
            "peak_pressure_Pa": float(np.max(np.abs(res[f"actuator{i}.pressure"]))),
        })
    dF = res["actuator1.force"] - res["actuator2.force"]
    out["peak_force_difference_N"] = float(np.max(np.abs(dF)))
    out["rms_force_difference_N"] = float(np.sqrt(np.mean(dF * dF)))
    out["peak_opposing_force_N"] = float(np.max(res["node.opposing_force"]))
    out["warnings"] = res.warnings()
    if rows is not None:
        n = len(res.time)
        out["replay_stroke_difference_m"] = float(max(
            np.max(np.abs(res[f"actuator{i}.stroke"] - rows[f"displacement_{i}"][:n])) for i in (1, 2)))
    return out
