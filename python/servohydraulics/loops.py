"""The paper's two real-time test methods, whole records in, every channel out.

* ``run_eft``: effective force testing in force control (Fig 1a): P_eff = -m a_g
  as the force command, velocity feedback compensation (none / linear /
  nonlinear) with the 5 ms phase lead.
* ``run_rpsd``: real-time pseudodynamic testing in displacement control (Figs 1b,
  7): an online solver of Eq (15), amplitude compensation T_d = 68 ms on the
  command, delay compensation T_ld = 11.2 ms on the restoring force.  Table I
  swaps the two symbols; we follow the text.
* ``run_tracking``: displacement-control tracking of a given command through the
  amplitude compensation alone (Fig 5).

The loops run in C++ (``_core.EffectiveForceTest``, ``_core.RealTimePseudoDynamicTest``;
this module mirrors loops.hpp); it only builds configurations and wraps the arrays
in a :class:`~servohydraulics.response.Response`.  The paper's constants (5 ms,
68 ms, 11.2 ms, alpha = 0.1, 7084 kg, 3.5 kN s/m, 0.5 ms) are the defaults of
the core's ``EftConfig`` and ``RpsdConfig``: a keyword left at None takes them.
"""

from __future__ import annotations

import copy
import math

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .response import Response, finish
from .rig import Rig
from .simulate import simulate, solver_options

COMPENSATION = {"none": _core.VelocityFeedbackCompensator.Kind.None_,
                "linear": _core.VelocityFeedbackCompensator.Kind.Linear,
                "nonlinear": _core.VelocityFeedbackCompensator.Kind.Nonlinear}
RESTORING_FORCE = {"calculated_displacement": _core.RestoringForce.CalculatedDisplacement,
                   "measured_displacement": _core.RestoringForce.MeasuredDisplacement,
                   "measured_force": _core.RestoringForce.MeasuredForce,
                   "measured_force_corrected": _core.RestoringForce.MeasuredForceCorrected}
SOLVERS = {"central_difference": _core.SolverKind.CentralDifference,
           "explicit_newmark": _core.SolverKind.ExplicitNewmark}
FORCE_MEASUREMENT = {"load_cell": _core.ForceMeasurement.LoadCell,
                     "actuator_pressure": _core.ForceMeasurement.ActuatorPressure}


def _default(value: float | None, config: object, name: str) -> float:
    """``value``, or the core config's default for ``name`` when None."""
    return getattr(config, name) if value is None else value


def _array(name: str, a: ArrayLike, n: int | None = None) -> np.ndarray:
    x = np.ascontiguousarray(a, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"invalid {name} shape = {x.shape}: expected a 1-D array")
    if n is not None and x.size != n:
        raise ValueError(f"invalid {name} length = {x.size}: expected {n} samples")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ValueError(f"invalid {name}[{bad[0]}] = {x[bad[0]]}: must be finite")
    return x


def _nonneg(name: str, v: float) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
        raise ValueError(f"invalid {name} = {v!r}: must be finite and >= 0")
    return float(v)


def _choice(name: str, v: str, table: dict):
    if v not in table:
        raise ValueError(f"invalid {name} = {v!r}: expected one of {sorted(table)}")
    return table[v]


def run_eft(rig: Rig, ground_acceleration: ArrayLike | None = None, effective_force: ArrayLike | None = None,
            dt: float | None = None, compensation: str = "linear", lead_T: float | None = None,
            alpha: float | None = None, mass: float | None = None, compute_delay: int = 0,
            model: Rig | None = None, options: _core.SolverOptions | None = None,
            raise_on_failure: bool = True) -> Response:
    """Effective force testing (force control) of ``rig``.

    Args:
        ground_acceleration: a_g [m/s^2] per controller sample; or
        effective_force: P_eff [N] directly (converted to a_g = -P_eff / m).
        dt: controller sample time [s] (None: the core's 0.5 ms).
        compensation: ``"none"``, ``"linear"`` (du = A v / (K_v K_s C_F G_p)) or
            ``"nonlinear"`` (inverse flow curve and load-pressure factor, Eq 3).
        lead_T: phase-lead time constant on the compensation [s] (None: the core's 5 ms; 0 = none).
        alpha: phase-lead constant [-] (None: the core's 0.1).
        mass: m in P_eff = -m a_g [kg] (default rig.m).
        compute_delay: samples of compute delay on the command.
        model: the controller's rig model for the compensator (default: ``rig``).
        raise_on_failure: raise SimulationError (with the partial Response) if the loop fails.

    Returns:
        A Response of kind ``"eft"``: the plant's channels, ``flags`` and the
        method's (ground_acceleration, effective_force, compensation,
        compensation_opening, command).
    """
    if (ground_acceleration is None) == (effective_force is None):
        raise ValueError("give exactly one of ground_acceleration [m/s^2] or effective_force [N]")
    cfg = _core.EftConfig()
    cfg.dt = _default(dt, cfg, "dt")
    cfg.mass = _nonneg("mass", 0.0 if mass is None else mass)
    m = cfg.mass if cfg.mass > 0 else rig.m
    ag = (_array("ground_acceleration", ground_acceleration) if effective_force is None
          else -_array("effective_force", effective_force) / m)
    cfg.compensation = _choice("compensation", compensation, COMPENSATION)
    cfg.lead_T = _nonneg("lead_T", _default(lead_T, cfg, "lead_T"))
    cfg.alpha = _default(alpha, cfg, "alpha")
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = options or solver_options()
    test = _core.EffectiveForceTest(rig, cfg, model)
    d, s = test.run(ag)
    return finish(Response(d, kind="eft", mode="force", dt=cfg.dt, rig=rig, work=s), raise_on_failure)


def run_rpsd(rig: Rig, ground_acceleration: ArrayLike | None = None, external_force: ArrayLike | None = None,
             restoring_force_error: ArrayLike | None = None, dt: float | None = None, m_m: float | None = None,
             c_m: float | None = None, k_m: float | None = None, solver: str = "central_difference",
             restoring_force: str = "measured_displacement", amplitude_T: float | None = None,
             delay_T: float | None = None, alpha: float | None = None, physical_mass_fraction: float = 1.0,
             force_measurement: str = "load_cell", subtract_mass: float | None = None,
             subtract_damping: float | None = None, compute_delay: int = 0,
             options: _core.SolverOptions | None = None, raise_on_failure: bool = True) -> Response:
    """Real-time pseudodynamic testing (displacement control) of ``rig``.

    The solver integrates m_m a + c_m v + f = -m_m a_g + P_ext (Eq 15) online.
    Keywords left at None take the core's ``RpsdConfig`` defaults (the paper's values).

    Args:
        ground_acceleration: a_g [m/s^2] per sample (None: zero; then external_force sets the length).
        external_force: P_ext into the solver [N] (Fig 9 ramp-and-release), or None.
        restoring_force_error: added to the restoring force [N] (Fig 9b), or None.
        dt: controller sample time [s] (0.5 ms).
        m_m, c_m: modelled mass [kg] and damping [N s/m] (Table I: 7084 kg, 3.5 kN s/m).
        k_m: stiffness for the displacement-based restoring forces [N/m] (default rig.k).
        solver: ``"central_difference"`` or ``"explicit_newmark"``.
        restoring_force: ``"calculated_displacement"`` (a), ``"measured_displacement"`` (b),
            ``"measured_force"`` (c) or ``"measured_force_corrected"`` (d: minus m a and c v).
        amplitude_T: amplitude compensation T_d on the command [s] (68 ms; 0 = none).
        delay_T: delay compensation T_ld on the restoring force [s]; default 11.2 ms, or 0 for
            ``"calculated_displacement"`` (the paper applied none there, Fig 9a).
        alpha: phase-lead constant [-] (0.1).
        physical_mass_fraction: the rig's structural mass is set to this times m_m (0.02 = 140 kg).
        force_measurement: ``"load_cell"`` or ``"actuator_pressure"`` (p A, includes the piston inertia).
        subtract_mass, subtract_damping: for (d) [kg], [N s/m]; default the physical values.
        raise_on_failure: raise SimulationError (with the partial Response) if the loop fails.

    Returns:
        A Response of kind ``"rpsd"`` whose ``rig`` is the physical rig (mass
        ``physical_mass_fraction * m_m``): the plant's channels, ``flags`` and the
        method's (ground_acceleration, external_force, measured_restoring_force,
        restoring_force, calc_displacement, calc_velocity, calc_acceleration,
        target_displacement, command).
    """
    n = None
    for a in (ground_acceleration, external_force, restoring_force_error):
        if a is not None:
            n = np.asarray(a).size if n is None else n
    if n is None:
        raise ValueError("give ground_acceleration [m/s^2] or external_force [N]")
    ag = np.zeros(n) if ground_acceleration is None else _array("ground_acceleration", ground_acceleration, n)
    pe = None if external_force is None else _array("external_force", external_force, n)
    fe = None if restoring_force_error is None else _array("restoring_force_error", restoring_force_error, n)
    cfg = _core.RpsdConfig()
    cfg.dt = _default(dt, cfg, "dt")
    m_m, c_m = _default(m_m, cfg.model, "m_m"), _default(c_m, cfg.model, "c_m")
    cfg.model = _core.ModelSDOF(m_m, c_m)
    cfg.k_m = _nonneg("k_m", 0.0 if k_m is None else k_m)
    cfg.solver = _choice("solver", solver, SOLVERS)
    cfg.restoring_force = _choice("restoring_force", restoring_force, RESTORING_FORCE)
    cfg.force_measurement = _choice("force_measurement", force_measurement, FORCE_MEASUREMENT)
    cfg.amplitude_T = _nonneg("amplitude_T", _default(amplitude_T, cfg, "amplitude_T"))
    if delay_T is None and restoring_force == "calculated_displacement":
        delay_T = 0.0
    cfg.delay_T = _nonneg("delay_T", _default(delay_T, cfg, "delay_T"))
    cfg.alpha = _default(alpha, cfg, "alpha")
    cfg.physical_mass_fraction = physical_mass_fraction
    cfg.subtract_mass = -1.0 if subtract_mass is None else _nonneg("subtract_mass", subtract_mass)
    cfg.subtract_damping = -1.0 if subtract_damping is None else _nonneg("subtract_damping", subtract_damping)
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = options or solver_options()
    test = _core.RealTimePseudoDynamicTest(rig, cfg)
    d, s = test.run(ag, pe, fe)
    phys = copy.deepcopy(rig)
    phys.m = physical_mass_fraction * m_m
    return finish(Response(d, kind="rpsd", mode="displacement", dt=cfg.dt, rig=phys, work=s), raise_on_failure)


def run_tracking(rig: Rig, displacement: ArrayLike, dt: float | None = None, amplitude_T: float | None = None,
                 alpha: float | None = None, options: _core.SolverOptions | None = None,
                 raise_on_failure: bool = True) -> Response:
    """Displacement control of a given displacement [m] through the amplitude compensation
    (T_d phase lead on the command, Fig 1b / Fig 5b).

    Keywords left at None take the core's ``RpsdConfig`` defaults (0.5 ms, 68 ms, 0.1).
    Returns a Response of kind ``"tracking"`` (the plant's channels; ``command`` is
    the lead-filtered command; ``.warnings()`` reports capacity and supply-pressure limits).
    """
    cfg = _core.RpsdConfig()
    dt = _default(dt, cfg, "dt")
    d = _array("displacement", displacement)
    lead = _core.PhaseLead(_nonneg("amplitude_T", _default(amplitude_T, cfg, "amplitude_T")),
                           _default(alpha, cfg, "alpha"), dt)
    lead.reset(float(d[0]))
    res = simulate(rig, "displacement", lead.filter(d), dt, x0=float(d[0]), options=options, raise_on_failure=False)
    out = Response(res.channels, kind="tracking", mode="displacement", dt=dt, rig=rig, work=res.work)
    return finish(out, raise_on_failure)
