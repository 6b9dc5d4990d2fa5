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

The loops run in C++ (``_core.EffectiveForceTest``, ``_core.RealTimePseudoDynamicTest``);
this module only builds configurations and wraps the arrays.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from . import _core
from .rig import Rig
from .simulate import SimulationResult, limit_warnings, simulate, solver_options

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

#: Paper constants (Table I and text), SI.
EFT_LEAD_T = 5e-3  #: EFT phase lead on the compensation, Table I T_d-hat [s]
AMPLITUDE_T = 68e-3  #: amplitude compensation T_d (text; Table I prints it as T_ld) [s]
DELAY_T = 11.2e-3  #: delay compensation T_ld (text; Table I prints it as T_d) [s]
ALPHA = 0.1  #: phase-lead constant (Table I)


class TestMethodError(RuntimeError):
    """The loop failed (solver failure or divergence); the message names time and cause."""


@dataclass
class MethodResult:
    """Every channel of a test-method run, SI units, one row per controller sample.

    Row k holds the sensors at ``time[k]`` and what the controller computed from
    them (held over the next sample).  ``channels`` maps names to arrays: the
    plant's (time, displacement, velocity, acceleration, force [load cell],
    pressure, spool, drive, flow, flags) and the method's (EFT: ground_acceleration,
    effective_force, compensation, compensation_opening, command; RPsD:
    ground_acceleration, external_force, measured_restoring_force,
    restoring_force, calc_displacement, calc_velocity, calc_acceleration,
    target_displacement, command).  Channels are also attributes."""

    method: str
    channels: dict
    summary: dict
    rig: Rig
    dt: float
    status: str = "ok"
    warnings: list = field(default_factory=list)

    def __getattr__(self, name: str) -> np.ndarray:
        ch = self.__dict__.get("channels", {})
        if name in ch:
            return ch[name]
        raise AttributeError(name)

    @property
    def capacity_exceeded(self) -> bool:
        """|load-cell force| > F_cap somewhere."""
        return bool(np.any(self.channels["flags"] & _core.FLAG_CAPACITY_EXCEEDED))

    @property
    def supply_limited(self) -> bool:
        """|p| >= 0.98 p_s somewhere (note p_s A = 139.6 kN < the 170 kN rating)."""
        return bool(np.any(self.channels["flags"] & _core.FLAG_SUPPLY_LIMITED))

    def first_flag_time(self, flags: int) -> float | None:
        """Time of the first row with any of ``flags`` [s], or None."""
        hit = np.flatnonzero(self.channels["flags"] & flags)
        return float(self.channels["time"][hit[0]]) if hit.size else None


def _summary(s: _core.RunSummary) -> dict:
    return {"status": s.status.message, "ok": s.status.ok(), "rows": s.rows, "internal_steps": s.internal_steps,
            "rhs_evals": s.rhs_evals, "restarts": s.restarts, "max_internal_steps": s.max_internal_steps,
            "flags_any": s.flags_any, "peak_force": s.peak_force, "first_capacity_time": s.first_capacity_time}


def _warnings(ch: dict, summ: dict, rig: Rig) -> list[str]:
    return limit_warnings(ch["flags"], ch["time"], summ, rig)


def _array(name: str, a, n: int | None = None) -> np.ndarray:
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


def _finish(method: str, d: dict, s: _core.RunSummary, rig: Rig, dt: float, raise_on_failure: bool) -> MethodResult:
    summ = _summary(s)
    res = MethodResult(method=method, channels=d, summary=summ, rig=rig, dt=dt, status=summ["status"],
                       warnings=_warnings(d, summ, rig))
    if not summ["ok"]:
        msg = f"{method} failed at t = {s.status.t:.4f} s: {summ['status']}"
        if raise_on_failure:
            raise TestMethodError(msg)
        res.warnings.append(msg)
    return res


def run_eft(rig: Rig, ground_acceleration=None, effective_force=None, dt: float = 5e-4,
            compensation: str = "linear", lead_T: float = EFT_LEAD_T, alpha: float = ALPHA,
            mass: float | None = None, compute_delay: int = 0, model: Rig | None = None,
            options: _core.SolverOptions | None = None, raise_on_failure: bool = True) -> MethodResult:
    """Effective force testing (force control) of ``rig``.

    Args:
        ground_acceleration: a_g [m/s^2] per controller sample; or
        effective_force: P_eff [N] directly (converted to a_g = -P_eff / m).
        compensation: ``"none"``, ``"linear"`` (du = A v / (K_v K_s C_F G_p)) or
            ``"nonlinear"`` (inverse flow curve and load-pressure factor, Eq 3).
        lead_T: phase-lead time constant on the compensation [s] (5 ms; 0 = none).
        mass: m in P_eff = -m a_g [kg] (default rig.m).
        compute_delay: samples of compute delay on the command.
        model: the controller's rig model for the compensator (default: ``rig``).
    """
    if (ground_acceleration is None) == (effective_force is None):
        raise ValueError("give exactly one of ground_acceleration [m/s^2] or effective_force [N]")
    cfg = _core.EftConfig()
    cfg.dt = dt
    cfg.mass = _nonneg("mass", 0.0 if mass is None else mass)
    m = cfg.mass if cfg.mass > 0 else rig.m
    ag = (_array("ground_acceleration", ground_acceleration) if effective_force is None
          else -_array("effective_force", effective_force) / m)
    cfg.compensation = _choice("compensation", compensation, COMPENSATION)
    cfg.lead_T = _nonneg("lead_T", lead_T)
    cfg.alpha = alpha
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = options or solver_options()
    test = _core.EffectiveForceTest(rig, cfg, model)
    d, s = test.run(ag)
    return _finish("EFT", d, s, rig, dt, raise_on_failure)


def run_rpsd(rig: Rig, ground_acceleration=None, external_force=None, restoring_force_error=None,
             dt: float = 5e-4, m_m: float = 7084.0, c_m: float = 3.5e3, k_m: float | None = None,
             solver: str = "central_difference", restoring_force: str = "measured_displacement",
             amplitude_T: float = AMPLITUDE_T, delay_T: float | None = None, alpha: float = ALPHA,
             physical_mass_fraction: float = 1.0, force_measurement: str = "load_cell",
             subtract_mass: float | None = None, subtract_damping: float | None = None,
             compute_delay: int = 0, options: _core.SolverOptions | None = None,
             raise_on_failure: bool = True) -> MethodResult:
    """Real-time pseudodynamic testing (displacement control) of ``rig``.

    The solver integrates m_m a + c_m v + f = -m_m a_g + P_ext (Eq 15) online.

    Args:
        ground_acceleration: a_g [m/s^2] per sample (None: zero; then external_force sets the length).
        external_force: P_ext into the solver [N] (Fig 9 ramp-and-release), or None.
        restoring_force_error: added to the restoring force [N] (Fig 9b), or None.
        m_m, c_m: modelled mass [kg] and damping [N s/m] (Table I: 7084 kg, 3.5 kN s/m).
        k_m: stiffness for the displacement-based restoring forces [N/m] (default rig.k).
        solver: ``"central_difference"`` or ``"explicit_newmark"``.
        restoring_force: ``"calculated_displacement"`` (a), ``"measured_displacement"`` (b),
            ``"measured_force"`` (c) or ``"measured_force_corrected"`` (d: minus m a and c v).
        amplitude_T: amplitude compensation T_d on the command [s] (68 ms; 0 = none).
        delay_T: delay compensation T_ld on the restoring force [s]; default 11.2 ms, or 0 for
            ``"calculated_displacement"`` (the paper applied none there, Fig 9a).
        physical_mass_fraction: the rig's structural mass is set to this times m_m (0.02 = 140 kg).
        force_measurement: ``"load_cell"`` or ``"actuator_pressure"`` (p A, includes the piston inertia).
        subtract_mass, subtract_damping: for (d) [kg], [N s/m]; default the physical values.
    """
    n = None
    for _name, a in (("ground_acceleration", ground_acceleration), ("external_force", external_force),
                    ("restoring_force_error", restoring_force_error)):
        if a is not None:
            n = np.asarray(a).size if n is None else n
    if n is None:
        raise ValueError("give ground_acceleration [m/s^2] or external_force [N]")
    ag = np.zeros(n) if ground_acceleration is None else _array("ground_acceleration", ground_acceleration, n)
    pe = None if external_force is None else _array("external_force", external_force, n)
    fe = None if restoring_force_error is None else _array("restoring_force_error", restoring_force_error, n)
    cfg = _core.RpsdConfig()
    cfg.dt = dt
    cfg.model = _core.ModelSDOF(m_m, c_m)
    cfg.k_m = _nonneg("k_m", 0.0 if k_m is None else k_m)
    cfg.solver = _choice("solver", solver, SOLVERS)
    cfg.restoring_force = _choice("restoring_force", restoring_force, RESTORING_FORCE)
    cfg.force_measurement = _choice("force_measurement", force_measurement, FORCE_MEASUREMENT)
    cfg.amplitude_T = _nonneg("amplitude_T", amplitude_T)
    if delay_T is None:
        delay_T = 0.0 if restoring_force == "calculated_displacement" else DELAY_T
    cfg.delay_T = _nonneg("delay_T", delay_T)
    cfg.alpha = alpha
    cfg.physical_mass_fraction = physical_mass_fraction
    cfg.subtract_mass = -1.0 if subtract_mass is None else _nonneg("subtract_mass", subtract_mass)
    cfg.subtract_damping = -1.0 if subtract_damping is None else _nonneg("subtract_damping", subtract_damping)
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = options or solver_options()
    test = _core.RealTimePseudoDynamicTest(rig, cfg)
    d, s = test.run(ag, pe, fe)
    phys = copy.deepcopy(rig)
    phys.m = physical_mass_fraction * m_m
    return _finish("RPsD", d, s, phys, dt, raise_on_failure)


def run_tracking(rig: Rig, displacement, dt: float = 5e-4, amplitude_T: float = AMPLITUDE_T,
                 alpha: float = ALPHA, options: _core.SolverOptions | None = None) -> SimulationResult:
    """Displacement control of a given displacement [m] through the amplitude compensation
    (T_d phase lead on the command, Fig 1b / Fig 5b); returns the plant's SimulationResult
    (``.warnings()`` reports capacity and supply-pressure limits)."""
    d = _array("displacement", displacement)
    lead = _core.PhaseLead(_nonneg("amplitude_T", amplitude_T), alpha, dt)
    lead.reset(float(d[0]))
    return simulate(rig, "displacement", lead.filter(d), dt, x0=float(d[0]), options=options,
                    raise_on_failure=False)

