"""Would a quasi-Newton Jacobian bring identify under its 10 s (issue 25, item 6)?  A study, not the default.

    python studies/identify_quasi_newton.py [--refresh 1,2,3,0] [--json FILE]

``servohydraulics identify chirp20Hz_0A.csv --mode displacement --specimen mr_damper`` (benchmarks/
lab_speed.py's ``identify`` case, the UTFSM 61.5 s chirp at 0 A) with the time stage's Jacobian
(``identification.fit.forward_jacobian``, forward differences: one run per key) replaced inside each
block fit by Broyden's rank-one update, J+ = J + (df - J dz) dz' / (dz' dz) between the points where
``least_squares`` asks for it (its residuals there are the target's cached runs: no run), by forward
differences again every ``refresh``-th time (1: forward differences throughout, the package's own
rule; 0: only at the fit's start).  The first Jacobian of every block fit and the final one of the
intervals (``fit.jacobian_at``) stay forward differences, so the intervals are computed by the same
rule.  Printed per refresh: the wall and CPU time of the whole command (writing its report and figures
included), the runs of the core, the identified values and NRMSEs against refresh 1, each value's
change in its own standard errors.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


class Broyden:
    """``fit.forward_jacobian`` by Broyden's update between forward-difference refreshes, per problem."""

    def __init__(self, inner, refresh: int) -> None:
        self.inner, self.refresh = inner, int(refresh)
        self.state: dict = {}
        self.lock = threading.Lock()
        self.differences = self.updates = 0

    def __call__(self, fun, z, f0, hi, workers, many=None):
        key = id(fun)
        with self.lock:
            prev = self.state.get(key)
        z, f0 = np.asarray(z, float).copy(), np.asarray(f0, float).copy()
        if prev is None or prev["fun"] is not fun or (self.refresh > 0 and prev["count"] % self.refresh == 0):
            J = self.inner(fun, z, f0, hi, workers, many)
            self.differences += 1
        else:
            dz, df = z - prev["z"], f0 - prev["f"]
            J = prev["J"].copy()
            d2 = float(dz @ dz)
            if d2 > 0:
                J += np.outer(df - J @ dz, dz) / d2
            self.updates += 1
        count = 1 if prev is None or prev["fun"] is not fun else prev["count"] + 1
        with self.lock:
            self.state[key] = {"fun": fun, "z": z, "f": f0, "J": J, "count": count}
        return J


def run(refresh: int) -> dict:
    import lab_speed

    from servohydraulics import cli
    from servohydraulics.identification import fit

    counter = lab_speed.Counters()
    saved = fit.forward_jacobian
    qn = Broyden(saved, refresh) if refresh != 1 else None
    if qn is not None:
        fit.forward_jacobian = qn
    try:
        with tempfile.TemporaryDirectory() as tmp, lab_speed.instrumented(counter), lab_speed._quiet():
            t0, c0 = time.perf_counter(), lab_speed._cpu_seconds()
            code = cli.main(["identify", str(lab_speed.DATA / "chirp20Hz_0A.csv"), "--mode", "displacement",
                             "--specimen", "mr_damper", "--out", tmp, "--quiet"])
            wall, cpu = time.perf_counter() - t0, lab_speed._cpu_seconds() - c0
            if code != 0:
                raise SystemExit(f"identify exited {code}")
            js = json.loads((Path(tmp) / "identification.json").read_text())
    finally:
        fit.forward_jacobian = saved
    return {"refresh": refresh, "wall_s": wall, "cpu_s": cpu, "runs": counter.sims,
            "differences": qn.differences if qn else None, "updates": qn.updates if qn else 0,
            "values": {k: p["value"] for k, p in js["parameters"].items()},
            "std": {k: p["std"] for k, p in js["parameters"].items()},
            "nrmse": js["records"][0]["after"], "kept": js["kept"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refresh", default="1,2,3,0", help="comma-separated refresh counts (1: the package's own)")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    rows = [run(int(r)) for r in args.refresh.split(",")]
    ref = next((r for r in rows if r["refresh"] == 1), rows[0])
    print("| refresh | wall [s] | CPU [s] | runs | FD / Broyden Jacobians | NRMSE x / F [%] | largest change "
          "[its sd] |\n|---|---|---|---|---|---|---|")
    for r in rows:
        moves = [abs(r["values"][k] - v) / ref["std"][k] for k, v in ref["values"].items()
                 if ref["std"].get(k) not in (None, 0) and np.isfinite(ref["std"][k])]
        worst = max(moves) if moves else float("nan")
        fd = "all" if r["differences"] is None else f"{r['differences']} / {r['updates']}"
        print(f"| {r['refresh'] or 'start only'} | {r['wall_s']:.1f} | {r['cpu_s']:.1f} | {r['runs']} | {fd} | "
              f"{r['nrmse']['displacement']:.4f} / {r['nrmse']['force']:.4f} | {worst:.2f} |")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
