"""Shared fixtures of the core tests.

The rigs are built fresh for each test from the preset (``sh.zhao2003()``), so
tests may change them.  Numbers that depend on the preset are computed from
the rig's own parameters, never hard-coded (the calibration may still move).
"""

from __future__ import annotations

import math
from typing import Callable

import control as ct
import numpy as np
import pytest

import servohydraulics as sh

DT = 5e-4  #: the paper's 2 kHz controller sample [s]

#: Effects that have no small-signal linearisation at the origin or that the
#: closed forms of Eqs (9), (12) leave out, by name of the Effects switch.
NONSMOOTH = ("coulomb_friction",)


@pytest.fixture
def dt() -> float:
    return DT


@pytest.fixture
def calibrated() -> sh.Rig:
    """The calibrated preset, actuator attached (c = 2.1 kN s/m, F_c = 31.6 N)."""
    return sh.zhao2003()


@pytest.fixture
def make_rig() -> Callable[..., sh.Rig]:
    """Factory: ``make_rig(variant="calibrated", actuator_attached=True, off=(...), **params)``
    builds a preset with the named effects switched off and parameters overridden."""

    def build(variant: str = "calibrated", actuator_attached: bool = True, off=(), **params) -> sh.Rig:
        rig = sh.zhao2003(variant, actuator_attached)
        for name in off:
            if not hasattr(rig.effects, name):
                raise AttributeError(f"no effect {name!r}")
            setattr(rig.effects, name, False)
        for key, value in params.items():
            if not hasattr(rig, key):
                raise AttributeError(f"no rig parameter {key!r}")
            setattr(rig, key, value)
        rig.validate()
        return rig

    return build


def zero_crossings(t: np.ndarray, x: np.ndarray, rising: bool = True) -> np.ndarray:
    """Times [s] where x crosses zero upwards (or downwards), linear interpolation."""
    s = np.signbit(x)
    idx = np.flatnonzero(s[:-1] & ~s[1:]) if rising else np.flatnonzero(~s[:-1] & s[1:])
    return t[idx] - x[idx] * (t[idx + 1] - t[idx]) / (x[idx + 1] - x[idx])


def peaks(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of a sampled signal, refined by a parabola through the three
    samples around each (times [s], values)."""
    i = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:])) + 1
    a, b, c = x[i - 1], x[i], x[i + 1]
    den = a - 2 * b + c
    off = np.where(den != 0, 0.5 * (a - c) / np.where(den != 0, den, 1.0), 0.0)
    h = t[1] - t[0]
    return t[i] + off * h, b - 0.25 * (a - c) * off


@pytest.fixture
def signal_tools():
    """Zero crossings and interpolated peaks of sampled records."""

    class Tools:
        zero_crossings = staticmethod(zero_crossings)
        peaks = staticmethod(peaks)

    return Tools


def closed_form_tf(rig: sh.Rig, mode: str) -> ct.TransferFunction:
    """Eq (9) (mode "force", output load-cell force) or Eq (12) (mode
    "displacement", output displacement) of the paper, extended as derived in
    test_core_linearization.py and selected by the rig's effect switches:
    servovalve dynamics inside the loop (K_s -> K_s V(s)) and the piston mass
    (Z -> (m + m_p) s^2 + c s + k; the load cell sees m s^2 + c s + k)."""
    e = rig.effects
    mp = rig.m_p if e.piston_mass else 0.0
    ZM = np.array([rig.m + mp, rig.c, rig.k])  # structure + piston
    Zm = np.array([rig.m, rig.c, rig.k])  # structure seen by the load cell
    CF = rig.C_F_force if mode == "force" else rig.C_F_disp
    G = rig.A * rig.K_v * CF * rig.K_s * rig.G_p
    if e.servovalve_dynamics:
        w = 2 * math.pi * rig.f_v
        vden, vnum = np.array([1.0, 2 * rig.zeta_v * w, w * w]), w * w
    else:
        vden, vnum = np.array([1.0]), 1.0
    hyd = np.polyadd(np.polymul([rig.K_a, rig.C_l], ZM), [rig.A**2, 0.0])  # (K_a s + C_l) Z_M + A^2 s
    fwd = G * vnum * (Zm if mode == "force" else np.array([1.0]))
    den = np.polyadd(np.polymul(hyd, vden), fwd)
    return ct.tf(fwd, den)


@pytest.fixture
def closed_form() -> Callable[[sh.Rig, str], ct.TransferFunction]:
    """``closed_form(rig, mode)``: Eq (9) or Eq (12) as a control.TransferFunction."""
    return closed_form_tf
