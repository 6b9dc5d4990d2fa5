"""The maRTHS benchmark (issue 23) against independent oracles: the ode4 plant against SciPy's integration
of the same state space (fourth-order convergence), the zero-pole-gain rebuild against the identified
state space, the Newmark structures against the exact response of a single-DOF system and against static
condensation of a massless DOF, RoDeAC's RLS against batch least squares, finddelay against a brute-force
lag search and MATLAB's documented examples, the whole loop against a NumPy re-implementation of
BENCHMARK.md, the Python seams (controllers, plants), the perturbed draws' statistics, and the nominal
El Centro run against BENCHMARK.md's reference row (its values and tolerances read from BENCHMARK.md)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from marths_support import write_folder
from scipy import integrate, signal

from servohydraulics import _core, marths
from servohydraulics.rths.data import Record

R = _core.marths
DT = marths.DT


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return write_folder(tmp_path_factory.mktemp("marths") / "data")


@pytest.fixture(scope="module")
def data(folder):
    return marths.load_data(folder)


@pytest.fixture(scope="module")
def record(folder):
    return marths.load_record(folder, "elcentro")


# ----------------------------------------------------------------------------- the plant

def _ode4_run(A, B, C, u, h, substeps):
    Phi, Gam = R.ode4_matrices(A, B, h / substeps)
    x = np.zeros(A.shape[0])
    y = []
    for uk in u:
        y.append(C @ x)
        for _ in range(substeps):
            x = Phi @ x + Gam @ uk
    return np.array(y)


def test_ode4_is_classical_rk4_converging_at_fourth_order_to_scipy():
    ss = R.BenchmarkPlantModel().transfer_matrix().realize()
    A, B, C = np.asarray(ss.A), np.asarray(ss.B), np.asarray(ss.C)
    rng = np.random.default_rng(4)
    n = 512
    u = np.repeat(rng.standard_normal((n // 16, 2)), 16, axis=0)  # held commands [mm]
    exact = []
    x = np.zeros(A.shape[0])
    for uk in u:  # the same held input, integrated to 1e-13 by DOP853
        exact.append(C @ x)
        x = integrate.solve_ivp(lambda t, z, uk=uk: A @ z + B @ uk, (0, DT), x, method="DOP853",
                                rtol=1e-13, atol=1e-15).y[:, -1]
    exact = np.array(exact)
    e1 = np.max(np.abs(_ode4_run(A, B, C, u, DT, 1) - exact))
    e2 = np.max(np.abs(_ode4_run(A, B, C, u, DT, 2) - exact))
    assert e1 < 2e-4 * np.max(np.abs(exact))
    assert 12.0 < e1 / e2 < 20.0  # fourth order: 2^4
    # the plant as a MultiActuatorSystem (SI at the seam) is the same map
    p = R.IdentifiedPlant(ss, DT)
    y = []
    for uk in u:
        y.append(p.displacements() * 1e3)
        p.step(uk * 1e-3)
    np.testing.assert_allclose(np.array(y), _ode4_run(A, B, C, u, DT, 1), rtol=0, atol=1e-12)


def test_the_zpk_rebuild_is_the_identified_state_space():
    from shared_data import shared_path

    d = marths.load_data(shared_path("marths-data"))
    ss = marths.plant_model(d)
    H = R.BenchmarkPlantModel().transfer_matrix()
    for f in np.logspace(-2, 2.7, 40):
        s = 2j * np.pi * f
        a, b = np.asarray(ss.frequency_response(s)), np.asarray(H.frequency_response(s))
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b))
    np.testing.assert_allclose(H.dc_gain(), [[0.8638, 0.1311], [0.1396, 0.9258]], atol=1e-4)


def test_perturbed_draws_follow_their_distributions():
    nominal = R.BenchmarkPlantModel()
    Hn = nominal.transfer_matrix()
    unc = R.PlantUncertainty()
    pole1, frame, zero22 = [], [], []
    for trial in range(1, 301):
        H = marths.perturbed_model(7, trial)
        pole1.append(H.poles[0][0] / Hn.poles[0][0])
        frame.append(H.poles[0][2] / Hn.poles[0][2])
        zero22.append(H.zeros[1][1][0] / Hn.zeros[1][1][0])
        if trial <= 20:  # every element keeps its nominal magnitude at the matching frequency
            s = 1j * unc.match_frequency
            for i in range(2):
                for j in range(2):
                    assert abs(H.element(i, j, s)) == pytest.approx(abs(Hn.element(i, j, s)), rel=1e-12)
            # stable, and realised with the columns sharing their poles
            assert np.all(np.linalg.eigvals(np.asarray(H.realize().A)).real < 0)
    for ratios, c in ((pole1, 0.06), (frame, 0.05), (zero22, 0.03)):
        r = np.real(ratios)
        assert abs(np.mean(r) - 1.0) < 4 * c / math.sqrt(len(r))
        assert np.std(r, ddof=1) == pytest.approx(c, rel=0.15)
    assert np.max(np.abs(np.imag(frame))) < 1e-12  # real and imaginary parts scaled by one factor
    # seeded: the same seed and trial give the same plant, other trials another
    assert marths.perturbed_model(7, 3).poles[0][0] == marths.perturbed_model(7, 3).poles[0][0]
    assert marths.perturbed_model(7, 3).poles[0][0] != marths.perturbed_model(7, 4).poles[0][0]


# ----------------------------------------------------------------------------- the structures

def _foh_ground(n, h, ramp_to=1.0):
    ag = np.full(n, ramp_to)
    ag[0] = 0.0
    return ag


@pytest.mark.parametrize("zeta", [0.0, 0.03])
def test_newmark_against_the_exact_sdof_response(zeta):
    """Average acceleration on m x'' + c x' + k x = -m a_g: second order in dt, to the exact response of the
    piecewise-linear ground acceleration (lsim's first-order hold is exact for it)."""
    m, f = 50.0, 2.0
    k = m * (2 * np.pi * f) ** 2
    c = 2 * zeta * math.sqrt(k * m)
    errors = []
    for h in (DT, DT / 2):
        n = int(round(2.0 / h)) + 1
        t = np.arange(n) * h
        ag = 3.0 * np.sin(2 * np.pi * 0.7 * t) * (t > 0.05)
        s = R.NewmarkStructure(R.StructureMatrices([[m]], [[c]], [[k]], [1.0]), h)
        x = []
        for a in ag:
            s.step(a)
            x.append(s.displacement[0])
        sys = signal.lti([[0, 1], [-k / m, -c / m]], [[0], [-1]], [[1, 0]], [[0]])
        _, exact, _ = signal.lsim(sys, ag, t, interp=True)
        errors.append(np.max(np.abs(np.array(x) - exact)) / np.max(np.abs(exact)))
    assert errors[0] < 1e-3
    assert 3.5 < errors[0] / errors[1] < 4.5  # second order


def test_newmark_with_a_massless_dof_equals_its_static_condensation():
    k1, k2, m = 4e6, 2e6, 120.0
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    M = np.diag([m, 0.0])  # the second DOF has no mass (as 16 of the FE model's 29)
    C = np.diag([300.0, 0.0])
    full = R.NewmarkStructure(R.StructureMatrices(M, C, K, [1.0, 0.0]), DT)
    kc = K[0, 0] - K[0, 1] ** 2 / K[1, 1]
    cond = R.NewmarkStructure(R.StructureMatrices([[m]], [[300.0]], [[kc]], [1.0]), DT)
    rng = np.random.default_rng(2)
    for a in rng.standard_normal(500):
        full.step(a)
        cond.step(a)
        assert full.displacement[0] == pytest.approx(cond.displacement[0], rel=1e-9, abs=1e-16)
        assert full.displacement[1] == pytest.approx(full.displacement[0] * -K[1, 0] / K[1, 1], rel=1e-9, abs=1e-16)


def test_the_benchmark_structures_modes_and_partition():
    import scipy.linalg as sl
    from shared_data import shared_path

    d = marths.load_data(shared_path("marths-data"))
    st = marths.structures(d)

    def omegas(S):
        w2 = sl.eigvals(np.asarray(S.K), np.asarray(S.M))
        w2 = w2[np.isfinite(w2)].real
        return np.sort(np.sqrt(w2[w2 > 0]))

    ref, num = omegas(st.reference), omegas(st.numerical)
    # the Rayleigh pair of build_reference.m: 165.125 rad/s is the reference's third mode (165.124); 13.493 is
    # no mode of the 29-DOF reference (its first is 14.396) nor of the numerical substructure (13.984)
    assert ref[2] == pytest.approx(165.125, abs=2e-3)
    assert ref[0] == pytest.approx(14.396, abs=1e-3) and num[0] == pytest.approx(13.984, abs=1e-3)
    assert np.min(np.abs(ref - 13.493)) > 0.5 and np.min(np.abs(num - 13.493)) > 0.4
    alpha, beta = R.rayleigh_coefficients(13.493, 165.125, 0.05)
    assert alpha == pytest.approx(1.2473724, rel=1e-7) and beta == pytest.approx(5.5985399e-4, rel=1e-7)
    np.testing.assert_allclose(np.asarray(st.reference.C), alpha * d.M + beta * d.K, rtol=1e-14, atol=1e-9)
    # the ideal frame's Rayleigh modes (24.54 and 279.24 rad/s) and the mass taken off DOF 27 only
    ideal = R.IdealFrameParameters()
    w = np.sqrt(sl.eigh(ideal.K(), ideal.M(), eigvals_only=True))
    assert w[0] == pytest.approx(24.54, abs=5e-3) and w[2] == pytest.approx(279.24, abs=5e-3)
    dM = d.M - np.asarray(st.numerical.M)
    assert dM[26, 26] == pytest.approx(902.527, abs=1e-3) and np.count_nonzero(dM) == 1
    idx = [26, 28, 20]
    np.testing.assert_allclose((d.K - np.asarray(st.numerical.K))[np.ix_(idx, idx)], ideal.K(), rtol=1e-12)
    assert d.influence_dofs == [13, 26, 27]


# ----------------------------------------------------------------------------- RoDeAC

def test_rodeac_rls_equals_batch_least_squares(data):
    """With lambda = 1, RLS from (theta0, P0) after N samples is the regularised batch solution
    (P0^-1 + sum X X^T)^-1 (P0^-1 theta0 + sum X uf); and each command is the updated theta times the taps."""
    cfg = marths.rodeac_config(data)
    ctrl = R.RodeacController(cfg)
    ctrl.reset()
    rng = np.random.default_rng(1)
    n = 3000
    t = np.arange(n) * DT
    desired = 1e-3 * np.column_stack([np.sin(2 * np.pi * 1.3 * t), 0.8 * np.sin(2 * np.pi * 0.9 * t + 1)])
    measured = 0.93 * np.roll(desired, 3, axis=0) + 2e-5 * rng.standard_normal((n, 2))
    u = np.array([ctrl.command(desired[k], measured[k]) for k in range(n)])
    b, a = signal.butter(4, 20 / (marths.FS / 2))
    np.testing.assert_allclose(cfg.filter.b, b, rtol=1e-12)
    np.testing.assert_allclose(cfg.filter.a, a, rtol=1e-12)
    for i in range(2):
        xf = signal.lfilter(b, a, 1e3 * measured[:, i])
        uf = signal.lfilter(b, a, 1e3 * u[:, i])
        X = np.column_stack([np.concatenate([np.zeros(j), xf[:n - j]]) for j in range(4)])
        P0inv = np.linalg.inv(data.P0[i])
        theta = np.linalg.solve(P0inv + X.T @ X, P0inv @ data.theta0[i] + X.T @ uf)
        np.testing.assert_allclose(ctrl.theta(i), theta, rtol=1e-6)
        T = np.column_stack([np.concatenate([np.zeros(j), 1e3 * desired[:n - j, i]]) for j in range(4)])
        assert 1e3 * u[-1, i] == pytest.approx(T[-1] @ ctrl.theta(i), rel=1e-10)


def test_rodeac_without_p0_is_the_fixed_fir(data):
    ctrl = R.RodeacController(marths.rodeac_config(data, adaptive=False))
    ctrl.reset()
    d = np.array([1e-3, -2e-3])
    u = ctrl.command(d, 0.9 * d)
    np.testing.assert_allclose(u, [data.theta0[0][0] * d[0], data.theta0[1][0] * d[1]], rtol=1e-14)
    np.testing.assert_allclose(ctrl.theta(0), data.theta0[0], rtol=0)


# ----------------------------------------------------------------------------- finddelay

def _brute_delay(x, y):
    n = x.size
    best, lag = -1.0, 0
    for L in range(-(n - 1), n):
        c = abs(np.dot(y[L:], x[:n - L]) if L >= 0 else np.dot(y[:n + L], x[-L:]))
        if c > best + 1e-12 * best or (abs(c - best) <= 1e-12 * best and (abs(L) < abs(lag) or (abs(L) == abs(lag)
                                                                                              and L > lag))):
            best, lag = c, L
    return lag


@pytest.mark.parametrize("seed", range(6))
def test_finddelay_against_a_brute_force_lag_search(seed):
    rng = np.random.default_rng(seed)
    n = 300
    x = np.convolve(rng.standard_normal(n + 20), np.ones(8) / 8, "same")[:n]
    shift = int(rng.integers(-25, 26))
    y = np.roll(x, shift) + 0.05 * rng.standard_normal(n)
    assert marths.finddelay(x, y) == _brute_delay(x, y)
    assert abs(marths.finddelay(x, y) - shift) <= 1


def test_finddelay_matches_matlabs_documented_examples():
    assert marths.finddelay([1, 2, 3], [0, 0, 1, 2, 3]) == 2
    assert marths.finddelay([0, 0, 0, 1, 2, 3, 0, 0], [1, 2, 3, 0]) == -3
    assert marths.finddelay([0, 0, 1, 2, 3, 0], [0.02, 0.12, 1.08, 2.21, 2.95, -0.09]) == 0
    assert marths.finddelay([0, 1, 2, 3], [1, 2, 3, 0, 0, 0, 0, 1, 2, 3, 0, 0]) == -1  # the smallest |delay|
    assert marths.finddelay(np.zeros(5), np.ones(5)) == 0


# ----------------------------------------------------------------------------- the loop against NumPy

def _numpy_loop(data, record, n, controller):
    """BENCHMARK.md sections 1-7 written again in NumPy/SciPy, independently of the C++ blocks (only the noise
    sequence is the core's generator): returns the channels of marths' rows, in SI."""
    fs = marths.FS
    dt = 1.0 / fs
    ag = 0.4 * np.interp(np.arange(n) * dt, record.time, record.acceleration)
    A, B, C = data.A, data.B, data.C
    hA = dt * A
    Phi = sum(np.linalg.matrix_power(hA, j) / math.factorial(j) for j in range(5))
    Gam = dt * sum(np.linalg.matrix_power(hA, j) / math.factorial(j + 1) for j in range(4)) @ B
    K, M, infl = data.K, data.M, data.influence
    wi, wj = 13.493, 165.125
    al, be = np.linalg.solve(0.5 * np.array([[1 / wi, wi], [1 / wj, wj]]), [0.05, 0.05])
    CR = al * M + be * K
    inch = 0.0254
    E = 200e9
    Lb, Lc, Ic, Ib, Ac, Ab, rho = 0.762, 0.635, 2.52 * inch**4, 0.6132 * inch**4, 1.67 * inch**2, 0.947 * inch**2, 785e3
    mb, mc = rho * Ab * Lb, rho * Ac * Lc
    MP = np.diag([mb + mc] + [mb / 2 * Lb**2 / 12 + mc / 2 * Lc**2 / 12] * 2)
    c3, r, bb = 3 * E * Ic / Lc**2, 3 * E * Ic / Lc + 4 * E * Ib / Lb, 2 * E * Ib / Lb
    KP = np.array([[6 * E * Ic / Lc**3, -c3, -c3], [-c3, r, -bb], [-c3, -bb, r]])
    lam = np.sort(np.real(np.linalg.eigvals(np.linalg.solve(MP, KP))))
    w1, w2 = math.sqrt(lam[0]), math.sqrt(lam[2])
    aP, bP = np.linalg.solve(0.5 * np.array([[1 / w1, w1], [1 / w2, w2]]), [0.05, 0.05])
    CP = aP * MP + bP * KP
    idx = [26, 28, 20]
    KN, CN, MN = K.copy(), CR.copy(), M.copy()
    KN[np.ix_(idx, idx)] -= KP
    CN[np.ix_(idx, idx)] -= CP
    MN[26, 26] -= MP[0, 0]
    a0, a1, a2, a3, a4, a5, a6, a7 = 4 / dt**2, 2 / dt, 4 / dt, 1.0, 1.0, 0.0, dt / 2, dt / 2

    class Newmark:
        def __init__(self, K, C, M):
            self.K, self.C, self.M = K, C, M
            self.Ki = np.linalg.inv(K + a0 * M + a1 * C)
            self.U, self.V, self.A = np.zeros(29), np.zeros(29), np.zeros(29)

        def step(self, a, F):
            Rb = self.M @ (a0 * self.U + a2 * self.V + a3 * self.A) + self.C @ (a1 * self.U + a4 * self.V + a5 * self.A)
            Rb = Rb - F - self.M @ infl * a
            U1 = self.Ki @ Rb
            A1 = a0 * (U1 - self.U) - a2 * self.V - a3 * self.A
            self.V = self.V + a7 * A1 + a6 * self.A
            self.U, self.A = U1, A1
            return U1

    ref, num = Newmark(K, CR, M), Newmark(KN, CN, MN)
    # the physical frame (physicalFrame_feedbackForce.m)
    Lc, Ic, Ib, Ab, rho = 0.64135, 0.7 * 2.52 * inch**4, 4.21372e-7, 7.56e-4, 7850.0

    def kloc(inertia, L):
        k = np.zeros((6, 6))
        ei = E * inertia
        a_, b_, c_, d_ = 12 * ei / L**3, 6 * ei / L**2, 4 * ei / L, 2 * ei / L
        k[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = [[a_, b_, -a_, b_], [b_, c_, -b_, d_], [-a_, -b_, a_, -b_],
                                                   [b_, d_, -b_, c_]]
        return k

    def rot(th):
        c, s = math.cos(th), math.sin(th)
        T = np.zeros((6, 6))
        for o in (0, 3):
            T[o:o + 2, o:o + 2] = [[c, s], [-s, c]]
            T[o + 2, o + 2] = 1
        return T

    Kc = rot(math.pi / 2).T @ kloc(Ic, Lc) @ rot(math.pi / 2)
    Kb = kloc(Ib, Lb)
    c_, b_ = (lambda i, j: Kc[i - 1, j - 1]), (lambda i, j: Kb[i - 1, j - 1])
    K5 = np.array([[c_(4, 4) * 2, c_(4, 6), c_(4, 6), c_(4, 3), c_(4, 3)],
                   [c_(6, 4), c_(6, 6) + b_(6, 6), b_(6, 3), 0, c_(6, 3)],
                   [c_(6, 4), b_(3, 6), c_(6, 6) + b_(3, 3), c_(6, 3), 0],
                   [c_(3, 4), 0, c_(3, 6), c_(3, 3), 0], [c_(3, 4), c_(3, 6), 0, 0, c_(3, 3)]])
    mb, mc = rho * Ab * Lb, rho * Ac * Lc
    M5 = 1.1 * np.diag([(mb + 2 * mc) / 2] + [(mb / 2 * Lb**2 + mc / 2 * Lc**2) / 3] * 2 + [mc / 2 * Lc**2 / 3] * 2)
    w2_, fi = np.linalg.eig(np.linalg.solve(M5, K5))
    o = np.argsort(np.sqrt(w2_.real))
    fr, fi = np.round(100 * np.sqrt(w2_.real[o])) / 100, fi[:, o].real
    C5 = sum(M5 @ (2 * 0.05 * fr[i] * np.outer(fi[:, i], fi[:, i]) / (fi[:, i] @ M5 @ fi[:, i])) @ M5 for i in range(5))
    G = -np.linalg.solve(K5[2:, 2:], K5[2:, :2])
    d = math.sqrt(0.2667**2 + 0.127**2)
    al1, al2 = -25.4633 * math.pi / 180, 25.4633 * math.pi / 180
    sigma = math.sqrt(1.5e-7 / dt)  # mm
    noise = _core.GaussianSequence(123, _core.NoiseGenerator.SimulinkRandomNumber)
    b, a = signal.butter(4, 20 / (fs / 2))
    theta = [t.copy() for t in data.theta0]
    P = [p.copy() for p in data.P0] if controller == "rodeac" else None
    zx, zu = [signal.lfilter_zi(b, a) * 0 for _ in range(2)], [signal.lfilter_zi(b, a) * 0 for _ in range(2)]
    X, T = [np.zeros(4), np.zeros(4)], [np.zeros(4), np.zeros(4)]
    x = np.zeros(A.shape[0])
    q_prev, d1_prev = np.zeros(5), np.zeros(5)
    out = {k: np.zeros(n) for k in ("target_1", "target_2", "measured_1", "measured_2", "command_1", "command_2",
                                     "x_estimate", "theta_estimate", "x_numerical", "theta_numerical", "x_reference",
                                     "theta_reference", "x_story3_numerical", "voltage_2")}
    for k in range(n):
        Ur = ref.step(ag[k], np.zeros(29))
        xm = C @ x + sigma * noise.next()  # mm, one draw on both channels
        x1, x2 = xm / 1000
        s = (x1 - x2) / (2 * d * math.sin(al2))
        the, xe = math.asin(s), x1 - d * (math.cos(al1 + s) - math.cos(al1))
        q = np.concatenate([[xe, the], G @ [xe, the]])
        d1 = np.zeros(5) if k == 0 else (q - q_prev) / dt
        d2 = np.zeros(5) if k == 0 else (d1 - d1_prev) / dt
        q_prev, d1_prev = q, d1
        f = K5 @ q + C5 @ d1 + M5 @ d2
        F = np.zeros(29)
        F[26], F[20], F[28] = f[0], -f[1], -f[2]
        Un = num.step(ag[k], F)
        xN, thN = Un[26], -Un[20]
        tgt = 1000 * np.array([xN + d * (math.cos(thN + al1) - math.cos(al1)),
                               xN + d * (math.cos(thN + al2) - math.cos(al2))])
        u = np.zeros(2)
        for i in range(2):
            xf, zx[i] = signal.lfilter(b, a, [xm[i]], zi=zx[i])
            X[i] = np.concatenate([xf, X[i][:3]])
            T[i] = np.concatenate([[tgt[i]], T[i][:3]])
            if controller == "none":
                u[i] = tgt[i]
                continue
            if P is None:
                u[i] = theta[i] @ T[i]
                continue
            phi = P[i] @ X[i] / (1 + X[i] @ P[i] @ X[i])
            s2 = zu[i][0]
            u[i] = (theta[i] @ T[i] + (phi @ T[i]) * (s2 - theta[i] @ X[i])) / (1 - b[0] * (phi @ T[i]))
            uf, zu[i] = signal.lfilter(b, a, [u[i]], zi=zu[i])
            theta[i] = theta[i] + phi * (uf[0] - theta[i] @ X[i])
            P[i] = P[i] - np.outer(phi, X[i] @ P[i])
        row = {"target_1": tgt[0], "target_2": tgt[1], "measured_1": xm[0], "measured_2": xm[1], "command_1": u[0],
               "command_2": u[1], "x_estimate": 1000 * xe, "theta_estimate": the / 1000 * 1000,
               "x_numerical": 1000 * xN, "theta_numerical": thN, "x_reference": 1000 * Ur[26],
               "theta_reference": -Ur[20], "x_story3_numerical": Un[12],
               "voltage_2": u[1] / (1.055 * 7.3907) + 0.0059 / 7.3907}
        for key, v in row.items():
            scale = 1e-3 if key in ("target_1", "target_2", "measured_1", "measured_2", "command_1", "command_2",
                                    "x_estimate", "x_numerical", "x_reference") else 1.0
            out[key][k] = v * scale
        x = Phi @ x + Gam @ u
    return out


@pytest.mark.parametrize("controller", ["rodeac", "rodeac_fixed", "none"])
def test_the_loop_equals_a_numpy_reimplementation_of_the_spec(data, record, controller):
    n = 1500
    short = Record(record.name, record.time, record.acceleration, source=record.source)
    ref = _numpy_loop(data, short, n, controller)
    st = marths.structures(data)
    loop = R.MarthsLoop(marths.nominal_plant(data), marths.make_controller(controller, data), st, marths.loop_config())
    out, summary = loop.run(_core.GroundMotion(record.time, record.acceleration, 0.4), n)
    assert summary.ok() and summary.rows == n
    for key, v in ref.items():
        scale = np.max(np.abs(v)) + 1e-30
        assert np.max(np.abs(out[key] - v)) <= 1e-8 * scale, key


# ----------------------------------------------------------------------------- the seams from Python

class PassThroughPy:
    """A user's multi-actuator controller: the command is the target."""

    def __init__(self):
        self.resets = 0

    def reset(self):
        self.resets += 1

    def command(self, desired, measured):
        return desired


class Rates(marths.MultiTrackingController):
    """A subclass that asks for the target rates."""

    def __init__(self):
        super().__init__(2)
        self.seen = []

    def reset(self):
        self.seen.clear()

    def command(self, desired, measured, desired_velocity=None, desired_acceleration=None):
        self.seen.append((desired_velocity.copy(), desired_acceleration.copy()))
        return np.asarray(desired) * 1.0


def test_python_controllers_run_in_the_loop(data, record):
    base = marths.run_trial(data, record, "none", keep_signals=True)
    user = PassThroughPy()
    mine = marths.run_trial(data, record, user, keep_signals=True)
    assert user.resets >= 1  # the loop resets it (at construction and before the run)
    for name in ("measured_1", "command_2", "x_numerical", "voltage_1"):
        np.testing.assert_array_equal(mine.response.channels[name], base.response.channels[name])
    sub = Rates()
    marths.run_trial(data, record, sub)
    assert len(sub.seen) == marths.samples(record)
    assert np.max(np.abs([v for v, _ in sub.seen])) > 0  # the numerical interface's rates through the coupler


class Broken:
    def reset(self):
        pass

    def command(self, desired, measured):
        if desired[0] != 0.0:
            raise ZeroDivisionError("bad sample")
        return desired


class WrongLength(PassThroughPy):
    def command(self, desired, measured):
        return [0.0]


def test_a_python_controllers_error_names_the_sample(data, record):
    with pytest.raises(RuntimeError, match=r"Broken.command\(\) raised at sample \d+ \(t = .* s\): "
                                           r"ZeroDivisionError: bad sample"):
        marths.run_trial(data, record, Broken())
    with pytest.raises(RuntimeError, match=r"expected 2 floats, the actuator commands \[m\]"):
        marths.run_trial(data, record, WrongLength())
    with pytest.raises(TypeError, match=r"lacks reset\(\), command\(\)"):
        _core.PythonMultiController(object())


class PyPlant:
    """A plant written in Python: the identified plant, stepped through the protocol."""

    def __init__(self, data, fail_at=None):
        self.inner = marths.nominal_plant(data)
        self.actuators, self.dt, self.k, self.fail_at = 2, marths.DT, 0, fail_at

    def reset(self):
        self.inner.reset()
        self.k = 0

    def displacements(self):
        return self.inner.displacements()

    def step(self, u):
        self.k += 1
        if self.fail_at is not None and self.k == self.fail_at:
            raise RuntimeError("valve stuck")
        self.inner.step(u)


def test_a_python_plant_runs_in_the_loop(data, record):
    a = marths.run_trial(data, record, "rodeac", keep_signals=True)
    b = marths.run_trial(data, record, "rodeac", plant=PyPlant(data), keep_signals=True)
    np.testing.assert_array_equal(a.response.channels["measured_2"], b.response.channels["measured_2"])
    with pytest.raises(RuntimeError, match=r"plant failed at t = 0.04785\d* s: RuntimeError: valve stuck"):
        marths.run_trial(data, record, "rodeac", plant=PyPlant(data, fail_at=50))


def test_decentralized_channels_can_be_python_controllers(data, record):
    class Half:
        def reset(self):
            pass

        def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
            return desired

    chans = [_core.rths.PythonController(Half()), _core.rths.PythonController(Half())]
    dec = R.DecentralizedController(chans, marths.DT)
    a = marths.run_trial(data, record, dec, keep_signals=True)
    b = marths.run_trial(data, record, "none", keep_signals=True)
    np.testing.assert_array_equal(a.response.channels["command_1"], b.response.channels["command_1"])


def test_perturbed_trials_are_seeded_and_summarised(folder):
    a = marths.run_benchmark(folder, "kobe", "rodeac", perturbed=2, seed=5, workers=1, progress=False)
    b = marths.run_benchmark(folder, "kobe", "rodeac", perturbed=2, seed=5, workers=1, progress=False)
    pa, pb = a["results"]["runs"]["perturbed"], b["results"]["runs"]["perturbed"]
    assert pa["J_mean"] == pb["J_mean"] and pa["runs"] == 2 and pa["ran_to_end"] == 2
    t1, t2 = pa["trials"]
    assert t1["J"]["J2"] != t2["J"]["J2"]
    assert pa["J_mean"]["J8"][3] == pytest.approx((t1["J"]["J8"][3] + t2["J"]["J8"][3]) / 2)
    assert pa["J_std"]["J2"][0] == pytest.approx(abs(t1["J"]["J2"][0] - t2["J"]["J2"][0]) / math.sqrt(2))
    assert a["results"]["runs"]["nominal"]["noise_seed"] == 5


# ----------------------------------------------------------------------------- the reference row

def _reference_row(text: str) -> dict[tuple[str, str], tuple[float, float]]:
    section = text[text.index("## 10."):]
    rows = re.findall(r"^\| (J\d+) \| (\w+) \| ([-\d.]+) \| ([\d.]+) \|$", section, flags=re.M)
    return {(j, c): (float(v), float(tol)) for j, c, v, tol in rows}


def test_the_nominal_el_centro_rodeac_run_lands_on_the_reference_row():
    from shared_data import shared_path

    folder = shared_path("marths-data")
    row = _reference_row((folder / "BENCHMARK.md").read_text(encoding="utf-8"))
    assert len(row) == 24
    trial = marths.run_trial(marths.load_data(folder), marths.load_record(folder, "elcentro"), "rodeac")
    assert trial.ok
    for j, comps in marths.J_COMPONENTS.items():
        for c, got in zip(comps, trial.J[j]):
            want, tol = row[(j, c)]
            assert abs(got - want) <= tol, f"{j} {c}: {got:.4f} vs {want:.4f} +- {tol}"
    volts = re.search(r"max \|v1\| = ([\d.]+) V, max \|v2\| = ([\d.]+) V", (folder / "BENCHMARK.md").read_text())
    assert trial.peak_voltage[0] == pytest.approx(float(volts.group(1)), abs=0.01)
    assert trial.peak_voltage[1] == pytest.approx(float(volts.group(2)), abs=0.01)
    assert trial.realizable
