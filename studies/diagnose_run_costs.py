"""What one search run of the diagnosis costs, by candidate and integrator (docs/benchmarks.md, lab-speed).

    python studies/diagnose_run_costs.py

The first 10 s of the UTFSM chirp at 1 A (benchmarks/lab_speed.py's ``diagnose10`` record) through
the 0 A rig (evaluation/utfsm_rig_0A.toml) and through it with a candidate the diagnosis fits there
(LuGre friction at sigma_0 = 3e6 N/m, F_c = 733 N; Coulomb friction at 700 N; the MR damper's c0 at
1e6 N s/m; the actuator re-sized 30 times by the load term ``A``, its upper bound): the CPU seconds of
the search's pair (dopri5 at rtol 1e-6, ``engine.run_options(True)``), of RK4 at 3 to 32 substeps and
of ROS2 at 8, 16 and 32 (``engine.ros2_options``), and each fixed-step run's largest difference from
the pair's as a fraction of the measured channel's standard deviation (``engine.agreement``;
``segments.AGREEMENT`` = 1e-3 is the fits' test), or "diverged".
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def main() -> None:
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import LIBRARY, apply_area
    from servohydraulics.identification.fit import rk4_options
    from servohydraulics.identification.run import simulate_command
    from servohydraulics.simulate import SimulationError

    rec = lab_speed._record("chirp20Hz_1A", 10.0)
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    case = engine.make_case(rec, "displacement", "chirp20Hz_1A[0, 10 s]")
    law = sh._core.mr_damper_law(rig)
    alpha = law["alpha"]
    rigs = {"0 A rig": rig, "LuGre sigma_0 3e6, F_c 733": LIBRARY["lugre_friction"].apply(rig, np.array([3e6, 733.0])),
            "Coulomb F_c 700": LIBRARY["coulomb_friction"].apply(rig, np.array([700.0])),
            "MR damper c0 1e6": LIBRARY["mr_damper"].apply(rig, np.array([alpha, 1e6, law["c1"]])),
            "actuator A x30": apply_area(rig, 30.0 * rig.A)}

    def run(r, opts):
        t = time.thread_time()
        try:
            s = simulate_command(r, "displacement", case.u, case.dt, case.x0_data, opts)
        except SimulationError:
            return None, time.thread_time() - t
        return {c: s.channels[c] for c in engine.SIM_CHANNELS}, time.thread_time() - t

    columns = [(f"RK4 {n}", rk4_options(n)) for n in (3, 4, 6, 8, 12, 32)] + \
              [(f"ROS2 {n}", engine.ros2_options(n)) for n in (8, 16, 32)]
    print("| rig | pair (rtol 1e-6) [s] | " + " | ".join(f"{c} [s] / gap" for c, _ in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for name, r in rigs.items():
        ref, tp = run(r, engine.run_options(True))
        cells = []
        for _, opts in columns:
            s, t = run(r, opts)
            cells.append("diverged" if s is None else f"{t:.3f} / {engine.agreement(s, ref, case)[0]:.1e}")
        print(f"| {name} | {tp:.3f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
