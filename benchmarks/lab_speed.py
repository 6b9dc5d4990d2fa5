"""How long identification and diagnosis of lab records take (issue 25, item 6), and where the time goes.

    python benchmarks/lab_speed.py [--cases identify,diagnose10,diagnose10sim,sweep1A] [--json FILE]
                                   [--profile] [--label NAME] [--v-stick V] [--continuation pair|search]
                                   [--stiff-steps N] [--search-stiff rosenbrock|cvode] [--ros2-rungs N,N]
                                   [--decision-stiff rosenbrock|cvode] [--stiffness-test on|off]
                                   [--rosenbrock-order 2|4] [--fit-ftol-max F] [--fit-step-gain G]
    python benchmarks/lab_speed.py --table benchmarks/lab_speed.json

The cases (records from ../shared/real-data/utfsm-mts-mrdamper, or $SH_SHARED_DIR/real-data/...):

* ``identify``: ``servohydraulics identify chirp20Hz_0A.csv --mode displacement --specimen mr_damper
  --out DIR`` (the UTFSM identification as docs/lab-records.md runs it, 61.5 s at 1 kHz), run
  in-process through ``cli.main`` (the interpreter's start and ``import servohydraulics`` are not
  counted: about 1 s on this machine), writing its report and plots.
* ``diagnose10``: ``sh.diagnose`` of the first 10 s of ``chirp20Hz_1A`` (1 A) against the rig
  identified at 0 A (``evaluation/utfsm_rig_0A.toml``), displacement control, every candidate.
* ``diagnose10sim``: ``sh.diagnose`` of the diagnosis evaluation's 10 s, 2 kHz runtime record
  (evaluation/diagnose_eval/generate.py: 300 N of hidden Coulomb friction, SNR 30 dB, made by the
  independent simulator) against its nominal rig.
* ``sweep1A``: ``sh.diagnose`` of the whole ``sweep15Hz_1A`` (51.9 s) against the 0 A rig.

For each: the wall time, the load average before and after (the machine is shared), the process' CPU
time (user + system over its threads: half of it bounds the wall time on an idle 2-core machine from
below, and it moves little with the others' load), the number of
simulations (calls into the core's record runs: a segment of a record counts as one), of Jacobian
evaluations and of least-squares calls, iterations (Jacobian evaluations inside them) and residual
evaluations, the time spent inside the core's runs (summed over threads), and what the run found
(NRMSE of the identified rig; the diagnosis' verdict, effects and gaps) so that a speed-up that
changes a result shows.  ``--profile`` adds cProfile's top functions (the main thread's) per case.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import platform
import pstats
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"
CASES = ("identify", "diagnose10", "diagnose10sim", "sweep1A")
#: the targets of issue 25, item 6 [s]
TARGETS = {"identify": 10.0, "diagnose10": 15.0, "diagnose10sim": 15.0, "sweep1A": 60.0}


class Counters:
    """Counts (thread-safe) the core's record runs and the least-squares work while installed."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.reset()

    def reset(self) -> None:
        self.sims = 0
        self.sim_seconds = 0.0
        self.lsq_calls = 0
        self.lsq_nfev = 0
        self.lsq_njev = 0
        self.jacobians_outside = 0

    def as_dict(self) -> dict:
        return {"simulations": self.sims, "simulation_s": self.sim_seconds, "least_squares_calls": self.lsq_calls,
                "least_squares_iterations": self.lsq_njev, "least_squares_residuals": self.lsq_nfev,
                "jacobian_evaluations": self.lsq_njev + self.jacobians_outside}


def _timed(counter: Counters, fn):
    def wrapper(*a, **k):
        t0 = time.perf_counter()
        try:
            return fn(*a, **k)
        finally:
            dt = time.perf_counter() - t0
            with counter.lock:
                counter.sims += 1
                counter.sim_seconds += dt
    return wrapper


@contextmanager
def instrumented(counter: Counters):
    """Wraps the core's record runs and every ``least_squares`` the fits call."""
    from servohydraulics import _core
    from servohydraulics.diagnosis import engine
    from servohydraulics.identification import fit

    saved = []

    def patch(obj, name, new):
        saved.append((obj, name, getattr(obj, name)))
        setattr(obj, name, new)

    patch(_core, "run_record", _timed(counter, _core.run_record))

    def counting(lsq):
        def wrapper(*a, **k):
            res = lsq(*a, **k)
            with counter.lock:
                counter.lsq_calls += 1
                counter.lsq_nfev += int(res.nfev)
                counter.lsq_njev += int(res.njev or 0)
            return res
        return wrapper

    mods = {m for m in (fit, engine) if hasattr(m, "least_squares")}
    for mod in sys.modules.values():  # any module of the package that imported least_squares by name
        if getattr(mod, "__name__", "").startswith("servohydraulics") and hasattr(mod, "least_squares"):
            mods.add(mod)
    for mod in mods:
        patch(mod, "least_squares", counting(mod.least_squares))
    if hasattr(fit, "jacobian_at"):
        inner = fit.jacobian_at

        def jacobian_at(*a, **k):
            with counter.lock:
                counter.jacobians_outside += 1
            return inner(*a, **k)
        patch(fit, "jacobian_at", jacobian_at)
    try:
        yield counter
    finally:
        for obj, name, old in reversed(saved):
            setattr(obj, name, old)


def _record(name: str, end: float | None = None):
    """The UTFSM record ``name`` (its first ``end`` seconds, or all of it): evaluation/utfsm_diagnose.py's reader."""
    if str(ROOT / "evaluation") not in sys.path:
        sys.path.insert(0, str(ROOT / "evaluation"))
    from utfsm_diagnose import _record as utfsm_record

    return utfsm_record(name, end)


def _simulated_record():
    """The diagnosis evaluation's 10 s runtime record and its nominal rig (made here, as generate.py does)."""
    sys.path.insert(0, str(ROOT / "evaluation" / "diagnose_eval"))
    import generate as gen

    from servohydraulics.records import Record

    items = gen.plan("default", "all")
    item = {"kind": "single", "effects": [("coulomb", 300.0)], "mode": "displacement", "cmd": "std",
            "snr": 30, "duration": 10.0, "runtime_check": True}
    rec, man, key = gen.make_record((len(items), item, 2003, 4.0))
    rig = gen.nominal_rig(man["mode"], key["rig"])
    return Record(rec), rig, man["mode"], key


def _diagnosis_summary(d) -> dict:
    js = d.to_dict()
    return {"verdict": js["verdict"], "effects": {e["name"]: {k: p["value"] for k, p in e["parameters"].items()}
                                                  for e in js["effects"]},
            "gap_before": js["gap_before"], "gap_after": js["gap_after"], "summary": js["summary"]}


class _Clock:
    """Wall and process CPU time [s] of the timed part of a case."""

    def __enter__(self):
        self.t0, self.c0 = time.perf_counter(), _cpu_seconds()
        return self

    def __exit__(self, *exc):
        self.wall, self.cpu = time.perf_counter() - self.t0, _cpu_seconds() - self.c0


def run_case(case: str, v_stick: float | None = None) -> dict:
    """One case; ``wall_s`` and ``cpu_s`` time the identification or the diagnosis alone (not the
    reading or the making of its record)."""
    import servohydraulics as sh
    from servohydraulics import cli

    if case == "identify":
        with tempfile.TemporaryDirectory() as tmp:
            argv = ["identify", str(DATA / "chirp20Hz_0A.csv"), "--mode", "displacement", "--specimen",
                    "mr_damper", "--out", tmp, "--quiet"]
            with _Clock() as clock, _quiet():
                code = cli.main(argv)
            if code != 0:
                raise SystemExit(f"identify exited {code}")
            js = json.loads((Path(tmp) / "identification.json").read_text())
        return {"wall_s": clock.wall, "cpu_s": clock.cpu,
                "result": {"values": {k: p["value"] for k, p in js["parameters"].items()},
                           "std": {k: p["std"] for k, p in js["parameters"].items()},
                           "nrmse_after": js["records"][0]["after"], "kept": js["kept"], "costs": js["costs"],
                           "runtime_s": js["runtime_s"], "nfev": js["nfev"], "runs": js.get("runs")}}
    if case in ("diagnose10", "sweep1A", "diagnose10sim"):
        if case == "diagnose10sim":
            rec, rig, mode, key = _simulated_record()
        else:
            rec = _record("chirp20Hz_1A", 10.0) if case == "diagnose10" else _record("sweep15Hz_1A")
            rig, mode = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml"), "displacement"
        if v_stick is not None:  # the nominal rig's friction law (0: the exact Coulomb law)
            rig.v_stick = v_stick
        from servohydraulics.diagnosis import engine

        hits = getattr(getattr(engine, "RUNS", None), "hits", None)  # None: a package before the run cache
        with _Clock() as clock:
            d = sh.diagnose([rec], rig, mode=mode, progress=False)
        out = _diagnosis_summary(d)
        if case == "diagnose10sim":
            out["truth"] = key["answers"]
        # the runs the diagnosis' run cache served (not runs of the core: not in "simulations")
        cached = None if hits is None else engine.RUNS.hits - hits
        return {"wall_s": clock.wall, "cpu_s": clock.cpu, "result": out, "runs_from_cache": cached}
    raise SystemExit(f"unknown case {case!r}: expected one of {CASES}")


def _cpu_seconds() -> float:
    """The process' CPU time so far [s], user and system, summed over its threads: on a shared machine
    the wall time grows with the others' load, this much less (cache and frequency effects only)."""
    import resource

    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


@contextmanager
def _quiet():
    old = sys.stdout
    sys.stdout = io.StringIO()
    try:
        yield
    finally:
        sys.stdout = old


def _summary(case: str, res: dict) -> str:
    """What the case found, for the table: the identified NRMSE, or the verdict and effects."""
    r = res["result"]
    if case == "identify":
        n = r["nrmse_after"]
        return f"NRMSE x {n['displacement']:.4f} %, F {n['force']:.4f} %"
    names = ", ".join(r["effects"]) or "-"
    return f"{r['verdict']}: {names}"


def table(path: Path, labels: list[str] | None = None) -> str:
    """The saved runs (``--json``) as a markdown table, one row per label and case."""
    saved = json.loads(path.read_text())
    rows = ["| case | run | wall [s] | load (1 min) | CPU [s] | simulations | least-squares iterations / residuals "
            "| result |", "|---|---|---|---|---|---|---|---|"]
    for case in CASES:
        for label in labels or list(saved):
            res = saved.get(label, {}).get("cases", {}).get(case)
            if res is None:
                continue
            load = f"{res['load_before'][0]:.1f} -> {res['load_after'][0]:.1f}"
            rows.append(f"| {case} | {label} | {res['wall_s']:.1f} | {load} | {res['cpu_s']:.1f} "
                        f"| {res['simulations']} | {res['least_squares_iterations']} / "
                        f"{res['least_squares_residuals']} | {_summary(case, res)} |")
    return "\n".join(rows)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cases", default=",".join(CASES), help=f"comma-separated, of {', '.join(CASES)}")
    p.add_argument("--json", help="write the results here (added under --label; a label already there is refused)")
    p.add_argument("--label", default="run", help="name of this run in the JSON (e.g. before, after)")
    p.add_argument("--profile", action="store_true", help="cProfile's top functions per case (main thread)")
    p.add_argument("--table", metavar="FILE", help="print the runs saved in FILE (--json) as a markdown table")
    p.add_argument("--v-stick", type=float, default=None, metavar="V",
                   help="the diagnosis cases' nominal rig with v_stick = V [m/s] (0: the exact Coulomb law, "
                        "docs/model.md); default: the rig's own")
    p.add_argument("--continuation", choices=("pair", "search"), default=None,
                   help="where a diagnosis fit goes on when its fixed step stopped agreeing with the pair "
                        "(diagnosis.engine.FIT_CONTINUATION; default: the package's, 'pair')")
    p.add_argument("--stiff-steps", type=int, default=None, metavar="N",
                   help="the diagnosis' error-controlled pair redoes a sample by its stiff integrator past N "
                        "dopri5 steps (diagnosis.engine.STIFF_STEPS; default: the package's, 100 since stop 46; "
                        "24, the core's, before)")
    p.add_argument("--search-stiff", choices=("rosenbrock", "cvode"), default=None,
                   help="the integrator of the diagnosis' search pair's stiff samples "
                        "(diagnosis.engine.SEARCH_STIFF_ROSENBROCK; default: the package's, rosenbrock since stop 46); "
                        "cvode brings back the fits' ROS2 rungs 8,16 as well, unless --ros2-rungs says otherwise")
    p.add_argument("--ros2-rungs", default=None, metavar="N,N",
                   help="the fixed ROS2 substep counts of the fits' integrator ladder, '' for none "
                        "(diagnosis.engine.SEARCH_ROS2_SUBSTEPS; default: the package's, none since stop 46)")
    p.add_argument("--decision-stiff", choices=("rosenbrock", "cvode"), default=None,
                   help="the integrator of the diagnosis' decision runs' stiff samples "
                        "(diagnosis.engine.DECISION_STIFF_ROSENBROCK; default: the package's, rosenbrock since "
                        "stop 47; cvode before)")
    p.add_argument("--stiffness-test", choices=("on", "off"), default=None,
                   help="Hairer's stiffness test in the diagnosis' pair (diagnosis.engine.STIFFNESS_TEST; default: "
                        "the package's, on since stop 47; off before)")
    p.add_argument("--rosenbrock-order", type=int, choices=(2, 4), default=None,
                   help="the order of the Rosenbrock method of the diagnosis pair's stiff samples "
                        "(diagnosis.engine.ROSENBROCK_ORDER; default: the package's, 4 (RODAS4) since stop 47; "
                        "2 before)")
    p.add_argument("--fit-step-gain", type=float, default=None, metavar="G",
                   help="a diagnosis fit stops where a step gains less than G of -2 log L "
                        "(diagnosis.engine.FIT_STEP_GAIN; default: the package's, 0.01 since stop 47)")
    p.add_argument("--fit-ftol-max", type=float, default=None, metavar="F",
                   help="the diagnosis fits' relative stopping tolerance at most (diagnosis.engine.FIT_FTOL_MAX; "
                        "default: the package's, 1e-4 since stop 47; 1e-8, the fixed tolerance before)")
    a = p.parse_args()
    if a.table:
        print(table(Path(a.table)))
        return
    import servohydraulics as sh
    from servohydraulics.diagnosis import engine

    # each flag sets one module switch of the diagnosis for this process (None: the package's default)
    switches = {"FIT_CONTINUATION": a.continuation, "STIFF_STEPS": a.stiff_steps,
                "ROSENBROCK_ORDER": a.rosenbrock_order, "FIT_STEP_GAIN": a.fit_step_gain,
                "FIT_FTOL_MAX": a.fit_ftol_max,
                "SEARCH_STIFF_ROSENBROCK": None if a.search_stiff is None else a.search_stiff == "rosenbrock",
                "DECISION_STIFF_ROSENBROCK": None if a.decision_stiff is None else a.decision_stiff == "rosenbrock",
                "STIFFNESS_TEST": None if a.stiffness_test is None else a.stiffness_test == "on"}
    if a.search_stiff == "cvode":
        switches["SEARCH_ROS2_SUBSTEPS"] = (8, 16)  # stop 45's search
    if a.ros2_rungs is not None:
        switches["SEARCH_ROS2_SUBSTEPS"] = tuple(int(v) for v in a.ros2_rungs.split(",") if v.strip())
    for name, value in switches.items():
        if value is not None:
            setattr(engine, name, value)
    cases = [c.strip() for c in a.cases.split(",") if c.strip()]
    if a.json and Path(a.json).exists() and a.label in json.loads(Path(a.json).read_text()):
        # the JSON is keyed by label: a second run under one label would replace the first's cases
        print(f"invalid --label = {a.label!r}: {a.json} already has a run of that name; choose another",
              file=sys.stderr)
        raise SystemExit(2)
    import numpy
    import scipy

    # the libraries' rounding moves the fits' paths (docs/benchmarks.md, "This venv's rounding"): recorded with the row
    out = {"label": a.label, "python": platform.python_version(), "numpy": numpy.__version__,
           "scipy": scipy.__version__, "cpus": os.cpu_count(),
           "command": "python benchmarks/lab_speed.py " + " ".join(sys.argv[1:]), "v_stick": a.v_stick,
           "continuation": a.continuation, "stiff_steps": a.stiff_steps, "cases": {}}
    out["stiff_steps_in_effect"] = engine.STIFF_STEPS  # rows before stop 46 lack it: 24 (the core's) by default
    out["search_stiff"] = "rosenbrock" if engine.SEARCH_STIFF_ROSENBROCK else "cvode"  # likewise: cvode before stop 46
    out["ros2_rungs"] = list(engine.SEARCH_ROS2_SUBSTEPS)  # likewise: [8, 16] before stop 46
    # rows before stop 47 lack these: cvode, off and 1e-8
    out["decision_stiff"] = "rosenbrock" if engine.DECISION_STIFF_ROSENBROCK else "cvode"
    out["stiffness_test"] = bool(engine.STIFFNESS_TEST)
    out["fit_ftol_max"] = engine.FIT_FTOL_MAX
    out["fit_step_gain"] = engine.FIT_STEP_GAIN  # rows before stop 47 lack it: the fixed ftol 1e-8 then
    out["rosenbrock_order"] = engine.ROSENBROCK_ORDER  # 2 before stop 47
    counter = Counters()
    for case in cases:
        counter.reset()
        load0 = os.getloadavg()
        prof = cProfile.Profile() if a.profile else None
        with instrumented(counter):
            if prof:
                prof.enable()
            res = run_case(case, a.v_stick)
            if prof:
                prof.disable()
        load1 = os.getloadavg()
        res.update(counter.as_dict())
        res["load_before"], res["load_after"] = [round(v, 2) for v in load0], [round(v, 2) for v in load1]
        res["target_s"] = TARGETS[case]
        out["cases"][case] = res
        print(f"{case}: {res['wall_s']:.1f} s (target {TARGETS[case]:g} s; load {load0[0]:.1f} -> {load1[0]:.1f}); "
              f"CPU {res['cpu_s']:.1f} s (an idle 2-core machine: >= {res['cpu_s'] / 2:.1f} s); "
              f"{res['simulations']} simulations ({res['simulation_s']:.1f} s summed over threads), "
              f"{res['jacobian_evaluations']} Jacobians, {res['least_squares_calls']} least-squares calls, "
              f"{res['least_squares_iterations']} iterations, {res['least_squares_residuals']} residuals",
              flush=True)
        print("   ", json.dumps(res["result"], default=float)[:2000], flush=True)
        if prof:
            s = io.StringIO()
            pstats.Stats(prof, stream=s).sort_stats("cumulative").print_stats(30)
            res["profile"] = s.getvalue()
            print(s.getvalue())
    if a.json:
        path = Path(a.json)
        saved = json.loads(path.read_text()) if path.exists() else {}
        saved[a.label] = out
        path.write_text(json.dumps(saved, indent=1, default=float) + "\n")
    del sh


if __name__ == "__main__":
    main()
