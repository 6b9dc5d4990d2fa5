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
this module only builds configurations and wraps the arrays.  The controllers
alone, for stepping by hand against a plant or a real rig, are
``servohydraulics.controllers`` (``sh.EftController``, ``sh.RpsdController``).
The defaults (2 kHz, 5 ms, 68 ms, 11.2 ms, alpha = 0.1, m_m, c_m) are the
core's ``_core.ZHAO2003_TEST_METHODS`` (zhao2003.hpp).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _core
from .rig import Rig
from .simulate import SimulationResult, limit_warnings, simulate
from .simulate import solver_options as _solver_options

COMPENSATION = {"none": _core.VelocityFeedbackCompensator.Kind.None_,
                "linear": _core.VelocityFeedbackCompensator.Kind.Linear,
                "nonlinear": _core.VelocityFeedbackCompensator.Kind.Nonlinear}
RESTORING_FORCE = {"calculated_displacement": _core.RestoringForce.CalculatedDisplacement,
                   "measured_displacement": _core.RestoringForce.MeasuredDisplacement,
                   "measured_force": _core.RestoringForce.MeasuredForce,
                   "measured_force_corrected": _core.RestoringForce.MeasuredForceCorrected}
SCHEMES = {"central_difference": _core.IntegrationScheme.CentralDifference,
           "explicit_newmark": _core.IntegrationScheme.ExplicitNewmark}
FORCE_MEASUREMENT = {"load_cell": _core.ForceMeasurement.LoadCell,
                     "actuator_pressure": _core.ForceMeasurement.ActuatorPressure}

#: The paper's test-method constants (Table I and text), SI, from the core.
_TM = _core.ZHAO2003_TEST_METHODS


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


def _renamed(old: str, old_value, new: str, new_value):
    """The value of a keyword renamed in issue 11; the old name warns (DeprecationWarning)."""
    if old_value is None:
        return new_value
    warnings.warn(f"{old}= is deprecated, use {new}=", DeprecationWarning, stacklevel=3)
    if new_value is not None:
        raise ValueError(f"give {new}= or its deprecated alias {old}=, not both")
    return old_value


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


def eft_config(dt: float = _TM.dt, compensation: str = "linear", lead_T: float = _TM.eft_lead_T,
               alpha: float = _TM.alpha, mass: float | None = None, compute_delay: int = 0,
               solver_options: _core.SolverOptions | None = None) -> _core.EftConfig:
    """The core's EftConfig (validated); None = the default (mass: the rig's m)."""
    cfg = _core.EftConfig()
    cfg.dt = dt
    cfg.mass = mass
    cfg.compensation = _choice("compensation", compensation, COMPENSATION)
    cfg.lead_T = _nonneg("lead_T", lead_T)
    cfg.alpha = alpha
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = solver_options or _core.SolverOptions()
    cfg.validate()
    return cfg


def run_eft(rig: Rig, ground_acceleration=None, effective_force=None, dt: float = _TM.dt,
            compensation: str = "linear", lead_T: float = _TM.eft_lead_T, alpha: float = _TM.alpha,
            mass: float | None = None, compute_delay: int = 0, model: Rig | None = None,
            solver_options: _core.SolverOptions | None = None, raise_on_failure: bool = True,
            options: _core.SolverOptions | None = None) -> MethodResult:
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
        solver_options: the plant's ODE integrator (``solver_options(...)``); ``options=`` is
            its deprecated alias.
    """
    if (ground_acceleration is None) == (effective_force is None):
        raise ValueError("give exactly one of ground_acceleration [m/s^2] or effective_force [N]")
    opts = _renamed("options", options, "solver_options", solver_options)
    cfg = eft_config(dt, compensation, lead_T, alpha, mass, compute_delay, opts or _solver_options())
    m = rig.m if cfg.mass is None else cfg.mass
    ag = (_array("ground_acceleration", ground_acceleration) if effective_force is None
          else -_array("effective_force", effective_force) / m)
    test = _core.EffectiveForceTest(rig, cfg, model)
    d, s = test.run(ag)
    return _finish("EFT", d, s, rig, dt, raise_on_failure)


def rpsd_config(dt: float = _TM.dt, m_m: float = _TM.model.m_m, c_m: float = _TM.model.c_m,
                k_m: float | None = None, scheme: str = "central_difference",
                restoring_force: str = "measured_displacement", amplitude_T: float = _TM.amplitude_T,
                delay_T: float | None = None, alpha: float = _TM.alpha, physical_mass_fraction: float = 1.0,
                force_measurement: str = "load_cell", subtract_mass: float | None = None,
                subtract_damping: float | None = None, compute_delay: int = 0,
                solver_options: _core.SolverOptions | None = None) -> _core.RpsdConfig:
    """The core's RpsdConfig (validated); None = the default (delay_T: 11.2 ms, or 0 for
    ``"calculated_displacement"``; k_m, subtract_mass, subtract_damping: from the physical rig)."""
    cfg = _core.RpsdConfig()
    cfg.dt = dt
    cfg.model = _core.ModelSDOF(m_m, c_m)
    cfg.k_m = k_m
    cfg.scheme = _choice("scheme", scheme, SCHEMES)
    cfg.restoring_force = _choice("restoring_force", restoring_force, RESTORING_FORCE)
    cfg.force_measurement = _choice("force_measurement", force_measurement, FORCE_MEASUREMENT)
    cfg.amplitude_T = _nonneg("amplitude_T", amplitude_T)
    if delay_T is None:
        delay_T = 0.0 if restoring_force == "calculated_displacement" else _TM.delay_T
    cfg.delay_T = _nonneg("delay_T", delay_T)
    cfg.alpha = alpha
    cfg.physical_mass_fraction = physical_mass_fraction
    cfg.subtract_mass = subtract_mass
    cfg.subtract_damping = subtract_damping
    cfg.compute_delay = int(compute_delay)
    cfg.plant_options = solver_options or _core.SolverOptions()
    cfg.validate()
    return cfg


def run_rpsd(rig: Rig, ground_acceleration=None, external_force=None, restoring_force_error=None,
             dt: float = _TM.dt, m_m: float = _TM.model.m_m, c_m: float = _TM.model.c_m,
             k_m: float | None = None, scheme: str | None = None, restoring_force: str = "measured_displacement",
             amplitude_T: float = _TM.amplitude_T, delay_T: float | None = None, alpha: float = _TM.alpha,
             physical_mass_fraction: float = 1.0, force_measurement: str = "load_cell",
             subtract_mass: float | None = None, subtract_damping: float | None = None,
             compute_delay: int = 0, solver_options: _core.SolverOptions | None = None,
             raise_on_failure: bool = True, solver: str | None = None,
             options: _core.SolverOptions | None = None) -> MethodResult:
    """Real-time pseudodynamic testing (displacement control) of ``rig``.

    The solver integrates m_m a + c_m v + f = -m_m a_g + P_ext (Eq 15) online.

    Args:
        ground_acceleration: a_g [m/s^2] per sample (None: zero; then external_force sets the length).
        external_force: P_ext into the solver [N] (Fig 9 ramp-and-release), or None.
        restoring_force_error: added to the restoring force [N] (Fig 9b), or None.
        m_m, c_m: modelled mass [kg] and damping [N s/m] (Table I: 7084 kg, 3.5 kN s/m).
        k_m: stiffness for the displacement-based restoring forces [N/m] (default rig.k).
        scheme: the Eq (15) integration scheme, ``"central_difference"`` (default) or
            ``"explicit_newmark"``; ``solver=`` is its deprecated alias.
        restoring_force: ``"calculated_displacement"`` (a), ``"measured_displacement"`` (b),
            ``"measured_force"`` (c) or ``"measured_force_corrected"`` (d: minus m a and c v).
        amplitude_T: amplitude compensation T_d on the command [s] (68 ms; 0 = none).
        delay_T: delay compensation T_ld on the restoring force [s]; default 11.2 ms, or 0 for
            ``"calculated_displacement"`` (the paper applied none there, Fig 9a).
        physical_mass_fraction: the rig's structural mass is set to this times m_m (0.02 = 140 kg).
        force_measurement: ``"load_cell"`` or ``"actuator_pressure"`` (p A, includes the piston inertia).
        subtract_mass, subtract_damping: for (d) [kg], [N s/m]; default the physical values.
        solver_options: the plant's ODE integrator; ``options=`` is its deprecated alias.
    """
    scheme = _renamed("solver", solver, "scheme", scheme) or "central_difference"
    opts = _renamed("options", options, "solver_options", solver_options)
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
    cfg = rpsd_config(dt, m_m, c_m, k_m, scheme, restoring_force, amplitude_T, delay_T, alpha,
                      physical_mass_fraction, force_measurement, subtract_mass, subtract_damping, compute_delay,
                      opts or _solver_options())
    test = _core.RealTimePseudoDynamicTest(rig, cfg)
    d, s = test.run(ag, pe, fe)
    phys = _core.RealTimePseudoDynamicTest.physical_rig(rig, cfg)
    return _finish("RPsD", d, s, phys, dt, raise_on_failure)


def run_tracking(rig: Rig, displacement, dt: float = _TM.dt, amplitude_T: float = _TM.amplitude_T,
                 alpha: float = _TM.alpha, solver_options: _core.SolverOptions | None = None,
                 options: _core.SolverOptions | None = None) -> SimulationResult:
    """Displacement control of a given displacement [m] through the amplitude compensation
    (T_d phase lead on the command, Fig 1b / Fig 5b); returns the plant's SimulationResult
    (``.warnings()`` reports capacity and supply-pressure limits)."""
    opts = _renamed("options", options, "solver_options", solver_options)
    d = _array("displacement", displacement)
    lead = _core.PhaseLead(_nonneg("amplitude_T", amplitude_T), alpha, dt)
    lead.reset(float(d[0]))
    return simulate(rig, "displacement", lead.filter(d), dt, x0=float(d[0]), options=opts,
                    raise_on_failure=False)


def paper_numbers(sweep_duration: float = 20.0) -> dict:
    """The numbers of docs/methods.md (the same runs as tests/python/test_methods.py):
    ``python -m servohydraulics.methods``.  About 30 s on one core."""
    from . import excitations as ex
    from .rig import zhao2003
    from .signals import fourier_ratio, identify_free_vibration

    dt = 5e-4
    out: dict = {}
    lin = zhao2003()
    e = lin.effects
    for name in ("flow_nonlinearity", "load_pressure", "coulomb_friction", "spring_softening"):
        setattr(e, name, False)
    lin.effects = e
    full = zhao2003()

    def frf(rig, amp, **kw):
        P = ex.sine_sweep(amp, duration=sweep_duration)
        res = run_eft(rig, effective_force=P, raise_on_failure=False, **kw)
        f, H = fourier_ratio(res.force, P, dt)
        b = (f > 0.3) & (f < 10)
        return f[b], H[b], res

    for label, rig, amp, kw in (("fig3a linear model, none", lin, 2.3e3, {"compensation": "none"}),
                                ("fig3b linear model, linear", lin, 2.3e3, {}),
                                ("full model 2.3 kN, linear", full, 2.3e3, {}),
                                ("full model 2.3 kN, nonlinear", full, 2.3e3, {"compensation": "nonlinear"}),
                                ("fig4b full model 8.9 kN, linear", full, 8.9e3, {}),
                                ("fig4c full model 8.9 kN, nonlinear", full, 8.9e3, {"compensation": "nonlinear"}),
                                ("linear model, lead 0 (under)", lin, 2.3e3, {"lead_T": 0.0}),
                                ("linear model, lead 5.28 ms (+ZOH)", lin, 2.3e3, {"lead_T": 5.28e-3}),
                                ("linear model, lead 12 ms (over)", lin, 2.3e3, {"lead_T": 12e-3}),
                                ("linear model, lead 40 ms (over)", lin, 2.3e3, {"lead_T": 40e-3})):
        f, H, res = frf(rig, amp, **kw)
        out[f"EFT {label}"] = (f"|F/P| min {H.min():.3f} at {f[np.argmin(H)]:.2f} Hz, max {H.max():.3f} at "
                               f"{f[np.argmax(H)]:.2f} Hz, max |spool| {np.max(np.abs(res.spool)):.3f}, "
                               f"max |x| {np.max(np.abs(res.displacement)) * 1e3:.1f} mm")

    ramp, hold, free = 5.0, 1.0, 4.0
    i0 = ex.release_index(ramp, hold)

    def fv(**kw):
        pe = ex.ramp_and_release(full.k * 0.016, ramp, hold, free)
        res = run_rpsd(full, external_force=pe, raise_on_failure=False, **kw)
        return identify_free_vibration(res.calc_displacement, dt, start=i0, duration=free)

    for label, kw in (("(a) calculated displacement, T_ld 0", {"restoring_force": "calculated_displacement"}),
                      ("(b) T_ld 0", {"delay_T": 0.0}), ("(b) T_ld 6 ms", {"delay_T": 6e-3}),
                      ("(b) T_ld 11.2 ms", {"delay_T": 11.2e-3}), ("(b) T_ld 16 ms", {"delay_T": 16e-3}),
                      ("(b) T_ld 20 ms", {"delay_T": 20e-3}),
                      ("(c) measured force, 100 % mass", {"restoring_force": "measured_force"}),
                      ("(b) 2 % mass", {"physical_mass_fraction": 0.02}),
                      ("(c) measured force, 2 % mass", {"restoring_force": "measured_force",
                                                         "physical_mass_fraction": 0.02}),
                      ("(d) pA minus (m + m_p) a + c v", {"restoring_force": "measured_force_corrected",
                                                          "force_measurement": "actuator_pressure"}),
                      ("(d) pA minus m a + c v (piston ignored)", {"restoring_force": "measured_force_corrected",
                                                                   "force_measurement": "actuator_pressure",
                                                                   "subtract_mass": 7084.0})):
        r = fv(**kw)
        out[f"RPsD free vibration {label}"] = f"f_d {r.frequency:.4f} Hz, zeta {r.damping_ratio * 100:+.2f} %"

    flowlin = zhao2003()
    e = flowlin.effects
    e.flow_nonlinearity = False
    flowlin.effects = e
    for T in (6e-3, 11.2e-3, 16e-3):
        pe = ex.ramp_and_release(flowlin.k * 0.016, ramp, hold, free)
        res = run_rpsd(flowlin, external_force=pe, delay_T=T, raise_on_failure=False)
        r = identify_free_vibration(res.calc_displacement, dt, start=i0, duration=free)
        out[f"RPsD free vibration (b) T_ld {T * 1e3:g} ms, flow nonlinearity off"] = (
            f"f_d {r.frequency:.4f} Hz, zeta {r.damping_ratio * 100:+.2f} %")

    u = ex.sine_sweep(0.0127, duration=sweep_duration)
    res = run_tracking(full, u, dt)
    hit = np.flatnonzero(res.flags & (_core.FLAG_SUPPLY_LIMITED | _core.FLAG_CAPACITY_EXCEEDED))
    if hit.size:
        out["1.27 cm sweep first supply/capacity flag"] = (
            f"t = {res.time[hit[0]]:.2f} s, f = {ex.sweep_frequency(res.time[hit[0]], duration=sweep_duration):.2f} Hz")
    out["1.27 cm sweep warnings"] = "; ".join(res.warnings())
    return out


if __name__ == "__main__":
    for k, v in paper_numbers().items():
        print(f"{k}: {v}")
