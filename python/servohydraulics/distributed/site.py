"""What a served site does with a trial: the core's objects behind the wire protocol.

* :class:`IdealSite` (``--actuator ideal``): the specimen follows the trial displacement
  exactly and the reply is the specimen's force as the core computes it,
  m a + f_s(x) + c v + F_f(v) (``Dynamics.structure_forces`` and the rig's mass): a linear
  spring answers k x.
* :class:`ModelSite` (``--actuator model``): the rig's actuator, servovalve and servo
  controller (a displacement-controlled ``Plant``) track the trial displacement, ramped
  from the previous one over the step's duration at the controller's sample time; the
  reply is what the transducers measure at the end (load-cell force, displacement).

Every element of the client's displacement vector is one actuator pushing its own copy of
the rig's specimen against the ground (n independent actuators, a diagonal stiffness).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _core
from ..rig import Rig
from .protocol import Action, ProtocolError

#: Specimen elements with a state of their own: the ideal site (stateless) refuses them.
STATEFUL_EFFECTS = ("lugre_friction", "bouc_wen_hysteresis", "mr_damper", "fluid_damper")
ACTUATORS = ("model", "ideal")
CONTROLLERS = ("none", "lead")


class SiteError(RuntimeError):
    """The site cannot go on (the plant failed): the connection ends with this reason."""


class Site:
    """The common part: n actuators of one rig, the trial bookkeeping and the matrices."""

    def __init__(self, rig: Rig, n: int):
        if not (isinstance(n, int) and n >= 1):
            raise ValueError(f"invalid actuators = {n!r}: expected a whole number >= 1")
        rig.validate()
        self.rig, self.n = rig, n
        self.stroke = float(rig.stroke)
        self._dyn = _core.Dynamics(rig, _core.ControlMode.Displacement)
        self.reset()

    def reset(self) -> None:
        z = np.zeros(self.n)
        self.x, self.v, self.a, self.f = z.copy(), z.copy(), z.copy(), z.copy()
        self.t = 0.0
        self.trials = 0
        self._tangent_at, self._tangent, self._zeros = None, None, np.zeros((self.n, self.n))

    def check_trial(self, x: np.ndarray) -> None:
        if np.abs(x).max() > self.stroke:
            over = np.flatnonzero(np.abs(x) > self.stroke)
            i = int(over[0])
            raise ProtocolError(f"trial displacement[{i}] = {x[i]:.6g} m beyond the stroke +-{self.stroke:.6g} m")

    def response(self) -> dict[str, np.ndarray]:
        return {"displacement": self.x, "velocity": self.v, "acceleration": self.a, "force": self.f,
                "time": np.array([self.t])}

    def stiffness(self, x: np.ndarray) -> np.ndarray:
        """The linearised specimen at displacements x: diag(df_s/dx) [N/m], the central difference
        of the core's spring force over +-h = 2^-20 m (about 1 um) around x rounded to a multiple
        of h: every operand a multiple of a power of two, so that a linear spring of a stiffness
        with few significant bits (1000, 700800 N/m) answers exactly k."""
        h = 2.0 ** -20
        sf = self._dyn.spring_force
        xq = np.round(np.asarray(x, dtype=float) / h) * h
        return np.diag([(sf(float(xi) + h) - sf(float(xi) - h)) / (2.0 * h) for xi in xq])

    def matrix(self, action: Action) -> np.ndarray:
        """The reply to GET_*_STIFFNESS, GET_DAMPING, GET_MASS.  Damping and mass are zero: the
        measured force already holds the specimen's inertia and damping force, and OpenSees'
        genericClient adds these matrices to its element (docs/distributed.md)."""
        if action == Action.GET_INITIAL_STIFFNESS:
            return self.stiffness(np.zeros(self.n))
        if action == Action.GET_TANGENT_STIFFNESS:
            key = self.x.tobytes()
            if key != self._tangent_at:  # asked several times a step at one displacement
                self._tangent_at, self._tangent = key, self.stiffness(self.x)
            return self._tangent
        return self._zeros

    def commit(self) -> None:
        pass

    def close(self) -> dict:
        """End of a connection: anything worth logging (a dict)."""
        return {}


class IdealSite(Site):
    """The specimen follows the trial exactly: force = m a + f_s(x) + c v + F_f(v).

    Velocity and acceleration are the client's when it sends them, else backward differences
    of the trial over the time channel (zero without one)."""

    def __init__(self, rig: Rig, n: int = 1):
        on = [e for e in STATEFUL_EFFECTS if getattr(rig.effects, e)]
        if on:
            raise ValueError(f"--actuator ideal: the rig's specimen has a state of its own ({', '.join(on)}): "
                             "switch it off or use --actuator model")
        super().__init__(rig, n)
        self._m = float(rig.m)

    def reset(self) -> None:
        super().reset()
        self._xc, self._vc, self._tc = np.zeros(self.n), np.zeros(self.n), 0.0

    def set_trial(self, trial: dict[str, np.ndarray], time: float | None) -> None:
        x = trial["displacement"]
        self.check_trial(x)
        t = self._tc if time is None else time
        h = t - self._tc
        v = trial.get("velocity")
        if v is None:
            v = (x - self._xc) / h if h > 0 else np.zeros(self.n)
        a = trial.get("acceleration")
        if a is None:
            a = (v - self._vc) / h if h > 0 else np.zeros(self.n)
        self.x, self.v, self.a, self.t = x, v, a, t
        self.f = self._m * a + self._dyn.structure_forces(x, v)
        self.trials += 1

    def commit(self) -> None:
        self._xc, self._vc, self._tc = self.x.copy(), self.v.copy(), self.t


class ModelSite(Site):
    """The rig's actuator and servo controller track each trial displacement.

    The site moves when the client asks for the response (get DAQ response, get
    displacement ... get time) or commits: if the client's time channel has advanced since the last
    move, the displacement command ramps linearly from the last target to the latest trial over
    round(t / dt) - round(t_last / dt) controller samples, and the reply is what the transducers
    read at the end.  Trials at an unchanged time (OpenSees' Newmark sends its predictor at the
    new time, then the corrector at that same time) only replace the pending target: a physical
    specimen cannot move without time passing, so the corrector is executed over the next step
    (``deferred`` counts them).  Without a time channel each changed target is executed over
    ``step_samples`` samples (None: 1).  ``controller`` ``"lead"`` puts the paper's amplitude
    compensation T_d (68 ms, alpha 0.1) on the command.  ``pacer`` (--realtime) is waited on
    before every sample.
    """

    def __init__(self, rig: Rig, n: int = 1, dt: float | None = None, controller: str = "none",
                 step_samples: int | None = None, options: _core.SolverOptions | None = None, pacer=None):
        cfg = _core.RpsdConfig()
        self.dt = float(cfg.dt if dt is None else dt)
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"invalid --dt = {dt!r}: finite and > 0 [s]")
        if controller not in CONTROLLERS:
            raise ValueError(f"invalid --controller = {controller!r}: expected one of {list(CONTROLLERS)}")
        if step_samples is not None and not (isinstance(step_samples, int) and step_samples >= 1):
            raise ValueError(f"invalid --step-samples = {step_samples!r}: a whole number >= 1")
        self.controller, self.step_samples, self.pacer = controller, step_samples, pacer
        self._plants = [_core.Plant(rig, _core.ControlMode.Displacement, self.dt, options or _core.SolverOptions())
                        for _ in range(n)]
        self._leads = ([_core.PhaseLead(cfg.amplitude_T, cfg.alpha, self.dt) for _ in range(n)]
                       if controller == "lead" else None)
        self._rows: list[np.ndarray] = []  # per controller sample: t, command[n], displacement[n], force[n]
        super().__init__(rig, n)

    def reset(self) -> None:
        super().reset()
        for p in self._plants:
            p.reset(0.0, 0.0)
        for lead in self._leads or ():
            lead.reset(0.0)
        self.k, self.target = 0, np.zeros(self.n)
        self.samples = self.deferred = 0
        self._pending, self._pending_k, self._client_k, self._timed = self.target, 0, 0, False
        self._rows = []
        self._observe([p.observe() for p in self._plants])
        if self.pacer is not None:
            self.pacer.start()  # the first deadline one period from now

    def _observe(self, outs) -> None:
        self.x = np.array([o.displacement for o in outs])
        self.v = np.array([o.velocity for o in outs])
        self.a = np.array([o.acceleration for o in outs])
        self.f = np.array([o.force for o in outs])
        self.t = self.k * self.dt

    def set_trial(self, trial: dict[str, np.ndarray], time: float | None) -> None:
        x = trial["displacement"]
        self.check_trial(x)
        if time is not None:
            k = int(round(time / self.dt))
            if k == self._client_k and not np.array_equal(x, self._pending):
                self.deferred += 1
            self._pending_k, self._timed = k, True
        self._pending = x.copy()
        self.trials += 1

    def response(self) -> dict[str, np.ndarray]:
        self._move()
        return super().response()

    def commit(self) -> None:
        self._move()  # a client that commits without asking still moves the specimen

    def _move(self) -> None:
        """Executes the pending trial over the time it gives (see the class)."""
        x = self._pending
        if self._timed:
            steps = self._pending_k - self._client_k
        else:
            steps = 0 if np.array_equal(x, self.target) else (self.step_samples or 1)
        if steps <= 0:
            return
        u0, outs = self.target, []
        for j in range(1, steps + 1):
            u = u0 + (x - u0) * (j / steps)
            if self.pacer is not None:
                self.pacer.wait()  # its stats() hold the wake-up latencies and misses
            outs = []
            for i, p in enumerate(self._plants):
                cmd = self._leads[i].step(float(u[i])) if self._leads else float(u[i])
                status, out = p.step(cmd)
                if not status.ok():
                    raise SiteError(f"actuator {i}: the plant failed at t = {p.time:.6g} s ({status.message})")
                outs.append(out)
            self._rows.append(np.concatenate(([(self.k + j) * self.dt], u, [o.displacement for o in outs],
                                              [o.force for o in outs])))
        self.k += steps
        self.samples += steps
        self._client_k = self._pending_k
        self.target = x
        self._observe(outs)

    def record(self) -> dict[str, np.ndarray]:
        """The connection's controller samples: time [s], the ramped displacement command [m] (the
        trial target before any compensation), the measured displacement [m] and force [N] (one
        column per actuator, suffixed _i when there are several)."""
        rows = np.array(self._rows).reshape(-1, 1 + 3 * self.n)
        out = {"time": rows[:, 0]}
        for j, name in enumerate(("command", "displacement", "force")):
            for i in range(self.n):
                out[name if self.n == 1 else f"{name}_{i}"] = rows[:, 1 + j * self.n + i]
        return out

    def close(self) -> dict:
        out = {"controller samples": self.samples, "trials deferred to the next step": self.deferred}
        if self.pacer is not None:
            out["pacing"] = self.pacer.stats()
        return out


def tracking_delay(time: np.ndarray, command: np.ndarray, measured: np.ndarray, longest: float = 0.15) -> float:
    """The lag [s] (0 .. ``longest``, on the record's sample grid) that maps the command best onto
    the measured displacement (least squares, the first fifth of the record left out as the
    start-up): the tracking delay of a ``ModelSite.record()``."""
    t = np.asarray(time, dtype=float)
    dt = float(t[1] - t[0])
    i0 = len(t) // 5
    lags = np.arange(int(longest / dt) + 1) * dt
    err = [np.mean((measured[i0:] - np.interp(t[i0:] - lag, t, command)) ** 2) for lag in lags]
    return float(lags[int(np.argmin(err))])


def make_site(rig: Rig, actuator: str = "model", n: int = 1, **model_options) -> Site:
    """The site of ``servohydraulics serve --actuator``."""
    if actuator == "ideal":
        return IdealSite(rig, n)
    if actuator == "model":
        return ModelSite(rig, n, **model_options)
    raise ValueError(f"invalid --actuator = {actuator!r}: expected one of {list(ACTUATORS)}")
