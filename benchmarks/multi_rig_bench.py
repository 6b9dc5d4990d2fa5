"""Step time of the two-actuator rig at 1024 Hz (issue 23): the calibrated maRTHS rig
(``sh.marths_rig()``) on a record as long as the benchmark's nominal El Centro run (42,169 samples).

The commands are the strokes of a frame motion like the benchmark's: the node's x and theta are the
responses of two SDOFs (2.15 Hz, the reference structure's first mode, and 3.5 Hz; 5 % damping) to the
synthetic ground motion of ``ground_motion.py`` (41.18 s at 1024 Hz), scaled to 4 mm and 8 mrad peak,
mapped to the two strokes by the coupler (a few mm each, as in the benchmark's run).

For each integrator (dopri5, the default at rtol 1e-8; the same at 1e-6; RK4 with its automatic
substeps; CVODE): the whole record through ``run_multi_record`` (the C++ loop; the fastest of
``--repeat`` passes) as microseconds per step and as a multiple of real time, the work per step, and
the per-step wall time of ``MultiRigPlant.step`` called from Python (median, p99, max; including the
binding's ~1 us), and the largest stroke difference to CVODE at rtol 1e-10.

    python benchmarks/multi_rig_bench.py [--repeat 3] [--write]

``--write`` puts the table into docs/multi-actuator.md between ``<!-- multi_rig_bench -->`` and
``<!-- /multi_rig_bench -->`` and the numbers into benchmarks/multi_rig_bench.json.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from ground_motion import ground_acceleration, sdof_displacement  # noqa: E402

import servohydraulics as sh  # noqa: E402
from servohydraulics import _core  # noqa: E402
from servohydraulics.atomic import replace_marked, write_text  # noqa: E402

FS = 1024.0
N = 42169  # the benchmark's nominal El Centro run (BENCHMARK.md section 1)

CASES = {
    "dopri5 (default, rtol 1e-8)": dict(method="dopri5"),
    "dopri5, rtol 1e-6": dict(method="dopri5", rtol=1e-6),
    "rk4 (automatic substeps)": dict(method="rk4"),
    "cvode (rtol 1e-8)": dict(method="cvode"),
}


def commands(rig: sh.MultiActuatorRig) -> np.ndarray:
    dt = 1.0 / FS
    ag = ground_acceleration(duration=(N - 1) / FS, dt=dt)[:N]
    motion = []
    for f, peak in ((2.15, 4e-3), (3.5, 8e-3)):
        w = 2 * math.pi * f
        x = sdof_displacement(ag, dt, 1.0, 2 * 0.05 * w, w * w)
        motion.append(x * peak / np.max(np.abs(x)))
    x, th = motion
    return np.c_[[x + d * (np.cos(th + a) - math.cos(a)) for d, a in zip(rig.arms, rig.angles)]].T.copy()


def run(rig, u, options, repeat: int):
    best = math.inf
    for _ in range(repeat):
        plant = rig.make_plant(1.0 / FS, options)
        t0 = time.perf_counter()
        cols, summary = _core.run_multi_record(plant, u)
        best = min(best, time.perf_counter() - t0)
    assert summary.ok(), summary.status.message
    s = np.c_[cols["actuator1.stroke"], cols["actuator2.stroke"]]
    return best, summary, s, plant


def per_step(rig, u, options, n: int = 8192) -> np.ndarray:
    plant = rig.make_plant(1.0 / FS, options)
    out = np.empty(n)
    clock = time.perf_counter_ns
    for k in range(n):
        t0 = clock()
        plant.step(u[k])
        out[k] = clock() - t0
    return out / 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    rig = sh.marths_rig()
    u = commands(rig)
    _, _, ref, _ = run(rig, u, sh.solver_options(method="cvode", rtol=1e-10), 1)
    rows, results = [], {}
    for name, kw in CASES.items():
        opt = sh.solver_options(**kw)
        wall, summary, s, plant = run(rig, u, opt, args.repeat)
        steps = per_step(rig, u, opt)
        us = wall / (N - 1) * 1e6
        err = float(np.max(np.abs(s - ref)))
        r = {"us_per_step": us, "real_time_factor": (N - 1) / FS / wall, "record_seconds": wall,
             "rhs_per_step": summary.rhs_evals / (N - 1), "stiff_samples": summary.stiff_samples,
             "inaccurate_samples": summary.inaccurate_samples, "rk4_substeps": plant.rk4_substeps,
             "step_median_us": float(np.median(steps)), "step_p99_us": float(np.percentile(steps, 99)),
             "step_max_us": float(np.max(steps)), "max_stroke_error_m": err}
        results[name] = r
        sub = f", {plant.rk4_substeps} substeps" if plant.rk4_substeps else ""
        rows.append(f"| {name}{sub} | {us:.1f} | {r['real_time_factor']:.1f} | {wall:.2f} | "
                    f"{r['rhs_per_step']:.1f} | {summary.stiff_samples} | {r['step_median_us']:.1f} / "
                    f"{r['step_p99_us']:.1f} / {r['step_max_us']:.0f} | {err * 1e6:.3g} |")
        print(rows[-1], flush=True)
    peak = np.max(np.abs(u), axis=0) * 1e3
    table = "\n".join([
        f"Record: {N} samples at 1024 Hz ({(N - 1) / FS:.2f} s), peak commands {peak[0]:.2f} / {peak[1]:.2f} mm; "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f} when it ran, Python {platform.python_version()}.",
        "",
        "| integrator | us per step (whole record) | x real time | record [s] | rhs per step | stiff samples "
        "| step() from Python: median / p99 / max [us] | max stroke error vs CVODE 1e-10 [um] |",
        "|---|---|---|---|---|---|---|---|", *rows])
    print(table)
    if args.write:
        write_text(ROOT / "benchmarks" / "multi_rig_bench.json", json.dumps(results, indent=2) + "\n")
        replace_marked(ROOT / "docs" / "multi-actuator.md", "multi_rig_bench", table)


if __name__ == "__main__":
    main()
