"""The default integrator with a Pade loop delay: cost and accuracy against tight CVODE
(docs/specimens.md, "Step-time cost").

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/pade_tolerance_probe.py

The paper's plant with a 2 ms in-loop delay of Pade order 1, 2, 3, 6 (and order 3 with
every specimen and delay element), 4000 samples at 2 kHz of 10 mm at 1 Hz plus 3 mm at
7 Hz, displacement control.  Per row: microseconds per step, internal steps per sample
and the largest displacement and force errors relative to their peaks, for the default
(dopri5) and CVODE at their default tolerances, against CVODE at rtol 1e-11; first, the
fastest mode of the linearised plant at rest for each order.  Run at two
commits to compare (e.g. before and after the Pade states' tolerance scales changed).
"""

from __future__ import annotations

import time

import numpy as np

import servohydraulics as sh
from servohydraulics import _core

DT = 5e-4


def rig(order: int, everything: bool = False) -> sh.Rig:
    r = sh.zhao2003()
    r.effects.loop_delay = True
    r.loop_delay, r.loop_delay_order = 2e-3, order
    if everything:
        r.effects.bouc_wen_hysteresis = r.effects.mr_damper = True
        r.command_delay = 2.5 * DT
        r.measurement_delay_displacement = r.measurement_delay_force = 1.5 * DT
    return r


def fastest_mode(r: sh.Rig) -> float:
    """The largest |eigenvalue| [1/s] of the Jacobian at rest (displacement control)."""
    d = _core.Dynamics(r, _core.ControlMode.Displacement)
    return float(np.max(np.abs(np.linalg.eigvals(d.jacobian(list(d.equilibrium(0.0)), 0.0)))))


def main() -> None:
    print("fastest mode at rest, Pade order 1, 2, 3, 6: "
          + ", ".join(f"{fastest_mode(rig(n)):.0f} 1/s" for n in (1, 2, 3, 6)))
    t = np.arange(4000) * DT
    u = 0.01 * np.sin(2 * np.pi * t) + 0.003 * np.sin(2 * np.pi * 7 * t)
    print("| Pade order | method | us/step | steps/sample | error x / peak | error F / peak |")
    print("|---|---|---|---|---|---|")
    for order, everything in ((1, False), (2, False), (3, False), (6, False), (3, True)):
        r = rig(order, everything)
        ref = sh.simulate(r, "displacement", u, dt=DT, options=sh.solver_options("cvode", rtol=1e-11))
        for name, opt in (("default (dopri5)", sh.solver_options()), ("CVODE", sh.solver_options("cvode"))):
            t0 = time.perf_counter()
            res = sh.simulate(r, "displacement", u, dt=DT, options=opt)
            wall = time.perf_counter() - t0
            ex, ef = (float(np.max(np.abs(getattr(res, c) - getattr(ref, c))) / np.max(np.abs(getattr(ref, c))))
                      for c in ("displacement", "force"))
            label = f"{order}{' + all elements' if everything else ''}"
            print(f"| {label} | {name} | {wall / u.size * 1e6:.1f} | {res.work.internal_steps / u.size:.1f} | "
                  f"{ex:.1e} | {ef:.1e} |", flush=True)


if __name__ == "__main__":
    main()
