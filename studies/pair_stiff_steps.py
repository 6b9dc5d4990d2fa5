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
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def main() -> int:
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import LIBRARY, apply_area
    from servohydraulics.identification.run import simulate_command

    rec = lab_speed._record("chirp20Hz_1A", 10.0)
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    case = engine.make_case(rec, "displacement", "chirp20Hz_1A[0, 10 s]")
    law = sh._core.mr_damper_law(rig)
    rigs = {"0 A rig": rig,
            "LuGre sigma_0 3e6, F_c 733": LIBRARY["lugre_friction"].apply(rig, np.array([3e6, 733.0])),
            "LuGre sigma_0 1e10, F_c 780": LIBRARY["lugre_friction"].apply(rig, np.array([1e10, 780.0])),
            "Coulomb F_c 700": LIBRARY["coulomb_friction"].apply(rig, np.array([700.0])),
            "MR damper c0 1e6": LIBRARY["mr_damper"].apply(rig, np.array([law["alpha"], 1e6, law["c1"]])),
            "actuator A x30": apply_area(rig, 30.0 * rig.A)}
    counts = (24, 100, 400)
    print("| rtol | rig | " + " | ".join(f"stiff_steps {n}: CPU [s] / CVODE samples / gap" for n in counts) + " |")
    print("|---|---|" + "---|" * len(counts))
    for search in (True, False):
        for name, r in rigs.items():
            cells, ref = [], None
            for n in counts:
                opts = engine.run_options(search)
                opts.stiff_steps = n
                best = None
                for _ in range(2):
                    t = time.thread_time()
                    s = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, opts)
                    best = min(best or np.inf, time.thread_time() - t)
                sim = {c: s.channels[c] for c in engine.SIM_CHANNELS}
                ref = sim if ref is None else ref
                cells.append(f"{best:.3f} / {s.work.stiff_samples} / {engine.agreement(sim, ref, case)[0]:.1e}")
            print(f"| {opts.rtol:g} | {name} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
