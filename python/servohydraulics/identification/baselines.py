"""The thesis' own models of the UTFSM records, as independent reference baselines.

Quiroz (2022), MSc thesis, UTFSM; code and data: github.com/DanielMaurelE/vRTHS_AMBC_MRdamper
(MIT licence), summarised in ``../shared/real-data/utfsm-mts-mrdamper/README.md``:

* :func:`thesis_displacement`: the thesis' linear actuator model (chapter 6,
  ``modelo.mat``) G(s) = 9045.99 / ((s + 183.83)(s + 48.58)) from the command
  to the measured displacement, simulated by ``scipy.signal.lsim`` (the input
  linearly interpolated between samples).
* :func:`thesis_mr_force`: the thesis' MR-damper model (chapter 7, Spencer's
  modified Bouc-Wen, ``parametros.mat``) driven by the MEASURED displacement.
  Its equations, in the thesis' units N, mm, s and coil current i [A]::

      dy/dt = (alpha z + k0 (x - y) + c0 dx/dt) / (c0 + c1)
      dz/dt = -gamma |dx/dt - dy/dt| |z|^(n-1) z - beta (dx/dt - dy/dt) |z|^n + A (dx/dt - dy/dt)
      F     = c1 dy/dt + k1 (x - x0)

These are plain NumPy/SciPy and share no code with the simulator's core:
they are the baselines our identified rigs are measured against, not a model
of ours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import integrate, signal

#: The thesis' command -> displacement model: numerator gain [1/s^2] and poles [rad/s].
THESIS_ACTUATOR = {"gain": 9045.99, "poles": (-183.83, -48.58)}


def thesis_actuator_tf() -> signal.TransferFunction:
    """G(s) = 9045.99 / ((s + 183.83)(s + 48.58)) [m/m] (DC gain 1.013)."""
    p1, p2 = THESIS_ACTUATOR["poles"]
    return signal.TransferFunction([THESIS_ACTUATOR["gain"]], np.polymul([1.0, -p1], [1.0, -p2]))


def thesis_displacement(time: ArrayLike, command: ArrayLike) -> np.ndarray:
    """Displacement [m] the thesis' G(s) predicts from the command [m], starting at rest."""
    t = np.asarray(time, dtype=float)
    _, y, _ = signal.lsim(thesis_actuator_tf(), np.asarray(command, dtype=float), t - t[0])
    return np.asarray(y, dtype=float)


@dataclass(frozen=True)
class SpencerParameters:
    """Modified Bouc-Wen (Spencer et al. 1997) parameters in the thesis' units N, mm, s."""

    alpha: float  #: [N/mm]
    c0: float  #: [N s/mm]
    c1: float  #: [N s/mm]
    k0: float  #: [N/mm]
    k1: float  #: [N/mm]
    x0: float  #: [mm]
    A: float  #: [-]
    beta: float  #: [mm^-2] (n = 2)
    gamma: float  #: [mm^-2]
    n: float  #: [-]


def thesis_mr_parameters(current: float) -> SpencerParameters:
    """The thesis' current-dependent fit (README: fitted to the May 2022 sinusoidal tests, 0-1 A)."""
    i = float(current)
    if not (math.isfinite(i) and 0.0 <= i <= 1.0):
        raise ValueError(f"invalid current = {current!r}: the thesis' fit covers 0 ... 1 A")
    bg = 1.8941 * math.exp(-3.6561 * i)
    return SpencerParameters(alpha=-38.152 * i**2 + 41.508 * i + 15.221, c0=7.6260 * i + 0.92491,
                             c1=78.337 * i + 9.8671, k0=1.5013e-4, k1=1.2388, x0=2.3091e-3, A=300.0,
                             beta=bg, gamma=bg, n=2.0)


def spencer_rig_keys(p: SpencerParameters) -> dict[str, float]:
    """The parameters as the core's ``[specimen]`` keys in SI units (N, m, s): N/mm -> N/m,
    N s/mm -> N s/m, mm -> m, mm^-n -> m^-n (z in m), the current folded into the
    ``_a`` terms (``_b`` = 0, ``mr_voltage`` = 0)."""
    return {"mr_alpha_a": 1e3 * p.alpha, "mr_alpha_b": 0.0, "mr_c0_a": 1e3 * p.c0, "mr_c0_b": 0.0,
            "mr_c1_a": 1e3 * p.c1, "mr_c1_b": 0.0, "mr_k0": 1e3 * p.k0, "mr_k1": 1e3 * p.k1, "mr_x0": 1e-3 * p.x0,
            "mr_A": p.A, "mr_beta": p.beta * 1e3**p.n, "mr_gamma": p.gamma * 1e3**p.n, "mr_n": p.n,
            "mr_voltage": 0.0}


def smoothed_motion(displacement: ArrayLike, dt: float, cutoff_hz: float = 200.0) -> tuple[np.ndarray, np.ndarray]:
    """(x, dx/dt) [m, m/s] from a measured displacement: the thesis' 4th-order
    Butterworth low-pass at 200 Hz (applied forward and backward, no phase
    shift) and central differences."""
    x = np.asarray(displacement, dtype=float)
    nyq = 0.5 / dt
    if cutoff_hz < nyq:
        sos = signal.butter(4, cutoff_hz / nyq, output="sos")
        x = signal.sosfiltfilt(sos, x)
    return x, np.gradient(x, dt)


def _spencer_rates(p: SpencerParameters, xt: float, vt: float, y: float, z: float) -> tuple[float, float]:
    ydot = (p.alpha * z + p.k0 * (xt - y) + p.c0 * vt) / (p.c0 + p.c1)
    r = vt - ydot
    az = abs(z)
    return ydot, -p.gamma * abs(r) * az ** (p.n - 1.0) * z - p.beta * r * az**p.n + p.A * r


def spencer_force(displacement: ArrayLike, dt: float, p: SpencerParameters, cutoff_hz: float = 200.0,
                  method: str = "rk4", substeps: int = 10) -> np.ndarray:
    """Damper force [N] of the modified Bouc-Wen model driven by a measured
    displacement [m] sampled at dt [s] (smoothed as :func:`smoothed_motion`),
    starting with y = x and z = 0, the motion interpolated linearly between samples.

    ``method="rk4"``: classical RK4 with ``substeps`` steps per sample (a plain
    Python loop, a few seconds for 60 000 samples); ``"lsoda"``: SciPy's LSODA
    (rtol 1e-6, at most one sample per step; ten times slower), the reference
    the RK4 is checked against (tests/python/test_lab_baselines.py)."""
    x_m, v_m = smoothed_motion(displacement, dt, cutoff_hz)
    x, v = 1e3 * x_m, 1e3 * v_m  # mm, mm/s
    if method == "lsoda":
        y, z = _spencer_lsoda(x, v, dt, p)
    elif method == "rk4":
        y, z = _spencer_rk4(x, v, dt, p, int(substeps))
    else:
        raise ValueError(f"invalid method = {method!r}: expected 'rk4' or 'lsoda'")
    ydot = (p.alpha * z + p.k0 * (x - y) + p.c0 * v) / (p.c0 + p.c1)
    return p.c1 * ydot + p.k1 * (x - p.x0)


def _spencer_rk4(x: np.ndarray, v: np.ndarray, dt: float, p: SpencerParameters,
                 substeps: int) -> tuple[np.ndarray, np.ndarray]:
    if substeps < 1:
        raise ValueError(f"invalid substeps = {substeps!r}: must be >= 1")
    n, h = x.size, 1.0 / substeps
    ys, zs = np.empty(n), np.empty(n)
    y, z = float(x[0]), 0.0
    ys[0], zs[0] = y, z
    xl, vl = x.tolist(), v.tolist()
    rates = _spencer_rates
    for k in range(n - 1):
        x0, dx, v0, dv = xl[k], xl[k + 1] - xl[k], vl[k], vl[k + 1] - vl[k]
        for j in range(substeps):
            w0, wm, w1 = j * h, (j + 0.5) * h, (j + 1) * h
            a1, b1 = rates(p, x0 + w0 * dx, v0 + w0 * dv, y, z)
            a2, b2 = rates(p, x0 + wm * dx, v0 + wm * dv, y + 0.5 * h * dt * a1, z + 0.5 * h * dt * b1)
            a3, b3 = rates(p, x0 + wm * dx, v0 + wm * dv, y + 0.5 * h * dt * a2, z + 0.5 * h * dt * b2)
            a4, b4 = rates(p, x0 + w1 * dx, v0 + w1 * dv, y + h * dt * a3, z + h * dt * b3)
            y += h * dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
            z += h * dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
        ys[k + 1], zs[k + 1] = y, z
    return ys, zs


def _spencer_lsoda(x: np.ndarray, v: np.ndarray, dt: float, p: SpencerParameters) -> tuple[np.ndarray, np.ndarray]:
    n = x.size

    def rhs(t: float, s: np.ndarray) -> list[float]:
        k = min(int(t / dt), n - 2)
        w = t / dt - k
        return list(_spencer_rates(p, x[k] + w * (x[k + 1] - x[k]), v[k] + w * (v[k + 1] - v[k]), s[0], s[1]))

    t = np.arange(n) * dt
    sol = integrate.solve_ivp(rhs, (0.0, t[-1]), [x[0], 0.0], method="LSODA", t_eval=t, rtol=1e-6,
                              atol=[1e-6, 1e-6], max_step=dt)
    if not sol.success:
        raise RuntimeError(f"the Bouc-Wen baseline failed at t = {sol.t[-1]:.4g} s: {sol.message}")
    return sol.y[0], sol.y[1]


def thesis_mr_force(displacement: ArrayLike, dt: float, current: float) -> np.ndarray:
    """The thesis' MR-damper force [N] at the coil current [A], driven by the measured displacement [m]."""
    return spencer_force(displacement, dt, thesis_mr_parameters(current))


__all__ = ["THESIS_ACTUATOR", "SpencerParameters", "smoothed_motion", "spencer_rig_keys", "spencer_force", "thesis_actuator_tf",
           "thesis_displacement", "thesis_mr_force", "thesis_mr_parameters"]
