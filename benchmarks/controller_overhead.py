"""The per-sample cost of a Python tracking controller in the C++ RTHS loop, against
the built-in C++ controllers (docs/rths-benchmark.md, "Bring your own controller").

One nominal run of the benchmark (case 1, El Centro x 0.4, 4096 Hz; the embedded
case 1 and a synthetic record without the data) per controller, with the loop's
per-sample timer (``RthsLoop.run(timing=True)``: the wall time of each sample, plant
+ numerical substructure + controller, measured by the C++ loop).  Each controller
runs ``--repeat`` times and each figure is the lowest of its runs (the least disturbed
by the rest of the machine).  Printed per controller: median and p99 per sample, the
mean (the whole run's wall time without the timer / samples) and the overhead over
the built-in sample controller (median difference).

    python benchmarks/controller_overhead.py --data ../shared/rths-data/mat [--repeat 5] [--json out.json]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from servohydraulics import rths

R = rths.core
ROOT = Path(__file__).resolve().parents[1]


def _example():
    """examples/07_user_controller.py: PiLead (PI + lead in pure Python, the core's converters), Delegating."""
    path = ROOT / "examples" / "07_user_controller.py"
    spec = importlib.util.spec_from_file_location("user_controller_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class NoOp:
    """Python, does nothing: the bare cost of calling Python once per sample."""

    def reset(self):
        pass

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        return 0.0


class NoOpAllInputs:
    """Python, does nothing, taking all seven inputs: measured_velocity and measured_pressure are
    passed as keywords (the loop reads command()'s signature once): the cost of the two keywords."""

    def reset(self):
        pass

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force,
                measured_velocity=0.0, measured_pressure=0.0):
        return 0.0


class DelegatingSubclass(rths.TrackingController):
    """Python, a TrackingController subclass (the trampoline), delegates to the built-in sample controller."""

    def __init__(self):
        super().__init__()
        self.inner = rths.make_controller("sample")

    def reset(self):
        self.inner.reset()

    def command(self, desired, desired_velocity, desired_acceleration, measured, measured_force):
        return self.inner.command(desired, desired_velocity, desired_acceleration, measured, measured_force)


def controllers() -> dict[str, object]:
    example = _example()
    out: dict[str, object] = {f"C++ built-in `{n}`": n for n in rths.CONTROLLERS}
    out["Python no-op (returns 0)"] = NoOp
    out["Python no-op taking all seven inputs (two as keywords)"] = NoOpAllInputs
    out["Python, delegating to the built-in `sample` (duck-typed)"] = example.Delegating
    out["Python, delegating to the built-in `sample` (TrackingController subclass)"] = DelegatingSubclass
    out["Python PI + phase lead (examples/07_user_controller.py)"] = example.PiLead
    return out


def measure(case, rec, make, repeat: int) -> dict[str, float]:
    """Per-sample [us]: median and p99 (the loop's timer) and mean (wall time without the timer),
    each the lowest of ``repeat`` runs (the least disturbed by the rest of the machine)."""
    rows = []
    ref = rths.case_reference(case, rec)
    for _ in range(repeat):
        ctrl = make() if isinstance(make, type) else make
        timed = rths.run_trial(case, rec, ctrl, reference=ref, timing=True, keep_signals=True)
        steps = timed.signals["step_seconds"]
        ctrl = make() if isinstance(make, type) else make
        plain = rths.run_trial(case, rec, ctrl, reference=ref)
        rows.append({"median_us": 1e6 * float(np.median(steps)), "p99_us": 1e6 * float(np.percentile(steps, 99)),
                     "mean_us": 1e6 * plain.wall_time / steps.size, "samples": int(steps.size),
                     "J2_rms_tracking_error_pct": plain.criteria["J2_rms_tracking_error_pct"]})
    return {k: min(r[k] for r in rows) for k in rows[0]}


def table(res: dict) -> str:
    base = res["rows"]["C++ built-in `sample`"]
    lines = ["| controller | median [µs/sample] | p99 [µs/sample] | mean [µs/sample] | overhead vs built-in "
             "`sample` (median) [µs] | J2 [%] |", "|---|---|---|---|---|---|"]
    for name, r in res["rows"].items():
        lines.append(f"| {name} | {r['median_us']:.2f} | {r['p99_us']:.2f} | {r['mean_us']:.2f} | "
                     f"{r['median_us'] - base['median_us']:+.2f} | {r['J2_rms_tracking_error_pct']:.2f} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=None, help="the benchmark's files (omitted: embedded case 1, synthetic record)")
    ap.add_argument("--repeat", type=int, default=5, help="runs per controller; each figure is the lowest")
    ap.add_argument("--json", default=None, help="also write the figures to this file")
    args = ap.parse_args()
    if args.data:
        case, rec = rths.load_case(args.data, 1), rths.load_record(args.data, "elcentro")
    else:
        case, rec = rths.embedded_case(1), rths.synthetic_record()
    t0 = time.perf_counter()
    res = {"record": rec.name, "synthetic": rec.synthetic, "repeat": args.repeat,
           "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
                      f"load average {os.getloadavg()[0]:.2f} at the start",
           "rows": {name: measure(case, rec, make, args.repeat) for name, make in controllers().items()}}
    res["wall_s"] = time.perf_counter() - t0
    print(f"case 1, {rec.name} x 0.4 ({res['rows']['C++ built-in `sample`']['samples']} samples), "
          f"best of {args.repeat}; {res['machine']}; {res['wall_s']:.0f} s\n")
    print(table(res))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2))


if __name__ == "__main__":
    main()
