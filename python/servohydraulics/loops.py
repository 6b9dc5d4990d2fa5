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
the core's ``EftConfig`` and ``RpsdConfig`` (``_core.ZHAO2003_TEST_METHODS``,
zhao2003.hpp): a keyword left at None takes them.  The controllers alone, for
stepping by hand against a plant or a real rig, are in
:mod:`servohydraulics.controllers` (``sh.EftController``, ``sh.RpsdController``)
and are built from the same ``eft_config`` / ``rpsd_config``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .response import Response, finish
from .rig import Rig
from .simulate import _assign, simulate
from .simulate import solver_options as _solver_options

# Names from the core's tables (enum_name.hpp), in the enum's order.
COMPENSATION = dict(_core.COMPENSATION_NAMES)
RESTORING_FORCE = dict(_core.RESTORING_FORCE_NAMES)
#: every structural scheme (a LinearSubstructure takes any); Eq (15) itself the first two (SCHEMES)
STRUCTURAL_SCHEMES = dict(_core.SCHEME_NAMES)
SCHEMES = dict(list(STRUCTURAL_SCHEMES.items())[:2])
FORCE_MEASUREMENT = dict(_core.FORCE_MEASUREMENT_NAMES)
NOISE_GENERATORS = {"mersenne_twister": _core.NoiseGenerator.MersenneTwister,
                    "simulink": _core.NoiseGenerator.SimulinkRandomNumber}


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


def _renamed(old: str, old_value, new: str, new_value):
    """The value of a keyword renamed in issue 11; the old name warns (DeprecationWarning)."""
    if old_value is None:
        return new_value
    warnings.warn(f"{old}= is deprecated, use {new}=", DeprecationWarning, stacklevel=3)
    if new_value is not None:
        raise ValueError(f"give {new}= or its deprecated alias {old}=, not both")
    return old_value


def _set(cfg: object, **values) -> None:
    """Set the config fields that were given (None keeps the core's default); a value the
    C++ field cannot hold is a ValueError naming it (simulate._assign)."""
    _assign(cfg, **values)


def _integer(name: str, v) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v != int(v):
        raise ValueError(f"invalid {name} = {v!r}: expected a whole number")
    return int(v)


def _choice(name: str, v: str, table: dict):
    if v not in table:
        raise ValueError(f"invalid {name} = {v!r}: expected one of {sorted(table)}")
    return table[v]


def _optional_nonneg(name: str, v: float | None) -> float | None:
    return None if v is None else _nonneg(name, v)


#: the keywords of eft_config / rpsd_config and the loop options that set a field not of their own name
FIELD_KEYWORDS = {"plant_options": ("solver_options",), "model": ("m_m", "c_m")}
#: the config fields a name selects, by field name (the enum name tables above)
_FIELD_CHOICES = {"compensation": COMPENSATION, "scheme": SCHEMES, "restoring_force": RESTORING_FORCE,
                  "force_measurement": FORCE_MEASUREMENT}


def _fill(cfg, table, **values):
    """Set every field of a core config from its field table (``_core.EFT_CONFIG_FIELDS``,
    ``RPSD_CONFIG_FIELDS``: controllers.hpp; ``EFT_LOOP_OPTION_FIELDS``,
    ``RPSD_LOOP_OPTION_FIELDS``: loops.hpp), in table order, and validate it.  ``values`` must
    name exactly the table's fields (a field added to the table and not here is a TypeError at
    every call); None keeps the core's default, a choice field takes its name, a field counted
    in samples a whole number."""
    names = [name for name, _, _ in table]
    if sorted(values) != sorted(names):
        raise TypeError(f"{type(cfg).__name__}: the keywords {sorted(values)} are not the core's fields {names}")
    for name, unit, _ in table:
        v = values[name]
        if v is not None and name in _FIELD_CHOICES:
            v = _choice(name, v, _FIELD_CHOICES[name])
        elif v is not None and unit == "samples":
            v = _integer(name, v)
        _set(cfg, **{name: v})
    cfg.validate()
    return cfg


def fields_doc(table) -> str:
    """The fields of a config table as docstring lines: ``name [unit]: meaning``."""
    return "\n".join(f"    {name}{f' [{unit}]' if unit else ''}: {meaning}" for name, unit, meaning in table)


def _document_fields(obj, table_name: str):
    """Appends the fields of ``_core.<table_name>`` (name, unit, meaning) to obj's docstring."""
    if obj.__doc__:  # None under python -OO
        obj.__doc__ += f"\n\n    Fields (_core.{table_name}):\n\n{fields_doc(getattr(_core, table_name))}\n"
    return obj


def sensor_channel(sigma: float = 0.0, quantum: float = 0.0, range: tuple[float, float] | None = None,
                   unit_delay: bool = False, gain: float = 1.0) -> _core.SensorChannel:
    """One measured channel of ``loop_converters``: y_k = AD(gain x_k + sigma w_k), w_k ~ N(0, 1)
    drawn once per sample, AD = saturation to ``range`` then quantizer of step ``quantum``
    (round half away from zero); ``unit_delay``: the controller sees y_{k-1}."""
    ch = _core.SensorChannel()
    ch.noise = _core.SensorNoise(_nonneg("sigma", sigma), gain)
    ch.converter = _converter("AnalogToDigital", quantum, range)
    ch.unit_delay = bool(unit_delay)
    return ch


def _converter(kind: str, quantum: float, range: tuple[float, float] | None) -> _core.Converter:
    c = _core.Converter()
    c.kind = getattr(_core.Converter.Kind, kind)
    c.enabled = quantum != 0.0 or range is not None
    c.quantizer = _core.Quantizer(_nonneg("quantum", quantum))
    big = np.finfo(float).max  # no range: a saturation that never acts
    lo, hi = (-big, big) if range is None else (float(range[0]), float(range[1]))
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        raise ValueError(f"invalid range = {range!r}: expected (lower, upper), finite, upper > lower")
    c.saturation = _core.Saturation(lo, hi)
    return c


def loop_converters(displacement: _core.SensorChannel | None = None, velocity: _core.SensorChannel | None = None,
                    force: _core.SensorChannel | None = None, command_quantum: float = 0.0,
                    command_range: tuple[float, float] | None = None, command_unit_delay: bool = False,
                    seed: int = 0, generator: str = "mersenne_twister") -> _core.LoopConverters:
    """The sensor and converter blocks of an EFT or RPsD loop (all off by default).

    Args:
        displacement, velocity, force: ``sensor_channel(...)`` of the measured channels
            the controller reads (None: ideal).
        command_quantum, command_range: the D/A on the command (quantizer then saturation).
        command_unit_delay: the plant receives the command of the previous sample.
        seed: of the noise generators (one per channel).
        generator: which generator draws the noise, ``"mersenne_twister"`` or ``"simulink"``
            (Simulink's Random Number block, the RTHS benchmark's; converters.hpp NoiseGenerator).
    """
    c = _core.LoopConverters()
    for name, ch in (("displacement", displacement), ("velocity", velocity), ("force", force)):
        if ch is not None:
            setattr(c, name, ch)
    c.command = _converter("DigitalToAnalog", command_quantum, command_range)
    c.command_unit_delay = bool(command_unit_delay)
    c.seed = _integer("seed", seed) & (2**64 - 1)
    c.generator = _choice("generator", generator, NOISE_GENERATORS)
    c.validate()
    return c


def _converters(c: _core.LoopConverters | None) -> _core.LoopConverters:
    if c is None:
        return _core.LoopConverters()
    if not isinstance(c, _core.LoopConverters):
        raise ValueError(f"invalid converters = {c!r}: expected loop_converters(...) or None")
    return c


def eft_config(dt: float | None = None, compensation: str = "linear", lead_T: float | None = None,
               alpha: float | None = None, mass: float | None = None,
               compute_delay: int = 0) -> _core.EftConfig:
    """The core's EftConfig (validated): the EFT controller's settings; a keyword left at None
    keeps the core's default (mass: None = the rig's m).  How the loop simulates the plant is
    :func:`eft_loop_options`."""
    cfg = _core.EftConfig()
    return _fill(cfg, _core.EFT_CONFIG_FIELDS, dt=dt, mass=mass, compensation=compensation,
                 lead_T=_nonneg("lead_T", _default(lead_T, cfg, "lead_T")), alpha=alpha,
                 compute_delay=compute_delay)


_document_fields(eft_config, "EFT_CONFIG_FIELDS")


def eft_loop_options(solver_options: _core.SolverOptions | None = None) -> _core.EftLoopOptions:
    """The simulated EFT loop's own settings (``_core.EftLoopOptions``, loops.hpp; validated):
    ``solver_options`` is the field ``plant_options`` (None: the core's default)."""
    return _fill(_core.EftLoopOptions(), _core.EFT_LOOP_OPTION_FIELDS, plant_options=solver_options)


_document_fields(eft_loop_options, "EFT_LOOP_OPTION_FIELDS")


def run_eft(rig: Rig, ground_acceleration: ArrayLike | None = None, effective_force: ArrayLike | None = None,
            dt: float | None = None, compensation: str = "linear", lead_T: float | None = None,
            alpha: float | None = None, mass: float | None = None, compute_delay: int = 0,
            model: Rig | None = None, solver_options: _core.SolverOptions | None = None,
            raise_on_failure: bool = True, options: _core.SolverOptions | None = None,
            converters: _core.LoopConverters | None = None, tracking=None) -> Response:
    """Effective force testing (force control) of ``rig``.

    ``tracking`` (None: the paper's velocity feedback compensation of ``compensation``) is any
    TrackingController (tracking.hpp): it reads desired = P_eff [N] and the measured force,
    velocity and pressure, and returns the force command [N].

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
        solver_options: the plant's ODE integrator (``solver_options(...)``); ``options=`` is
            its deprecated alias.
        raise_on_failure: raise SimulationError (with the partial Response) if the loop fails.
        converters: sensor noise, A/D and D/A converters and unit delays between the plant
            and the controller (``loop_converters(...)``); None: ideal (all off).

    Returns:
        A Response of kind ``"eft"``: the plant's channels, ``flags`` and the
        method's (ground_acceleration, effective_force, compensation,
        compensation_opening, command).
    """
    if (ground_acceleration is None) == (effective_force is None):
        raise ValueError("give exactly one of ground_acceleration [m/s^2] or effective_force [N]")
    opts = _renamed("options", options, "solver_options", solver_options)
    cfg = eft_config(dt, compensation, lead_T, alpha, mass, compute_delay)
    loop_options = eft_loop_options(opts or _solver_options())
    m = rig.m if cfg.mass is None else cfg.mass
    ag = (_array("ground_acceleration", ground_acceleration) if effective_force is None
          else -_array("effective_force", effective_force) / m)
    tr = _tracking(tracking)
    test = _core.EffectiveForceTest(rig, cfg, model, _converters(converters), tr, loop_options)
    d, s = _run_with(tr, cfg.dt, lambda: test.run(ag))
    return finish(Response(d, kind="eft", mode="force", dt=cfg.dt, rig=rig, work=s), raise_on_failure)


_SUBSTRUCTURE_PROTOCOL = ("h", "size", "interface_dof", "reset", "step", "displacements", "interface_velocity",
                          "interface_acceleration")


def linear_substructure(M: ArrayLike, C: ArrayLike, K: ArrayLike, ground: ArrayLike | None = None,
                        interface: ArrayLike | int = 0, dt: float | None = None,
                        scheme: str = "central_difference") -> _core.rths.LinearSubstructure:
    """A linear numerical substructure M x'' + C x' + K x = -ground a_g - interface f_in of any
    size, for ``run_rpsd(substructure=...)`` (and the RTHS loop).

    Args:
        M, C, K: mass [kg], damping [N s/m] and stiffness [N/m] matrices (n x n; scalars for 1 DOF).
        ground: ground-load vector [kg] (None: M @ 1, a rigid base).
        interface: the DOF the measured restoring force acts on (an index), or the vector gamma.
        dt: sample time [s] (None: the core's RPsD 0.5 ms); must equal the loop's.
        scheme: ``"central_difference"``, ``"explicit_newmark"``, ``"average_acceleration"`` or
            ``"runge_kutta4"`` (substructure.hpp).
    """
    Mm, Cm, Km = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (M, C, K))
    n = Mm.shape[0]
    g = Mm @ np.ones(n) if ground is None else np.atleast_1d(np.asarray(ground, dtype=float))
    if isinstance(interface, (int, np.integer)) and not isinstance(interface, bool):
        if not 0 <= interface < n:
            raise ValueError(f"invalid interface = {interface}: a DOF index 0..{n - 1}")
        gam = np.zeros(n)
        gam[int(interface)] = 1.0
    else:
        gam = np.atleast_1d(np.asarray(interface, dtype=float))
    model = _core.rths.LinearSubstructureModel(Mm, Cm, Km, g, gam)
    model.validate()
    h = _default(dt, _core.RpsdConfig(), "dt")
    return _core.rths.LinearSubstructure(model, h, _choice("scheme", scheme, STRUCTURAL_SCHEMES))


def _substructure(sub):
    """The core object for ``run_rpsd(substructure=...)``: a core NumericalSubstructure as is, a
    Python object with the adapter protocol (rths.OpenSeesSubstructure) wrapped, None kept."""
    if sub is None or isinstance(sub, _core.rths.NumericalSubstructure):
        return sub
    missing = [a for a in _SUBSTRUCTURE_PROTOCOL if not hasattr(sub, a)]
    if missing:
        raise ValueError(f"invalid substructure = {sub!r}: expected a NumericalSubstructure "
                         f"(linear_substructure(...)) or an object with {', '.join(missing)}")
    return _core.rths.PythonSubstructure(sub)


def _tracking(t):
    """The loop's tracking controller: None (the paper's), a TrackingController (C++ or a Python
    subclass) or any object with reset() and command(...) (wrapped, docs/rths-benchmark.md)."""
    if t is None or isinstance(t, _core.rths.TrackingController):
        return t
    if callable(getattr(t, "reset", None)) and callable(getattr(t, "command", None)):
        return _core.rths.PythonController(t)
    raise ValueError(f"invalid tracking = {t!r}: expected a TrackingController (e.g. _core.rths.AdaptiveTimeSeries) "
                     "or an object with reset() and command(...)")


def _run_with(tracking, dt: float, run):
    """run(), then what a Python tracking controller raised during it (RuntimeError naming the
    sample and its time, from the controller's own exception) before any failure it caused."""
    try:
        out = run()
    except Exception:
        if tracking is not None:
            tracking.raise_stored_error(dt)
        raise
    if tracking is not None:
        tracking.raise_stored_error(dt)
    return out


def rpsd_config(dt: float | None = None, m_m: float | None = None, c_m: float | None = None,
                k_m: float | None = None, scheme: str = "central_difference",
                restoring_force: str = "measured_displacement", amplitude_T: float | None = None,
                delay_T: float | None = None, alpha: float | None = None, force_measurement: str = "load_cell",
                subtract_mass: float | None = None, subtract_damping: float | None = None,
                compute_delay: int = 0) -> _core.RpsdConfig:
    """The core's RpsdConfig (validated): the RPsD controller's settings; a keyword left at None
    keeps the core's default (delay_T: 11.2 ms, or 0 for ``"calculated_displacement"``; k_m,
    subtract_mass, subtract_damping: None = from the physical rig).  How the loop simulates the
    plant is :func:`rpsd_loop_options`."""
    cfg = _core.RpsdConfig()
    if delay_T is None and restoring_force == "calculated_displacement":
        delay_T = 0.0
    return _fill(cfg, _core.RPSD_CONFIG_FIELDS, dt=dt,
                 model=_core.ModelSDOF(_default(m_m, cfg.model, "m_m"), _default(c_m, cfg.model, "c_m")),
                 k_m=_optional_nonneg("k_m", k_m), scheme=scheme, restoring_force=restoring_force,
                 force_measurement=force_measurement,
                 amplitude_T=_nonneg("amplitude_T", _default(amplitude_T, cfg, "amplitude_T")),
                 delay_T=_nonneg("delay_T", _default(delay_T, cfg, "delay_T")), alpha=alpha,
                 subtract_mass=_optional_nonneg("subtract_mass", subtract_mass),
                 subtract_damping=_optional_nonneg("subtract_damping", subtract_damping),
                 compute_delay=compute_delay)


_document_fields(rpsd_config, "RPSD_CONFIG_FIELDS")


def rpsd_loop_options(physical_mass_fraction: float = 1.0,
                      solver_options: _core.SolverOptions | None = None) -> _core.RpsdLoopOptions:
    """The simulated RPsD loop's own settings (``_core.RpsdLoopOptions``, loops.hpp; validated):
    the plant's structural mass is ``physical_mass_fraction`` times m_m; ``solver_options`` is
    the field ``plant_options`` (None: the core's default)."""
    return _fill(_core.RpsdLoopOptions(), _core.RPSD_LOOP_OPTION_FIELDS, plant_options=solver_options,
                 physical_mass_fraction=physical_mass_fraction)


_document_fields(rpsd_loop_options, "RPSD_LOOP_OPTION_FIELDS")


def run_rpsd(rig: Rig, ground_acceleration: ArrayLike | None = None, external_force: ArrayLike | None = None,
             restoring_force_error: ArrayLike | None = None, dt: float | None = None, m_m: float | None = None,
             c_m: float | None = None, k_m: float | None = None, scheme: str | None = None,
             restoring_force: str = "measured_displacement", amplitude_T: float | None = None,
             delay_T: float | None = None, alpha: float | None = None, physical_mass_fraction: float = 1.0,
             force_measurement: str = "load_cell", subtract_mass: float | None = None,
             subtract_damping: float | None = None, compute_delay: int = 0,
             solver_options: _core.SolverOptions | None = None, raise_on_failure: bool = True,
             solver: str | None = None, options: _core.SolverOptions | None = None,
             converters: _core.LoopConverters | None = None, substructure=None, tracking=None) -> Response:
    """Real-time pseudodynamic testing (displacement control) of ``rig``.

    ``substructure`` (None: Eq (15)'s 1-DOF model of m_m, c_m and ``scheme``) is the numerical
    substructure the solver steps: ``linear_substructure(M, C, K, ...)`` of any size, or a Python
    object with the adapter protocol (``rths.OpenSeesSubstructure(..., h=dt)``).  It is stepped
    with a_g held over the sample; the restoring force f (minus P_ext) acts on its interface
    DOF, and the command's target is that DOF's displacement.  ``tracking`` (None: the paper's
    amplitude compensation T_d) is any TrackingController (tracking.hpp), e.g. ATS.

    ``converters`` (``loop_converters(...)``; None: ideal) puts sensor noise, A/D and D/A
    converters and unit delays between the plant and the controller.

    The solver integrates m_m a + c_m v + f = -m_m a_g + P_ext (Eq 15) online.
    Keywords left at None take the core's ``RpsdConfig`` defaults (the paper's values).

    Args:
        ground_acceleration: a_g [m/s^2] per sample (None: zero; then external_force sets the length).
        external_force: P_ext into the solver [N] (Fig 9 ramp-and-release), or None.
        restoring_force_error: added to the restoring force [N] (Fig 9b), or None.
        dt: controller sample time [s] (0.5 ms).
        m_m, c_m: modelled mass [kg] and damping [N s/m] (Table I: 7084 kg, 3.5 kN s/m).
        k_m: stiffness for the displacement-based restoring forces [N/m] (default rig.k).
        scheme: the Eq (15) integration scheme, ``"central_difference"`` (default) or
            ``"explicit_newmark"``; ``solver=`` is its deprecated alias.
        restoring_force: ``"calculated_displacement"`` (a), ``"measured_displacement"`` (b),
            ``"measured_force"`` (c) or ``"measured_force_corrected"`` (d: minus m a and c v).
        amplitude_T: amplitude compensation T_d on the command [s] (68 ms; 0 = none).
        delay_T: delay compensation T_ld on the restoring force [s]; default 11.2 ms, or 0 for
            ``"calculated_displacement"`` (the paper applied none there, Fig 9a).
        alpha: phase-lead constant [-] (0.1).
        physical_mass_fraction: the rig's structural mass is set to this times m_m (0.02 = 140 kg).
        force_measurement: ``"load_cell"`` or ``"actuator_pressure"`` (p A, includes the piston inertia).
        subtract_mass, subtract_damping: for (d) [kg], [N s/m]; default the physical values.
        solver_options: the plant's ODE integrator; ``options=`` is its deprecated alias.
        raise_on_failure: raise SimulationError (with the partial Response) if the loop fails.

    Returns:
        A Response of kind ``"rpsd"`` whose ``rig`` is the physical rig (mass
        ``physical_mass_fraction * m_m``): the plant's channels, ``flags`` and the
        method's (ground_acceleration, external_force, measured_restoring_force,
        restoring_force, calc_displacement, calc_velocity, calc_acceleration,
        target_displacement, command).
    """
    scheme = _renamed("solver", solver, "scheme", scheme) or "central_difference"
    opts = _renamed("options", options, "solver_options", solver_options)
    n = None
    for a in (ground_acceleration, external_force, restoring_force_error):
        if a is not None:
            n = np.asarray(a).size if n is None else n
    if n is None:
        raise ValueError("give ground_acceleration [m/s^2] or external_force [N]")
    ag = np.zeros(n) if ground_acceleration is None else _array("ground_acceleration", ground_acceleration, n)
    pe = None if external_force is None else _array("external_force", external_force, n)
    fe = None if restoring_force_error is None else _array("restoring_force_error", restoring_force_error, n)
    cfg = rpsd_config(dt, m_m, c_m, k_m, scheme, restoring_force, amplitude_T, delay_T, alpha,
                      force_measurement, subtract_mass, subtract_damping, compute_delay)
    loop_options = rpsd_loop_options(physical_mass_fraction, opts or _solver_options())
    sub = _substructure(substructure)
    tr = _tracking(tracking)
    test = _core.RealTimePseudoDynamicTest(rig, cfg, _converters(converters), tr, sub, loop_options)
    d, s = _run_with(tr, cfg.dt, lambda: test.run(ag, pe, fe))
    if isinstance(sub, _core.rths.PythonSubstructure) and sub.error:
        raise RuntimeError(f"numerical substructure failed: {sub.error}")
    phys = _core.RealTimePseudoDynamicTest.physical_rig(rig, cfg, loop_options)
    return finish(Response(d, kind="rpsd", mode="displacement", dt=cfg.dt, rig=phys, work=s), raise_on_failure)


def run_tracking(rig: Rig, displacement: ArrayLike, dt: float | None = None, amplitude_T: float | None = None,
                 alpha: float | None = None, solver_options: _core.SolverOptions | None = None,
                 raise_on_failure: bool = True, options: _core.SolverOptions | None = None) -> Response:
    """Displacement control of a given displacement [m] through the amplitude compensation
    (T_d phase lead on the command, Fig 1b / Fig 5b).

    Keywords left at None take the core's ``RpsdConfig`` defaults (0.5 ms, 68 ms, 0.1).
    Returns a Response of kind ``"tracking"`` (the plant's channels; ``command`` is
    the lead-filtered command; ``.warnings()`` reports capacity and supply-pressure limits).
    """
    opts = _renamed("options", options, "solver_options", solver_options)
    cfg = _core.RpsdConfig()
    dt = _default(dt, cfg, "dt")
    d = _array("displacement", displacement)
    lead = _core.PhaseLead(_nonneg("amplitude_T", _default(amplitude_T, cfg, "amplitude_T")),
                           _default(alpha, cfg, "alpha"), dt)
    lead.reset(float(d[0]))
    res = simulate(rig, "displacement", lead.filter(d), dt, x0=float(d[0]), options=opts, raise_on_failure=False)
    out = Response(res.channels, kind="tracking", mode="displacement", dt=dt, rig=rig, work=res.work)
    return finish(out, raise_on_failure)
