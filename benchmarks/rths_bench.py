"""RTHS benchmark timings (docs/rths-benchmark.md):
    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python benchmarks/rths_bench.py --data ../shared/rths-data/mat
One nominal El Centro run (168,674 steps) in the C++ loop with per-step times,
then 20 perturbed runs x 4 cases through sh.sweep on 2 processes."""

from __future__ import annotations

import argparse
import time

import numpy as np

from servohydraulics import rths
from servohydraulics.rths.report import run_benchmark


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", required=True)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    case, rec = rths.load_case(a.data, 1), rths.load_record(a.data, "elcentro")
    ref = rths.case_reference(case, rec)
    walls = [rths.run_trial(case, rec, "sample", seed=0, reference=ref).wall_time for _ in range(5)]
    t = rths.run_trial(case, rec, "sample", seed=0, reference=ref, keep_signals=True, timing=True)
    steps = t.signals["step_seconds"]
    print(f"nominal El Centro run: {rec.samples()} steps, C++ loop wall time median of 5 = {np.median(walls):.3f} s; "
          f"per step (a run with a clock read around each step) median {1e6 * np.median(steps):.3f} us, "
          f"p99.9 {1e6 * np.quantile(steps, 0.999):.3f} us")
    t0 = time.perf_counter()
    run_benchmark(a.data, "elcentro", "1,2,3,4", "sample", perturbed=20, seed=1, workers=a.workers, progress=False)
    print(f"4 cases x (1 nominal + 20 perturbed) on {a.workers} processes: {time.perf_counter() - t0:.1f} s wall")


if __name__ == "__main__":
    main()
