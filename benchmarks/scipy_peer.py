"""The peer a Python user would otherwise write: Eqs (1)-(5) of Zhao et al.
(2003) as a plain Python right-hand side for ``scipy.integrate.solve_ivp``,
written from the paper and the rig's parameters, independently of the C++
``Dynamics`` (so it is also an independent-solver oracle for the core).

Displacement control, every nonlinear effect on (rig.effects): drive and
spool saturation, servovalve second order (Eq 2), flow curve g(x_v) and the
load-pressure square root (Eq 3), actuator compressibility and leakage
(Eq 4), structure with softening springs, regularised Coulomb friction and
the piston mass (Eq 5).  The command is held over each controller sample
(zero-order hold), looked up from the time.
"""

from __future__ import annotations

import bisect
import math
import time

import numpy as np
from scipy.integrate import solve_ivp


def flow_gain(rig):
    """g(s) of Fig 4(a): the rig's rational curve s / (1 + b |s|) or its table
    (piecewise linear in |s|, odd, the end segments extended)."""
    fc = rig.flow_curve
    if fc.kind.name == "Rational":
        b = fc.b
        return lambda s: s / (1.0 + b * abs(s))
    xs, qs = list(fc.opening), list(fc.flow)
    last = len(xs) - 2

    def g(s: float) -> float:
        a = abs(s)
        i = min(max(bisect.bisect_right(xs, a) - 1, 0), last)
        q = qs[i] + (qs[i + 1] - qs[i]) / (xs[i + 1] - xs[i]) * (a - xs[i])
        return math.copysign(q, s)

    return g


def make_rhs(rig, command: np.ndarray, dt: float):
    """f(t, y) for y = [x, v, p, x_v, x_v'] under the held displacement command [m]."""
    m_tot = rig.m + rig.m_p
    A, K_a, C_l, p_s = rig.A, rig.K_a, rig.C_l, rig.p_s
    K_v, K_s = rig.K_v, rig.K_s
    g = flow_gain(rig)
    wv = 2 * math.pi * rig.f_v
    zv = rig.zeta_v
    CF, Gp = rig.C_F_disp, rig.G_p
    vmax, xvmax = rig.v_max, rig.x_v_max
    k, k2, xc, c = rig.k, rig.k_2, rig.x_contact, rig.c
    Fc, vs = rig.F_c, rig.v_stick
    n = command.size
    u_list = command.tolist()

    def rhs(t, y):
        x, v, p, xv, xvd = y
        i = int(t / dt + 1e-9)
        u = u_list[i if i < n else n - 1]
        # Eq (1): proportional servo controller, drive limited to +-v_max.
        drive = CF * Gp * (u - x)
        drive = max(-vmax, min(vmax, drive))
        # Eq (2): second-order servovalve; the metering opening stops at +-x_v_max.
        xvdd = wv * wv * (K_s * drive - xv) - 2 * zv * wv * xvd
        s = max(-xvmax, min(xvmax, xv))
        # Eq (3): Q = K_v g(s) sqrt(1 - sign(s) p / p_s).
        r = 1.0 - math.copysign(1.0, s) * p / p_s if s != 0 else 1.0
        Q = K_v * g(s) * math.copysign(math.sqrt(abs(r)), r)
        # Eq (4): K_a p' = Q - C_l p - A x'.
        pdot = (Q - C_l * p - A * v) / K_a
        # Eq (5): structure plus piston, springs soften past +-x_contact.
        fs = k * x if abs(x) <= xc else math.copysign(k * xc + k2 * (abs(x) - xc), x)
        a = (p * A - Fc * math.tanh(v / vs) - c * v - fs) / m_tot
        return [v, a, pdot, xvd, xvdd]

    def force(y):
        """Load-cell force F = p A - m_p a [N] along a solution y[5, n]."""
        x, v, p = y[0], y[1], y[2]
        fs = np.where(np.abs(x) <= xc, k * x, np.sign(x) * (k * xc + k2 * (np.abs(x) - xc)))
        a = (p * A - Fc * np.tanh(v / vs) - c * v - fs) / m_tot
        return p * A - rig.m_p * a

    return rhs, force


def run(rig, command: np.ndarray, dt: float, method: str, rtol: float) -> dict:
    """Integrates the whole command with one solve_ivp call; outputs at the
    sample times (row k = state at k dt, the convention of sh.simulate)."""
    rhs, force = make_rhs(rig, command, dt)
    t_eval = np.arange(command.size) * dt
    # Absolute tolerances with the scales of the C++ core's defaults.
    atol = rtol * np.array([1e-3, 1e-2, 1e5, 1e-2, 1.0])
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, t_eval[-1]), np.zeros(5), method=method, t_eval=t_eval, rtol=rtol, atol=atol)
    wall = time.perf_counter() - t0
    if not sol.success or sol.y.shape[1] != t_eval.size:
        return {"method": method, "rtol": rtol, "ok": False, "message": sol.message, "wall_s": wall}
    return {"method": method, "rtol": rtol, "ok": True, "wall_s": wall, "nfev": int(sol.nfev),
            "displacement": sol.y[0], "force": force(sol.y)}
