"""The OpenSeesPy numerical substructure (rths.OpenSeesSubstructure) against our
linear M, C, K substructure: same matrices, same scheme (central difference),
alone under the same inputs and inside the RTHS loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from servohydraulics import rths

pytest.importorskip("openseespy.opensees")
R = rths.core


def _matrices():
    """The benchmark's case-1 structure (embedded), partitioned at the first floor, with
    Rayleigh damping C = a M + b K (what OpenSees' rayleigh() builds) of 5 % at modes 1 and 3."""
    case = rths.embedded_case(1)
    sp = rths.nominal_plant().specimen()
    M, K = case.M.copy(), case.K.copy()
    M[0, 0] -= sp.m
    K[0, 0] -= sp.k
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    a, b = np.linalg.solve([[1 / (2 * w[0]), w[0] / 2], [1 / (2 * w[2]), w[2] / 2]], [0.05, 0.05])
    return case, M, K, a, b


def _frame(M, K, a, b, yielding=None):
    return rths.spring_model(M, K, rayleigh=(a, b), yielding=yielding)



def _step_both(ours, osp, n: int, seed: int) -> tuple[float, float]:
    """Steps our substructure and the OpenSees one n samples with the same rough ground
    motion [m/s^2] and interface force [N]: (worst difference, peak) of the displacements [m]."""
    rng = np.random.default_rng(seed)
    ag = np.cumsum(rng.standard_normal(n + 1)) * 0.05
    f = np.cumsum(rng.standard_normal(n + 1)) * 20.0
    worst, peak = 0.0, 0.0
    for k in range(n):
        ours.step(ag[k], 0.5 * (ag[k] + ag[k + 1]), ag[k + 1], f[k])
        osp.step(ag[k], 0.5 * (ag[k] + ag[k + 1]), ag[k + 1], f[k])
        x = np.asarray(ours.displacement)
        worst = max(worst, float(np.max(np.abs(np.asarray(osp.displacements()) - x))))
        peak = max(peak, float(np.max(np.abs(x))))
    return worst, peak

def test_linear_opensees_model_equals_our_substructure_step_by_step():
    case, M, K, a, b = _matrices()
    g = np.diag(case.M).copy()
    ours = R.LinearSubstructure(R.LinearSubstructureModel(M, a * M + b * K, K, g, np.array([1.0, 0, 0])), rths.DT,
                                R.SubstructureScheme.CentralDifference)
    osp = rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1), (2, 1), (3, 1)], ground=g, interface=0)
    worst, peak = _step_both(ours, osp, 4096, seed=4)
    print(f"OpenSees vs ours, central difference, 1 s at 4096 Hz: worst {worst:.3g} m of peak {peak:.3g} m")
    assert peak > 1e-4 and worst <= 1e-9 * peak


def test_opensees_substructure_in_the_rths_loop():
    case, M, K, a, b = _matrices()
    rec = rths.synthetic_record(duration=3.0)
    g = np.diag(case.M).copy()
    lin = R.LinearSubstructure(R.LinearSubstructureModel(M, a * M + b * K, K, g, np.array([1.0, 0, 0])), rths.DT,
                               R.SubstructureScheme.CentralDifference)
    osp = rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1), (2, 1), (3, 1)], ground=g)
    t1 = rths.run_trial(case, rec, "sample", seed=2, numerical=lin, keep_signals=True)
    t2 = rths.run_trial(case, rec, "sample", seed=2, numerical=osp, keep_signals=True)
    assert t1.ok and t2.ok
    d = np.max(np.abs(t2.signals["numerical"] - t1.signals["numerical"]))
    assert d <= 1e-9 * np.max(np.abs(t1.signals["numerical"]))
    np.testing.assert_allclose(t2.J, t1.J, atol=0.011)  # J rounded to 0.01: equal up to one rounding step


def test_opensees_failure_is_an_error_with_the_time():
    case, M, K, a, b = _matrices()

    class Failing(rths.OpenSeesSubstructure):
        def step(self, *args):
            if self.ops.getTime() > 0.01:
                raise RuntimeError("element 7 failed")
            super().step(*args)

    osp = Failing(_frame(M, K, a, b), dofs=[(1, 1), (2, 1), (3, 1)], ground=np.diag(case.M))
    with pytest.raises(RuntimeError, match=r"numerical substructure failed at t = 0\.01.*element 7 failed"):
        rths.run_trial(case, rths.synthetic_record(duration=1.0), "sample", numerical=osp)


def test_bad_input_names_the_field():
    case, M, K, a, b = _matrices()
    with pytest.raises(ValueError, match="interface"):
        rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1)], ground=[1.0], interface=3)
    with pytest.raises(ValueError, match="ground"):
        rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1), (2, 1)], ground=[1.0])
    with pytest.raises(ValueError, match="scheme"):
        rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1)], ground=[1.0], scheme="rk4")
    assert math.isfinite(rths.OpenSeesSubstructure(_frame(M, K, a, b), dofs=[(1, 1)], ground=[1.0]).h)


def _shear_building():
    """rths.shear_building (6, 5, 4 MN/m storeys, 1000 kg floors, 5 % Rayleigh) and its numerical
    part (M, K) without the specimen, with its Rayleigh coefficients (a, b)."""
    case = rths.shear_building()
    Kr, Cr, Mr = case.K, case.C, case.M
    a, b = np.linalg.lstsq(np.c_[Mr.ravel(), Kr.ravel()], Cr.ravel(), rcond=None)[0]
    np.testing.assert_allclose(a * Mr + b * Kr, Cr, rtol=1e-12, atol=1e-9)
    sp = rths.nominal_plant().specimen()
    M, K = Mr.copy(), Kr.copy()
    M[0, 0] -= sp.m
    K[0, 0] -= sp.k
    w = np.sqrt(np.linalg.eigvals(np.linalg.solve(Mr, Kr)).real)
    zeta = a / (2 * w) + b * w / 2
    assert zeta.min() > 0.03 and max(zeta[np.argmin(w)], zeta[np.argmax(w)]) == pytest.approx(0.05)
    return case, M, K, a, b


def test_yielding_storey_that_never_yields_is_the_linear_model_and_one_that_yields_drifts():
    """Steel01 of the same initial stiffness on the first storey: a yield force never reached
    gives the linear response (to round-off); a low one leaves a residual drift."""
    case, M, K, a, b = _shear_building()
    rec = rths.synthetic_record(duration=4.0, pga=4.0)
    g, dofs = np.diag(case.M).copy(), [(1, 1), (2, 1), (3, 1)]

    def run(yielding):
        osp = rths.OpenSeesSubstructure(_frame(M, K, a, b, yielding), dofs=dofs, ground=g)
        return rths.run_trial(case, rec, "sample", seed=2, numerical=osp, keep_signals=True)

    lin = run(None)
    stiff = run({(0, 1): (1e9, 0.02)})
    np.testing.assert_allclose(stiff.signals["numerical"], lin.signals["numerical"], rtol=0,
                               atol=1e-9 * np.max(np.abs(lin.signals["numerical"])))
    x_lin = lin.signals["numerical"][:, 0]
    peak = np.max(np.abs(x_lin))
    fy = 0.3 * K[0].sum() * peak  # the first storey (less the specimen) yields at 30 % of the linear peak
    soft = run({(0, 1): (fy, 0.02)})
    x1 = soft.signals["numerical"][:, 0]
    tail = slice(-4096, None)  # the last second of the 5 s of free vibration: the mean is the residual drift
    print(f"peak {peak:.3g} m; residual drift: linear {np.mean(x_lin[tail]):.3g} m, yielding {np.mean(x1[tail]):.3g} m")
    assert soft.ok and np.max(np.abs(x1)) < 10 * peak
    assert abs(np.mean(x1[tail])) > 0.02 * peak  # 0.05 peak here
    assert abs(np.mean(x_lin[tail])) < 1e-3 * peak  # 4e-6 peak here


def test_example_06_runs(monkeypatch, capsys):
    """examples/06_rths_opensees.py (the docs' nonlinear example) on its synthetic ground motion."""
    import runpy
    import sys
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "examples" / "06_rths_opensees.py"
    monkeypatch.setattr(sys, "argv", [str(path)])
    runpy.run_path(str(path), run_name="__main__")
    rows = {}
    for line in capsys.readouterr().out.splitlines():
        name, _, rest = line.partition(": ")
        if name in ("linear", "yielding"):
            rows[name] = dict(kv.split("=") for kv in rest.split())
    assert rows["linear"]["ok"] == rows["yielding"]["ok"] == "True"
    assert abs(float(rows["linear"]["residual_drift_mm"])) < 0.005
    assert abs(float(rows["yielding"]["residual_drift_mm"])) > 0.05


E_STEEL, IC, IB, STOREY, BAY = 200e9, 2.520 * 0.0254**4, 255267e-12, 0.635, 0.762  # BENCHMARK.md 4.2


def _benchmark_frame(floor_masses, alpha, k_remove, A=100.0):
    """The benchmark's frame as a 2-D OpenSees model: 3 storeys of 0.635 m, 2 bays of 0.762 m,
    pinned bases, elastic beam-columns (E = 200 GPa, I_c, I_b of BENCHMARK.md 4.2, A = 100 m^2:
    axially rigid), rigid floors (equalDOF), lateral masses on the floors' left nodes, damping
    alpha M, and a spring of -k_remove at the first floor (the specimen taken out)."""
    def build(ops):
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        for j in range(4):
            for i in range(3):
                ops.node(10 * j + i, i * BAY, j * STOREY)
        for i in range(3):
            ops.fix(i, 1, 1, 0)
        ops.geomTransf("Linear", 1)
        tag = 1
        for j in range(3):
            for i in range(3):
                ops.element("elasticBeamColumn", tag, 10 * j + i, 10 * (j + 1) + i, A, E_STEEL, IC, 1)
                tag += 1
        for j in (1, 2, 3):
            for i in range(2):
                ops.element("elasticBeamColumn", tag, 10 * j + i, 10 * j + i + 1, A, E_STEEL, IB, 1)
                tag += 1
            for i in (1, 2):
                ops.equalDOF(10 * j, 10 * j + i, 1)
            ops.mass(10 * j, floor_masses[j - 1], 0.0, 0.0)
        ops.node(99, 0.0, STOREY)
        ops.fix(99, 1, 1, 1)
        ops.uniaxialMaterial("Elastic", 99, -k_remove)
        ops.element("zeroLength", 99, 99, 10, "-mat", 99, "-dir", 1)
        ops.rayleigh(alpha, 0.0, 0.0, 0.0)
    return build


def test_opensees_frame_is_the_benchmark_structure_and_steps_as_ours():
    """The frame in OpenSees, stepped with average-acceleration Newmark, against our
    AverageAcceleration substructure with the benchmark's condensed K (KK_mat, BENCHMARK.md
    4.2): the same response, because the massless, undamped joint rotations condense exactly."""
    case = rths.embedded_case(1)
    sp = rths.nominal_plant().specimen()
    Mn, Kn = case.M.copy(), case.K.copy()
    Mn[0, 0] -= sp.m
    Kn[0, 0] -= sp.k
    alpha = 2 * 0.05 * np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(case.M, case.K)).real))
    g = np.diag(case.M).copy()
    ours = R.LinearSubstructure(R.LinearSubstructureModel(Mn, alpha * Mn, Kn, g, np.array([1.0, 0, 0])), rths.DT,
                                R.SubstructureScheme.AverageAcceleration)
    osp = rths.OpenSeesSubstructure(_benchmark_frame(np.diag(Mn), alpha, sp.k), dofs=[(10, 1), (20, 1), (30, 1)],
                                    ground=g, scheme="newmark")
    worst, peak = _step_both(ours, osp, 2048, seed=5)
    print(f"OpenSees frame vs ours, average acceleration, 0.5 s: worst {worst:.3g} m of peak {peak:.3g} m")
    assert peak > 1e-4 and worst <= 1e-6 * peak  # A = 100 m^2: axial flexibility ~1e-8 of the lateral
    # ... and in the RTHS loop, with the benchmark plant and the sample controller
    rec = rths.synthetic_record(duration=2.0)
    lin = R.LinearSubstructure(R.LinearSubstructureModel(Mn, alpha * Mn, Kn, g, np.array([1.0, 0, 0])), rths.DT,
                               R.SubstructureScheme.AverageAcceleration)
    t1 = rths.run_trial(case, rec, "sample", seed=3, numerical=lin, keep_signals=True)
    t2 = rths.run_trial(case, rec, "sample", seed=3, numerical=osp, keep_signals=True)
    assert t1.ok and t2.ok
    # The 2e-7 difference of the frame flips the controller's 3.8 um quantizer now and then, and the
    # loop carries the flips on: the loop agrees to 1e-3, not to 1e-6.
    d = np.max(np.abs(t2.signals["numerical"] - t1.signals["numerical"]))
    print(f"in the loop: worst {d:.3g} m of peak {np.max(np.abs(t1.signals['numerical'])):.3g} m; J {t1.J} vs {t2.J}")
    assert d <= 1e-3 * np.max(np.abs(t1.signals["numerical"]))
    np.testing.assert_allclose(t2.J, t1.J, atol=0.05)
