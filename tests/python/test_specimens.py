"""Specimens in parallel with the structure (docs/specimens.md): the Bouc-Wen
hysteretic element against its closed-form n = 1 branches, loop area and
small-amplitude stiffness; the MR damper (Spencer, Dyke, Sain, Carlson 1997)
against an independent transcription of the paper's Eqs and its Bingham limit;
rig files, the state table and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.rig import load_rig, rig_from_dict, save_rig

DT = 1.0 / 1024.0


def _bouc_wen_rig(**values) -> sh.Rig:
    r = sh.zhao2003()
    r.effects.bouc_wen_hysteresis = True
    for k, v in values.items():
        setattr(r, k, v)
    return r


def _run_states(rig: sh.Rig, command: np.ndarray, mode=_core.ControlMode.Displacement, rtol: float = 1e-9):
    """Steps a plant by hand and returns the state after every sample (rows) and the outputs."""
    opts = _core.SolverOptions()
    opts.rtol = rtol
    plant = _core.Plant(rig, mode, DT, opts)
    ys = np.empty((len(command), plant.dynamics.num_states))
    for k, u in enumerate(command):
        st, _ = plant.step(float(u))
        assert st.ok(), st.message
        ys[k] = plant.state
    return plant, ys


# ---- closed form of the n = 1 Bouc-Wen law along a monotone displacement path ------------------
# z' = A v - beta |v| z - gamma v |z|.  For v > 0: dz/dx = A - c z with c = beta + gamma (z >= 0)
# or beta - gamma (z < 0): exponential (or linear when c = 0) between the crossings of z = 0.

def _segment(x, x0, z0, A, c):
    if c == 0.0:
        return z0 + A * (x - x0)
    return A / c + (z0 - A / c) * np.exp(-c * (x - x0))


def _z_up(x, x0, z0, A, beta, gamma):
    """z at x >= x0 loading (v > 0) from (x0, z0)."""
    x = np.asarray(x, dtype=float)
    if z0 >= 0.0:
        return _segment(x, x0, z0, A, beta + gamma)
    c = beta - gamma  # z < 0 until it crosses 0 at x_star
    x_star = x0 - z0 / A if c == 0.0 else x0 - math.log(A / (A - c * z0)) / c
    return np.where(x < x_star, _segment(x, x0, z0, A, c), _segment(x, x_star, 0.0, A, beta + gamma))


def _z_branch(x, x0, z0, sign, A, beta, gamma):
    return _z_up(x, x0, z0, A, beta, gamma) if sign > 0 else -_z_up(-np.asarray(x), -x0, -z0, A, beta, gamma)


@pytest.fixture(scope="module")
def bouc_wen_cycles():
    rig = _bouc_wen_rig(bw_beta=60.0, bw_gamma=40.0, bw_A=1.0)
    t = np.arange(1, 3 * 1024 + 1) * DT
    command = 0.02 * np.sin(2 * np.pi * 1.0 * t)
    plant, ys = _run_states(rig, command)
    return rig, plant, ys


def test_bouc_wen_n1_follows_the_closed_form_branches(bouc_wen_cycles):
    """Along every monotone stretch of the simulated displacement, z(x) is the closed-form
    n = 1 branch from the stretch's first sample (rate independence: the path alone decides)."""
    rig, plant, ys = bouc_wen_cycles
    iz = plant.dynamics.layout["bw_z"]
    x, v, z = ys[:, 0], ys[:, 1], ys[:, iz]
    s = np.sign(v)
    changes = np.flatnonzero(s[1:] != s[:-1]) + 1
    edges = [0, *changes, len(v)]
    worst, checked = 0.0, 0
    for a, b in zip(edges[:-1], edges[1:]):
        a, b = a + 1, b - 1  # stay off the samples that straddle a reversal
        if b - a < 20:
            continue
        zc = _z_branch(x[a:b], x[a], z[a], s[a], rig.bw_A, rig.bw_beta, rig.bw_gamma)
        worst = max(worst, float(np.max(np.abs(zc - z[a:b]))))
        checked += b - a
    z_u = rig.bw_A / (rig.bw_beta + rig.bw_gamma)
    assert checked > 2500 and len(changes) >= 5
    assert worst < 1e-8 * z_u, f"worst |z - closed form| = {worst:.3g} m"


def test_bouc_wen_energy_per_cycle_is_the_closed_form_loop_area(bouc_wen_cycles):
    """The work of the hysteretic force over the last full cycle (trapezoid over the samples)
    equals the area between the closed-form branches through the same reversal points."""
    rig, plant, ys = bouc_wen_cycles
    iz = plant.dynamics.layout["bw_z"]
    x, z = ys[:, 0], ys[:, iz]
    last = slice(2 * 1024, 3 * 1024)  # the third cycle (the first shed the virgin curve)
    xs, zs = x[last], z[last]
    i_min, i_max = int(np.argmin(xs)), int(np.argmax(xs))
    x_min, x_max = xs[i_min], xs[i_max]
    A, b, g = rig.bw_A, rig.bw_beta, rig.bw_gamma
    # upper branch from (x_min, z there), lower from where it ends at x_max
    z_at_min = zs[i_min]
    z_at_max = float(_z_branch(x_max, x_min, z_at_min, +1, A, b, g))
    up = lambda xx: float(_z_branch(xx, x_min, z_at_min, +1, A, b, g))  # noqa: E731
    down = lambda xx: float(_z_branch(xx, x_max, z_at_max, -1, A, b, g))  # noqa: E731
    area = rig.bw_k * quad(lambda xx: up(xx) - down(xx), x_min, x_max, epsabs=0, epsrel=1e-12, limit=200)[0]
    # the simulated cycle from the minimum to the next minimum: W = closed integral of F dx
    lo = int(np.argmin(x[1024:2048])) + 1024
    hi = int(np.argmin(x[2048:3072])) + 2048
    F = rig.bw_k * z[lo:hi + 1]
    work = float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(x[lo:hi + 1])))
    assert area > 0.1 * rig.bw_k * (A / (b + g)) * (x_max - x_min)  # a fat loop, not a line
    assert abs(work - area) < 1e-4 * area, f"loop work {work:.6g} J vs closed-form area {area:.6g} J"


def test_bouc_wen_small_amplitude_stiffness():
    """At z = 0 the element is a spring bw_k A: the free structure's linearised natural
    frequency is sqrt((k + bw_k A) / m) (no damping, no friction), and a 10 um cycle
    gives a secant stiffness F/x within (beta + gamma) X of bw_k A."""
    r = _bouc_wen_rig(bw_A=0.8, bw_k=500e3)
    r.c = 0.0
    r.effects.coulomb_friction = False
    sys = sh.linearize(r, mode="free", outputs=("displacement",))
    wn = np.sort(np.abs(np.imag(sys.poles())))[-1]
    expected = math.sqrt((r.k + r.bw_k * r.bw_A) / r.m)
    assert abs(wn - expected) < 1e-9 * expected
    # the specimen_force output of the linearisation (z' = A v at rest: z is A x plus a constant, so
    # the DC gain is undefined): at w it carries bw_k A / (k + bw_k A - m w^2) of the applied force
    w = 3.0
    H = complex(np.squeeze(sh.linearize(r, mode="free", outputs=("specimen_force",))(1j * w)))
    assert H == pytest.approx(r.bw_k * r.bw_A / (r.k + r.bw_k * r.bw_A - r.m * w ** 2), rel=1e-9)
    X = 1e-5
    t = np.arange(1, 1025) * DT
    plant, ys = _run_states(_bouc_wen_rig(bw_A=0.8, bw_k=500e3), X * np.sin(2 * np.pi * t))
    x, z = ys[:, 0], ys[:, plant.dynamics.layout["bw_z"]]
    k_secant = np.polyfit(x, r.bw_k * z, 1)[0]
    bound = (r.bw_beta + r.bw_gamma) * X  # relative softening of the n = 1 law at amplitude X
    assert abs(k_secant / (r.bw_k * r.bw_A) - 1.0) < bound


# ---- MR damper -------------------------------------------------------------------------------

SPENCER_CM = dict(  # Spencer et al. (1997), Table 1, in the paper's units (N, cm, s, V)
    c0a=21.0, c0b=3.50, k0=46.9, c1a=283.0, c1b=2.95, k1=5.00, x0=14.3, alpha_a=140.0, alpha_b=695.0,
    gamma=363.0, beta=363.0, A=301.0, n=2.0)


def _spencer_force(t_end: float, X_cm: float, f: float, u: float, rtol=1e-10):
    """An independent transcription of the model of Spencer et al. (1997) in cm, N, s under
    x = X sin(2 pi f t) (the paper's test signal), integrated by SciPy; returns (t, F [N])."""
    p = SPENCER_CM
    alpha, c0, c1 = p["alpha_a"] + p["alpha_b"] * u, p["c0a"] + p["c0b"] * u, p["c1a"] + p["c1b"] * u
    w = 2 * np.pi * f

    def ydot_of(t, s):
        x, xd = X_cm * np.sin(w * t), X_cm * w * np.cos(w * t)
        y, z = s
        return (alpha * z + c0 * xd + p["k0"] * (x - y)) / (c0 + c1), x, xd

    def rhs(t, s):
        yd, x, xd = ydot_of(t, s)
        z = s[1]
        r = xd - yd
        zd = -p["gamma"] * abs(r) * z * abs(z) ** (p["n"] - 1) - p["beta"] * r * abs(z) ** p["n"] + p["A"] * r
        return [yd, zd]

    t = np.arange(0, t_end, 1e-3)
    sol = solve_ivp(rhs, (0, t_end), [0.0, 0.0], method="Radau", t_eval=t, rtol=rtol, atol=1e-12)
    F = np.array([c1 * ydot_of(ti, si)[0] + p["k1"] * (X_cm * np.sin(w * ti) - p["x0"])
                  for ti, si in zip(sol.t, sol.y.T)])
    return sol.t, F


def test_mr_damper_defaults_are_spencer_table_1_in_si():
    r = sh.zhao2003()
    p = SPENCER_CM
    pairs = {"mr_c0_a": p["c0a"] * 1e2, "mr_c0_b": p["c0b"] * 1e2, "mr_k0": p["k0"] * 1e2, "mr_c1_a": p["c1a"] * 1e2,
             "mr_c1_b": p["c1b"] * 1e2, "mr_k1": p["k1"] * 1e2, "mr_x0": p["x0"] * 1e-2,
             "mr_alpha_a": p["alpha_a"] * 1e2, "mr_alpha_b": p["alpha_b"] * 1e2, "mr_gamma": p["gamma"] * 1e4,
             "mr_beta": p["beta"] * 1e4, "mr_A": p["A"], "mr_n": p["n"]}
    for key, si in pairs.items():
        assert getattr(r, key) == pytest.approx(si, rel=1e-12), key


@pytest.mark.parametrize("volts", [0.0, 0.75, 1.5, 2.25])
def test_mr_damper_matches_an_independent_transcription_of_spencer_1997(volts):
    """The core's MR damper (SI, its rhs integrated by SciPy under the prescribed motion of the
    paper's test: 2.5 Hz, 1.5 cm) against the paper's Eqs transcribed anew in N, cm, s."""
    rig = sh.zhao2003()
    rig.effects.mr_damper = True
    rig.mr_voltage = volts
    dyn = _core.Dynamics(rig, _core.ControlMode.Free)
    iy = dyn.layout["mr_y"]
    X, f, T = 0.015, 2.5, 0.8
    w = 2 * np.pi * f
    base = np.zeros(dyn.num_states)

    def state(t, s):
        y = base.copy()
        y[0], y[1] = X * np.sin(w * t), X * w * np.cos(w * t)
        y[iy], y[iy + 1] = s
        return y

    def rhs(t, s):
        return dyn.rhs(state(t, s), 0.0)[iy:iy + 2]

    t = np.arange(0, T, 1e-3)
    sol = solve_ivp(rhs, (0, T), [0.0, 0.0], method="Radau", t_eval=t, rtol=1e-10, atol=1e-14,
                    jac=lambda t, s: dyn.jacobian(state(t, s), 0.0)[iy:iy + 2, iy:iy + 2])
    F_core = np.array([dyn.specimen_force(state(ti, si)) for ti, si in zip(sol.t, sol.y.T)])
    _, F_ref = _spencer_force(T, 1.5, f, volts)
    peak = np.max(np.abs(F_ref))
    assert np.max(np.abs(F_core - F_ref)) < 1e-8 * peak


def test_mr_damper_bingham_limit_is_coulomb_plus_viscous():
    """k0 = k1 = 0 and c1 >> c0 (y' -> 0) with a fast-saturating n = 1 law (z -> z_u sgn v,
    z_u = A / (beta + gamma)): the damper force tends to alpha z_u sgn(v) + c0 v (the Bingham
    model, Coulomb plus viscous), checked in a closed loop away from reversals."""
    r = sh.zhao2003()
    r.effects.mr_damper = True
    r.mr_k0 = r.mr_k1 = r.mr_x0 = 0.0
    r.mr_c1_a, r.mr_c1_b = 1e8, 0.0
    r.mr_n, r.mr_A, r.mr_beta, r.mr_gamma = 1.0, 1000.0, 5e4, 5e4
    r.mr_voltage = 2.0
    t = np.arange(1, 2049) * DT
    plant, ys = _run_states(r, 0.02 * np.sin(2 * np.pi * 1.0 * t), rtol=1e-8)
    dyn = plant.dynamics
    alpha, c0 = r.mr_alpha_a + r.mr_alpha_b * r.mr_voltage, r.mr_c0_a + r.mr_c0_b * r.mr_voltage
    Fc = alpha * r.mr_A / (r.mr_beta + r.mr_gamma)
    F = np.array([dyn.specimen_force(y) for y in ys])
    x, v = ys[:, 0], ys[:, 1]
    # away from reversals: at least 1 mm of travel since the last extremum of x
    ext = np.flatnonzero(np.sign(v[1:]) != np.sign(v[:-1])) + 1
    last_ext = np.maximum.accumulate(np.where(np.isin(np.arange(len(x)), ext), np.arange(len(x)), 0))
    far = np.abs(x - x[last_ext]) > 1e-3
    bingham = Fc * np.sign(v) + c0 * v
    err = np.abs(F - bingham)[far]
    assert far.sum() > 1500
    assert np.max(err) < 2e-4 * (Fc + c0 * np.max(np.abs(v)))


def test_mr_damper_at_rest_holds_the_accumulator_force():
    """At rest y = x, z = 0: the damper pushes k1 (x - x0); the operating point carries it."""
    r = sh.zhao2003()
    r.effects.mr_damper = True
    dyn = _core.Dynamics(r, _core.ControlMode.Free)
    y0, u0 = dyn.operating_point(0.01)
    assert dyn.specimen_force(y0) == pytest.approx(r.mr_k1 * (0.01 - r.mr_x0), rel=1e-14)
    assert u0 == pytest.approx(r.k * 0.01 + r.mr_k1 * (0.01 - r.mr_x0), rel=1e-14)
    assert np.max(np.abs(dyn.rhs(y0, u0))) < 1e-9


# ---- Python surface ---------------------------------------------------------------------------

def test_states_table_and_simulate_with_every_element(tmp_path):
    r = sh.zhao2003()
    r.effects.bouc_wen_hysteresis = r.effects.mr_damper = r.effects.loop_delay = True
    r.loop_delay_order = 4
    dyn = _core.Dynamics(r, _core.ControlMode.Displacement)
    names = [s[0] for s in dyn.states]
    assert names == ["x", "v", "p", "x_v", "x_v_dot", "z", "bw_z", "mr_y", "mr_z",
                     "delay_1", "delay_2", "delay_3", "delay_4"]
    # each element's first state by its switch (-1: off, as every other element), and each
    # appended state by its name
    on = {k: i for k, i in dyn.layout.items() if i >= 0}
    assert on == dict(num_states=13, bouc_wen_hysteresis=6, mr_damper=7, loop_delay=9, bw_z=6, mr_y=7,
                      mr_z=8, delay_1=9, delay_2=10, delay_3=11, delay_4=12)
    assert set(dyn.layout.values()) - set(on.values()) <= {-1}
    path = save_rig(r, tmp_path / "spec.toml")
    text = path.read_text()
    assert "[specimen]" in text and "[delays]" in text
    back = load_rig(path)
    assert back == r
    res = sh.simulate(back, "displacement", 0.01 * np.sin(2 * np.pi * 2 * np.arange(1024) * DT), dt=DT)
    assert np.all(np.isfinite(res.force)) and res.work.status.ok
    with pytest.raises(ValueError, match=r"invalid y \(length\) = 6: this plant has 13 states"):
        dyn.rhs(np.zeros(6), 0.0)
    # the specimen_force channel: the Bouc-Wen and MR damper forces at every sample, in every loop
    plant = _core.Plant(back, _core.ControlMode.Displacement, DT)
    for k in range(200):
        _, out = plant.step(0.01 * math.sin(2 * math.pi * 2 * k * DT))
        y = plant.state
        expected = back.bw_k * y[6] + (back.mr_c1_a + back.mr_c1_b * back.mr_voltage) * dyn.rhs(y, 0.0)[7] \
            + back.mr_k1 * (y[0] - back.mr_x0)
        assert out.specimen_force == pytest.approx(expected, rel=1e-12, abs=1e-9)
    assert np.max(np.abs(res.specimen_force)) > 100.0
    eft = sh.run_eft(back, ground_acceleration=np.sin(2 * np.pi * 2 * np.arange(400) * DT), dt=DT)
    assert np.max(np.abs(eft.specimen_force)) > 0.0


@pytest.mark.parametrize("section,key,value,match", [
    ("specimen", "bw_n", 0.5, "invalid bw_n = 0.5"),
    ("specimen", "mr_n", 0.9, "invalid mr_n = 0.9"),
    ("specimen", "bw_gamma", -3.0, "invalid bw_gamma = -3"),
    ("specimen", "mr_alpha_a", -1.0, "invalid mr_alpha_a = -1"),
    ("specimen", "mr_c1_a", 0.0, "invalid mr_c1_a = 0"),
    ("delays", "command_delay", -0.001, "invalid command_delay = -0.001"),
    ("delays", "loop_delay_order", 3.5, "invalid loop_delay_order = 3.5"),
    ("delays", "loop_delay_order", 9.0, "invalid loop_delay_order = 9"),
])
def test_bad_specimen_and_delay_values_name_the_field(section, key, value, match):
    with pytest.raises(ValueError, match=match):
        rig_from_dict({section: {key: value}})


def test_non_finite_and_unknown_keys():
    with pytest.raises(ValueError, match="invalid specimen.bw_k = nan: must be finite"):
        rig_from_dict({"specimen": {"bw_k": float("nan")}})
    with pytest.raises(ValueError, match="unknown rig key specimen.bw_q"):
        rig_from_dict({"specimen": {"bw_q": 1.0}})
    r = sh.zhao2003()
    r.mr_voltage = float("inf")
    with pytest.raises(ValueError, match="invalid mr_voltage = inf"):
        r.validate()
