"""Where ``identify`` on the UTFSM chirp leaves a core idle (issue 25, item 6).

    python studies/identify_timeline.py [--runs 1] [--json FILE]

Runs benchmarks/lab_speed.py's ``identify`` case (``servohydraulics identify chirp20Hz_0A.csv --mode
displacement --specimen mr_damper``, in-process, writing its report) with every run of the core
(``_core.run_record``) timed on the thread that makes it, and the steps of ``identify`` (the frequency
stage, the start's whole runs, the time stage, the intervals, the comparisons, the report) timed on
the main thread.  For each step: its wall time, the core's thread time inside it, and how much of
its wall time had 0, 1 or 2 runs of the core going (on two cores, time with fewer than 2 runs is a
core idle, or Python working on one).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "python"))


class Timeline:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.runs: list[tuple[float, float]] = []
        self.steps: list[tuple[str, float, float]] = []


@contextmanager
def instrumented(tl: Timeline):
    import importlib

    from servohydraulics import _core
    from servohydraulics.identification import records

    cmp_mod = importlib.import_module("servohydraulics.identification.compare")  # the package exports its function

    saved = []

    def patch(obj, name, new):
        saved.append((obj, name, getattr(obj, name)))
        setattr(obj, name, new)

    core_run = _core.run_record

    def run_record(*a, **k):
        t0 = time.perf_counter()
        try:
            return core_run(*a, **k)
        finally:
            t1 = time.perf_counter()
            with tl.lock:
                tl.runs.append((t0, t1))

    patch(_core, "run_record", run_record)

    def step(obj, name, label):
        inner = getattr(obj, name)

        def wrapper(*a, **k):
            t0 = time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                tl.steps.append((label, t0, time.perf_counter()))
        patch(obj, name, wrapper)

    step(records, "fit_frequency", "frequency stage")
    step(records, "_whole_runs", "whole runs (the pair)")
    step(records, "_fit_target", "integrator choice (RK4 count)")
    step(records, "_time_stage", "time stage fits")
    step(records, "keep_best", "keep_best")
    step(records, "uncertainty", "intervals and removals")
    step(records, "compare", "comparisons")
    step(records.Identification, "write", "report (figures, files)")
    step(cmp_mod.Comparison, "figures", "  figures drawn")
    step(records, "save_figures", "  figures saved (PNG)")
    try:
        yield tl
    finally:
        for obj, name, old in reversed(saved):
            setattr(obj, name, old)


def occupancy(runs: list[tuple[float, float]], a: float, b: float) -> dict[int, float]:
    """Seconds of [a, b] with 0, 1, 2 (or more, counted as 2) runs of the core going."""
    events = []
    for s, e in runs:
        s, e = max(s, a), min(e, b)
        if e > s:
            events += [(s, 1), (e, -1)]
    events.sort()
    out = {0: 0.0, 1: 0.0, 2: 0.0}
    level, t = 0, a
    for when, d in events:
        out[min(level, 2)] += when - t
        level, t = level + d, when
    out[min(level, 2)] += b - t
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    import lab_speed

    from servohydraulics import cli

    rows = []
    for _ in range(args.runs):
        tl = Timeline()
        with tempfile.TemporaryDirectory() as tmp, instrumented(tl):
            argv = ["identify", str(lab_speed.DATA / "chirp20Hz_0A.csv"), "--mode", "displacement", "--specimen",
                    "mr_damper", "--out", tmp, "--quiet"]
            c0 = lab_speed._cpu_seconds()
            t0 = time.perf_counter()
            with lab_speed._quiet():
                code = cli.main(argv)
            t1 = time.perf_counter()
            cpu = lab_speed._cpu_seconds() - c0
        if code != 0:
            raise SystemExit(f"identify exited {code}")
        whole = occupancy(tl.runs, t0, t1)
        row = {"wall_s": t1 - t0, "cpu_s": cpu, "runs": len(tl.runs),
               "run_thread_s": sum(e - s for s, e in tl.runs), "occupancy_s": whole, "steps": []}
        print(f"identify: {t1 - t0:.2f} s wall, {cpu:.2f} s CPU, {len(tl.runs)} runs of the core "
              f"({row['run_thread_s']:.2f} s on their threads); 0/1/2 runs going: "
              f"{whole[0]:.2f} / {whole[1]:.2f} / {whole[2]:.2f} s")
        print("| step | calls | wall [s] | core thread time [s] | 0 runs going [s] | 1 [s] | 2 [s] |")
        print("|---|---|---|---|---|---|---|")
        agg: dict[str, list] = {}
        for label, a, b in tl.steps:
            occ = occupancy(tl.runs, a, b)
            busy = sum(min(e, b) - max(s, a) for s, e in tl.runs if min(e, b) > max(s, a))
            g = agg.setdefault(label, [0, 0.0, 0.0, 0.0, 0.0, 0.0])
            g[0] += 1
            g[1] += b - a
            g[2] += busy
            for lv in range(3):
                g[3 + lv] += occ[lv]
        for label, g in agg.items():
            print(f"| {label} | {g[0]} | {g[1]:.2f} | {g[2]:.2f} | {g[3]:.2f} | {g[4]:.2f} | {g[5]:.2f} |")
            row["steps"].append({"step": label, "calls": g[0], "wall_s": g[1], "core_thread_s": g[2],
                                 "occupancy_s": {str(lv): g[3 + lv] for lv in range(3)}})
        rows.append(row)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
