"""Compensator design (Fig 6a, delay compensation) and frequency-domain
read-outs of LTI loops.  SI units; frequencies in Hz where a name or argument says so.
"""

from __future__ import annotations

import math

import control as ct
import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ..excitations import TWO_PI
from .linear import ALPHA, phase_lead


def acceptable_band(sys_: ct.LTI, T: float, tol: float = 0.05, alpha: float = ALPHA,
                    f_max: float = 20.0) -> float:
    """Highest frequency [Hz] up to which | |lead(T) G(jw)| - 1 | <= tol (first exceedance)."""
    f = np.linspace(0.01, f_max, 4000)
    h = np.abs(np.asarray((phase_lead(T, alpha) * sys_)(1j * TWO_PI * f)))
    bad = np.flatnonzero(np.abs(h - 1.0) > tol)
    if bad.size == 0:
        return f_max
    i = bad[0]
    if i == 0:
        return 0.0
    return float(brentq(lambda ff: abs(abs(complex((phase_lead(T, alpha) * sys_)(1j * TWO_PI * ff))) - 1) - tol,
                        f[i - 1], f[i]))


def amplitude_compensation_T(sys_: ct.LTI, band: tuple[float, float] = (0.0, 5.0), alpha: float = ALPHA,
                             bounds: tuple[float, float] = (0.005, 0.3)) -> tuple[float, float]:
    """Minimax amplitude-compensation time constant over a band [Hz].

    Minimises max over the band of | |lead(T) G(jw)| - 1 |, where G is the
    displacement response (e.g. ``G_xu(rig) * zoh_delay(dt)``).
    Returns (T [s], the worst deviation [-]).
    """
    f = np.linspace(max(band[0], 0.01), band[1], 300)
    w = TWO_PI * f
    g = np.abs(np.asarray(sys_(1j * w)))

    def dev(T: float) -> float:
        lead_mag = np.sqrt((1.0 + (w * T) ** 2) / (1.0 + (alpha * w * T) ** 2))
        return float(np.max(np.abs(lead_mag * g - 1.0)))

    res = minimize_scalar(dev, bounds=bounds, method="bounded", options={"xatol": 1e-7})
    return float(res.x), float(res.fun)


def delay_compensation_T(total_delay: float, amplitude_T: float, sys_: ct.LTI | None = None,
                         frequency: float | None = None, alpha: float = ALPHA) -> float:
    """Delay-compensation time constant T_ld [s].

    Without ``sys_``: the paper's estimate, total response delay minus the
    amplitude-compensation constant (81 - 68 = 13 ms).  With ``sys_`` (the
    amplitude-compensated displacement response) and ``frequency`` [Hz]: the
    lead whose phase cancels the residual lag of ``sys_`` at that frequency.
    """
    if sys_ is None:
        return float(total_delay - amplitude_T)
    if frequency is None:
        raise ValueError("give frequency [Hz] with sys_")
    w = TWO_PI * frequency
    lag = -float(np.angle(complex(sys_(1j * w))))
    if lag <= 0:
        return 0.0

    def phase(T: float) -> float:
        return math.atan(w * T) - math.atan(alpha * w * T) - lag

    return float(brentq(phase, 1e-7, 1.0 / (w * math.sqrt(alpha))))


def equivalent_delay(sys_: ct.LTI, frequency: float) -> float:
    """Phase lag at a frequency [Hz] expressed as a delay -angle/w [s]."""
    w = TWO_PI * frequency
    return -float(np.angle(complex(sys_(1j * w)))) / w


def group_delay(sys_: ct.LTI, frequency: float = 0.01) -> float:
    """Group delay -d(phase)/dw at a frequency [Hz] [s] (central difference)."""
    df = 1e-4 * frequency
    ph = np.unwrap(np.angle([complex(sys_(1j * TWO_PI * (frequency + d))) for d in (-df, df)]))
    return float(-(ph[1] - ph[0]) / (TWO_PI * 2.0 * df))


def dominant_modes(sys_: ct.LTI) -> list[tuple[float, float]]:
    """(natural frequency [Hz], damping ratio [-]) of every complex pole pair, lowest first."""
    p = np.asarray(sys_.poles())
    p = p[np.imag(p) > 0]
    return sorted((float(abs(z) / TWO_PI), float(-np.real(z) / abs(z))) for z in p)


def structural_mode(sys_: ct.LTI, near: float) -> tuple[float, float]:
    """(frequency [Hz], damping ratio [-]) of the complex pole pair closest to
    ``near`` [rad/s] (the structural mode of a test loop)."""
    p = np.asarray(sys_.poles())
    p = p[np.imag(p) > 1e-9]
    z = p[np.argmin(np.abs(np.abs(p) - near))]
    return float(abs(z) / TWO_PI), float(-np.real(z) / abs(z))


__all__ = ["acceptable_band", "amplitude_compensation_T", "delay_compensation_T", "dominant_modes",
           "equivalent_delay", "group_delay", "structural_mode"]
