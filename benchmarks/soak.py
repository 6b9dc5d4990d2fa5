"""Soak benchmark (issue 16): long runs stay flat, still and on time.

    python3 benchmarks/soak.py            # ~1-2 min of CPU on one core

1. builds benchmarks/soak.cpp (build/soak, only that target, Release);
2. runs it: 1 h simulated at 2 kHz (7.2 M samples) with the real-time option
   (RK4) and 10 min (1.2 M samples) with the default integrator, every step
   timed: step-time percentiles and RSS per simulated minute, the structure
   back at rest after the last minute (command 0), the clock against k dt;
3. in this process: 1,000 short ``sh.simulate`` calls (0.1 s each) after 200
   warm-up calls, RSS before and every 100 calls;
4. writes the results between ``<!-- BEGIN soak -->`` and ``<!-- END soak -->``
   in docs/benchmarks.md (the markers are added at the end if absent) and
   benchmarks/soak.json.

The RSS growth is printed, not judged here: flat is a few kB over the run.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- BEGIN soak -->", "<!-- END soak -->"


def build(build_dir: Path) -> Path:
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                    "-DSH_BUILD_BENCHMARKS=ON", "-DSH_BUILD_PYTHON=OFF"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(build_dir), "--target", "sh_bench_soak", "-j", "2"], check=True)
    return build_dir / "benchmarks" / "sh_bench_soak"


def soak_cpp(exe: Path, method: str, minutes: int, out: Path, cpu_time: bool) -> dict:
    path = out / f"soak_{method}.json"
    subprocess.run([str(exe), "--method", method, "--minutes", str(minutes), "--cpu-time", str(int(cpu_time)),
                    "--json", str(path)], check=True)
    return json.loads(path.read_text())


def rss_kb() -> int:
    return int(Path("/proc/self/statm").read_text().split()[1]) * (os.sysconf("SC_PAGESIZE") // 1024)


def soak_python(calls: int = 1000, every: int = 100) -> dict:
    from tqdm import tqdm

    import servohydraulics as sh

    rig = sh.zhao2003()
    u = 5e-3 * np.sin(2 * np.pi * 2.0 * np.arange(200) * 5e-4)
    for _ in range(200):  # warm-up: NumPy's and the allocator's caches fill during the first calls
        sh.simulate(rig, "displacement", u)
    gc.collect()
    samples = [{"calls": 0, "rss_kb": rss_kb()}]
    t0 = time.perf_counter()
    for i in tqdm(range(1, calls + 1), desc="sh.simulate calls", disable=not sys.stderr.isatty()):
        sh.simulate(rig, "displacement", u)
        if i % every == 0:
            gc.collect()
            samples.append({"calls": i, "rss_kb": rss_kb()})
    return {"calls": calls, "seconds": time.perf_counter() - t0, "rss": samples}


def _us(row: dict, key: str) -> str:
    return f"{row[key]:.2f}" if key in row else "n/a"


def _minutes_table(run: dict, label: str) -> list[str]:
    rows = run["minutes"]
    pick = sorted({0, 1, len(rows) // 2, len(rows) - 2, len(rows) - 1} & set(range(len(rows))))
    lines = [f"| {label} minute | median [us] | p99 [us] | p99.9 [us] | max [us] | CPU median [us] | CPU p99.9 [us] "
             "| CPU max [us] | RSS [MB] |", "|---|---|---|---|---|---|---|---|---|"]
    for i in pick:
        r = rows[i]
        lines.append(f"| {r['minute']} | {r['median_us']:.2f} | {r['p99_us']:.2f} | {r['p999_us']:.2f} | "
                     f"{r['max_us']:.1f} | {_us(r, 'cpu_median_us')} | {_us(r, 'cpu_p999_us')} | "
                     f"{_us(r, 'cpu_max_us')} | {r['rss_kb'] / 1024:.2f} |")
    return lines


def _range(r: tuple[float, float]) -> str:
    return "n/a" if math.isnan(r[0]) else f"{r[0]:.2f} - {r[1]:.2f}"


def summary(run: dict) -> dict:
    rows = run["minutes"]
    med = [r["median_us"] for r in rows]
    p999 = [r["p999_us"] for r in rows]
    cpu999 = [r["cpu_p999_us"] for r in rows if "cpu_p999_us" in r] or [math.nan]
    rss = [r["rss_kb"] for r in rows]
    return {"samples": run["samples"], "cpu_s": run["cpu_s"], "wall_s": run["wall_s"], "failed": run["failed"],
            "median_range_us": (min(med), max(med)), "p999_range_us": (min(p999), max(p999)),
            "cpu_p999_range_us": (min(cpu999), max(cpu999)),
            "rss_growth_kb": rss[-1] - rss[0], "end_displacement_m": run["end_displacement_m"],
            "end_velocity_m_s": run["end_velocity_m_s"], "clock_error_s": run["clock_error_s"]}


def markdown(rk4: dict, default: dict, py: dict, command: str) -> str:
    lines = [BEGIN, "## Soak", "",
             f"Made by `{command}` ({time.strftime('%Y-%m-%d')}, this machine, shared by other jobs: wall-time "
             "maxima include preemption). Displacement control of the calibrated rig, a 5 mm 1 Hz + 2 mm "
             "3.7 Hz command for all but the last simulated minute, then 0. Every step is timed "
             "(benchmarks/soak.cpp); RSS is the process's resident set at the end of each minute. The default's "
             "steps are also timed in thread CPU time (without preemption; the clock call adds ~0.5 us); "
             "RK4's steps are too short for that clock (n/a).", "",
             "| run | samples | CPU [s] | failed steps | median per minute [us] | p99.9 per minute [us] | "
             "CPU-time p99.9 per minute [us] | "
             "RSS growth after minute 1 | end displacement [m] | end velocity [m/s] | clock error [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, run in (("real-time option (RK4)", rk4), ("default", default)):
        label = f"{len(run['minutes'])} min, {name}"
        s = summary(run)
        lines.append(f"| {label} | {s['samples']:,} | {s['cpu_s']:.1f} | {s['failed']} | "
                     f"{s['median_range_us'][0]:.2f} - {s['median_range_us'][1]:.2f} | "
                     f"{s['p999_range_us'][0]:.2f} - {s['p999_range_us'][1]:.2f} | "
                     f"{_range(s['cpu_p999_range_us'])} | {s['rss_growth_kb']} kB | "
                     f"{s['end_displacement_m']:.3g} | {s['end_velocity_m_s']:.3g} | {s['clock_error_s']:.3g} |")
    lines += [""] + _minutes_table(rk4, "RK4") + [""] + _minutes_table(default, "default") + [""]
    rss = py["rss"]
    lines += [f"Python: {py['calls']:,} short `sh.simulate` calls (200 samples each) in {py['seconds']:.1f} s; "
              "RSS before and every 100 calls [MB]: " + ", ".join(f"{r['rss_kb'] / 1024:.1f}" for r in rss) +
              f" (growth over the {py['calls']:,} calls: {(rss[-1]['rss_kb'] - rss[0]['rss_kb'])} kB, after 200 "
              "warm-up calls).", END]
    return "\n".join(lines) + "\n"


def write_section(doc: Path, text: str) -> None:
    from servohydraulics.atomic import write_text

    old = doc.read_text() if doc.exists() else ""
    if BEGIN in old and END in old:
        new = old[: old.index(BEGIN)] + text.rstrip("\n") + old[old.index(END) + len(END):]
    else:
        new = old.rstrip("\n") + "\n\n" + text
    write_text(doc, new)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rk4-minutes", type=int, default=60)
    p.add_argument("--default-minutes", type=int, default=10)
    p.add_argument("--calls", type=int, default=1000)
    p.add_argument("--no-write", action="store_true", help="print, do not touch docs/benchmarks.md")
    a = p.parse_args()
    build_dir = ROOT / "build" / "soak"
    exe = build(build_dir)
    # RK4's step (~0.5 us) is as short as the thread-CPU clock call: wall time only.
    rk4 = soak_cpp(exe, "rk4", a.rk4_minutes, build_dir, cpu_time=False)
    default = soak_cpp(exe, "default", a.default_minutes, build_dir, cpu_time=True)
    py = soak_python(a.calls)
    results = {"rk4": rk4, "default": default, "python": py}
    args = " ".join(sys.argv[1:])
    text = markdown(rk4, default, py, "python3 benchmarks/soak.py" + (f" {args}" if args else ""))
    print(text)
    if not a.no_write:
        from servohydraulics.atomic import write_text

        write_text(ROOT / "benchmarks" / "soak.json", json.dumps(results, indent=1))
        write_section(ROOT / "docs" / "benchmarks.md", text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
