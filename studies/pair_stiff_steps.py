"""When does the diagnosis' error-controlled pair hand a sample to CVODE, and what does it cost?  (issue 25,
item 6; docs/benchmarks.md, stop 45)

    python studies/pair_stiff_steps.py

dopri5 redoes a sample by CVODE once it has taken more than ``stiff_steps`` steps in it (the core's default
24; ``diagnosis.engine.STIFF_STEPS`` sets it for the diagnosis' runs).  Past 24 steps a sample may be stiff
(a sharp friction law on a light structure) or only accuracy-limited (a fast, lightly damped oil column:
the 0 A rig re-sized x30 by the load term, where the sweep's loop re-fit ends).  For the rigs of
``studies/diagnose_run_costs.py`` (the first 10 s of the UTFSM 1 A chirp through the 0 A rig and through it
with the diagnosis' candidates, LuGre at its 1e10 N/m bound added), at the search's tolerance (rtol 1e-6) and
the decisions' (1e-8): the thread CPU [s] of the pair at stiff_steps 24, 100 and 400, the samples CVODE took,
and the largest difference from the run at 24 as a fraction of the measured channel's standard deviation
(``engine.agreement``).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "studies"))


def main() -> int:
    from diagnose_run_costs import case_and_rigs, timed_run

    from servohydraulics.diagnosis import engine

    case, rigs = case_and_rigs(lugre_bound=True)
    counts = (24, 100, 400)
    print("| rtol | rig | " + " | ".join(f"stiff_steps {n}: CPU [s] / CVODE samples / gap" for n in counts) + " |")
    print("|---|---|" + "---|" * len(counts))
    for search in (True, False):
        for name, r in rigs.items():
            cells, ref = [], None
            for n in counts:
                opts = engine.run_options(search)
                opts.stiff_steps = n
                sim, best, response = timed_run(r, opts, case, repeats=2)
                if sim is None:
                    cells.append("failed")
                    continue
                ref = sim if ref is None else ref
                cells.append(f"{best:.3f} / {response.work.stiff_samples} / {engine.agreement(sim, ref, case)[0]:.1e}")
            print(f"| {opts.rtol:g} | {name} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
