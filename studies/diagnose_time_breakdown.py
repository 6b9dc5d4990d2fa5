"""Where a diagnosis spends its simulation time, by step of the workflow (docs/benchmarks.md, lab-speed).

    python studies/diagnose_time_breakdown.py [--record chirp20Hz_1A] [--end 10] [--json FILE] [--v-stick V]
                                               [--stiff-steps N]

``sh.diagnose`` of a UTFSM record (default: the first 10 s of ``chirp20Hz_1A``, benchmarks/lab_speed.py's
``diagnose10``) against the rig identified at 0 A (evaluation/utfsm_rig_0A.toml), displacement control,
every candidate.  Every run of the core the diagnosis makes (``identification.run.simulate_command``) is
timed on the thread that makes it and attributed to the step that asked for it: a candidate's
confirmation (``confirm:NAME``: its start, train, held-out, all-data and interacting fits, with their
difference columns on the fit's threads), its integrator choice and checks (``>search_options``,
``>agrees``), the screening, the initial displacements, the loop and joint re-fits, the restoring re-fit.
For each step: the runs, their summed thread time and share, and the integrators they ran on (the
search's error-controlled pair, RK4 or ROS2 at n substeps); then the same with each step's integrator
choice and checks folded into it; then the runs and thread time by integrator.  The runs served by
the diagnosis' run cache (``engine.RUNS``) are not runs of the core and are counted apart.  The thread
times add up to more than the wall time on two cores.
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

#: the workflow's steps whose runs are attributed to them (module attribute names)
WORKFLOW_STEPS = ("_screen_all", "_polish_loop", "_polish", "_restore", "_accept", "_nominal_run_checks")
ENGINE_STEPS = ("refine_x0", "secant_screen", "search_options", "agrees")
JOINT_STEPS = ("loop_refit", "loop_refit_displacement", "joint_refit", "restore_refit")


class Attribution:
    """The runs of the core by step (a thread-local label set by the wrapped steps)."""

    def __init__(self) -> None:
        self.local = threading.local()
        self.lock = threading.Lock()
        self.rows: dict = collections.defaultdict(lambda: {"runs": 0, "seconds": 0.0,
                                                           "integrators": collections.Counter()})
        self.by_integrator: dict = collections.defaultdict(lambda: [0, 0.0])  # integrator -> [runs, seconds]
        self.saved: list = []

    def label(self) -> str:
        return getattr(self.local, "label", None) or "other"

    def _patch(self, obj, name, new) -> None:
        self.saved.append((obj, name, getattr(obj, name)))
        setattr(obj, name, new)

    def labelled(self, obj, name: str, text=None) -> None:
        inner = getattr(obj, name)

        def wrapper(*a, **k):
            old = getattr(self.local, "label", None)
            own = text(*a) if text is not None else name
            self.local.label = own if old is None else f"{old}>{own}"
            try:
                return inner(*a, **k)
            finally:
                self.local.label = old
        self._patch(obj, name, wrapper)

    def install(self) -> None:
        from servohydraulics.diagnosis import engine, workflow

        inner_run = engine.simulate_command

        def run(rig, *a, **k):
            opts = a[4] if len(a) > 4 else k.get("options")
            t0 = time.perf_counter()
            try:
                return inner_run(rig, *a, **k)
            finally:
                dt = time.perf_counter() - t0
                how = "default" if opts is None else str(opts.method).split(".")[-1].lower()
                if how == "rk4":
                    how += f" {opts.rk4_substeps}"
                elif how == "ros2":
                    how += f" {opts.ros2_substeps}"
                elif how == "dopri5":
                    how = f"pair (rtol {opts.rtol:g})"
                with self.lock:
                    row = self.rows[self.label()]
                    row["runs"] += 1
                    row["seconds"] += dt
                    row["integrators"][how] += 1
                    self.by_integrator[how][0] += 1
                    self.by_integrator[how][1] += dt
        self._patch(engine, "simulate_command", run)
        inner_workers = engine.workers

        def workers():  # the fits' difference columns: on the pool's threads, under the caller's label
            m = inner_workers()
            if m is None:
                return None
            label = getattr(self.local, "label", None)

            def mapper(fn, *items):
                def call(*x):
                    self.local.label = label
                    return fn(*x)
                return m(call, *items)
            return mapper
        self._patch(engine, "workers", workers)
        self.labelled(workflow, "confirm", lambda space, *a: f"confirm:{space.cand.name}")
        for name in WORKFLOW_STEPS:
            self.labelled(workflow, name)
        for name in ENGINE_STEPS:
            self.labelled(engine, name)
        for name in JOINT_STEPS:
            if hasattr(workflow, name):
                self.labelled(workflow, name)

    def remove(self) -> None:
        for obj, name, old in reversed(self.saved):
            setattr(obj, name, old)
        self.saved.clear()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", default="chirp20Hz_1A", help="a UTFSM record's name (default chirp20Hz_1A)")
    ap.add_argument("--end", type=float, default=10.0, help="its first END seconds (0: the whole record)")
    ap.add_argument("--json", type=Path, help="also write the table to this JSON file")
    ap.add_argument("--v-stick", type=float, default=None, metavar="V",
                    help="the nominal rig with v_stick = V [m/s] (0: the exact Coulomb law); default: the rig's own")
    ap.add_argument("--stiff-steps", type=int, default=None, metavar="N",
                    help="the pair hands a sample to its stiff integrator past N dopri5 steps "
                         "(diagnosis.engine.STIFF_STEPS; default: the package's, 100)")
    args = ap.parse_args(argv)
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine

    rec = lab_speed._record(args.record, args.end if args.end > 0 else None)
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    if args.v_stick is not None:
        rig.v_stick = args.v_stick
    if args.stiff_steps is not None:
        engine.STIFF_STEPS = args.stiff_steps
    att = Attribution()
    att.install()
    h0, m0 = engine.RUNS.hits, engine.RUNS.misses
    t0, c0 = time.perf_counter(), lab_speed._cpu_seconds()
    try:
        d = sh.diagnose([rec], rig, mode="displacement", progress=False)
    finally:
        att.remove()
    wall, cpu = time.perf_counter() - t0, lab_speed._cpu_seconds() - c0
    total = sum(r["seconds"] for r in att.rows.values())
    runs = sum(r["runs"] for r in att.rows.values())
    hits = engine.RUNS.hits - h0
    print(f"{args.record} [0, {args.end:g} s]: {wall:.1f} s wall, {cpu:.1f} s CPU; {runs} runs of the core "
          f"({total:.1f} s summed over threads), {hits} more served by the run cache "
          f"(of {hits + engine.RUNS.misses - m0} asked for)")
    s = lab_speed._diagnosis_summary(d)
    print(f"verdict {s['verdict']}: {', '.join(s['effects'])}; gap after "
          + ", ".join(f"{k} {100 * v:.2f} %" for k, v in s["gap_after"].items()))
    print("\n| step | runs | thread time [s] | share | integrators (runs) |\n|---|---|---|---|---|")
    table = []
    for name, r in sorted(att.rows.items(), key=lambda kv: -kv[1]["seconds"]):
        how = ", ".join(f"{k} {v}" for k, v in r["integrators"].most_common())
        print(f"| {name} | {r['runs']} | {r['seconds']:.1f} | {100 * r['seconds'] / total:.1f} % | {how} |")
        table.append({"step": name, "runs": r["runs"], "seconds": r["seconds"], "integrators": dict(r["integrators"])})
    folded: dict = collections.defaultdict(lambda: [0, 0.0])
    for name, r in att.rows.items():  # a step's integrator choice and checks folded into the step
        step = name
        for child in (">search_options", ">agrees"):
            step = step.replace(child, "")
        step = step.replace("_accept>", "").replace("_polish_loop>", "")
        folded[step][0] += r["runs"]
        folded[step][1] += r["seconds"]
    print("\n| step (its integrator choice and checks included) | runs | thread time [s] | share |\n|---|---|---|---|")
    for name, (n, sec) in sorted(folded.items(), key=lambda kv: -kv[1][1]):
        print(f"| {name} | {n} | {sec:.1f} | {100 * sec / total:.1f} % |")
    print("\n| integrator | runs | thread time [s] | share | per run [s] |\n|---|---|---|---|---|")
    integrators = []
    for how, (n, sec) in sorted(att.by_integrator.items(), key=lambda kv: -kv[1][1]):
        print(f"| {how} | {n} | {sec:.1f} | {100 * sec / total:.1f} % | {sec / n:.3f} |")
        integrators.append({"integrator": how, "runs": n, "seconds": sec})
    if args.json:
        args.json.write_text(json.dumps({"record": args.record, "end_s": args.end, "wall_s": wall, "cpu_s": cpu,
                                         "runs": runs, "run_seconds": total, "cache_hits": hits, "result": s,
                                         "steps": table, "integrators": integrators}, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
