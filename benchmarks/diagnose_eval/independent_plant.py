"""An independent simulator of Zhao et al. (2003) Eqs (1)-(5) for the diagnose
evaluation: plain Python, classical RK4 with a fixed substep, no code shared with
the C++ core.  It carries effects in forms the diagnose library does not have:
Stribeck and LuGre friction, a tabulated flow curve, a delay made of a filter
(2nd-order Bessel low-pass of the command) or a true continuous-time delay of
the held command.

Units SI.  State: x [m], v [m/s], p [Pa], x_v [-], x_v' [1/s], plus z [m] (LuGre
bristle deflection) and two filter states when a filter delay is on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Truth:
    """Parameters of the simulated rig (defaults: the paper's rig, Table I,
    with the project's calibrated K_a, C_l, f_v, zeta_v)."""

    m: float = 7084.0
    c: float = 2.1e3
    k: float = 700.8e3
    k_2: float = 350.4e3
    x_contact: float = 0.025
    spring_softening: bool = False
    friction: str = "none"  # none | coulomb | stribeck | lugre
    F_c: float = 0.0  # Coulomb level [N]
    F_s: float = 0.0  # static (breakaway) level [N], Stribeck/LuGre
    v_s: float = 0.01  # Stribeck velocity [m/s]
    sigma_0: float = 5e5  # LuGre bristle stiffness [N/m]
    v_stick: float = 1e-4  # regularisation of sgn(v) [m/s]
    m_p: float = 54.0
    piston_mass: bool = True
    A: float = 82.1e-4
    K_a: float = 1.36e-12
    C_l: float = 3.4e-11
    p_s: float = 1.7e7
    load_pressure: bool = False
    K_v: float = 1.6e-2
    K_s: float = 0.1
    f_v: float = 70.7
    zeta_v: float = 1.0
    x_v_max: float = 1.0
    flow: str = "linear"  # linear | rational | table
    b: float = 0.6
    table_opening: list = field(default_factory=list)
    table_flow: list = field(default_factory=list)
    C_F_disp: float = 78.74
    C_F_force: float = 0.056e-3
    G_p: float = 0.8059
    v_max: float = 10.0
    delay: str = "none"  # none | pure | filter
    tau: float = 0.0  # [s]: pure delay, or DC group delay of the Bessel filter


def simulate(tr: Truth, mode: str, u: np.ndarray, dt: float, x0: float = 0.0, substeps: int = 8) -> dict:
    """Runs the record; row k is the state at t_k before command u[k] is applied
    (the project's record convention).  Returns channels as arrays."""
    actuator = mode != "free"
    mp = tr.m_p if (actuator and tr.piston_mass) else 0.0
    M = tr.m + mp
    wv = 2 * math.pi * tr.f_v
    CF = tr.C_F_force if mode == "force" else tr.C_F_disp
    op = np.asarray(tr.table_opening, float)
    fl = np.asarray(tr.table_flow, float)

    def g(s: float) -> float:
        if tr.flow == "linear":
            return s
        if tr.flow == "rational":
            return s / (1 + tr.b * abs(s))
        return math.copysign(float(np.interp(abs(s), op, fl)), s)

    def friction(v: float, z: float, zdot: float) -> float:
        if tr.friction == "none":
            return 0.0
        sg = math.tanh(v / tr.v_stick)
        if tr.friction == "coulomb":
            return tr.F_c * sg
        level = tr.F_c + (tr.F_s - tr.F_c) * math.exp(-(v / tr.v_s) ** 2)
        if tr.friction == "stribeck":
            return level * sg
        return tr.sigma_0 * z  # LuGre (sigma_1 = sigma_2 = 0; viscous part is c v)

    def spring(x: float) -> float:
        if not tr.spring_softening or abs(x) <= tr.x_contact:
            return tr.k * x
        return math.copysign(tr.k * tr.x_contact + tr.k_2 * (abs(x) - tr.x_contact), x)

    def rhs(y: list, uc: float) -> list:
        x, v, p, xv, xvd, z, f1, f2 = y
        # delay filter: 2nd-order Bessel 1/(1 + tau s + tau^2 s^2 / 3), states f1 (output), f2 = f1'
        if tr.delay == "filter":
            w2 = 3.0 / tr.tau ** 2
            f2d = w2 * (uc - f1) - 3.0 / tr.tau * f2
            ucmd = f1
        else:
            f2d = 0.0
            ucmd = uc
        if tr.friction == "lugre":
            level = tr.F_c + (tr.F_s - tr.F_c) * math.exp(-(v / tr.v_s) ** 2)
            zd = v - tr.sigma_0 * abs(v) * z / level
        else:
            zd = 0.0
        fr = friction(v, z, zd)
        applied = p * tr.A if actuator else ucmd
        a = (applied - fr - tr.c * v - spring(x)) / M
        if not actuator:
            return [v, a, 0.0, 0.0, 0.0, zd, f2, f2d]
        F = p * tr.A - mp * a
        err = (ucmd - x) if mode == "displacement" else (ucmd - F)
        drive = CF * tr.G_p * err
        drive = max(-tr.v_max, min(tr.v_max, drive))
        xvdd = wv * wv * (tr.K_s * drive - xv) - 2 * tr.zeta_v * wv * xvd
        s = max(-tr.x_v_max, min(tr.x_v_max, xv))
        R = 1.0
        if tr.load_pressure:
            r = 1.0 - (1.0 if s > 0 else -1.0 if s < 0 else 0.0) * p / tr.p_s
            R = math.copysign(math.sqrt(abs(r)), r)
        Q = tr.K_v * g(s) * R
        pd = (Q - tr.C_l * p - tr.A * v) / tr.K_a
        return [v, a, pd, xvd, xvdd, zd, f2, f2d]

    n = len(u)
    # initial state: static equilibrium at x0 (pressure holds the springs; spool feeds the leakage)
    y = [x0, 0.0, 0.0, 0.0, 0.0, 0.0, float(u[0]) if tr.delay == "filter" else 0.0, 0.0]
    if actuator:
        p0 = spring(x0) / tr.A
        y[2] = p0
        q = tr.C_l * p0 / tr.K_v
        if tr.flow == "rational":
            s0 = q / (1 - tr.b * abs(q))
        elif tr.flow == "table":
            s0 = math.copysign(float(np.interp(abs(q), fl, op)), q)
        else:
            s0 = q
        y[3] = s0
    out = {k: np.empty(n) for k in ("displacement", "velocity", "acceleration", "force", "pressure", "spool",
                                    "friction")}
    h = dt / substeps

    def outputs(k: int, y: list, uc: float) -> None:
        d = rhs(y, uc)
        out["displacement"][k] = y[0]
        out["velocity"][k] = y[1]
        out["acceleration"][k] = d[1]
        out["pressure"][k] = y[2] if actuator else 0.0
        out["spool"][k] = max(-tr.x_v_max, min(tr.x_v_max, y[3])) if actuator else 0.0
        out["force"][k] = (y[2] * tr.A - mp * d[1]) if actuator else uc
        out["friction"][k] = friction(y[1], y[5], d[5])  # friction force on the structure [N]

    def held(t: float) -> float:
        # command seen by the controller at time t: the ZOH staircase, delayed by tau if "pure"
        tt = t - tr.tau if tr.delay == "pure" else t
        j = int(math.floor(tt / dt + 1e-9))
        return float(u[min(max(j, 0), n - 1)])

    for k in range(n):
        t0 = k * dt
        outputs(k, y, held(t0) if tr.delay == "pure" else float(u[k]))
        for i in range(substeps):
            t = t0 + i * h
            if tr.delay == "pure":
                u1, u2, u3 = held(t), held(t + 0.5 * h), held(t + h - 1e-12)
            else:
                u1 = u2 = u3 = float(u[k])
            k1 = rhs(y, u1)
            k2 = rhs([a + 0.5 * h * b for a, b in zip(y, k1)], u2)
            k3 = rhs([a + 0.5 * h * b for a, b in zip(y, k2)], u2)
            k4 = rhs([a + h * b for a, b in zip(y, k3)], u3)
            y = [a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4)]
    out["command"] = np.asarray(u, float)
    out["time"] = np.arange(n) * dt
    if not actuator:
        out["force"] = np.asarray(u, float)
    return out
