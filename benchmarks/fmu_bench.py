"""The FMU's step time against the C++ API's, and the FMU-vs-library equality figures.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python benchmarks/fmu_bench.py [--steps 4000] [--write]

The plant of the calibrated Zhao (2003) rig in displacement control, the default integrator (dopri5), a
2 Hz, 10 mm sine command at the 0.5 ms controller sample.  Per sample, in the
same run (models built outside the timed region):

* C++ API, whole record: ``_core.run_record`` (the loop in C++; mean per step);
* C++ API, ``Plant.step`` called from Python per sample (pybind11);
* FMU through its C ABI from Python (ctypes: fmi2SetReal, fmi2DoStep, fmi2GetReal of the 8 outputs);
* FMU through fmpy's ``FMU2Slave`` (setReal, doStep, getReal);
* FMU, one doStep over the whole record at a held command vs ``run_record`` on the same held command:
  the FMU layer's own cost without any per-call overhead.

Then the largest relative difference between the FMUs and sh.simulate / sh.run_eft /
sh.run_rpsd on the same inputs.  ``--write`` replaces the marked section of docs/fmu.md.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import platform
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.fmu import _Slave, cosimulate

DT = 5e-4
ROOT = Path(__file__).resolve().parent.parent
COMMAND = "PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python benchmarks/fmu_bench.py --write"


def stats(ns: np.ndarray) -> dict[str, float]:
    us = np.asarray(ns, dtype=float) / 1e3
    return {"median": float(np.median(us)), "p99": float(np.percentile(us, 99)), "max": float(us.max()),
            "mean": float(us.mean())}


def time_cpp_whole(rig, u, repeat: int = 3) -> float:
    """Mean per step of the fastest of `repeat` whole-record runs [us]."""
    best = np.inf
    for _ in range(repeat):
        plant = sh.make_plant(rig, "displacement", DT)
        t0 = time.perf_counter_ns()
        _core.run_record(plant, u)
        best = min(best, (time.perf_counter_ns() - t0) / (u.size - 1) / 1e3)
    return best


def best_of(repeat: int, run) -> dict[str, float]:
    """The per-step statistics of the run (of `repeat`) with the lowest median."""
    return min((run() for _ in range(repeat)), key=lambda s: s["median"])


def time_pybind(rig, u) -> dict[str, float]:
    plant = sh.make_plant(rig, "displacement", DT)
    u = [float(x) for x in u]
    ns = np.empty(len(u))
    for k in range(len(u)):
        t0 = time.perf_counter_ns()
        plant.step(u[k])
        ns[k] = time.perf_counter_ns() - t0
    return stats(ns)


def time_fmu(slave: _Slave, u, raw: bool) -> dict[str, float]:
    f = slave.fmu
    out_vr, u_vr = slave.refs(slave.outputs), slave.refs(["command"])
    ns = np.empty(u.size)
    if raw:  # the C ABI through ctypes, no fmpy wrapper
        comp = f.component
        vr_u = (ctypes.c_uint * 1)(*u_vr)
        vr_out = (ctypes.c_uint * len(out_vr))(*out_vr)
        val_u, val_out = (ctypes.c_double * 1)(), (ctypes.c_double * len(out_vr))()
        set_real, do_step, get_real = f.dll.fmi2SetReal, f.dll.fmi2DoStep, f.dll.fmi2GetReal
        for k in range(u.size):
            t0 = time.perf_counter_ns()
            val_u[0] = u[k]
            set_real(comp, vr_u, 1, val_u)
            st = do_step(comp, k * DT, DT, 1)
            get_real(comp, vr_out, len(out_vr), val_out)
            ns[k] = time.perf_counter_ns() - t0
            if st != 0:
                raise RuntimeError(f"fmi2DoStep returned {st} at sample {k}")
    else:
        for k in range(u.size):
            t0 = time.perf_counter_ns()
            f.setReal(u_vr, [u[k]])
            f.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
            f.getReal(out_vr)
            ns[k] = time.perf_counter_ns() - t0
    return stats(ns)


def time_block(rig, plant_fmu, work, n, repeat) -> tuple[float, float]:
    """One doStep over n samples at a held command vs run_record on the same held command
    [us per sample, the fastest of `repeat` runs each]."""
    u = np.full(n + 1, 0.005)
    cpp = time_cpp_whole(rig, u, repeat)
    fmu = np.inf
    for i in range(repeat):
        s = _Slave(plant_fmu, work, f"block{i}")
        s.fmu.setReal(s.refs(["command"]), [0.005])
        t0 = time.perf_counter_ns()
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=n * DT)
        fmu = min(fmu, (time.perf_counter_ns() - t0) / n / 1e3)
        s.close()
    return cpp, fmu


def rel(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def equality(rig, work: Path, n: int) -> dict[str, float]:
    """Largest relative difference over every compared channel, per FMU kind."""
    t = np.arange(n) * DT
    u = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    plant = _Slave(sh.export_fmu(rig, work / "eq_plant.fmu"), str(work), "eq")
    ref = sh.simulate(rig, "displacement", u, DT)
    rows = {c: [] for c in plant.outputs}
    for k in range(n):
        for c, v in zip(plant.outputs, plant.fmu.getReal(plant.refs(plant.outputs))):
            rows[c].append(v)
        plant.fmu.setReal(plant.refs(["command"]), [u[k]])
        plant.fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
    plant.close()
    out = {"plant": max(rel(rows[c], ref.channels[c]) for c in rows)}
    ag = 3.0 * np.sin(2 * np.pi * 1.5 * t)
    ref = sh.run_eft(rig, ag, dt=DT)
    got = cosimulate(sh.export_fmu(rig, work / "eq_pf.fmu", mode="force"),
                     sh.export_fmu(rig, work / "eq_eft.fmu", kind="eft"), ag)
    out["eft"] = max(rel(got.channels[c], ref.channels[c]) for c in got.channels if c != "time")
    ref = sh.run_rpsd(rig, ag, dt=DT, physical_mass_fraction=0.02)
    got = cosimulate(sh.export_fmu(ref.rig, work / "eq_pd.fmu"),
                     sh.export_fmu(ref.rig, work / "eq_rpsd.fmu", kind="rpsd"), ag)
    out["rpsd"] = max(rel(got.channels[c], ref.channels[c]) for c in got.channels if c != "time")
    return out


def table(res: dict) -> str:
    def cells(s):
        return [f"{s[k]:.1f}" for k in ("median", "p99", "max", "mean")]

    rows = [("C++ API, whole record (`_core.run_record`; no per-step timer)", ["", "", "", f"{res['cpp_whole']:.1f}"]),
            ("C++ API, `Plant.step` from Python (pybind11)", cells(res["pybind"])),
            ("FMU, C ABI from Python (ctypes: SetReal, DoStep, GetReal x8)", cells(res["fmu_raw"])),
            ("FMU, fmpy `FMU2Slave` (setReal, doStep, getReal)", cells(res["fmu_fmpy"]))]
    lines = ["| per 0.5 ms sample | median [us] | p99 [us] | max [us] | mean [us] |", "|---|---|---|---|---|"]
    lines += [f"| {name} | " + " | ".join(c) + " |" for name, c in rows]
    cpp, fmu = res["block"]
    lines += ["", f"Held command, one `doStep` over {5 * res['steps']} samples: {fmu:.2f} us per sample, "
              f"`run_record` on the same held command {cpp:.2f} us per sample (ratio {fmu / cpp:.3f}).", "",
              "Largest relative difference, FMU vs library (every channel): " +
              ", ".join(f"{k} {v:.1e}" for k, v in res["equality"].items()) + ".", "",
              f"Machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
              f"{os.cpu_count()} CPUs, shared with other jobs; {res['steps']} samples, the fastest of "
              f"{res['repeat']} runs.  Command: `{COMMAND}`"]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=4000, help="samples per timed run")
    ap.add_argument("--repeat", type=int, default=3, help="runs per measurement (the fastest is reported)")
    ap.add_argument("--write", action="store_true", help="replace the marked section of docs/fmu.md")
    args = ap.parse_args(argv)
    rig = sh.zhao2003()
    u = 0.01 * np.sin(2 * np.pi * 2.0 * np.arange(args.steps) * DT)
    with tempfile.TemporaryDirectory(prefix="sh_fmu_bench_") as work:
        plant_fmu = sh.export_fmu(rig, Path(work) / "plant.fmu")
        res = {"steps": args.steps, "repeat": args.repeat, "cpp_whole": time_cpp_whole(rig, u, args.repeat),
               "pybind": best_of(args.repeat, lambda: time_pybind(rig, u))}
        runs = iter(range(10**6))  # a fresh directory per instance: never overwrite a loaded binary
        for key, raw in (("fmu_raw", True), ("fmu_fmpy", False)):
            def run(key=key, raw=raw):
                s = _Slave(plant_fmu, work, f"{key}{next(runs)}")
                try:
                    return time_fmu(s, u, raw)
                finally:
                    s.close()
            res[key] = best_of(args.repeat, run)
        res["block"] = time_block(rig, plant_fmu, work, 5 * args.steps, args.repeat)
        res["equality"] = equality(rig, Path(work), 800)
    text = table(res)
    print(text)
    if args.write:
        doc = ROOT / "docs" / "fmu.md"
        src = doc.read_text()
        new = re.sub(r"(<!-- fmu_bench:begin -->\n).*?(\n<!-- fmu_bench:end -->)",
                     lambda m: m.group(1) + text + m.group(2), src, flags=re.S)
        if new == src and text not in src:
            print("docs/fmu.md has no <!-- fmu_bench:begin/end --> markers", file=sys.stderr)
            return 1
        doc.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
