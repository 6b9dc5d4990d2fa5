"""Per-step round trip of ``servohydraulics serve`` on loopback with OpenSeesPy's genericClient
as the client (issue 24, item 4): the frame of servohydraulics.distributed.frame, its brace a
remote ideal linear spring, median and p99 of each analysis step's wall time, with the server's
delayed-ACK countermeasure (TCP_QUICKACK after every read) on and off, and the same frame with
the local spring for scale.

    PYTHONPATH=python python benchmarks/serve_latency.py [--steps 400] [--slow-steps 60] [--pin]
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.distributed.frame import linear_specimen_rig, run_frame
from servohydraulics.distributed.server import start_server_process


def measure(rig: Path, steps: int, quickack: bool, dt: float = 0.01, server_cpu: int | None = None) -> np.ndarray:
    args = ["--rig", str(rig), "--actuator", "ideal", "--max-clients", "1"] + ([] if quickack else ["--no-quickack"])
    proc, port = start_server_process(*args, prefix=[] if server_cpu is None else ["taskset", "-c", str(server_cpu)])
    try:
        res = run_frame(port=port, dt=dt, duration=steps * dt)
    finally:
        proc.wait(timeout=60)
    return res["step_seconds"][1:]


def row(name: str, s: np.ndarray) -> str:
    return (f"| {name} | {len(s)} | {1e6 * np.median(s):.0f} | {1e6 * np.percentile(s, 99):.0f} | "
            f"{1e6 * s.max():.0f} |")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=400, help="analysis steps with the countermeasure (default 400)")
    p.add_argument("--slow-steps", type=int, default=60, help="steps without it (each may stall ~40 ms; default 60)")
    p.add_argument("--pin", action="store_true",
                   help="also run with the client on CPU 0 and the server on CPU 1, and both on CPU 0 (taskset)")
    a = p.parse_args()
    pinned = {}
    with tempfile.TemporaryDirectory() as tmp:
        rig = sh.save_rig(linear_specimen_rig(700800.0), Path(tmp) / "linear.toml")
        local = run_frame(local_k=700800.0, duration=a.steps * 0.01)["step_seconds"][1:]
        fast = measure(rig, a.steps, quickack=True)
        slow = measure(rig, a.slow_steps, quickack=False)
        if a.pin:
            mask = os.sched_getaffinity(0)
            try:
                os.sched_setaffinity(0, {0})
                pinned["remote, default, client on CPU 0, server on CPU 1"] = measure(rig, a.steps, True, server_cpu=1)
                pinned["remote, default, client and server on CPU 0"] = measure(rig, a.steps, True, server_cpu=0)
            finally:
                os.sched_setaffinity(0, mask)
    print("| client step (OpenSeesPy analyze(1, dt)) | steps | median [us] | p99 [us] | max [us] |")
    print("|---|---|---|---|---|")
    print(row("local spring (no network)", local))
    print(row("remote, server TCP_NODELAY + TCP_QUICKACK (default)", fast))
    print(row("remote, server TCP_NODELAY only (--no-quickack)", slow))
    for name, s in pinned.items():
        print(row(name, s))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
