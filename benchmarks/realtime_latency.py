"""How well this machine paces the loop to the wall clock, at the paper's 2 kHz
and the RTHS benchmark's 4096 Hz (docs/realtime.md publishes the table).

    PYTHONPATH=python python benchmarks/realtime_latency.py [--seconds 10] [--example build/ex/10_realtime_eft]
        [--cyclictest] [--out benchmarks/realtime_latency.json]

For each rate, two runs of ``servohydraulics latency`` (the Python Pacer with one
step of the paper's plant in the loop): as an ordinary process, and asking for
SCHED_FIFO 80, mlockall and CPU 1 (granted or refused, the table says which).
With ``--example``, the C++ EFT loop (examples/10_realtime_eft) runs the same
pairs; with ``--cyclictest``, cyclictest itself (rt-tests) does, for comparison.
Each run is bounded (--seconds, default 10).  The figures are what this machine
gives, misses included; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from servohydraulics.commands.latency import measure, table  # noqa: E402

RATES = (2000.0, 4096.0)
ASK = {"fifo": 80, "cpu": 1, "mlock": True}


def _example(path: str, rate: float, seconds: float, ask: bool) -> dict:
    """One run of the C++ example, parsed into measure()'s shape."""
    argv = [path, f"{rate:g}", f"{seconds:g}"]
    if ask:
        argv += ["--fifo", str(ASK["fifo"]), "--cpu", str(ASK["cpu"]), "--mlock"]
    res = subprocess.run(argv, capture_output=True, text=True, timeout=seconds * 10 + 60)
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed ({res.returncode}): {res.stderr.strip()}")
    kv = dict(line.split("=", 1) for line in res.stdout.splitlines() if "=" in line and " " not in line.split("=")[0])

    def pct(name: str) -> dict:
        return {"min": float(kv[f"{name}_us_min"]), "p50": float(kv[f"{name}_us_p50"]),
                "p99": float(kv[f"{name}_us_p99"]), "p99.9": float(kv[f"{name}_us_p999"]),
                "max": float(kv[f"{name}_us_max"])}

    out = {"rate_hz": rate, "seconds": seconds, "step": "EFT loop (C++)", "samples": int(kv["samples"]),
           "misses": int(kv["deadline_misses"]), "latency_us": pct("wakeup_latency"), "compute_us": pct("compute")}
    for name in ("fifo", "mlockall", "cpu_affinity"):
        out[f"{name}_reason"] = kv[name]
        out[name] = kv[name].startswith("granted")
    return out


def _cyclictest(rate: float, seconds: float, ask: bool) -> dict | None:
    """cyclictest itself (rt-tests) at the nearest whole-us interval, percentiles from
    its 1 us histogram (nearest rank; samples beyond the histogram count as its end)."""
    exe = shutil.which("cyclictest")
    if exe is None:
        return None
    interval = round(1e6 / rate)
    n = round(seconds * rate)
    argv = [exe, "-q", "-m", "-t", "1", "-i", str(interval), "-l", str(n), "-h", "20000"]
    if ask:
        argv += ["-p", str(ASK["fifo"]), "-a", str(ASK["cpu"])]
    res = subprocess.run(argv, capture_output=True, text=True, timeout=seconds * 10 + 60)
    counts, info = [], {}
    for line in res.stdout.splitlines():
        if line[:1].isdigit():
            us, c = line.split()[:2]
            counts.append((int(us), int(c)))
        elif line.startswith("# ") and ":" in line:
            key, _, value = line[2:].partition(":")
            info[key.strip()] = value.split()[0] if value.split() else ""
    if res.returncode != 0 or "Total" not in info:
        return {"step": "cyclictest", "error": (res.stderr or res.stdout).strip()[-300:]}
    overflow = int(info.get("Histogram Overflows", 0))
    total = sum(c for _, c in counts) + overflow

    def q(p: float) -> float:
        rank, seen = max(1, -(-int(p * 1000) * total // 1000)), 0
        for us, c in counts:
            seen += c
            if seen >= rank:
                return float(us)
        return float(counts[-1][0] + 1)

    lat = {"min": float(info["Min Latencies"]), "p50": q(0.5), "p99": q(0.99), "p99.9": q(0.999),
           "max": float(info["Max Latencies"])}
    return {"rate_hz": 1e6 / interval, "seconds": seconds, "step": "cyclictest (C, no work)", "samples": total,
            "misses": None, "latency_us": lat, "compute_us": None, "command": " ".join(argv[1:]),
            "fifo": ask, "fifo_reason": "cyclictest -p" if ask else "not requested",
            "mlockall": True, "mlockall_reason": "cyclictest -m",
            "cpu_affinity": ask, "cpu_affinity_reason": "cyclictest -a" if ask else "not requested"}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=10.0, help="length of each run [s] (default 10)")
    p.add_argument("--example", default=None, help="path of the built examples/10_realtime_eft (optional)")
    p.add_argument("--cyclictest", action="store_true", help="also run cyclictest (rt-tests) with the same settings")
    p.add_argument("--out", default=str(ROOT / "benchmarks" / "realtime_latency.json"))
    args = p.parse_args()

    load_before = os.getloadavg()
    rows = []
    for rate in RATES:
        for ask in (False, True):
            kw = ASK if ask else {}
            rows.append(measure(rate, args.seconds, plant=True, **kw) | {"step": "Python loop, plant step"})
            print(table(rows[-1:]).splitlines()[-1], flush=True)
            if args.example:
                rows.append(_example(args.example, rate, args.seconds, ask))
                print(table(rows[-1:]).splitlines()[-1], flush=True)
            if args.cyclictest:
                row = _cyclictest(rate, args.seconds, ask)
                if row is None:
                    print("cyclictest is not installed (apt-get install rt-tests): skipped")
                elif "error" in row:
                    print(f"cyclictest failed: {row['error']}")
                else:
                    rows.append(row)
                    print(table(rows[-1:]).splitlines()[-1], flush=True)
    result = {
        "command": "PYTHONPATH=python python benchmarks/realtime_latency.py " + " ".join(sys.argv[1:]),
        "machine": {"kernel": platform.release(), "kernel_version": platform.version(), "cpus": os.cpu_count(),
                    "realtime_kernel": Path("/sys/kernel/realtime").exists(),
                    "load_average_1_5_15_min_before": load_before, "load_average_1_5_15_min_after": os.getloadavg()},
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
        "runs": rows,
    }
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print()
    print(table(rows))
    for r in rows:
        for name in ("fifo", "mlockall", "cpu_affinity"):
            if not r[name] and r[f"{name}_reason"] != "not requested":
                print(f"{r['rate_hz']:g} Hz {r['step']}: {name}: {r[f'{name}_reason']}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
