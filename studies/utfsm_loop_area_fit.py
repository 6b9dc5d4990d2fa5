"""The loop (K_v, f_v, zeta_v) and the actuator's size A fitted together on the displacement channel alone, the
diagnosed damper held, on a UTFSM run of evaluation/utfsm_diagnose.py (docs/diagnose.md, issue 25 item 2, the
May 0 A -> 1 A run): can any setting of the loop and the load term give the nominal model's displacement back?

    python studies/utfsm_loop_area_fit.py [--run may_0A_to_1A] [--out build/utfsm25] [--start-ratios 30,5]

Reads OUT/RUN/rig_updated.toml (the diagnosed rig) and the run's record, and fits, from each start (A as a
multiple of the nominal rig's, the loop at the diagnosed rig's values), the loop's three parameters and A
(``effects.apply_area``: the loop's no-load response kept) by the diagnosis' own fit (``engine.fit``, the force
channel weighted 0), then prints the fitted A ratio and both channels' gaps beside the nominal's and the
diagnosed model's.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"


def main() -> None:
    sys.path.insert(0, str(ROOT / "evaluation"))
    from utfsm_diagnose import RUNS

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine, workflow
    from servohydraulics.diagnosis.joint import LOOP
    from servohydraulics.records import read_record

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--run", default="may_0A_to_1A", choices=[r[0] for r in RUNS])
    p.add_argument("--out", default="build/utfsm25", help="the runs' folder (OUT of utfsm_diagnose.py --run)")
    p.add_argument("--start-ratios", default="30,5", help="comma-separated starts of A, multiples of the nominal's")
    a = p.parse_args()
    label, rig_from, record = next(r for r in RUNS if r[0] == a.run)
    path = DATA / f"{record}.csv"
    updated = Path(a.out) / label / "rig_updated.toml"
    for f in (path, updated):
        if not f.exists():
            raise SystemExit(f"{f} is absent (the record: ../shared/real-data; the rig: run "
                             f"evaluation/utfsm_diagnose.py --run {label} --end 0 --out {a.out} first)")
    try:
        ratios = [float(v) for v in a.start_ratios.split(",")]
    except ValueError:
        raise SystemExit(f"invalid --start-ratios {a.start_ratios!r}: comma-separated numbers") from None
    nominal = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{rig_from}.toml")
    rig = sh.load_rig(updated)
    setup = workflow._prepare([read_record(path)], nominal, "displacement", None, workflow.KEEP, True, True, None)
    cases = setup.cases

    def run(r):
        x0 = engine.refine_x0(r, cases, 0.0)
        sims = engine.simulate_all(r, cases, 0.0, x0)
        return x0, sims, engine.gap(sims, cases)

    pct = lambda g: f"displacement {100 * g['displacement']:.3f} %, force {100 * g['force']:.2f} %"  # noqa: E731
    print(f"nominal rig: {pct(run(nominal)[2])}")
    x0, sims, g = run(rig)
    print(f"diagnosed rig (A x{rig.A / nominal.A:.3g}): {pct(g)}")
    ctx = workflow._context(setup, workflow._State(rig=rig, tau=0.0, x0=tuple(x0), sims=sims))
    space = engine.Space(LOOP, ctx, (("A", "m^2"),))
    weights = {(c.name, ch): 0.0 for c in cases for ch in c.meas if ch != "displacement"}
    for ratio in ratios:
        t0 = time.time()
        z0 = space.absent.copy()
        z0[-1] = 1.0 / (ratio * nominal.A)  # A is fitted as 1 / A (its range reaches "no load coupling")
        res = engine.fit(space, cases, z0, 0.0, "all", x0, max_nfev=30, weights=weights)
        rig1, tau1 = space.rig_and_tau(res.z, 0.0)
        g1 = engine.gap(engine.simulate_all(rig1, cases, tau1, res.x0), cases)
        bound = 1.0 / (space.lo[-1] * nominal.A)
        print(f"start A x{ratio:g}: fitted A x{rig1.A / nominal.A:.3g} (bound x{bound:.3g}), "
              f"K_v {rig1.K_v:.4g}, f_v {rig1.f_v:.4g} Hz, zeta_v {rig1.zeta_v:.3g}: {pct(g1)} "
              f"({time.time() - t0:.0f} s, {res.nfev} evaluations)")


if __name__ == "__main__":
    main()
