"""What the exact Coulomb law (``v_stick = 0``) costs a run, and how far the regularised law is from it
(docs/benchmarks.md, lab speed; docs/model.md).

    python studies/exact_coulomb_cost.py [--repeats 3]

The first 10 s of the UTFSM chirp at 1 A (benchmarks/lab_speed.py's ``diagnose10`` record) through the
0 A rig (evaluation/utfsm_rig_0A.toml) with Coulomb friction of 780 N (the level the diagnosis fits
there), the friction regularised at v_stick = 1e-4 (the rig's), 1e-5 and 1e-6 m/s, and exact
(v_stick = 0): for each, the thread CPU seconds of a run (the least of ``--repeats``) by the search's
pair (dopri5 at rtol 1e-6, ``engine.run_options(True)``), the decisions' pair (rtol 1e-8), RK4 at 4
and 8 substeps and ROS2 at 8 (``engine.ros2_options``), and on the rig's own law (v_stick = 1e-4) CVODE alone
at rtol 1e-6 restarted at every sample (the core's default: a held command's change is a discontinuity) and
never restarted (``restart="never"``: its history carried across the samples), the run's internal steps, and its rms and
largest difference from the exact law's rtol-1e-8 run on displacement and force, as fractions of the
measured channel's standard deviation; then the substeps per sample of RK4 at 4 on the exact law (a
switch re-integrates its stretch: a real-time step's cost).  RK4 is not run on the regularised law: it diverges there
(studies/diagnose_run_costs.py).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

F_C = 780.0  # [N]
V_STICKS = (1e-4, 1e-5, 1e-6, 0.0)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeats", type=int, default=3, help="runs per cell; the least CPU time is printed")
    a = p.parse_args()
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.identification.fit import rk4_options
    from servohydraulics.identification.run import simulate_command

    rec = lab_speed._record("chirp20Hz_1A", 10.0)
    case = engine.make_case(rec, "displacement", "chirp20Hz_1A[0, 10 s]")
    integrators = [("pair 1e-6", engine.run_options(True)), ("pair 1e-8", engine.run_options(False)),
                   ("RK4 x4", rk4_options(4)), ("RK4 x8", rk4_options(8)), ("ROS2 x8", engine.ros2_options(8))]
    # CVODE alone on the rig's own law: does carrying its history across the samples save the restarts' steps?
    cvode = {"method": "cvode", "rtol": 1e-6, "stiff_check": False}
    cvode_rows = [("CVODE 1e-6, restarted each sample", sh.solver_options(**cvode)),
                  ("CVODE 1e-6, never restarted", sh.solver_options(**cvode, restart="never"))]

    def rig_with(v_stick: float):
        r = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
        e = r.effects
        e.coulomb_friction = True
        r.effects = e
        r.F_c, r.v_stick = F_C, v_stick
        return r

    def run(r, opts):
        best, out = np.inf, None
        for _ in range(a.repeats):
            t = time.thread_time()
            out = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, opts)
            best = min(best, time.thread_time() - t)
        return out, best

    ref, _ = run(rig_with(0.0), engine.run_options(False))
    sd = {c: float(np.std(np.asarray(rec.channels[c]))) for c in ("displacement", "force")}
    print(f"UTFSM 0 A rig + Coulomb friction {F_C:g} N, chirp20Hz_1A [0, 10 s]; differences from the exact "
          "law's rtol-1e-8 run, rms / largest, as fractions of the measured channel's standard deviation\n")
    print("| v_stick [m/s] | integrator | CPU [s] | internal steps | displacement rms / max | force rms / max |")
    print("|---|---|---|---|---|---|")
    for vs in V_STICKS:
        r = rig_with(vs)
        for name, opts in integrators + (cvode_rows if vs == 1e-4 else []):
            if vs > 0 and name.startswith("RK4"):
                continue
            out, cpu = run(r, opts)
            cells = []
            for c in ("displacement", "force"):
                d = (np.asarray(out.channels[c]) - np.asarray(ref.channels[c])) / sd[c]
                cells.append(f"{np.sqrt(np.mean(d ** 2)):.2g} / {np.max(np.abs(d)):.2g}")
            label = "0 (exact)" if vs == 0 else f"{vs:g}"
            print(f"| {label} | {name} | {cpu:.3f} | {out.work.internal_steps:,} | {cells[0]} | {cells[1]} |",
                  flush=True)
    # what a real-time step costs: a switch re-integrates its stretch, so RK4's cost per sample is no longer fixed
    out, _ = run(rig_with(0.0), rk4_options(4))
    steps = np.asarray(out.channels["internal_steps"])
    plain = int(np.median(steps))
    print(f"\nRK4 x4 on the exact law, per sample: {plain} substeps in a sample without a switch; "
          f"{int(np.sum(steps > plain))} of {steps.size:,} samples switched, the most substeps in one "
          f"{int(steps.max())}")


if __name__ == "__main__":
    main()
