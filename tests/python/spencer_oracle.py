"""An independent NumPy transcription of the thesis' modified Bouc-Wen (Spencer et al. 1997)
MR-damper law, in the thesis' units N, mm, s: the oracle the core's MR element is checked
against when it runs as the lab baseline (lab/baselines.py).  Not used by the package.

    dy/dt = (alpha z + k0 (x - y) + c0 dx/dt) / (c0 + c1)
    dz/dt = -gamma |dx/dt - dy/dt| |z|^(n-1) z - beta (dx/dt - dy/dt) |z|^n + A (dx/dt - dy/dt)
    F     = c1 dy/dt + k1 (x - x0)
"""

from __future__ import annotations

import numpy as np
from scipy import integrate


def _rates(p, xt: float, vt: float, y: float, z: float) -> tuple[float, float]:
    ydot = (p.alpha * z + p.k0 * (xt - y) + p.c0 * vt) / (p.c0 + p.c1)
    r = vt - ydot
    az = abs(z)
    return ydot, -p.gamma * abs(r) * az ** (p.n - 1.0) * z - p.beta * r * az**p.n + p.A * r


def _force(p, x: np.ndarray, v: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    ydot = (p.alpha * z + p.k0 * (x - y) + p.c0 * v) / (p.c0 + p.c1)
    return p.c1 * ydot + p.k1 * (x - p.x0)


def spencer_force_rk4(x_m: np.ndarray, v_m: np.ndarray, dt: float, p, substeps: int = 10) -> np.ndarray:
    """Force [N] along the motion x [m], v [m/s]: classical RK4, `substeps` per sample, the motion
    interpolated linearly between samples, starting at y = x[0], z = 0."""
    x, v = 1e3 * np.asarray(x_m), 1e3 * np.asarray(v_m)  # mm, mm/s
    n, h = x.size, 1.0 / substeps
    ys, zs = np.empty(n), np.empty(n)
    y, z = float(x[0]), 0.0
    ys[0], zs[0] = y, z
    for k in range(n - 1):
        x0, dx, v0, dv = x[k], x[k + 1] - x[k], v[k], v[k + 1] - v[k]
        for j in range(substeps):
            w0, wm, w1 = j * h, (j + 0.5) * h, (j + 1) * h
            a1, b1 = _rates(p, x0 + w0 * dx, v0 + w0 * dv, y, z)
            a2, b2 = _rates(p, x0 + wm * dx, v0 + wm * dv, y + 0.5 * h * dt * a1, z + 0.5 * h * dt * b1)
            a3, b3 = _rates(p, x0 + wm * dx, v0 + wm * dv, y + 0.5 * h * dt * a2, z + 0.5 * h * dt * b2)
            a4, b4 = _rates(p, x0 + w1 * dx, v0 + w1 * dv, y + h * dt * a3, z + h * dt * b3)
            y += h * dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
            z += h * dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
        ys[k + 1], zs[k + 1] = y, z
    return _force(p, x, v, ys, zs)


def spencer_force_lsoda(x_m: np.ndarray, v_m: np.ndarray, dt: float, p) -> np.ndarray:
    """The same by SciPy's LSODA (rtol 1e-6, at most one sample per step)."""
    x, v = 1e3 * np.asarray(x_m), 1e3 * np.asarray(v_m)
    n = x.size

    def rhs(t: float, s: np.ndarray) -> list[float]:
        k = min(int(t / dt), n - 2)
        w = t / dt - k
        return list(_rates(p, x[k] + w * (x[k + 1] - x[k]), v[k] + w * (v[k + 1] - v[k]), s[0], s[1]))

    t = np.arange(n) * dt
    sol = integrate.solve_ivp(rhs, (0.0, t[-1]), [x[0], 0.0], method="LSODA", t_eval=t, rtol=1e-6,
                              atol=[1e-6, 1e-6], max_step=dt)
    assert sol.success, sol.message
    return _force(p, x, v, sol.y[0], sol.y[1])
