"""The closed forms of Zhao et al. (2003), Eqs (2), (8)-(14): the one home of
each equation in Python.  Every other module (the linear analysis, the paper's
reproduction, the demo, the scripts) calls these instead of re-typing them.

SI units; frequencies in rad/s.
"""

from __future__ import annotations

import math

import control as ct

from ..excitations import TWO_PI
from ..rig import Rig


def servovalve(rig: Rig) -> ct.TransferFunction:
    """Servovalve second order of Eq (2) with unit static gain: w_v^2/(s^2 + 2 zeta_v w_v s + w_v^2)."""
    w = TWO_PI * rig.f_v
    return ct.tf([w * w], [1.0, 2.0 * rig.zeta_v * w, w * w])


def _use_valve(rig: Rig, servovalve_on: bool | None) -> bool:
    return rig.effects.servovalve_dynamics if servovalve_on is None else bool(servovalve_on)


def _piston(rig: Rig) -> float:
    return rig.m_p if rig.effects.piston_mass else 0.0


def moving_mass(rig: Rig) -> float:
    """Mass moving with the piston in an actuated mode, m + m_p (piston-mass effect on) [kg]."""
    return rig.m + _piston(rig)


def loop_gain_displacement(rig: Rig, G_p: float | None = None) -> float:
    """K_v C_F K_s G_p of Eq (12), displacement control [m^3/s per m] (G_p default rig.G_p)."""
    return rig.K_v * rig.C_F_disp * rig.K_s * (rig.G_p if G_p is None else float(G_p))


def loop_gain_force(rig: Rig) -> float:
    """K_v C_F K_s G_p of Eq (9), force control [m^3/s per N]."""
    return rig.K_v * rig.C_F_force * rig.K_s * rig.G_p


def velocity_feedback_gain(rig: Rig) -> float:
    """A / (K_v C_F K_s G_p): the EFT velocity-feedback compensation gain of Fig 1(a),
    the linear inverse of the natural velocity feedback [N per m/s]."""
    return rig.A / loop_gain_force(rig)


def equivalent_viscous_damping(rig: Rig, amplitude: float, frequency: float | None = None) -> float:
    """Energy-equivalent viscous damping of Coulomb friction, 4 F_c/(pi w X) [N s/m].

    amplitude X [m] and frequency w [rad/s] (default: sqrt(k/m)) of the harmonic motion.
    """
    if not (math.isfinite(amplitude) and amplitude > 0):
        raise ValueError(f"invalid friction_amplitude = {amplitude!r}: must be > 0 [m]")
    w = math.sqrt(rig.k / rig.m) if frequency is None else float(frequency)
    if not (math.isfinite(w) and w > 0):
        raise ValueError(f"invalid friction_frequency = {frequency!r}: must be > 0 [rad/s]")
    return 4.0 * rig.F_c / (math.pi * w * amplitude)


def G_fu(rig: Rig, servovalve_on: bool | None = None) -> ct.TransferFunction:
    """Force control, command u [N] to load-cell force f [N], Eq (9).

    With the piston mass m_p on, the actuator pushes m + m_p while the load cell
    sees the structure's m s^2 + c s + k only; m_p = 0 gives Eq (9) exactly.
    With the servovalve on, its second order multiplies the loop gain.
    """
    s = ct.tf("s")
    Z = rig.m * s**2 + rig.c * s + rig.k
    Zt = Z + _piston(rig) * s**2
    L = loop_gain_force(rig) * (servovalve(rig) if _use_valve(rig, servovalve_on) else 1)
    return ct.minreal(rig.A * L * Z / (rig.A**2 * s + (rig.K_a * s + rig.C_l) * Zt + rig.A * L * Z), verbose=False)


def G_fu_compensated(rig: Rig) -> ct.TransferFunction:
    """Force control with the exact velocity-feedback compensation, Eq (10) [N/N]."""
    AL = rig.A * loop_gain_force(rig)
    return ct.tf([AL], [rig.K_a, rig.C_l + AL])


def G_xu(rig: Rig, servovalve_on: bool | None = None, mass: float | None = None) -> ct.TransferFunction:
    """Displacement control, command u [m] to displacement x [m], Eq (12).

    mass: total moving mass [kg] (default m + m_p); the valve second order
    multiplies the loop gain when on.
    """
    s = ct.tf("s")
    M = moving_mass(rig) if mass is None else float(mass)
    Zt = M * s**2 + rig.c * s + rig.k
    L = loop_gain_displacement(rig) * (servovalve(rig) if _use_valve(rig, servovalve_on) else 1)
    return ct.minreal(rig.A * L / ((rig.C_l + rig.K_a * s) * Zt + rig.A**2 * s + rig.A * L), verbose=False)


def omega_cEFT(rig: Rig) -> float:
    """Roll-off of the compensated force loop, Eq (11) [rad/s]."""
    return (rig.C_l + rig.A * loop_gain_force(rig)) / rig.K_a


def omega_cRPD(rig: Rig) -> float:
    """Equivalent first-order roll-off of the displacement loop, Eq (13) [rad/s]."""
    return loop_gain_displacement(rig) / rig.A


def omega_oil_column(rig: Rig, mass: float | None = None) -> float:
    """Oil-column frequency sqrt(A^2/(m K_a)), Eq (14) [rad/s]; mass default m + m_p [kg]."""
    M = moving_mass(rig) if mass is None else float(mass)
    return math.sqrt(rig.A**2 / (M * rig.K_a))


def natural_frequency(rig: Rig, mass: float | None = None) -> float:
    """sqrt(k/m) of the structure [rad/s] (mass default: the structure's m)."""
    return math.sqrt(rig.k / (rig.m if mass is None else mass))


def damping_ratio(rig: Rig, c: float | None = None) -> float:
    """Viscous damping ratio c/(2 sqrt(k m)) of the structure [-]."""
    return (rig.c if c is None else c) / (2.0 * math.sqrt(rig.k * rig.m))


__all__ = ["G_fu", "G_fu_compensated", "G_xu", "damping_ratio", "equivalent_viscous_damping",
           "loop_gain_displacement", "loop_gain_force", "moving_mass", "natural_frequency", "omega_cEFT",
           "omega_cRPD", "omega_oil_column", "servovalve", "velocity_feedback_gain"]
