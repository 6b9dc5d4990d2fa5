"""Whole-record simulation of the plant: NumPy in, NumPy out."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .response import Response, SimulationError, finish
from .rig import Rig
from .timegrid import time_axis

#: Largest initial displacement [m]: the plant's divergence guard (plant.cpp, kMaxDisplacement).
MAX_X0 = 100.0

# Names from the core's tables (enum_name.hpp), in the enum's order.  Integrators: dopri5 (the
# default: error-controlled, fast, CVODE for stiff samples), cvode (the reference), rk4 (the
# real-time option: fixed cost, flagged by its error estimate), arkode_erk, arkode_dirk, ros2 (fixed
# cost on a stiff rig: the diagnosis' fits where RK4 would need too many substeps).
MODES = dict(_core.CONTROL_MODE_NAMES)
METHODS = dict(_core.METHOD_NAMES)
RESTARTS = dict(_core.RESTART_NAMES)
#: The core's default integrator's name (SolverOptions().method): "dopri5".
DEFAULT_METHOD = next(name for name, value in METHODS.items() if value == _core.SolverOptions().method)


def solver_options(method: str = DEFAULT_METHOD, rtol: float | None = None, restart: str | None = None,
                   rk4_substeps: int | None = None, max_steps_per_sample: int | None = None,
                   max_order: int | None = None, rk4_h_rho: float | None = None,
                   rk4_v_ref: float | None = None, atol_fraction: float | None = None,
                   stiff_fallback: bool | None = None, stiff_steps: int | None = None,
                   stiff_check: bool | None = None, rk4_flag_rtol: float | None = None,
                   rk4_max_refinements: int | None = None, stiff_rosenbrock: bool | None = None,
                   max_internal_step: float | None = None, ros2_substeps: int | None = None,
                   stiffness_test: bool | None = None, rosenbrock_order: int | None = None) -> _core.SolverOptions:
    """Builds solver options; see ``SolverOptions`` in solver_options.hpp (one keyword per row of
    its field table, ``_core.SOLVER_OPTION_FIELDS``).

    ``method``: ``"dopri5"`` (default: Dormand-Prince 5(4) with error control at ``rtol``, a sample
    where it turns stiff is redone by CVODE (by an error-controlled Rosenbrock method, a one-step method
    that needs no restart at each sample, if ``stiff_rosenbrock``: of order 2, or RODAS4 if ``rosenbrock_order``
    is 4; found stiff by Hairer's stiffness test as well
    as by its step count if ``stiffness_test``), or reported as status ``stiff`` if
    ``stiff_fallback`` is False; a run that turned stiff is checked against one at ``rtol / 10``, ``stiff_check`` False
    drops that check), ``"rk4"`` (the real-time option: fixed cost, ``rk4_substeps`` per sample or automatic,
    checked by a companion run at twice the substeps that flags where the two differ by more than
    ``rk4_flag_rtol`` of the peaks (0: no check), the rest of the run at doubled substeps from a
    flagged sample up to ``rk4_max_refinements`` times), ``"cvode"`` (BDF, the reference), ``"arkode_erk"``,
    ``"arkode_dirk"`` (SUNDIALS ARKODE references), ``"ros2"`` (Verwer's linearly implicit, L-stable
    second-order method at ``ros2_substeps`` fixed substeps per sample, the analytic Jacobian each
    substep: a fixed cost on a rig too stiff for RK4; no error estimate).  Absolute tolerances scale with the rig:
    ``rtol * atol_fraction * state_scale`` (``_core.absolute_tolerances``).  A keyword left at None
    keeps the core's default."""
    if method not in METHODS:
        raise ValueError(f"invalid method = {method!r}: expected one of {sorted(METHODS)}")
    if restart is not None and restart not in RESTARTS:
        raise ValueError(f"invalid restart = {restart!r}: expected one of {sorted(RESTARTS)}")
    o = _core.SolverOptions()
    o.method = METHODS[method]
    _assign(o, restart=None if restart is None else RESTARTS[restart], rtol=rtol, rk4_substeps=rk4_substeps,
            max_steps_per_sample=max_steps_per_sample, max_order=max_order, rk4_h_rho=rk4_h_rho,
            rk4_v_ref=rk4_v_ref, atol_fraction=atol_fraction,
            stiff_fallback=None if stiff_fallback is None else bool(stiff_fallback), stiff_steps=stiff_steps,
            stiff_check=None if stiff_check is None else bool(stiff_check), rk4_flag_rtol=rk4_flag_rtol,
            rk4_max_refinements=rk4_max_refinements,
            stiff_rosenbrock=None if stiff_rosenbrock is None else bool(stiff_rosenbrock),
            max_internal_step=max_internal_step, ros2_substeps=ros2_substeps,
            stiffness_test=None if stiffness_test is None else bool(stiffness_test),
            rosenbrock_order=rosenbrock_order)
    o.validate()
    return o


def _assign(obj: object, **fields) -> None:
    """Sets the binding's fields (None: keep its default); a value the C++ type cannot
    hold (a string, an integer beyond 32 bits) is a ValueError naming the field."""
    for name, value in fields.items():
        if value is None:
            continue
        try:
            setattr(obj, name, value)
        except TypeError:
            kind = type(getattr(obj, name)).__name__
            text = f"an integer of {value.bit_length()} bits" if isinstance(value, int) else repr(value)
            raise ValueError(f"invalid {name} = {text}: expected a value of type {kind} in the range of "
                             "the C++ field") from None


def _check_dt(dt: float) -> float:
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt) or dt <= 0:
        raise ValueError(f"invalid dt = {dt!r}: the controller sample time must be finite and > 0 [s]")
    return float(dt)


def _command_array(command: ArrayLike | None, duration: float | None, dt: float) -> np.ndarray:
    if command is None:
        if duration is None:
            raise ValueError("give a command array or a duration [s]")
        if not math.isfinite(duration) or duration <= 0:
            raise ValueError(f"invalid duration = {duration!r}: must be finite and > 0 [s]")
        return np.zeros(time_axis(duration, dt).size)
    try:
        u = np.asarray(command)
        if np.iscomplexobj(u):  # a float cast drops the imaginary part (a ComplexWarning at most)
            bad = np.flatnonzero(np.ravel(u.imag) != 0)
            if bad.size:
                raise ValueError(f"invalid command[{bad[0]}] = {np.ravel(u)[bad[0]]}: complex; the command is "
                                 "real [m or N]")
            u = u.real
        u = u.astype(float)
    except (TypeError, ValueError) as e:
        if str(e).startswith("invalid command"):
            raise
        raise ValueError(f"invalid command: not an array of numbers ({' '.join(str(e).split())})") from None
    if u.ndim != 1:
        raise ValueError(f"invalid command shape = {u.shape}: expected a 1-D array")
    if u.size < 2:
        raise ValueError(f"invalid command length = {u.size}: need at least 2 samples")
    bad = np.flatnonzero(~np.isfinite(u))
    if bad.size:
        raise ValueError(f"invalid command[{bad[0]}] = {u[bad[0]]}: commands must be finite (no NaN or inf)")
    if duration is not None:
        n = time_axis(duration, dt).size
        if n != u.size:
            raise ValueError(f"invalid command length = {u.size}: duration = {duration} s at dt = {dt} s "
                             f"needs {n} samples")
    return u


def check_x0(x0: float) -> float:
    """The initial displacement as a float; ValueError naming it unless finite and within +-MAX_X0 m."""
    if isinstance(x0, bool) or not isinstance(x0, (int, float)) or not math.isfinite(x0) or abs(x0) > MAX_X0:
        raise ValueError(f"invalid x0 = {x0!r}: must be finite and within +-{MAX_X0:g} m (the plant's "
                         "divergence guard)")
    return float(x0)


def make_plant(rig: Rig, mode: str, dt: float = 5e-4, options: _core.SolverOptions | None = None,
               x0: float = 0.0) -> _core.Plant:
    """Constructs and resets a plant (validates everything, raises ValueError)."""
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    check_x0(x0)
    plant = _core.Plant(rig, MODES[mode], _check_dt(dt), options or solver_options())
    plant.reset(float(x0))
    return plant


def simulate(rig: Rig, mode: str = "displacement", command: ArrayLike | None = None, dt: float = 5e-4,
             duration: float | None = None, x0: float = 0.0,
             options: _core.SolverOptions | None = None, raise_on_failure: bool = True) -> Response:
    """Simulates the rig under a held command, one controller sample per element.

    Args:
        rig: the rig (e.g. ``zhao2003()`` or ``load_rig(path)``).
        mode: ``"displacement"`` (command in m), ``"force"`` (command in N) or
            ``"free"`` (the structure alone, no actuator, released from ``x0``;
            a command, if given, is an ideal external force in N).
        command: 1-D array, or None for a zero command over ``duration``.
        dt: controller sample time [s] (the paper's DSP ran at 2 kHz).
        duration: run length [s] when ``command`` is None (checked against it otherwise).
        x0: initial displacement [m]; the run starts from static equilibrium there.
        options: solver options (``solver_options(...)``); by default the error-controlled
            Dormand-Prince pair (``"dopri5"``, CVODE for stiff samples).
        raise_on_failure: raise SimulationError (carrying the partial Response) on a
            solver failure or divergence; otherwise return the rows computed so far.

    Returns:
        A :class:`~servohydraulics.response.Response` of kind ``"plant"``: the
        plant's channels, ``command``, ``flags``, ``internal_steps``, ``rhs_evals``;
        ``work.stiff_samples`` counts the samples CVODE took over; ``work.error_estimate`` is
        the run's accuracy check over its bound (> 1: the run probably misses the method's stated
        accuracy, also in ``warnings()``: RK4's companion at twice the substeps, or the default's
        check of a run that turned stiff), ``work.inaccurate_samples`` the samples it flagged.
    """
    dt = _check_dt(dt)
    u = _command_array(command, duration, dt)
    opts = options or solver_options()
    plant = make_plant(rig, mode, dt, opts, x0)
    channels, s = _core.run_record(plant, u)
    # A default run that turned stiff is checked from its start as well (record.hpp, check_record).
    tight = _core.record_check_options(opts, s)
    if tight is not None:
        s = _core.check_record(make_plant(rig, mode, dt, tight, x0), u, channels["displacement"][: s.rows],
                               channels["force"][: s.rows], s)
    data = {"time": channels["time"][: s.rows], "command": u[: s.rows]}
    data.update((k, v[: s.rows]) for k, v in channels.items())
    return finish(Response(data, kind="plant", mode=mode, dt=dt, rig=rig, work=s), raise_on_failure)


__all__ = ["MODES", "SimulationError", "make_plant", "simulate", "solver_options"]
