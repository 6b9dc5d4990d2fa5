"""How the diagnosed model's displacement gap on a UTFSM record moves with the actuator's size (docs/diagnose.md,
issue 25 item 2, the May runs).

    python studies/utfsm_area_displacement.py [--run may_0A_to_1A] [--out build/utfsm25] [--ratios 1,3.33,33.3]

Reads the diagnosed rig of an ``evaluation/utfsm_diagnose.py --run LABEL --out OUT`` run (OUT/LABEL/
rig_updated.toml), re-sizes its actuator by each ratio with the diagnosis' own load term
(``effects.apply_area``: A with K_v, K_a, C_l and F_cap, the loop's no-load response kept, what a force costs
the displacement scaled by 1 / A) and prints the displacement and force gaps (rms(measured - simulated) /
rms(measured), the record's command alone driving the model, the initial displacement refined as the
diagnosis does) on the run's diagnosed record, beside the nominal rig's.  A ratio of 1 is the diagnosed model
itself; large ratios take the load coupling away (an ideal displacement source with the same no-load loop).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"


def main() -> None:
    sys.path.insert(0, str(ROOT / "evaluation"))
    from utfsm_diagnose import RUNS

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import apply_area
    from servohydraulics.records import read_record

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--run", default="may_0A_to_1A", choices=[r[0] for r in RUNS])
    p.add_argument("--out", default="build/utfsm25", help="the runs' folder (OUT of utfsm_diagnose.py --run)")
    p.add_argument("--ratios", default="1,3.33,33.3", help="comma-separated multiples of the diagnosed area")
    a = p.parse_args()
    try:
        ratios = [float(v) for v in a.ratios.split(",")]
    except ValueError:
        p.error(f"--ratios {a.ratios!r}: not comma-separated numbers")
    if not ratios or any(not r > 0 for r in ratios):
        p.error(f"--ratios {a.ratios!r}: each must be > 0")
    label, rig_from, record = next(r for r in RUNS if r[0] == a.run)
    diagnosed = Path(a.out) / label / "rig_updated.toml"
    if not diagnosed.exists():
        p.error(f"{diagnosed} is absent: run `python evaluation/utfsm_diagnose.py --run {label} --end 0 --out {a.out}`")
    path = DATA / f"{record}.csv"
    if not path.exists():
        p.error(f"record {path} is absent: the UTFSM data live in ../shared/real-data (or $SH_SHARED_DIR)")
    rig = sh.load_rig(diagnosed)
    nominal = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{rig_from}.toml")
    cases = [engine.make_case(read_record(path), "displacement", record)]

    def gaps(r) -> dict:
        x0 = engine.refine_x0(r, cases, 0.0)
        return engine.gap(engine.simulate_all(r, cases, 0.0, x0), cases)

    g = gaps(nominal)
    print(f"{label}: `{record}` through the rig of `{rig_from}` (displacement / force gap, %)")
    print("| model | A / nominal A | displacement | force |\n|---|---|---|---|")
    print(f"| nominal | 1 | {100 * g['displacement']:.2f} | {100 * g['force']:.1f} |")
    for q in ratios:
        r = apply_area(rig, rig.A * q) if q != 1.0 else rig
        g = gaps(r)
        print(f"| diagnosed, A x{q:g} | {r.A / nominal.A:.3g} | {100 * g['displacement']:.2f} | "
              f"{100 * g['force']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
