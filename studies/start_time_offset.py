"""A large start time against t0 = 0 (docs/robustness.md, issue 26): one plant per
integrator, reset at t0 = 0, 1.7e9 s (a Unix time) and 1e10 s, driven by the same
0.5 s, 5 Hz, 2 mm sine; prints the largest force difference relative to the peak
force of the t0 = 0 run (0 when the integrators work in time since the reset).

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/start_time_offset.py
"""

from __future__ import annotations

import numpy as np

import servohydraulics as sh
from servohydraulics.simulate import METHODS, make_plant

DT = 5e-4
STARTS = (0.0, 1.7e9, 1e10)


def force(method: str, t0: float, u: np.ndarray) -> np.ndarray:
    p = make_plant(sh.zhao2003(), "displacement", DT, sh.solver_options(method))
    p.reset(0.0, t0)
    return np.array([p.step(v)[1].force for v in u])


def main() -> None:
    u = 0.002 * np.sin(2 * np.pi * 5 * np.arange(1000) * DT)
    print("method       " + "  ".join(f"t0 = {t0:<8.3g}" for t0 in STARTS[1:]))
    for method in METHODS:
        ref = force(method, 0.0, u)
        errs = [float(np.max(np.abs(force(method, t0, u) - ref)) / np.max(np.abs(ref))) for t0 in STARTS[1:]]
        print(f"{method:12s} " + "  ".join(f"{e:<13.3g}" for e in errs))


if __name__ == "__main__":
    main()
