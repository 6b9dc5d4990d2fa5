"""Stability of the displacement loop: its characteristic polynomial (the
denominator of Eq 12), Routh bounds on the P-gain (Fig 6b) and root loci.
SI units; frequencies in rad/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import control as ct
import numpy as np

from ..excitations import TWO_PI
from ..rig import Rig, copy_rig
from .closed_form import loop_gain_displacement, moving_mass, servovalve


def characteristic_polynomial(rig: Rig, G_p: float | None = None, mass: float | None = None,
                              servovalve_on: bool | None = None) -> np.ndarray:
    """Coefficients (highest power first) of the displacement loop's characteristic
    polynomial, the denominator of Eq (12) (times the valve's when on)."""
    M = moving_mass(rig) if mass is None else float(mass)
    L = rig.A * loop_gain_displacement(rig, G_p)
    base = np.polymul([rig.K_a, rig.C_l], [M, rig.c, rig.k])
    base = np.polyadd(base, [rig.A**2, 0.0])
    if rig.effects.servovalve_dynamics if servovalve_on is None else servovalve_on:
        w = TWO_PI * rig.f_v
        return np.polyadd(np.polymul(base, [1.0, 2.0 * rig.zeta_v * w, w * w]), [L * w * w])
    return np.polyadd(base, [L])


def routh_array(coeffs: Sequence[float]) -> np.ndarray:
    """Routh array of a polynomial (highest power first); rows s^n ... s^0."""
    a = np.asarray(coeffs, dtype=float)
    a = a / a[0]
    n = len(a) - 1
    cols = n // 2 + 1
    R = np.zeros((n + 1, cols))
    R[0, : len(a[0::2])] = a[0::2]
    R[1, : len(a[1::2])] = a[1::2]
    for i in range(2, n + 1):
        piv = R[i - 1, 0]
        if piv == 0.0:
            piv = 1e-300  # epsilon method: a zero pivot means a marginal case
        for j in range(cols - 1):
            R[i, j] = (piv * R[i - 2, j + 1] - R[i - 2, 0] * R[i - 1, j + 1]) / piv
    return R


def routh_stable(coeffs: Sequence[float]) -> bool:
    """All roots in the open left half plane by Routh's criterion."""
    a = np.asarray(coeffs, dtype=float)
    if np.any(a * np.sign(a[0]) <= 0):
        return False
    return bool(np.all(routh_array(a)[:, 0] > 0))


def max_p_gain(rig: Rig, mass: float | None = None, servovalve_on: bool | None = None,
               rtol: float = 1e-9) -> float:
    """Largest G_p for which the displacement loop is stable (Routh), at a total
    moving mass [kg] (default m + m_p); inf if stable for every gain."""
    def stable(gp: float) -> bool:
        return routh_stable(characteristic_polynomial(rig, gp, mass, servovalve_on))

    lo, hi = 0.0, 1.0
    while stable(hi):
        lo, hi = hi, hi * 4.0
        if hi > 1e9:
            return math.inf
    if lo == 0.0:
        lo = hi
        while not stable(lo):
            lo /= 4.0
            if lo < 1e-12:
                return 0.0
        hi = lo * 4.0
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return 0.5 * (lo + hi)


def max_p_gain_curve(rig: Rig, masses: Sequence[float], servovalve_on: bool | None = None) -> np.ndarray:
    """Routh bound G_p,max at each total moving mass [kg] (Fig 6b)."""
    return np.array([max_p_gain(rig, m, servovalve_on) for m in masses])


def rig_with_mass(rig: Rig, mass: float) -> Rig:
    """Copy of the rig whose total moving mass is ``mass`` [kg] (piston mass
    switched off and m = mass, so 54 kg is the piston alone)."""
    r = copy_rig(rig)
    r.effects.piston_mass = False
    r.m = float(mass)
    return r


def root_locus_gains(rig: Rig, gains: Sequence[float], mass: float | None = None,
                     servovalve_on: bool | None = None) -> np.ndarray:
    """Closed-loop poles of the displacement loop at each G_p (rows) [rad/s]."""
    return np.array([np.roots(characteristic_polynomial(rig, g, mass, servovalve_on)) for g in gains])


def displacement_open_loop(rig: Rig, servovalve_on: bool | None = None,
                           mass: float | None = None) -> ct.TransferFunction:
    """Loop transfer of Fig 1(b) at G_p = 1, whose root locus over G_p is the
    closed loop of Eq (12) [-]."""
    s = ct.tf("s")
    M = moving_mass(rig) if mass is None else float(mass)
    Zt = M * s**2 + rig.c * s + rig.k
    use_valve = rig.effects.servovalve_dynamics if servovalve_on is None else servovalve_on
    L = loop_gain_displacement(rig, G_p=1.0) * (servovalve(rig) if use_valve else 1)
    return rig.A * L / ((rig.C_l + rig.K_a * s) * Zt + rig.A**2 * s)


__all__ = ["characteristic_polynomial", "displacement_open_loop", "max_p_gain", "max_p_gain_curve",
           "rig_with_mass", "root_locus_gains", "routh_array", "routh_stable"]
