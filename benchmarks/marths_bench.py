"""maRTHS benchmark timings (docs/marths-benchmark.md):
    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python benchmarks/marths_bench.py --data ../shared/marths-data
The nominal El Centro RoDeAC run (42,169 steps): the C++ loop alone and the whole trial (loop + J1-J10), median
of 5, and the per-step times of a run that reads the clock around each step; then 20 perturbed runs through
sh.sweep on 2 processes (pool start-up included), and the whole command's run (nominal + 20 perturbed); then the
nominal El Centro rodeac_fixed and none runs on the nonlinear two-actuator rig (--plant nonlinear: dopri5 with the
CVODE fallback), the loop alone, once each (RoDeAC itself oscillates there at 167 Hz: docs/multi-actuator.md).
The load average is printed before and after (the machine is shared)."""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from servohydraulics import marths
from servohydraulics.marths.report import execute, prepare


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", required=True)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--perturbed", type=int, default=20)
    a = ap.parse_args()
    print("load average (1, 5, 15 min) before: " + ", ".join(f"{v:.1f}" for v in os.getloadavg()))
    data, rec = marths.load_data(a.data), marths.load_record(a.data, "elcentro")
    st = marths.structures(data)
    marths.run_trial(data, rec, "rodeac", structures_=st)  # warm: imports (SciPy's FFT), caches
    loops, trials = [], []
    for _ in range(5):
        t0 = time.perf_counter()
        t = marths.run_trial(data, rec, "rodeac", structures_=st)
        trials.append(time.perf_counter() - t0)
        loops.append(t.wall_time)
    t = marths.run_trial(data, rec, "rodeac", structures_=st, keep_signals=True, timing=True)
    steps = np.asarray(t.response.channels["step_seconds"])
    print(f"nominal El Centro RoDeAC run: {marths.samples(rec)} steps; C++ loop median of 5 = "
          f"{np.median(loops):.3f} s, "
          f"whole trial (loop + J1-J10) median of 5 = {np.median(trials):.3f} s; per step (clock read around each) "
          f"median {1e6 * np.median(steps):.2f} us, p99.9 {1e6 * np.quantile(steps, 0.999):.2f} us, "
          f"max {1e6 * np.max(steps):.1f} us")
    setup = prepare(a.data, "elcentro", "rodeac", perturbed=a.perturbed, seed=1, workers=a.workers)
    t0 = time.perf_counter()
    run = execute(setup, progress=False)
    total = time.perf_counter() - t0
    pert = total - run["trial"].wall_time
    walls = run["table"]["wall_time"].to_numpy()
    print(f"{a.perturbed} perturbed El Centro RoDeAC runs on {a.workers} processes: {pert:.1f} s wall (pool start-up "
          f"included; C++ loop per run median {np.median(walls):.3f} s); nominal + {a.perturbed} perturbed: "
          f"{total:.1f} s")
    import servohydraulics as sh

    rig = sh.marths_rig()
    for ctrl in ("rodeac_fixed", "none"):  # RoDeAC oscillates on the rig (docs/multi-actuator.md): not a timing
        t = marths.run_trial(data, rec, ctrl, plant=rig, structures_=st)
        steps = t.work.internal_steps / marths.samples(rec)
        print(f"nominal El Centro {ctrl} run on the nonlinear rig (--plant nonlinear): C++ loop {t.wall_time:.3f} s, "
              f"{steps:.1f} dopri5 steps per sample; keep_signals replays it for the rig's channels: as much again")
    print("load average (1, 5, 15 min) after: " + ", ".join(f"{v:.1f}" for v in os.getloadavg()))


if __name__ == "__main__":
    main()
