"""Running the RTHS benchmark (Silva et al. 2020): partitioning, one trial in
the C++ loop, J1-J9, and the perturbed trials through ``sh.sweep``."""

from __future__ import annotations

import hashlib
import math
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .. import _core
from ..response import Response, Work
from .data import DT, EQ_INTENSITY, BenchmarkCase, Record
from .evaluation import J_NAMES, criteria, evaluate, psi, reference_response

R = _core.rths

__all__ = ["CONTROLLERS", "make_controller", "load_controller", "as_controller", "controller_label",
           "nominal_plant", "perturbed_plant", "partition", "Trial", "TrialSignals", "run_trial", "run_case",
           "trial_seed", "FORCE_LIMIT", "NOISE_GENERATORS", "noise_generator", "polynomial_controller"]

FORCE_LIMIT = 8900.0  #: the benchmark's actuator capacity check on max|f| [N] (F4_evaluation.m L60-62)
STROKE_LIMIT = 7e-3   #: paper limit (not checked by the code) [m]
VELOCITY_LIMIT = 0.3  #: paper limit (not checked by the code) [m/s]


def nominal_plant(csi_derivative_block: bool = False) -> R.BenchmarkPlantParameters:
    """The code values of F1_input_file.m (the C++ defaults).  ``csi_derivative_block``: the CSI
    term as the code's Simulink Derivative block instead of the exact a2 x' (BENCHMARK.md 2.1:
    optional; docs/rths-benchmark.md, "The J5 gap")."""
    p = R.BenchmarkPlantParameters()
    p.csi_derivative_block = bool(csi_derivative_block)
    return p


def trial_seed(seed: int, *parts: Any) -> int:
    """A 64-bit seed derived from the user's seed and a trial's identity (stable across runs)."""
    h = hashlib.sha256(repr((int(seed),) + parts).encode()).digest()
    return int.from_bytes(h[:8], "little")


def perturbed_plant(seed: int, case: int, trial: int,
                    csi_derivative_block: bool = False) -> R.BenchmarkPlantParameters:
    """Trial ``trial`` >= 1 of the perturbed plants of one case: ke, beta1, beta2,
    a3 drawn from the official distributions (F1 L67, L119-121), untruncated."""
    return R.BenchmarkPlantUncertainty().draw(nominal_plant(csi_derivative_block),
                                              trial_seed(seed, "plant", case, trial))


def partition(case: BenchmarkCase, specimen) -> R.LinearSubstructureModel:
    """Mn = Mr - Me, Cn = Cr - Ce, Kn = Kr - Ke at the first floor; the ground load
    is the whole Mr iota; the interface is the first floor (BENCHMARK.md 5.1)."""
    n = case.n
    Mn, Cn, Kn = case.M.copy(), case.C.copy(), case.K.copy()
    Mn[0, 0] -= specimen.m
    Cn[0, 0] -= specimen.c
    Kn[0, 0] -= specimen.k
    gamma = np.zeros(n)
    gamma[0] = 1.0
    return R.LinearSubstructureModel(Mn, Cn, Kn, case.M @ np.ones(n), gamma)


# ----------------------------------------------------------------------------- controllers

def _sample(plant, dt):
    return R.SampleController(R.SampleControllerConfig())


def polynomial_controller(plant, dt, order: int | None = None, stride: int | None = None):
    """The polynomial extrapolation designed on ``plant``: lead tau = A1/A0 (plant_delay), a
    Lagrange polynomial of ``order`` through points ``stride`` samples apart, plus the PI.
    ``None``: the core's defaults (first order, stride 16; PolynomialConfig says why)."""
    c = R.PolynomialConfig()
    c.dt = dt
    c.tau = R.plant_delay(plant)
    if order is not None:
        c.order = order
    if stride is not None:
        c.stride = stride
    c.static_gain = plant.numerator() / plant.denominator()[5]
    return R.PolynomialExtrapolation(c)


def _polynomial(plant, dt):
    return polynomial_controller(plant, dt)


def _ats(plant, dt):
    c = R.AtsConfig()
    c.dt = dt
    mb = R.ModelBasedConfig.from_plant(plant, 2).coefficients
    c.initial = [mb[0], mb[1], mb[2]]
    return R.AdaptiveTimeSeries(c)


def _model(plant, dt):
    c = R.ModelBasedConfig.from_plant(plant, 3)
    c.dt = dt
    return R.ModelBasedCompensator(c)


#: name -> (factory(nominal plant parameters, dt), citation)
CONTROLLERS: dict[str, tuple[Callable, str]] = {
    "sample": (_sample, "PI + phase lead (Silva et al. 2020, Sec 5.2-5.3)"),
    "polynomial": (_polynomial, "polynomial extrapolation (Horiuchi et al. 1999) + PI"),
    "ats": (_ats, "adaptive time series (Chae, Kazemibidokhti, Ricles 2013) + PI"),
    "model": (_model, "model-based feedforward (Phillips and Spencer 2013) + PI feedback"),
}


def make_controller(name: str, dt: float = DT, plant=None):
    """A tracking controller object: a built-in by name (``sample``, ``polynomial``, ``ats``,
    ``model``), designed on ``plant`` (None: the NOMINAL plant; the designer does not know the
    perturbed plant), or a user's class as ``"module:Class"``, imported from PYTHONPATH and
    built with no arguments (:func:`load_controller`).  The built-ins are
    ``rths.core.TrackingController`` objects with ``reset()`` and
    ``command(desired, desired_velocity, desired_acceleration, measured, measured_force,
    measured_velocity=0, measured_pressure=0)``, the interface a user's controller implements
    (the last two optional: passed as keywords when its command() names them; docs/rths-benchmark.md,
    "Bring your own controller")."""
    if isinstance(name, str) and ":" in name:
        return load_controller(name)
    if name not in CONTROLLERS:
        raise ValueError(f"invalid controller = {name!r}: expected one of {sorted(CONTROLLERS)} or 'module:Class'")
    return CONTROLLERS[name][0](plant if plant is not None else nominal_plant(), dt)


def load_controller(spec: str):
    """``"module:Class"``: the module imported from PYTHONPATH, the class built with no
    arguments, checked to be a tracking controller.  Every failure is a ValueError naming
    ``spec`` and what failed (module not found, class not found, constructor failure, not a
    controller)."""
    obj = build_user_object(spec, sorted(CONTROLLERS))
    try:
        return as_controller(obj)
    except TypeError as e:
        raise ValueError(f"invalid controller = {spec!r}: {e}") from e


def build_user_object(spec: str, builtins: list[str]):
    """The object of a user's ``"module:Class"``: the module imported from PYTHONPATH, the class built
    with no arguments (``builtins``: the built-in names, for the message).  Every failure is a ValueError
    naming ``spec`` and what failed (module not found, class not found, constructor failure)."""
    import importlib

    module_name, _, class_name = spec.partition(":")
    if not module_name or not class_name or ":" in class_name:
        raise ValueError(f"invalid controller = {spec!r}: expected a built-in name {builtins} or 'module:Class'")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as e:
        if e.name == module_name or module_name.startswith(f"{e.name}."):  # not a module it imports
            raise ValueError(f"invalid controller = {spec!r}: module {module_name!r} not found on PYTHONPATH") from e
        raise ValueError(f"invalid controller = {spec!r}: importing module {module_name!r} failed: "
                         f"{type(e).__name__}: {e}") from e
    except Exception as e:  # noqa: BLE001 - a user's module: any failure is reported with its type
        raise ValueError(f"invalid controller = {spec!r}: importing module {module_name!r} failed: "
                         f"{type(e).__name__}: {e}") from e
    cls = getattr(module, class_name, None)
    if cls is None:
        raise ValueError(f"invalid controller = {spec!r}: module {module_name!r} ({getattr(module, '__file__', '?')}) "
                         f"has no class {class_name!r}")
    if not callable(cls):
        raise ValueError(f"invalid controller = {spec!r}: {module_name}.{class_name} is a "
                         f"{type(cls).__name__}, not a class")
    try:
        return cls()
    except Exception as e:  # noqa: BLE001 - a user's constructor: any failure is reported with its type
        raise ValueError(f"invalid controller = {spec!r}: {class_name}() raised {type(e).__name__}: {e}") from e


def as_controller(controller):
    """The loop's controller for ``controller``: a built-in name or ``"module:Class"``
    (:func:`make_controller`), a ``rths.core.TrackingController`` (a built-in, or a Python
    subclass) as it is, or any object with ``reset()`` and ``command(...)`` wrapped in
    ``rths.core.PythonController`` (TypeError if it lacks either)."""
    if isinstance(controller, str):
        return make_controller(controller)
    if isinstance(controller, R.TrackingController):
        return controller
    return R.PythonController(controller)


def controller_label(controller) -> tuple[str, str]:
    """(name, description) of a controller for reports: a built-in's name and citation, or the
    ``module:Class`` of a user's controller (a spec is built once, so a bad one raises the
    ValueError of :func:`load_controller`) and the first line of its class's docstring."""
    if isinstance(controller, str) and controller in CONTROLLERS:
        return controller, CONTROLLERS[controller][1]
    obj = make_controller(controller) if isinstance(controller, str) else controller
    cls = type(obj.controller if isinstance(obj, R.PythonController) else obj)
    spec = controller if isinstance(controller, str) else f"{cls.__module__}:{cls.__qualname__}"
    doc = (cls.__doc__ or "").strip().splitlines()
    return spec, (doc[0].strip() if doc else "user controller")


# ----------------------------------------------------------------------------- one trial

class TrialSignals(Mapping):
    """A trial's signals, a read-only mapping onto its :class:`Response`'s channels: each
    channel by name, and the per-DOF channels ``numerical_i`` / ``reference_i`` also
    stacked as ``numerical`` / ``reference`` (rows x DOFs).  Empty without a response."""

    __slots__ = ("_response", "_stacked")

    def __init__(self, response: Response | None):
        self._response = response
        names = list(response.channels) if response is not None else []
        self._stacked = {p: [n for n in names if n.rpartition("_")[0] == p and n.rpartition("_")[2].isdigit()]
                         for p in ("numerical", "reference")}

    def __getitem__(self, name: str) -> np.ndarray:
        cols = self._stacked.get(name)
        if cols:
            return np.column_stack([self._response.channels[c] for c in cols])
        if self._response is None or name not in self._response.channels:
            raise KeyError(name)
        return self._response.channels[name]

    def __iter__(self) -> Iterator[str]:
        if self._response is not None:
            yield from self._response.channels
        yield from (p for p, cols in self._stacked.items() if cols)

    def __len__(self) -> int:
        return sum(1 for _ in self)


@dataclass
class Trial:
    """One benchmark trial: J1-J9 and the limits, plus (``keep_signals``) the run's record as
    ``response``: a :class:`Response` of kind ``"rths"`` whose channels are the loop's
    (``_core.rths.RTHS_CHANNELS``), ``numerical_i`` and ``reference_i`` per DOF i [m] and
    ``step_seconds`` [s] (``timing``).  ``signals`` reads the same data (:class:`TrialSignals`)."""
    J: list[float]
    max_force_N: float
    max_displacement_m: float
    max_velocity_m_per_s: float
    ok: bool
    failure_time: float
    wall_time: float
    response: Response | None = None

    @property
    def signals(self) -> TrialSignals:
        """The response's channels by name, ``numerical`` and ``reference`` as (rows x DOFs)."""
        return TrialSignals(self.response)

    @property
    def criteria(self) -> dict[str, float]:
        """J1-J9 by name (``J1_delay_ms``, ``J2_rms_tracking_error_pct``, ...: ``rths.J_NAMES``)."""
        return criteria(self.J)

    @property
    def capacity_exceeded(self) -> bool:
        return self.max_force_N >= FORCE_LIMIT

    def to_pandas(self):
        """One row: the criteria by name, the peaks and limits, ``ok``, ``stable``, ``wall_time``."""
        import pandas as pd

        row = {**self.criteria, "max_force_N": self.max_force_N, "max_displacement_m": self.max_displacement_m,
               "max_velocity_m_per_s": self.max_velocity_m_per_s, "capacity_exceeded": self.capacity_exceeded,
               "ok": self.ok, "stable": self.stable, "failure_time": self.failure_time, "wall_time": self.wall_time}
        return pd.DataFrame([row])

    @property
    def stable(self) -> bool:
        """Ran to the end with the tracking error smaller than the signal (J2 < 100 %).
        A loop that diverges still runs to the end in floating point (a 59 Hz
        oscillation of 4.8 MN did), so "ran to the end" alone does not say stable."""
        return self.ok and math.isfinite(self.J[1]) and self.J[1] < STABLE_J2_PCT


def _ground_motion(record: Record, scale: float) -> R.GroundMotion:
    return R.GroundMotion(record.time, record.acceleration, scale)


NOISE_GENERATORS = ("simulink", "mersenne")
#: A trial is stable when it ran to the end with J2 below this [%] (Trial.stable).
STABLE_J2_PCT = 100.0


def noise_generator(noise: str) -> R.NoiseGenerator:
    """The core's generator for a ``noise`` name (``simulink`` or ``mersenne``)."""
    if noise == "simulink":
        return R.NoiseGenerator.SimulinkRandomNumber
    if noise == "mersenne":
        return R.NoiseGenerator.MersenneTwister
    raise ValueError(f"invalid noise = {noise!r}: expected one of {list(NOISE_GENERATORS)}")


def run_trial(case: BenchmarkCase, record: Record, controller: Any = "sample", plant=None, seed: int = 0,
              scale: float = EQ_INTENSITY, scheme: str = "RungeKutta4", reference: np.ndarray | None = None,
              keep_signals: bool = False, timing: bool = False, experimental=None, numerical=None,
              noise: str = "simulink") -> Trial:
    """One vRTHS run on the 4096 Hz grid of the record, then J1-J9.

    Args:
        controller: a built-in name or ``"module:Class"`` (:func:`make_controller`; a new
            controller per trial), or a controller object: a ``rths.core.TrackingController``
            or any object with ``reset()`` and ``command(...)`` (docs/rths-benchmark.md, "Bring
            your own controller"); the loop resets it first.  What a Python controller raises
            stops the run and is re-raised as a RuntimeError naming the sample and time.
        plant: BenchmarkPlantParameters of the control plant (None: nominal).
        seed: of the sensor noise (one sequence shared by both channels).
        noise: the noise generator: ``"simulink"`` (default), the algorithm of Simulink's
            Random Number block inside the official SENSORS subsystem, so that seed 0 is
            the official run's realisation (BENCHMARK.md 3.2); ``"mersenne"``: a 64-bit
            Mersenne twister (the loop's general-purpose generator).
        scheme: the numerical substructure's integrator (``RungeKutta4`` as the
            benchmark, ``CentralDifference``, ``ExplicitNewmark``, ``AverageAcceleration``).
        reference: the reference displacements (N x 3), if already computed.
        experimental: another ExperimentalSubstructure (e.g. ServoHydraulicSubstructure) or a
            Python object with its protocol (e.g. ``distributed.RemoteSite``: a site across the
            network); None: the benchmark plant.
        numerical: another numerical substructure: a core NumericalSubstructure (e.g. a
            LinearSubstructure of other matrices) or a Python object with its protocol (e.g.
            ``rths.OpenSeesSubstructure``); None: the case partitioned at the first floor.
    """
    plant = plant if plant is not None else nominal_plant()
    exp = (R.BenchmarkPlant(plant, DT) if experimental is None
           else experimental if isinstance(experimental, R.ExperimentalSubstructure)
           else R.PythonExperimentalSubstructure(experimental))
    num = _numerical(numerical, case, exp, scheme)
    ctrl = as_controller(controller)
    cfg = R.RthsLoopConfig()
    cfg.seed = int(seed) & (2**64 - 1)
    cfg.generator = noise_generator(noise)
    loop = R.RthsLoop(exp, num, ctrl, cfg)
    gm = _ground_motion(record, scale)
    n = record.samples()
    t0 = time.perf_counter()
    out, summary = loop.run(num, gm, n, timing)
    wall = time.perf_counter() - t0
    if reference is None:
        reference = case_reference(case, record, scale)
    work = Work.from_core(summary)  # the core's RunSummary, as every loop's (peak_force: the actuator's)
    if work.ok:
        J = evaluate(out["measured"], out["numerical"], reference, DT)
    else:
        J = [math.nan] * 9
    trial = Trial(J, work.peak_force, work.peak_displacement, work.peak_velocity, work.ok, work.failure_time, wall)
    if keep_signals:
        trial.response = _response(out, work, reference)
    return trial


def _response(out: dict[str, Any], work: Work, reference: np.ndarray) -> Response:
    """The loop's output (RthsLoop.run: channels and summary) and the reference (up to the rows
    run) as a Response."""
    names = [n for n, _ in R.RTHS_CHANNELS] + (["step_seconds"] if "step_seconds" in out else [])
    channels = {n: out[n] for n in names}
    for prefix, data in (("numerical", np.asarray(out["numerical"])),
                         ("reference", np.asarray(reference)[:work.rows])):
        channels.update((f"{prefix}_{i}", data[:, i]) for i in range(data.shape[1]))
    units = {n: "m" for n in channels if n.startswith(("numerical_", "reference_"))}
    return Response(channels, kind="rths", dt=DT, work=work, units=units)


def _numerical(numerical, case: BenchmarkCase, exp, scheme: str):
    if numerical is None:
        return R.LinearSubstructure(partition(case, exp.specimen()), DT, getattr(R.SubstructureScheme, scheme))
    if isinstance(numerical, R.NumericalSubstructure):
        return numerical
    return R.PythonSubstructure(numerical)


_REFERENCE_CACHE: dict[tuple, np.ndarray] = {}


def case_reference(case: BenchmarkCase, record: Record, scale: float = EQ_INTENSITY) -> np.ndarray:
    """The reference displacements (N x 3) on the 4096 Hz grid, cached per process."""
    key = (case.number, case.source, hashlib.sha256(case.C.tobytes() + case.K.tobytes() + case.M.tobytes()).hexdigest(),
           record.name, record.source, record.acceleration.size, float(record.acceleration.sum()), scale)
    if key not in _REFERENCE_CACHE:
        if len(_REFERENCE_CACHE) > 8:
            _REFERENCE_CACHE.clear()
        _REFERENCE_CACHE[key] = _reference(case, record, scale)
    return _REFERENCE_CACHE[key]


def _reference(case: BenchmarkCase, record: Record, scale: float) -> np.ndarray:
    n = record.samples()
    ag = scale * np.interp(np.arange(n) * DT, record.time, record.acceleration)
    return reference_response(case.M, case.C, case.K, ag, DT)


def case_psi(case: BenchmarkCase) -> float:
    sp = nominal_plant().specimen()
    return psi(case.M, case.C, case.K, sp.m, sp.c, sp.k)


def _perturbed_job(rig, trial: int, case: BenchmarkCase, record: Record, controller: Any, seed: int,
                   scale: float, csi_derivative_block: bool = False, noise: str = "simulink") -> dict[str, Any]:
    """One perturbed trial in a sweep worker (the rig argument of sh.sweep is unused)."""
    plant = perturbed_plant(seed, case.number, trial, csi_derivative_block)
    t = run_trial(case, record, controller, plant=plant, seed=seed, scale=scale,
                  reference=case_reference(case, record, scale), noise=noise)
    out = t.criteria
    out.update(ok=t.ok, stable=t.stable, max_force_N=t.max_force_N, max_displacement_m=t.max_displacement_m,
               max_velocity_m_per_s=t.max_velocity_m_per_s, wall_time=t.wall_time,
               k_e=plant.k_e, beta1=plant.beta1, beta2=plant.beta2, a3=plant.a3)
    return out


def run_case(case: BenchmarkCase, record: Record, controller: Any = "sample", perturbed: int = 0, seed: int = 0,
             scale: float = EQ_INTENSITY, executor=None, max_workers: int | None = None,
             progress: bool = True, keep_signals: bool = False,
             csi_derivative_block: bool = False, noise: str = "simulink") -> dict[str, Any]:
    """The nominal trial and ``perturbed`` perturbed trials (through ``sh.sweep``) of one case.

    ``controller``: a built-in name or ``"module:Class"`` (each trial builds its own, in the
    worker processes), or a controller object (:func:`run_trial`): the perturbed trials then
    run one after another in this process (a thread pool of one), unless ``executor`` is given.

    Returns ``{"nominal": {...}, "perturbed": {...} (if any), "trial": Trial, "table": DataFrame | None}``;
    the criteria by name (``J1_delay_ms``, ...: ``rths.J_NAMES``) in ``nominal["criteria"]``,
    ``perturbed["criteria_mean"]``/``["criteria_std"]`` and the table's columns.
    """
    noise_generator(noise)  # validates the name before any run
    if not isinstance(controller, str):
        as_controller(controller)  # TypeError now, not in a worker, if it is not a controller
    ref = case_reference(case, record, scale)
    nom = run_trial(case, record, controller, plant=nominal_plant(csi_derivative_block), seed=seed, scale=scale,
                    reference=ref, keep_signals=keep_signals, noise=noise)
    res: dict[str, Any] = {"nominal": {"J": nom.J, "criteria": nom.criteria, "max_force_N": nom.max_force_N,
                                       "max_displacement_m": nom.max_displacement_m,
                                       "max_velocity_m_per_s": nom.max_velocity_m_per_s,
                                       "capacity_exceeded": nom.capacity_exceeded, "ok": nom.ok,
                                       "PSI": case_psi(case)},
                           "trial": nom, "table": None}
    if perturbed > 0:
        from ..parameter_sweep import sweep
        own = None
        if executor is None and not isinstance(controller, str):
            from concurrent.futures import ThreadPoolExecutor
            executor = own = ThreadPoolExecutor(max_workers=1)
        try:
            df = sweep(grid={"trial": list(range(1, perturbed + 1))}, run=_perturbed_job,
                       fixed={"case": case, "record": record, "controller": controller, "seed": seed, "scale": scale,
                              "csi_derivative_block": bool(csi_derivative_block), "noise": noise},
                       executor=executor, max_workers=max_workers, progress=progress)
        finally:
            if own is not None:
                own.shutdown(wait=True)
        df = df.drop(columns=["case", "record", "csi_derivative_block", "noise"])
        if not isinstance(controller, str):
            df["controller"] = controller_label(controller)[0]  # its name, not the object
        if "error" in df.columns and df["error"].notna().any():
            raise RuntimeError(f"perturbed trial failed: {df['error'].dropna().iloc[0]}")
        Js = df[list(J_NAMES)].to_numpy(dtype=float)
        mean = [float(v) for v in np.mean(Js, axis=0)]
        std = [float(v) for v in np.std(Js, axis=0, ddof=1)] if perturbed > 1 else [0.0] * 9
        res["perturbed"] = {"J_mean": mean, "J_std": std, "criteria_mean": criteria(mean),
                            "criteria_std": criteria(std),
                            "runs": int(perturbed), "ran_to_end": int(df["ok"].sum()),
                            "stable": int(df["stable"].sum()),
                            "capacity_exceeded": int((df["max_force_N"] >= FORCE_LIMIT).sum())}
        res["table"] = df
    return res
