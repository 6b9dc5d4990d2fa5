"""An independent simulator of Zhao et al. (2003) Eqs (1)-(5) for the diagnose
evaluation: plain Python, classical RK4 with a fixed substep, no code shared with
the C++ core.  It carries effects in forms the diagnose library does not have:
Stribeck and LuGre friction, a tabulated flow curve, a delay made of a filter
(2nd-order Bessel low-pass of the command) or a true continuous-time delay of
the held command, a true transport delay of the valve drive inside the loop
(method of steps on the stored drive history, not a Pade approximant), and a
Bouc-Wen hysteretic specimen (Wen 1976) in parallel with the structure.

Units SI.  State: x [m], v [m/s], p [Pa], x_v [-], x_v' [1/s], plus z [m] (LuGre
bristle deflection), two filter states when a filter delay is on, and the
Bouc-Wen displacement z_b [m].
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
    loop_delay: float = 0.0  # [s]: transport delay of the valve drive inside the loop (0: none)
    bouc_wen: bool = False  # Bouc-Wen specimen F = bw_k z_b in parallel with the structure
    bw_k: float = 0.0  # [N/m]
    bw_A: float = 1.0
    bw_beta: float = 0.0  # [1/m^n]
    bw_gamma: float = 0.0  # [1/m^n]
    bw_n: float = 1.0


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

    def commanded(y: list, uc: float) -> float:
        # the command the controller sees: through the Bessel filter (state f1) or as held
        return y[6] if tr.delay == "filter" else uc

    def drive_of(y: list, uc: float) -> float:
        # the saturated valve drive of the inner loop, Eq (1); the force feedback F = p A - m_p a, a from the
        # structure's balance (independent of the drive)
        x, p = y[0], y[2]
        a = (p * tr.A - structure(y)) / M
        F = p * tr.A - mp * a
        err = (commanded(y, uc) - x) if mode == "displacement" else (commanded(y, uc) - F)
        return max(-tr.v_max, min(tr.v_max, CF * tr.G_p * err))

    def structure(y: list) -> float:
        # every force of the structure against the applied one, with the friction law and the Bouc-Wen specimen
        x, v, z = y[0], y[1], y[5]
        fr = friction(v, z, 0.0)
        return fr + tr.c * v + spring(x) + (tr.bw_k * y[8] if tr.bouc_wen else 0.0)

    def rhs(y: list, uc: float, w_del: float | None = None) -> list:
        x, v, p, xv, xvd, z, f1, f2, zb = y
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
        if tr.bouc_wen:
            zbd = (tr.bw_A * v - tr.bw_beta * abs(v) * abs(zb) ** (tr.bw_n - 1) * zb
                   - tr.bw_gamma * v * abs(zb) ** tr.bw_n)
        else:
            zbd = 0.0
        applied = p * tr.A if actuator else ucmd
        a = (applied - structure(y)) / M
        if not actuator:
            return [v, a, 0.0, 0.0, 0.0, zd, f2, f2d, zbd]
        drive = drive_of(y, uc) if w_del is None else w_del
        xvdd = wv * wv * (tr.K_s * drive - xv) - 2 * tr.zeta_v * wv * xvd
        s = max(-tr.x_v_max, min(tr.x_v_max, xv))
        R = 1.0
        if tr.load_pressure:
            r = 1.0 - (1.0 if s > 0 else -1.0 if s < 0 else 0.0) * p / tr.p_s
            R = math.copysign(math.sqrt(abs(r)), r)
        Q = tr.K_v * g(s) * R
        pd = (Q - tr.C_l * p - tr.A * v) / tr.K_a
        return [v, a, pd, xvd, xvdd, zd, f2, f2d, zbd]

    n = len(u)
    # initial state: static equilibrium at x0 (pressure holds the springs; spool feeds the leakage)
    y = [x0, 0.0, 0.0, 0.0, 0.0, 0.0, float(u[0]) if tr.delay == "filter" else 0.0, 0.0, 0.0]
    if actuator:
        p0 = spring(x0) / tr.A  # (the Bouc-Wen specimen starts unstrained: z_b = 0)
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

    # loop delay: the drive at every substep boundary (times j h), before t = 0 the initial state's steady drive
    # (the spool holding the leakage: x_v = K_s w); the delayed drive at a stage time is linearly interpolated
    lag = tr.loop_delay if actuator else 0.0
    if lag > 0.0 and lag < h:
        raise ValueError(f"invalid loop_delay = {lag}: must be at least one substep ({h} s)")
    w_hist = [y[3] / tr.K_s] if lag > 0.0 else []

    def w_delayed(t: float) -> float | None:
        if lag <= 0.0:
            return None
        s_ = (t - lag) / h
        if s_ <= 0.0:
            return w_hist[0]
        j = int(math.floor(s_))
        f = s_ - j
        return w_hist[j + 1] if f == 0.0 else w_hist[j + 1] * (1 - f) + w_hist[j + 2] * f if j + 2 < len(w_hist) \
            else w_hist[-1]

    for k in range(n):
        t0 = k * dt
        outputs(k, y, held(t0) if tr.delay == "pure" else float(u[k]))
        for i in range(substeps):
            t = t0 + i * h
            if tr.delay == "pure":
                u1, u2, u3 = held(t), held(t + 0.5 * h), held(t + h - 1e-12)
            else:
                u1 = u2 = u3 = float(u[k])
            if lag > 0.0 and len(w_hist) == k * substeps + i + 1:
                w_hist.append(drive_of(y, u1))  # the drive at t (index k substeps + i + 1: index 0 is t < 0)
            w1, w2, w3 = w_delayed(t), w_delayed(t + 0.5 * h), w_delayed(t + h)
            k1 = rhs(y, u1, w1)
            k2 = rhs([a + 0.5 * h * b for a, b in zip(y, k1)], u2, w2)
            k3 = rhs([a + 0.5 * h * b for a, b in zip(y, k2)], u2, w2)
            k4 = rhs([a + h * b for a, b in zip(y, k3)], u3, w3)
            y = [a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4)]
    out["command"] = np.asarray(u, float)
    out["time"] = np.arange(n) * dt
    if not actuator:
        out["force"] = np.asarray(u, float)
    return out
