"""The paper-era fits (Zhao et al. 2003, Fig 2b and Fig 5a).

* :func:`identify_damping_friction`: the paper's Fig 2(b) procedure: viscous
  damping c and Coulomb friction F_c of Eq (5) fitted by least squares on the
  simulation error of the C++ free-structure model (released from rest at x0,
  or driven by a measured force: the paper's forced-vibration tests with the
  actuator attached), with standard errors from the HAC sandwich covariance of
  :mod:`.stats` (the package's one rule).
* :func:`identify_first_order`: the equivalent first-order roll-off and delay
  of a displacement-controlled actuator from a sweep record (Eq 13: 1.96 Hz,
  81 ms in the paper).
* :func:`identify_free_vibration`: frequency and damping of a free vibration
  (a damped cosine fitted by least squares; Figs 2b, 9).

The frequency responses of sweep records are :func:`.frf.dft_ratio`; the statistics
(AR(1) effective sample size) are :mod:`.stats`.

SI units: m, s, N, N s/m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from ..excitations import TWO_PI, linear_chirp
from ..response import SimulationError
from ..rig import Rig, copy_rig
from ..simulate import solver_options
from ..timegrid import uniform_dt
from .frf import dft_ratio
from .run import simulate_command
from .stats import ar1_coefficient, ar1_effective_n, covariance, quantile


@dataclass
class FrictionEstimate:
    """Result of :func:`identify_damping_friction` (SI units)."""

    c: float  #: viscous damping [N s/m]
    F_c: float  #: Coulomb friction [N]
    zeta: float  #: damping ratio c / (2 sqrt(k m)) [-]
    c_std: float  #: standard error of c [N s/m]
    F_c_std: float  #: standard error of F_c [N]
    zeta_std: float  #: standard error of zeta [-]
    cov: np.ndarray  #: covariance of (c, F_c)
    n: int  #: samples in the fit
    n_eff: float  #: effective sample size after the AR(1) correction
    rho1: float  #: lag-1 autocorrelation of the residuals [-]
    rms_residual: float  #: [m]
    nfev: int  #: simulations used
    fitted: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))  #: simulated record [m]
    x0: float = 0.0  #: release displacement, fitted when not given [m]
    x0_std: float = 0.0  #: its standard error [m] (0 when given)

    def interval(self, name: str, level: float = 0.95) -> tuple[float, float]:
        """Two-sided normal confidence interval of ``c``, ``F_c`` or ``zeta``."""
        z = quantile(level)
        v, s = getattr(self, name), getattr(self, f"{name}_std")
        return v - z * s, v + z * s


def _uniform_dt(time: ArrayLike) -> float:
    return uniform_dt(time, "invalid time", min_rows=10)


def simulate_structure(rig: Rig, c: float, F_c: float, n: int, dt: float, x0: float = 0.0,
                       force: np.ndarray | None = None, rtol: float = 1e-8) -> np.ndarray:
    """Displacement [m] of the structure alone (Eq 5, Free mode) with damping c
    [N s/m] and friction F_c [N], released at rest from x0 [m] and driven by
    ``force`` [N] per sample (zero if None); n samples at dt [s]."""
    r = copy_rig(rig)
    r.c, r.F_c = float(c), float(F_c)
    r.effects.coulomb_friction = True
    u = np.zeros(n) if force is None else _interval_mean(np.asarray(force, dtype=float))
    try:
        res = simulate_command(r, "free", u, dt, x0, solver_options(rtol=rtol, max_steps_per_sample=20000))
    except SimulationError:
        return np.full(n, np.nan)
    x = res.displacement
    if x.size < n or not np.all(np.isfinite(x[:n])):
        return np.full(n, np.nan)
    return x[:n]


def _interval_mean(force: np.ndarray) -> np.ndarray:
    """Force held over [t_k, t_k+1]: the mean of the samples at both ends.

    Holding the sample at t_k would apply the measured force dt/2 late, which
    biases the identified damping (a delayed force does work like damping)."""
    held = force.copy()
    held[:-1] = 0.5 * (force[:-1] + force[1:])
    return held


def identify_damping_friction(time: ArrayLike, displacement: ArrayLike, rig: Rig,
                              force: np.ndarray | None = None, x0: float | None = None,
                              guess: tuple[float, float] | None = None) -> FrictionEstimate:
    """Least-squares fit of c and F_c of Eq (5) to a displacement record (Fig 2b).

    Args:
        time, displacement: the record [s], [m], uniformly sampled.
        rig: supplies m, k (and the spring softening); its c and F_c are ignored.
        force: measured force acting on the structure per sample [N] (forced
            vibration with the actuator attached); None for free vibration.
            Over each sample interval the mean of its two end samples is held.
        x0: release displacement [m]; None: fitted as a third parameter
            (started from the first sample, which carries the sensor noise).
            The structure starts at rest.
        guess: starting (c [N s/m], F_c [N]); default (1 % damping, 50 N).

    The simulation error x_sim(c, F_c) - x_meas is minimised with
    ``scipy.optimize.least_squares`` (trust region reflective).  The
    covariance is the package's one rule, the HAC sandwich of
    :func:`.stats.covariance`, so that correlated residuals (model error,
    coloured noise) do not give overconfident intervals; ``n_eff`` and
    ``rho1`` summarise the residual's AR(1) autocorrelation.
    """
    dt = _uniform_dt(time)
    x = np.asarray(displacement, dtype=float)
    if x.shape != np.asarray(time).shape:
        raise ValueError(f"invalid displacement shape = {x.shape}: must match time {np.asarray(time).shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("invalid displacement: contains NaN or inf")
    if force is not None and np.asarray(force).shape != x.shape:
        raise ValueError(f"invalid force shape = {np.asarray(force).shape}: must match time")
    fit_x0 = x0 is None
    x_release = float(x[0]) if x0 is None else float(x0)
    c_crit = 2.0 * math.sqrt(rig.k * rig.m)
    c0, f0 = guess if guess is not None else (0.01 * c_crit, 50.0)
    x_ref = max(abs(x_release), 1e-3)
    scale = np.array([max(c0, 0.002 * c_crit), max(f0, 10.0)] + ([x_ref] if fit_x0 else []))
    n = x.size

    def residual(theta: np.ndarray) -> np.ndarray:
        q = theta * scale
        xs = simulate_structure(rig, q[0], q[1], n, dt, q[2] if fit_x0 else x_release, force)
        if not np.all(np.isfinite(xs)):
            return np.full(n, 1e3)
        return xs - x

    # Unbounded trust region: with bounds the scaled steps stall before the
    # optimum.  The forward-difference step 1e-4 (relative) stays well above
    # the integration error of the rtol = 1e-8 simulations.
    start = np.array([c0, f0] + ([x_release] if fit_x0 else [])) / scale
    sol = least_squares(residual, start, diff_step=1e-4, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    res = sol.fun
    J = sol.jac / scale  # d res / d (c, F_c[, x0])
    p = J.shape[1]
    rho = ar1_coefficient(res)
    n_eff = ar1_effective_n(res.size, rho)
    cov_all = covariance(J, res, scale).matrix
    cov = cov_all[:2, :2]
    q = sol.x * scale
    c, fc = float(q[0]), float(q[1])
    c_std, fc_std = np.sqrt(np.diag(cov)).tolist()
    return FrictionEstimate(c=c, F_c=fc, zeta=c / c_crit, c_std=c_std, F_c_std=fc_std, zeta_std=c_std / c_crit,
                            cov=cov, n=n, n_eff=n_eff, rho1=rho, rms_residual=math.sqrt(float(res @ res) / n),
                            nfev=int(sol.nfev + sol.njev * p), fitted=res + x,
                            x0=float(q[2]) if fit_x0 else x_release,
                            x0_std=float(math.sqrt(cov_all[2, 2])) if fit_x0 else 0.0)


@dataclass
class FirstOrderEstimate:
    """Equivalent first order K/(tau s + 1) of a displacement loop (SI units)."""

    gain: float  #: static gain K [-]
    tau: float  #: time constant = equivalent response delay [s] (paper: 81 ms)
    roll_off_hz: float  #: 1/(2 pi tau) [Hz] (paper: 1.96 Hz)
    frequency: np.ndarray = field(repr=False)  #: frequencies of the estimate [Hz]
    response: np.ndarray = field(repr=False)  #: H1 frequency-response estimate x/u [-]
    excited: np.ndarray = field(repr=False)  #: mask of the frequencies the sweep excites
    band: tuple[float, float] = (0.1, 2.0)  #: fitted band [Hz]

    def first_order(self, f: np.ndarray) -> np.ndarray:
        """The fitted K/(j w tau + 1) at frequencies f [Hz]."""
        return self.gain / (1j * TWO_PI * np.asarray(f) * self.tau + 1.0)


def identify_first_order(time: ArrayLike, command: ArrayLike, response: ArrayLike,
                         band: tuple[float, float] = (0.1, 2.0)) -> FirstOrderEstimate:
    """Equivalent first-order roll-off and delay from a displacement-control sweep.

    The frequency response over ``band`` [Hz] (:func:`.frf.dft_ratio`) is
    fitted by K/(j w tau + 1) in complex least squares.  tau is the paper's
    "total response delay" (1/w_cRPD, 81 ms) and 1/(2 pi tau) its roll-off
    frequency (1.96 Hz).
    """
    dt = _uniform_dt(time)
    u, y = np.asarray(command, dtype=float), np.asarray(response, dtype=float)
    if u.shape != y.shape:
        raise ValueError(f"invalid response shape = {y.shape}: must match command {u.shape}")
    est = dft_ratio(u, y, dt)
    f, h, ok = est.frequency, est.response, est.excited
    sel = (f >= band[0]) & (f <= band[1]) & ok
    if np.count_nonzero(sel) < 4:
        raise ValueError(f"invalid band = {band}: fewer than 4 excited frequency points in it")
    w, hs = TWO_PI * f[sel], h[sel]

    def res(theta: np.ndarray) -> np.ndarray:
        e = theta[0] / (1j * w * theta[1] + 1.0) - hs
        return np.concatenate([e.real, e.imag])

    sol = least_squares(res, np.array([1.0, 0.08]), bounds=([0.0, 1e-5], [10.0, 10.0]))
    K, tau = sol.x.tolist()
    return FirstOrderEstimate(gain=K, tau=tau, roll_off_hz=1.0 / (TWO_PI * tau), frequency=f, response=h,
                              excited=ok, band=band)


@dataclass
class FreeVibration:
    """Identified free vibration x(t) = X exp(-zeta w_n t) cos(w_d t + phi) + x_inf."""

    frequency: float  #: damped natural frequency f_d [Hz]
    damping_ratio: float  #: zeta [-] (negative: the response grows)
    amplitude: float  #: X [same unit as the signal]
    offset: float  #: x_inf
    rms_error: float  #: fit residual relative to X [-]


def identify_free_vibration(x: ArrayLike, dt: float, start: int = 0, duration: float = 4.0) -> FreeVibration:
    """Fits a damped cosine to x[start : start + duration/dt] by least squares.

    The frequency is started from the zero-padded FFT peak of the window; zeta from 0.
    Robust to the small oil-column ripple that makes peak picking unreliable."""
    n = int(round(duration / dt))
    y = np.asarray(x, dtype=float)[start: start + n]
    if y.size < 16:
        raise ValueError(f"invalid window: {y.size} samples from start = {start}")
    t = np.arange(y.size) * dt
    yc = y - y.mean()
    nfft = 16 * y.size
    spec = np.abs(np.fft.rfft(yc * np.hanning(y.size), nfft))
    freqs = np.fft.rfftfreq(nfft, dt)
    f0 = freqs[np.argmax(spec[1:]) + 1]

    def model(p: np.ndarray) -> np.ndarray:
        X, z, f, phi, c = p
        wn = 2 * np.pi * f / np.sqrt(max(1 - z * z, 1e-9))
        return X * np.exp(-z * wn * t) * np.cos(2 * np.pi * f * t + phi) + c

    X0 = np.abs(yc).max()
    best = None
    for phi0 in (0.0, np.pi / 2, np.pi, -np.pi / 2):
        r = least_squares(lambda p: model(p) - y, [X0, 0.0, f0, phi0, y.mean()],
                                   bounds=([0, -0.9, 0.5 * f0, -10, -np.inf], [np.inf, 0.9, 2 * f0, 10, np.inf]))
        if best is None or r.cost < best.cost:
            best = r
    X, z, f, _, c = best.x
    rms = float(np.sqrt(np.mean(best.fun**2)) / max(X, 1e-300))
    return FreeVibration(frequency=float(f), damping_ratio=float(z), amplitude=float(X), offset=float(c),
                         rms_error=rms)


__all__ = ["FirstOrderEstimate", "FreeVibration", "FrictionEstimate", "identify_damping_friction",
           "identify_first_order", "identify_free_vibration", "linear_chirp", "simulate_structure"]
