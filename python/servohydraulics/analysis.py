"""Linear analysis of the rig: linearisation of the C++ model, the closed forms of
Eqs (9)-(14) of Zhao et al. (2003), Routh bounds on the P-gain (Fig 6b) and
compensator design helpers (Fig 6a, delay compensation).

LTI objects are python-control ``StateSpace``/``TransferFunction``; SI units
throughout (frequencies in rad/s unless a name ends in ``_hz``).

Nonsmooth effects at an equilibrium
-----------------------------------
The nonlinear model has two points where the tangent linearisation is not the
small-signal model the paper analyses (Eqs 6-8):

* Coulomb friction ``F_c tanh(v / v_stick)`` has slope ``F_c / v_stick`` at
  ``v = 0`` (3.2e5 N s/m for the attached rig, 150 times ``c``): the tangent
  model describes a structure stuck in static friction.  ``linearize`` therefore
  takes ``friction="off"`` (default: F_c dropped), ``"equivalent"`` (Eq 8: F_c
  replaced by the energy-equivalent viscous damping ``4 F_c / (pi w X)`` of a
  harmonic motion of amplitude X at w, Jacobsen) or ``"tangent"`` (the raw
  Jacobian, stuck structure).
* The load-pressure factor of Eq (3) contains ``sgn(x_v)``; its derivative by p
  is multiplied by ``g(x_v)``, which vanishes at the null spool, so the Jacobian
  is continuous there (the C++ code uses sgn(0) = 0).  Away from null, the
  operating point's spool sign selects the branch: that is the valve's
  flow-pressure coefficient at that opening, and it is kept.
* Saturations (drive, spool end stops) are inactive at any equilibrium inside
  the travel; spring softening only matters for ``|x0| > x_contact``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import control as ct
import numpy as np
from scipy.optimize import brentq, minimize_scalar

from . import _core
from .rig import Rig, rig_from_dict, rig_to_dict
from .simulate import MODES

TWO_PI = 2.0 * math.pi
ALPHA = 0.1  #: constant of the paper's phase-lead networks (Table I) [-]
OUTPUTS = ("displacement", "velocity", "acceleration", "force", "pressure", "spool", "drive", "flow")
OUTPUT_UNITS = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2", "force": "N",
                "pressure": "Pa", "spool": "-", "drive": "V", "flow": "m^3/s"}
STATES = ("x", "v", "p", "x_v", "x_v_dot", "z")
FRICTION_TREATMENTS = ("off", "equivalent", "tangent")


# --------------------------------------------------------------------------- blocks
def phase_lead(T: float, alpha: float = ALPHA) -> ct.TransferFunction:
    """Phase-lead network (T s + 1)/(alpha T s + 1) of Fig 1 [-]; T [s]."""
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"invalid T = {T!r}: the lead time constant must be finite and > 0 [s]")
    if not (0 < alpha < 1):
        raise ValueError(f"invalid alpha = {alpha!r}: must be in (0, 1)")
    return ct.tf([T, 1.0], [alpha * T, 1.0])


def servovalve(rig: Rig) -> ct.TransferFunction:
    """Servovalve second order of Eq (2) with unit static gain: w_v^2/(s^2 + 2 zeta_v w_v s + w_v^2)."""
    w = TWO_PI * rig.f_v
    return ct.tf([w * w], [1.0, 2.0 * rig.zeta_v * w, w * w])


def zoh_delay(dt: float, order: int = 3) -> ct.TransferFunction:
    """Half-sample delay of the zero-order hold of a controller at sample time dt [s] (Pade)."""
    num, den = ct.pade(dt / 2.0, order)
    return ct.tf(num, den)


@dataclass(frozen=True)
class Compensation:
    """Linear compensators put in the loop by :func:`linearize` (all times in s).

    amplitude_T: amplitude compensation lead (T s+1)/(alpha T s+1) on the
        command, Fig 1(b) (paper: 68 ms).
    velocity_feedback: EFT velocity-feedback compensation of Fig 1(a): the
        command gets ``A / (K_v K_s C_F G_p) * lead(velocity_feedback_T) * v``
        added, the linear inverse of the natural velocity feedback.
    velocity_feedback_T: phase lead of that path (paper: 5 ms); None: no lead.
    zoh_dt: controller sample time whose half-sample ZOH delay is put on the
        command (None: continuous).
    """

    amplitude_T: float | None = None
    velocity_feedback: bool = False
    velocity_feedback_T: float | None = None
    alpha: float = ALPHA
    zoh_dt: float | None = None


# --------------------------------------------------------------------------- linearisation
def _copy(rig: Rig) -> Rig:
    """An independent copy of a rig (every parameter, flow curve and effect switch)."""
    return rig_from_dict(rig_to_dict(rig))


def linear_analysis_rig(rig: Rig, friction: str = "off", friction_amplitude: float = 0.0127,
                        friction_frequency: float | None = None) -> Rig:
    """Copy of the rig with the friction treated as in the linear analysis.

    friction: ``"off"`` (F_c dropped), ``"equivalent"`` (F_c replaced by
    ``c_eq = 4 F_c / (pi w X)``, Eq 8, at amplitude ``friction_amplitude`` [m]
    and ``friction_frequency`` [rad/s], default sqrt(k/m)), ``"tangent"``
    (unchanged).
    """
    if friction not in FRICTION_TREATMENTS:
        raise ValueError(f"invalid friction = {friction!r}: expected one of {list(FRICTION_TREATMENTS)}")
    r = _copy(rig)
    if friction == "tangent":
        return r
    if friction == "equivalent" and r.effects.coulomb_friction:
        r.c = r.c + equivalent_viscous_damping(r, friction_amplitude, friction_frequency)
    r.effects.coulomb_friction = False
    return r


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


def hold_command(dyn: _core.Dynamics, y0: Sequence[float]) -> float:
    """The held command u0 [m or N] for which the equilibrium state y0 is at rest.

    The rate equation that u drives (the spool, or the pressure with a static
    valve) is affine in u away from saturation: two secant steps make it exact.
    """
    mode = dyn.mode
    if mode == _core.ControlMode.Free:
        return float(dyn.spring_force(y0[0]))
    idx = 4 if dyn.rhs(list(y0), 1.0)[4] != dyn.rhs(list(y0), 0.0)[4] else 2

    def r(u: float) -> float:
        return float(dyn.rhs(list(y0), u)[idx])

    u_a = float(y0[0]) if mode == _core.ControlMode.Displacement else float(dyn.outputs(list(y0), 0.0).force)
    scale = 1e-4 if mode == _core.ControlMode.Displacement else 10.0
    u_b = u_a + scale
    for _ in range(3):
        ra, rb = r(u_a), r(u_b)
        if rb == ra:
            break
        u_a, u_b = u_b, u_b - rb * (u_b - u_a) / (rb - ra)
    return u_b


def linearize(rig: Rig, mode: str = "displacement", x0: float = 0.0, u0: float | None = None,
              outputs: Sequence[str] = ("displacement",), compensators: Compensation | None = None,
              friction: str = "off", friction_amplitude: float = 0.0127,
              friction_frequency: float | None = None) -> ct.StateSpace:
    """Linearises the nonlinear C++ model about its static equilibrium at x0.

    Args:
        rig: the rig (not modified).
        mode: ``"displacement"`` (input: command [m]), ``"force"`` (command [N])
            or ``"free"`` (ideal external force [N]).
        x0: operating displacement [m].
        u0: held command [m or N]; default: the command that holds x0.
        outputs: channels among ``OUTPUTS`` (SI units, see ``OUTPUT_UNITS``).
        compensators: linear compensators in the loop (:class:`Compensation`).
        friction: treatment of the Coulomb friction (module docstring).
        friction_amplitude, friction_frequency: X [m] and w [rad/s] of the
            equivalent viscous damping (``friction="equivalent"``).

    Returns:
        ``control.StateSpace`` from input ``"u"`` to the named outputs, with the
        inactive states (pressure and spool in Free mode, the spool without
        valve dynamics) dropped, and the compensator states appended.
    """
    if mode not in MODES:
        raise ValueError(f"invalid mode = {mode!r}: expected one of {sorted(MODES)}")
    outs = list(outputs)
    for o in outs:
        if o not in OUTPUTS:
            raise ValueError(f"invalid output = {o!r}: expected one of {list(OUTPUTS)}")
    if not outs:
        raise ValueError("invalid outputs = (): name at least one output channel")
    if not math.isfinite(x0):
        raise ValueError(f"invalid x0 = {x0!r}: must be finite [m]")
    comp = compensators or Compensation()
    r = linear_analysis_rig(rig, friction, friction_amplitude, friction_frequency)
    dyn = _core.Dynamics(r, MODES[mode])
    y0 = list(dyn.equilibrium(float(x0)))
    u_op = hold_command(dyn, y0) if u0 is None else float(u0)
    lm = _core.linearize(dyn, y0, u_op)
    keep = np.flatnonzero(np.asarray(lm.active, dtype=bool))
    need = list(dict.fromkeys(outs + (["velocity"] if comp.velocity_feedback else [])))
    rows = [OUTPUTS.index(o) for o in need]
    A = np.asarray(lm.A)[np.ix_(keep, keep)]
    B = np.asarray(lm.B).reshape(-1, 1)[keep]
    C = np.asarray(lm.C)[np.ix_(rows, keep)]
    D = np.asarray(lm.D).reshape(-1, 1)[rows]
    plant = ct.ss(A, B, C, D, inputs=["u"], outputs=need, states=[STATES[i] for i in keep],
                  name="plant")
    return _close_compensators(plant, r, mode, comp, outs)


def _close_compensators(plant: ct.StateSpace, rig: Rig, mode: str, comp: Compensation,
                        outs: list[str]) -> ct.StateSpace:
    """Puts the linear compensators around the plant (python-control interconnect)."""
    if comp.amplitude_T is None and not comp.velocity_feedback and comp.zoh_dt is None:
        return ct.ss(plant[[plant.output_labels.index(o) for o in outs], :]) if len(outs) < plant.noutputs \
            else plant
    blocks: list = [plant]
    signal = "u_cmd"
    chain: list[tuple[str, ct.TransferFunction]] = []
    if comp.amplitude_T is not None:
        chain.append(("amplitude_lead", phase_lead(comp.amplitude_T, comp.alpha)))
    if comp.zoh_dt is not None:
        chain.append(("zoh", zoh_delay(comp.zoh_dt)))
    for name, tf in chain:
        nxt = f"{name}_out"
        blocks.append(ct.ss(tf, inputs=[signal], outputs=[nxt], name=name))
        signal = nxt
    if comp.velocity_feedback:
        if mode != "force":
            raise ValueError(f"invalid compensators.velocity_feedback = True in mode = {mode!r}: "
                             "velocity-feedback compensation is the force-control (EFT) scheme")
        gain = rig.A / (rig.K_v * rig.K_s * rig.C_F_force * rig.G_p)  # [N per m/s]
        vf = ct.tf([gain], [1.0]) if comp.velocity_feedback_T is None else \
            gain * phase_lead(comp.velocity_feedback_T, comp.alpha)
        blocks.append(ct.ss(vf, inputs=["velocity"], outputs=["u_vfc"], name="velocity_feedback"))
        blocks.append(ct.summing_junction(inputs=[signal, "u_vfc"], output="u", name="sum"))
    else:
        blocks.append(ct.summing_junction(inputs=[signal], output="u", name="sum"))
    return ct.interconnect(blocks, inplist=["u_cmd"], outlist=outs, inputs=["u"], outputs=outs,
                           name="compensated")


# --------------------------------------------------------------------------- closed forms, Eqs (9)-(14)
def _use_valve(rig: Rig, servovalve_on: bool | None) -> bool:
    return rig.effects.servovalve_dynamics if servovalve_on is None else bool(servovalve_on)


def _piston(rig: Rig) -> float:
    return rig.m_p if rig.effects.piston_mass else 0.0


def moving_mass(rig: Rig) -> float:
    """Mass moving with the piston in an actuated mode, m + m_p (piston-mass effect on) [kg]."""
    return rig.m + _piston(rig)


def loop_gain_displacement(rig: Rig) -> float:
    """K_v C_F K_s G_p of Eq (12), displacement control [m^3/s per m]."""
    return rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p


def loop_gain_force(rig: Rig) -> float:
    """K_v C_F K_s G_p of Eq (9), force control [m^3/s per N]."""
    return rig.K_v * rig.C_F_force * rig.K_s * rig.G_p


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


# --------------------------------------------------------------------------- Routh bound, Fig 6(b)
def characteristic_polynomial(rig: Rig, G_p: float | None = None, mass: float | None = None,
                              servovalve_on: bool | None = None) -> np.ndarray:
    """Coefficients (highest power first) of the displacement loop's characteristic
    polynomial, the denominator of Eq (12) (times the valve's when on)."""
    M = moving_mass(rig) if mass is None else float(mass)
    gp = rig.G_p if G_p is None else float(G_p)
    L = rig.A * rig.K_v * rig.C_F_disp * rig.K_s * gp
    base = np.polymul([rig.K_a, rig.C_l], [M, rig.c, rig.k])
    base = np.polyadd(base, [rig.A**2, 0.0])
    if _use_valve(rig, servovalve_on):
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
    r = _copy(rig)
    r.effects.piston_mass = False
    r.m = float(mass)
    return r


# --------------------------------------------------------------------------- compensator design
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
    L = rig.K_v * rig.C_F_disp * rig.K_s * (servovalve(rig) if _use_valve(rig, servovalve_on) else 1)
    return rig.A * L / ((rig.C_l + rig.K_a * s) * Zt + rig.A**2 * s)


# --------------------------------------------------------------------------- RPsD loop, Figs 7-10
RESTORING_FORCES = ("measured_displacement", "measured_force", "force_minus_inertia",
                    "force_minus_inertia_damping", "force_corrected")


def rpsd_loop(rig: Rig, m_m: float = 7084.0, c_m: float = 3.5e3, restoring_force: str = "measured_displacement",
              amplitude_T: float | None = 0.068, delay_T: float | None = 0.0112, alpha: float = ALPHA,
              physical_mass: float | None = None, zoh_dt: float | None = 5e-4) -> ct.StateSpace:
    """Linear model of the real-time pseudodynamic loop of Fig 7 (solver in continuous time).

    The solver of Eq (15), m_m a_c + c_m v_c + f = P, sends its displacement x_c
    through the amplitude lead (T_d, 68 ms) and the ZOH to the linearised
    displacement-controlled rig; the restoring force f comes back through the
    delay-compensation lead (T_ld, 11.2 ms).  ``restoring_force``:

    * ``"measured_displacement"``: f = k x_meas (Fig 7a, Figs 8, 9b);
    * ``"measured_force"``: f = p A, the actuator force (Fig 10b/c, inertia and damping kept);
    * ``"force_minus_inertia"``: f = p A - m a (damping term kept);
    * ``"force_minus_inertia_damping"``: f = p A - m a - c v (piston mass ignored);
    * ``"force_corrected"``: f = p A - (m + m_p) a - c v (Fig 7b, exact).

    physical_mass: installed structural mass [kg] (default: the rig's m;
    substructuring with 2 % of m_m = 140 kg for Fig 10c).  Friction is off
    (linear analysis).  Input ``P`` [N] (external force, -m_m a_g), outputs
    ``x_c`` (calculated) and ``x`` (measured) [m].
    """
    if restoring_force not in RESTORING_FORCES:
        raise ValueError(f"invalid restoring_force = {restoring_force!r}: expected one of {list(RESTORING_FORCES)}")
    r = _copy(rig)
    if physical_mass is not None:
        r.m = float(physical_mass)
    plant = linearize(r, "displacement", outputs=("displacement", "velocity", "acceleration", "pressure"))
    plant = ct.ss(plant.A, plant.B, plant.C, plant.D, inputs=["u"],
                  outputs=["x", "v_meas", "a_meas", "p_meas"], name="rig")
    mp = r.m_p if r.effects.piston_mass else 0.0
    weights = {  # f = w_x x + w_v v + w_a a + w_p p
        "measured_displacement": (r.k, 0.0, 0.0, 0.0),
        "measured_force": (0.0, 0.0, 0.0, r.A),
        "force_minus_inertia": (0.0, 0.0, -r.m, r.A),
        "force_minus_inertia_damping": (0.0, -r.c, -r.m, r.A),
        "force_corrected": (0.0, -r.c, -(r.m + mp), r.A),
    }[restoring_force]
    meas = ct.ss([], [], [], [list(weights)], inputs=["x", "v_meas", "a_meas", "p_meas"], outputs=["f_meas"],
                 name="restoring_force")
    solver = ct.ss([[0.0, 1.0], [0.0, -c_m / m_m]], [[0.0, 0.0], [1.0 / m_m, -1.0 / m_m]], [[1.0, 0.0]],
                   [[0.0, 0.0]], inputs=["P", "f"], outputs=["x_c"], name="solver")
    blocks = [plant, meas, solver]
    cmd = "x_c"
    chain = []
    if amplitude_T:
        chain.append(("amplitude_lead", phase_lead(amplitude_T, alpha)))
    if zoh_dt:
        chain.append(("zoh", zoh_delay(zoh_dt)))
    for name, tf in chain:
        blocks.append(ct.ss(tf, inputs=[cmd], outputs=[f"{name}_out"], name=name))
        cmd = f"{name}_out"
    blocks.append(ct.summing_junction(inputs=[cmd], output="u", name="command"))
    if delay_T:
        blocks.append(ct.ss(phase_lead(delay_T, alpha), inputs=["f_meas"], outputs=["f"], name="delay_lead"))
    else:
        blocks.append(ct.summing_junction(inputs=["f_meas"], output="f", name="delay_lead"))
    return ct.interconnect(blocks, inplist=["P"], outlist=["x_c", "x"], inputs=["P"], outputs=["x_c", "x"],
                           name="rpsd")


def structural_mode(sys_: ct.LTI, near: float) -> tuple[float, float]:
    """(frequency [Hz], damping ratio [-]) of the complex pole pair closest to
    ``near`` [rad/s] (the structural mode of a test loop)."""
    p = np.asarray(sys_.poles())
    p = p[np.imag(p) > 1e-9]
    z = p[np.argmin(np.abs(np.abs(p) - near))]
    return float(abs(z) / TWO_PI), float(-np.real(z) / abs(z))


__all__ = [
    "ALPHA",
    "Compensation",
    "FRICTION_TREATMENTS",
    "G_fu",
    "G_fu_compensated",
    "G_xu",
    "OUTPUTS",
    "RESTORING_FORCES",
    "acceptable_band",
    "amplitude_compensation_T",
    "characteristic_polynomial",
    "damping_ratio",
    "delay_compensation_T",
    "displacement_open_loop",
    "dominant_modes",
    "equivalent_delay",
    "equivalent_viscous_damping",
    "group_delay",
    "hold_command",
    "linear_analysis_rig",
    "linearize",
    "max_p_gain",
    "max_p_gain_curve",
    "moving_mass",
    "natural_frequency",
    "omega_cEFT",
    "omega_cRPD",
    "omega_oil_column",
    "phase_lead",
    "rig_with_mass",
    "root_locus_gains",
    "routh_array",
    "routh_stable",
    "rpsd_loop",
    "servovalve",
    "structural_mode",
    "zoh_delay",
]
