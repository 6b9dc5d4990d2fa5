"""ROS2 with W from the structure's and the oil column's block of the Jacobian only: does a cheaper
linearly implicit step agree with the pair on the diagnosis' stiff rigs?  (issue 25, item 6; a study
of a core change that is not in the package: its patch is beside this file.)

    git apply studies/ros2_partial_jacobian.patch          # the core with the option
    cmake --build build/dev --target _core                 # (any build of the core with the patch)
    SERVOHYDRAULICS_CORE_DIR=build/dev python studies/ros2_partial_jacobian.py
    git apply -R studies/ros2_partial_jacobian.patch       # back to the package's core

The patch adds ``SolverOptions.ros2_partial_jacobian``: ROS2 (a W-method, second order for any W)
with W = I - gamma h J_S, J_S the Jacobian's rows and columns of the velocity, the pressure, LuGre's
bristle and the specimens' states by forward differences of the right-hand side (1e-7 of each
state's scale), the displacement, the valve's spool and the drive elements explicit: a k x k solve
(k = 2-4) instead of the whole Jacobian and an n x n LU at every substep.

The rigs and the record are ``studies/diagnose_run_costs.py``'s (the first 10 s of the UTFSM 1 A
chirp through the 0 A rig, and through it with the candidates the diagnosis fits there), with
LuGre at its bound sigma_0 = 1e10 N/m added (diagnose10's round 1 ends there).  Each cell: the
least thread CPU of two runs [s] / the largest difference from the search's pair (dopri5 at rtol
1e-6) as a fraction of the measured channel's standard deviation (``engine.agreement``; the fits'
test is 1e-3).
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
    from servohydraulics.identification.fit import rk4_options

    if not hasattr(engine.ros2_options(8), "ros2_partial_jacobian"):
        print("this core has no SolverOptions.ros2_partial_jacobian: apply studies/ros2_partial_jacobian.patch "
              "and build the core (this file's docstring)", file=sys.stderr)
        return 2
    case, rigs = case_and_rigs(lugre_bound=True)

    def ros2(n, partial):
        o = engine.ros2_options(n)
        o.ros2_partial_jacobian = partial
        return o

    columns = [("RK4 4", rk4_options(4))] + [(f"ROS2 {n}", ros2(n, False)) for n in (8, 16, 32)] + \
              [(f"ROS2 block {n}", ros2(n, True)) for n in (8, 16, 32)]
    print("| rig | pair (rtol 1e-6) [s] | " + " | ".join(f"{c} [s] / gap" for c, _ in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for name, r in rigs.items():
        ref, tp, _ = timed_run(r, engine.run_options(True), case, repeats=2)
        cells = []
        for _, opts in columns:
            s, t, _ = timed_run(r, opts, case, repeats=2)
            cells.append("diverged" if s is None else f"{t:.3f} / {engine.agreement(s, ref, case)[0]:.1e}")
        print(f"| {name} | {tp:.3f} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
