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


def case_and_rigs(lugre_bound: bool = False):
    """The record's case (the first 10 s of the UTFSM 1 A chirp, benchmarks/lab_speed.py's ``diagnose10``) and
    the rigs by name: the 0 A rig (evaluation/utfsm_rig_0A.toml) and it with the candidates the diagnosis fits
    there; ``lugre_bound`` adds LuGre at its sigma_0 bound (1e10 N/m, F_c 780 N: diagnose10's round 1 ends there).
    Shared by the studies of run costs (studies/pair_stiff_steps.py, studies/ros2_partial_jacobian.py)."""
    import lab_speed

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.diagnosis.effects import LIBRARY, apply_area

    rec = lab_speed._record("chirp20Hz_1A", 10.0)
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    case = engine.make_case(rec, "displacement", "chirp20Hz_1A[0, 10 s]")
    law = sh._core.mr_damper_law(rig)
    rigs = {"0 A rig": rig, "LuGre sigma_0 3e6, F_c 733": LIBRARY["lugre_friction"].apply(rig, np.array([3e6, 733.0]))}
    if lugre_bound:
        rigs["LuGre sigma_0 1e10, F_c 780"] = LIBRARY["lugre_friction"].apply(rig, np.array([1e10, 780.0]))
    rigs.update({"Coulomb F_c 700": LIBRARY["coulomb_friction"].apply(rig, np.array([700.0])),
                 "MR damper c0 1e6": LIBRARY["mr_damper"].apply(rig, np.array([law["alpha"], 1e6, law["c1"]])),
                 "actuator A x30": apply_area(rig, 30.0 * rig.A)})
    return case, rigs


def timed_run(rig, opts, case, repeats: int = 1):
    """The run of the case's command through ``rig`` by ``opts``: (its compared channels, the least thread CPU
    of ``repeats`` runs [s], the Response); (None, the CPU until it failed, None) when the run fails."""
    from servohydraulics.diagnosis import engine
    from servohydraulics.identification.run import simulate_command
    from servohydraulics.simulate import SimulationError

    best, sim = None, None
    for _ in range(repeats):
        t = time.thread_time()
        try:
            sim = simulate_command(rig, "displacement", case.u, case.dt, case.x0_data, opts)
        except SimulationError:
            return None, time.thread_time() - t, None
        dt = time.thread_time() - t
        best = dt if best is None else min(best, dt)
    return {c: sim.channels[c] for c in engine.SIM_CHANNELS}, best, sim


def main() -> None:
    from servohydraulics.diagnosis import engine
    from servohydraulics.identification.fit import rk4_options

    case, rigs = case_and_rigs()
    columns = [(f"RK4 {n}", rk4_options(n)) for n in (3, 4, 6, 8, 12, 32)] + \
              [(f"ROS2 {n}", engine.ros2_options(n)) for n in (8, 16, 32)]
    print("| rig | pair (rtol 1e-6) [s] | " + " | ".join(f"{c} [s] / gap" for c, _ in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for name, r in rigs.items():
        ref, tp, _ = timed_run(r, engine.run_options(True), case)
        cells = []
        for _, opts in columns:
            s, t, _ = timed_run(r, opts, case)
            cells.append("diverged" if s is None else f"{t:.3f} / {engine.agreement(s, ref, case)[0]:.1e}")
        print(f"| {name} | {tp:.3f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
