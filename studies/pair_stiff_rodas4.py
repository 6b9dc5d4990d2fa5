"""The pair's stiff samples by CVODE, by the second-order Rosenbrock formula or by RODAS4 (docs/benchmarks.md,
"Stop 47").

    python studies/pair_stiff_rodas4.py [--json benchmarks/pair_stiff_rodas4.json]

The diagnosis' dopri5 pair (``diagnosis.engine.run_options``: Hairer's stiffness test and ``stiff_steps`` 100)
redoes a sample it finds stiff by its stiff integrator: CVODE's BDF (the core's default), the second-order
L-stable formula of Shampine and Reichelt (``SolverOptions.stiff_rosenbrock``, ``rosenbrock_order`` 2: stop
46) or Hairer and Wanner's RODAS4 (``rosenbrock_order`` 4: six stages, L-stable, stiffly accurate, with an
embedded third-order solution).  On the first 10 s of the UTFSM 1 A chirp (benchmarks/lab_speed.py's diagnose10)
through the rigs of ``diagnose_run_costs.case_and_rigs`` that turn stiff (Coulomb friction at 700 N, LuGre at its
sigma_0 bound), and on the whole 1 A sweep (51.9 s, lab_speed's sweep1A) through the 0 A rig with the Coulomb
friction of the sweep's round-1 fit (1,063 N: the candidate that took a third of the sweep's time at stop 46), at
the search's rtol (1e-6) and the decisions' (1e-8): the least thread CPU of two runs [s], the samples found stiff,
the steps and right-hand sides, and each run's largest difference from a tight reference (CVODE alone at rtol
1e-10) as a fraction of the measured channel's standard deviation (``engine.agreement``; the fits' test is 1e-3).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))
sys.path.insert(0, str(ROOT / "benchmarks"))

#: the stiff integrators compared: (label, stiff_rosenbrock, rosenbrock_order)
INTEGRATORS = (("CVODE", False, 2), ("order 2", True, 2), ("RODAS4", True, 4))


def cases() -> list:
    """(case name, case, {rig name: rig}) of the comparison."""
    from diagnose_run_costs import case_and_rigs
    from lab_speed import _record

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import LIBRARY

    chirp, rigs = case_and_rigs(lugre_bound=True)
    stiff = {k: v for k, v in rigs.items() if k in ("LuGre sigma_0 1e10, F_c 780", "Coulomb F_c 700")}
    rig0 = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    sweep = engine.make_case(_record("sweep15Hz_1A"), "displacement", "sweep15Hz_1A")
    return [("chirp20Hz_1A [0, 10 s]", chirp, stiff),
            ("sweep15Hz_1A (51.9 s)", sweep, {"Coulomb F_c 1063": LIBRARY["coulomb_friction"].apply(
                rig0, np.array([1063.0]))})]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    from diagnose_run_costs import timed_run

    from servohydraulics.diagnosis import engine
    from servohydraulics.simulate import solver_options

    rows = []
    print("| record | rig | rtol | stiff samples | " + " | ".join(f"{k}: CPU [s] / steps / rhs / gap" for k, _, _
                                                                  in INTEGRATORS) + " |")
    print("|---|---|---|---|" + "---|" * len(INTEGRATORS))
    for record, case, rigs in cases():
        for name, rig in rigs.items():
            ref, _, _ = timed_run(rig, solver_options(method="cvode", rtol=1e-10), case)
            for rtol in (1e-6, 1e-8):
                cells = {}
                for label, rosenbrock, order in INTEGRATORS:
                    opts = engine.run_options(True)
                    opts.rtol, opts.stiff_rosenbrock, opts.rosenbrock_order = rtol, rosenbrock, order
                    sim, cpu, resp = timed_run(rig, opts, case, repeats=2)
                    cells[label] = ({"failed": True, "cpu_s": cpu} if resp is None else
                                    {"cpu_s": cpu, "stiff_samples": resp.work.stiff_samples,
                                     "steps": resp.work.internal_steps, "rhs": resp.work.rhs_evals,
                                     "gap": engine.agreement(sim, ref, case)[0]})
                stiff = next((c["stiff_samples"] for c in cells.values() if "stiff_samples" in c), "-")
                text = " | ".join("failed" if c.get("failed") else
                                  f"{c['cpu_s']:.3f} / {c['steps']:,} / {c['rhs']:,} / {c['gap']:.1e}"
                                  for c in cells.values())
                print(f"| {record} | {name} | {rtol:g} | {stiff} | {text} |", flush=True)
                rows.append({"record": record, "rig": name, "rtol": rtol, **cells})
    if args.json:
        args.json.write_text(json.dumps({"command": "python studies/pair_stiff_rodas4.py "
                                                    + " ".join(argv if argv is not None else sys.argv[1:]),
                                         "reference": "CVODE alone at rtol 1e-10", "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
