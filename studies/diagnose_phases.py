"""The steps of a diagnosis in time: when each starts, its wall time, the process' CPU over it and so how busy the
two cores were (docs/benchmarks.md, "Stop 47").

    python studies/diagnose_phases.py [--record chirp20Hz_1A] [--end 10]

``sh.diagnose`` of a UTFSM record (default: the first 10 s of ``chirp20Hz_1A``, benchmarks/lab_speed.py's
``diagnose10``; ``--record sweep15Hz_1A --end 0``: its sweep1A) against the rig identified at 0 A
(evaluation/utfsm_rig_0A.toml), displacement control, every candidate.  The workflow's steps
(``diagnosis.workflow``: the screening and the candidates' fits of each round, the acceptance with its loop
re-fits, the restoring re-fit, the initial displacements) are timed where they run: start and wall time [s],
the process' CPU over them (user + system, every thread) and its ratio to the wall time (2: both cores busy).
The nominal run as ``compare`` makes it (``_nominal_run_checks``) runs on its own thread beside the rounds; its
line gives that thread's own CPU as well.  Steps overlap (an acceptance contains its loop re-fits; the nominal
run spans the first round), so the lines do not add up.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

#: the workflow's steps timed (``diagnosis.workflow`` module attributes)
STEPS = ("_screen_all", "_confirm_all", "_accept", "_polish_loop", "_polish", "_restore", "_nominal_run_checks")


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", default="chirp20Hz_1A", help="a UTFSM record's name (default chirp20Hz_1A)")
    ap.add_argument("--end", type=float, default=10.0, help="its first END seconds (0: the whole record)")
    args = ap.parse_args(argv)
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine, workflow

    lines: list[tuple[float, str]] = []
    t0 = [time.perf_counter()]

    def timed(name: str, fn):
        def run(*a, **k):
            t, c, tc = time.perf_counter(), _cpu(), time.thread_time()
            try:
                return fn(*a, **k)
            finally:
                wall, cpu = time.perf_counter() - t, _cpu() - c
                own = f", its thread's CPU {time.thread_time() - tc:.1f}" if name == "_nominal_run_checks" else ""
                lines.append((t - t0[0], f"| {name} | {t - t0[0]:.1f} | {wall:.1f} | {cpu:.1f} | "
                                         f"{cpu / max(wall, 1e-9):.2f}{own} |"))
        return run

    for name in STEPS:
        setattr(workflow, name, timed(name, getattr(workflow, name)))
    engine.refine_x0 = timed("refine_x0", engine.refine_x0)
    rec = lab_speed._record(args.record, args.end) if args.end > 0 else lab_speed._record(args.record)
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    t0[0], c0 = time.perf_counter(), _cpu()
    d = sh.diagnose([rec], rig, mode="displacement", progress=False)
    wall, cpu = time.perf_counter() - t0[0], _cpu() - c0
    window = f"first {args.end:g} s" if args.end > 0 else "whole"
    print(f"{args.record} ({window}): {wall:.1f} s wall, {cpu:.1f} s CPU ({cpu / wall:.2f} cores busy); "
          f"{d.verdict}: {', '.join(e['name'] for e in d.effects) or '-'}\n")
    print("| step | start [s] | wall [s] | CPU [s] | cores busy |")
    print("|---|---|---|---|---|")
    for _, line in sorted(lines):
        print(line)


if __name__ == "__main__":
    main()
