"""The pair's stiff samples by CVODE or by the error-controlled Rosenbrock (docs/benchmarks.md, "Stop 46").

    python studies/pair_stiff_rosenbrock.py [--json benchmarks/pair_stiff_rosenbrock.json]

The dopri5 pair redoes a sample it finds stiff (past ``stiff_steps`` steps in it) by its stiff integrator:
CVODE's BDF (the core's default), which restarts at order 1 with a small first step at every sample's
input jump, or (``SolverOptions.stiff_rosenbrock``) the second-order L-stable Rosenbrock formula of Shampine
and Reichelt (1997) with its third-order error estimate, a one-step method that carries its step from
sample to sample.  For the first 10 s of the UTFSM 1 A chirp (benchmarks/lab_speed.py's diagnose10) through
the 0 A rig and through it with the candidates the diagnosis fits there (``diagnose_run_costs.case_and_rigs``),
at the search's rtol (1e-6) and the decisions' (1e-8), both at the diagnosis' ``stiff_steps`` of 100: the
least thread CPU of three runs [s], the samples the pair found stiff, the steps and right-hand sides, and
each run's largest difference from the reference (CVODE's pair at rtol 1e-8, the decisions' run) as a
fraction of the measured channel's standard deviation (``engine.agreement``; the fits' test is 1e-3).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    from diagnose_run_costs import case_and_rigs, timed_run

    from servohydraulics.diagnosis import engine

    case, rigs = case_and_rigs(lugre_bound=True)
    rows = []
    print("| rig | rtol | stiff samples | CVODE: CPU [s] / steps / rhs / gap | Rosenbrock: CPU [s] / steps / rhs / gap "
          "| CPU ratio |")
    print("|---|---|---|---|---|---|")
    for name, rig in rigs.items():
        ref_opts = engine.run_options(False)
        ref_opts.stiff_rosenbrock = False
        ref, _, _ = timed_run(rig, ref_opts, case)
        for rtol in (1e-6, 1e-8):
            cells = {}
            for label, ros2 in (("cvode", False), ("rosenbrock", True)):
                opts = engine.run_options(True)
                opts.rtol, opts.stiff_rosenbrock = rtol, ros2
                sim, cpu, resp = timed_run(rig, opts, case, repeats=3)
                if resp is None:
                    cells[label] = {"failed": True, "cpu_s": cpu}
                    continue
                cells[label] = {"cpu_s": cpu, "stiff_samples": resp.work.stiff_samples,
                                "steps": resp.work.internal_steps, "rhs": resp.work.rhs_evals,
                                "gap": engine.agreement(sim, ref, case)[0]}
            c, r = cells["cvode"], cells["rosenbrock"]

            def fmt(d):
                if d.get("failed"):
                    return "failed"
                return f"{d['cpu_s']:.3f} / {d['steps']:,} / {d['rhs']:,} / {d['gap']:.1e}"

            ratio = (f"{c['cpu_s'] / r['cpu_s']:.2f}" if not (c.get("failed") or r.get("failed")) else "-")
            print(f"| {name} | {rtol:g} | {c.get('stiff_samples', '-')} | {fmt(c)} | {fmt(r)} | {ratio} |", flush=True)
            rows.append({"rig": name, "rtol": rtol, "cvode": c, "rosenbrock": r})
    if args.json:
        args.json.write_text(json.dumps({"command": "python studies/pair_stiff_rosenbrock.py "
                                                    + " ".join(argv if argv is not None else sys.argv[1:]),
                                         "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
