"""J1-J9 exactly as the benchmark's F4_evaluation.m computes them, the
reference response (lsim of sys_r with a first-order hold) and the predictive
stability indicator PSI (BENCHMARK.md 4.5, 8.1, 8.2)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["J_NAMES", "J_LABELS", "criteria", "evaluate", "reference_response", "critical_delay", "psi",
           "matlab_round"]

#: The criteria's names in the code's (and Table 3's) order, meaning and unit as BENCHMARK.md 8.1
#: reads F4_evaluation.m: J1 the tracking delay [ms]; J2/J3 the RMS (std) / peak tracking error of
#: X_m against y_n(1); J4/J5 of X_m against the reference's 1st floor; J6/J7 the RMS errors of the
#: 2nd/3rd floors; J8/J9 their peak errors, all in percent of the compared signal's std or peak.
#: (The code numbers J5-J7 differently from the paper's text: code J5 = paper J7, J6 = J5, J7 = J6.)
J_NAMES = ("J1_delay_ms", "J2_rms_tracking_error_pct", "J3_peak_tracking_error_pct", "J4_rms_error_floor1_pct",
           "J5_peak_error_floor1_pct", "J6_rms_error_floor2_pct", "J7_rms_error_floor3_pct",
           "J8_peak_error_floor2_pct", "J9_peak_error_floor3_pct")
#: The same criteria as table labels.
J_LABELS = ("J1 delay [ms]", "J2 RMS tracking [%]", "J3 peak tracking [%]", "J4 RMS floor 1 [%]",
            "J5 peak floor 1 [%]", "J6 RMS floor 2 [%]", "J7 RMS floor 3 [%]", "J8 peak floor 2 [%]",
            "J9 peak floor 3 [%]")


def criteria(J) -> dict[str, float]:
    """J1-J9 (a sequence in the code's order) by name (``J_NAMES``)."""
    values = [float(v) for v in J]
    if len(values) != len(J_NAMES):
        raise ValueError(f"invalid J: {len(values)} values, expected {len(J_NAMES)} (J1-J9)")
    return dict(zip(J_NAMES, values))


def matlab_round(x: float) -> float:
    """MATLAB's round: half away from zero."""
    return math.copysign(math.floor(abs(x) + 0.5), x)


def _lagged_corr(x: np.ndarray, y: np.ndarray, max_lag: int) -> np.ndarray:
    """Pearson correlation of x[L:] and y[:N-L] for L = 0 .. max_lag-1 (MATLAB
    ``corr`` of the overlapping segments, each with its own mean removed), by
    running sums after removing the global means (for conditioning)."""
    x = x - x.mean()
    y = y - y.mean()
    N = x.size
    cx, cy = np.concatenate([[0.0], np.cumsum(x)]), np.concatenate([[0.0], np.cumsum(y)])
    cxx, cyy = np.concatenate([[0.0], np.cumsum(x * x)]), np.concatenate([[0.0], np.cumsum(y * y)])
    r = np.empty(max_lag)
    for L in range(max_lag):
        n = N - L
        sa, sb = cx[N] - cx[L], cy[n]
        saa, sbb = cxx[N] - cxx[L], cyy[n]
        sab = float(np.einsum("i,i->", x[L:], y[:n]))  # not np.dot: a threaded BLAS call is 40x slower here
        r[L] = (sab - sa * sb / n) / math.sqrt((saa - sa * sa / n) * (sbb - sb * sb / n))
    return r


def evaluate(measured: np.ndarray, numerical: np.ndarray, reference: np.ndarray, dt: float,
             max_lag: int = 50) -> list[float]:
    """[J1 .. J9] of F4_evaluation.m L11-39.

    Args:
        measured: X_m, the measured specimen displacement, N samples [m].
        numerical: N x 3 numerical-substructure displacements [m].
        reference: N x 3 reference displacements [m].
        dt: sample time [s].
    """
    xm = np.asarray(measured, dtype=float)
    num = np.asarray(numerical, dtype=float)
    ref = np.asarray(reference, dtype=float)
    if num.ndim != 2 or num.shape[0] != xm.size or ref.shape != num.shape:
        raise ValueError(f"invalid shapes: measured {xm.shape}, numerical {num.shape}, reference {ref.shape}")
    n1 = num[:, 0]
    lag = int(np.argmax(_lagged_corr(xm, n1, max_lag)))  # first maximum, as MATLAB's max
    J = [matlab_round(10000.0 * lag * dt) / 10.0]

    def pct(x: float) -> float:
        return matlab_round(10000.0 * x) / 100.0

    std = lambda v: float(np.std(v, ddof=1))  # noqa: E731
    peak = lambda v: float(np.max(np.abs(v)))  # noqa: E731
    J += [pct(std(xm - n1) / std(n1)), pct(peak(xm - n1) / peak(n1)),
          pct(std(xm - ref[:, 0]) / std(ref[:, 0])), pct(peak(xm - ref[:, 0]) / peak(ref[:, 0])),
          pct(std(num[:, 1] - ref[:, 1]) / std(ref[:, 1])), pct(std(num[:, 2] - ref[:, 2]) / std(ref[:, 2])),
          pct(peak(num[:, 1] - ref[:, 1]) / peak(ref[:, 1])), pct(peak(num[:, 2] - ref[:, 2]) / peak(ref[:, 2]))]
    return J


def reference_response(M: np.ndarray, C: np.ndarray, K: np.ndarray, ag: np.ndarray, dt: float) -> np.ndarray:
    """Displacements [m] (N x n) of M x'' + C x' + K x = -M iota a_g from rest, a_g
    sampled every dt and varying linearly in between (first-order hold, as
    ``lsim``), by the exact FOH recurrence in modal coordinates."""
    from scipy import linalg, signal  # here: importing the benchmark (e.g. the CLI's parser) loads no SciPy

    n = M.shape[0]
    MiK, MiC = np.linalg.solve(M, K), np.linalg.solve(M, C)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-MiK, -MiC]])
    B = np.concatenate([np.zeros(n), -np.ones(n)])[:, None]
    big = np.zeros((2 * n + 2, 2 * n + 2))
    big[:2 * n, :2 * n] = A * dt
    big[:2 * n, 2 * n:2 * n + 1] = B * dt
    big[2 * n, 2 * n + 1] = 1.0
    E = linalg.expm(big)
    Phi, G0, G1 = E[:2 * n, :2 * n], E[:2 * n, 2 * n], E[:2 * n, 2 * n + 1]
    # x_{k+1} = Phi x_k + (G0 - G1) u_k + G1 u_{k+1}: each mode of Phi is a first-order recursion.
    lam, V = np.linalg.eig(Phi)
    Vi = np.linalg.inv(V)
    b0, b1 = Vi @ (G0 - G1), Vi @ G1
    u = np.asarray(ag, dtype=float)
    z = np.empty((u.size, 2 * n), dtype=complex)
    for i in range(2 * n):
        z[:, i] = signal.lfilter([0.0, b0[i]], [1.0, -lam[i]], u) + signal.lfilter([0.0, b1[i]], [1.0, -lam[i]],
                                                                                       np.append(u[1:], 0.0))
    return (z @ V.T[:, :n]).real


def _polymat_det3(P: list[list[np.poly1d]]) -> np.poly1d:
    return (P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1]) - P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0])
            + P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0]))


def critical_delay(M: np.ndarray, C: np.ndarray, K: np.ndarray, me: float, ce: float, ke: float) -> float:
    """tau_cr [s]: the smallest delay of the feedback force at which the
    partitioned loop (Eq 8) loses stability, from the characteristic equation
    det A(s) + exp(-s tau) b(s) cof11(A(s)) = 0 (BENCHMARK.md 8.2)."""
    if M.shape != (3, 3):
        raise ValueError(f"invalid M.shape = {M.shape}: the PSI route is written for 3 DOF")
    Mn, Cn, Kn = M.copy(), C.copy(), K.copy()
    Mn[0, 0] -= me
    Cn[0, 0] -= ce
    Kn[0, 0] -= ke
    A = [[np.poly1d([Mn[i, j], Cn[i, j], Kn[i, j]]) for j in range(3)] for i in range(3)]
    detA = _polymat_det3(A)
    cof = A[1][1] * A[2][2] - A[1][2] * A[2][1]
    bc = np.poly1d([me, ce, ke]) * cof

    def mirror(p: np.poly1d) -> np.poly1d:  # p(-s)
        c = p.c.copy()
        deg = len(c) - 1
        return np.poly1d(c * np.array([(-1) ** (deg - i) for i in range(deg + 1)]))

    q = detA * mirror(detA) - bc * mirror(bc)  # even in s: |.|^2 at s = j omega
    c = q.c[::-1]  # ascending powers of s
    even = c[0::2] * np.array([(-1) ** k for k in range(len(c[0::2]))])  # coefficients of omega^(2k)
    roots = np.roots(even[::-1])
    taus = []
    for x in roots:
        if abs(x.imag) > 1e-6 * max(1.0, abs(x)) or x.real <= 0:
            continue
        w = math.sqrt(x.real)
        s = 1j * w
        R = -detA(s) / bc(s)
        theta = (-np.angle(R)) % (2 * math.pi)
        taus.append(theta / w if theta > 0 else 2 * math.pi / w)
    if not taus:
        return math.inf
    return min(taus)


def psi(M: np.ndarray, C: np.ndarray, K: np.ndarray, me: float, ce: float, ke: float) -> float:
    """PSI = log10(tau_cr in ms) (paper Sec 3.1)."""
    return math.log10(1000.0 * critical_delay(M, C, K, me, ce, ke))
