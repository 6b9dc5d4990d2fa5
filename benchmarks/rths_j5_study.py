"""The J5 study of docs/rths-benchmark.md ("The J5 gap"): the seed-to-seed spread of
the case-1 nominal row, and the spec readings tried against the published Table 3 row.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python benchmarks/rths_j5_study.py \
        --data ../shared/rths-data/mat [--seeds 60]

Part 1 runs the C++ loop (rths.run_trial) over noise seeds, with the exact CSI
(default) and with the code's Derivative block on the CSI.  Part 2 re-implements
the loop of BENCHMARK.md 5.4 in Python on the same C++ blocks (plant, substructure,
controller), with one reading changed at a time, 6 seeds each."""

from __future__ import annotations

import argparse

import numpy as np
from scipy import signal

from servohydraulics import _core, rths
from servohydraulics.rths.benchmark import nominal_plant, partition
from servohydraulics.rths.evaluation import evaluate

R, DT = _core.rths, rths.DT
PUBLISHED = [4.6, 10.4, 11.5, 36.1, 19.0, 32.3, 32.4, 14.8, 14.8]


def fmt(v) -> str:
    return " ".join(f"{x:6.2f}" for x in v)


def seed_spread(case, rec, ref, seeds: int) -> None:
    print(f"{'published':34s} {fmt(PUBLISHED)}")
    for csi in (False, True):
        p = nominal_plant()
        p.csi_derivative_block = csi
        Js = np.array([rths.run_trial(case, rec, "sample", plant=p, seed=s, reference=ref).J for s in range(seeds)])
        name = "CSI Derivative block" if csi else "exact CSI (default)"
        print(f"{name + f', mean of {seeds}':34s} {fmt(Js.mean(0))}")
        print(f"{'  sd':34s} {fmt(Js.std(0, ddof=1))}")
        j5 = np.floor(10 * Js[:, 4] + 0.5) / 10
        print(f"  J5 min {Js[:, 4].min():.2f} max {Js[:, 4].max():.2f}; seeds rounding to >= 19.0: "
              f"{int((j5 >= 19.0).sum())} of {seeds}")


def py_loop(case, rec, seed, ag_hold=False, csi=False, force_delay=1, noise=True):
    """BENCHMARK.md 5.4 step by step; ag_hold: a_g held at t_k over the RK4 stages."""
    n = rec.samples()
    p = nominal_plant()
    p.csi_derivative_block = csi
    exp = R.BenchmarkPlant(p, DT)
    sp = exp.specimen()
    num = R.LinearSubstructure(partition(case, sp), DT, R.SubstructureScheme.RungeKutta4)
    ctrl = R.SampleController(R.SampleControllerConfig())
    w = np.random.default_rng(seed).standard_normal(n) if noise else np.zeros(n)
    t = np.arange(n) * DT
    ag = [0.4 * np.interp(t + d, rec.time, rec.acceleration) for d in (0.0, DT / 2, DT)]
    if ag_hold:
        ag = [ag[0]] * 3
    xm, nums = np.empty(n), np.empty((n, 3))
    x1 = v1 = 0.0
    queue = [0.0] * force_delay
    for k in range(n):
        x = exp.displacement
        xm[k] = x + 1.6e-5 * w[k]
        v = 0.0 if k == 0 else (x - x1) / DT
        a = 0.0 if k == 0 else (v - v1) / DT
        x1, v1 = x, v
        queue.append(sp.k * x + sp.c * v + sp.m * a + 2.1797614548385793 * w[k])
        fin = queue.pop(0)
        u = ctrl.command(R.TrackingInput(num.displacement[0], 0.0, 0.0, xm[k], queue[-1]))
        nums[k] = num.displacement
        exp.step(u)
        num.step(ag[0][k], ag[1][k], ag[2][k], fin)
    return xm, nums


def zoh_reference(case, rec):
    n = rec.samples()
    MiK, MiC = np.linalg.solve(case.M, case.K), np.linalg.solve(case.M, case.C)
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-MiK, -MiC]])
    B = np.r_[np.zeros(3), -np.ones(3)][:, None]
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, np.c_[np.eye(3), np.zeros((3, 3))], np.zeros((3, 1))), DT)
    return signal.dlsim((Ad, Bd, Cd, Dd, DT), 0.4 * np.interp(np.arange(n) * DT, rec.time, rec.acceleration))[1]


def readings(case, rec, ref) -> None:
    refs = {"foh": ref, "zoh": zoh_reference(case, rec)}
    variants = [("as specified (Python loop)", {}, "foh"), ("no sensor noise", {"noise": False}, "foh"),
                ("CSI Derivative block", {"csi": True}, "foh"), ("a_g held over the step", {"ag_hold": True}, "foh"),
                ("reference by ZOH lsim", {}, "zoh"), ("force delayed 2 samples", {"force_delay": 2}, "foh")]
    for name, kw, r in variants:
        seeds = [0] if kw.get("noise") is False else range(6)
        Js = np.array([evaluate(*py_loop(case, rec, s, **kw), refs[r], DT) for s in seeds])
        print(f"{name + f' ({len(seeds)} seeds)':34s} {fmt(Js.mean(0))}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", required=True)
    ap.add_argument("--seeds", type=int, default=60)
    a = ap.parse_args()
    case, rec = rths.load_case(a.data, 1), rths.load_record(a.data, "elcentro")
    ref = rths.case_reference(case, rec)
    seed_spread(case, rec, ref, a.seeds)
    readings(case, rec, ref)


if __name__ == "__main__":
    main()
