"""A nonlinear numerical substructure from OpenSeesPy in the RTHS loop: a 3-storey
shear building (rths.shear_building: 6, 5, 4 MN/m storeys, 1000 kg floors, 5 %
Rayleigh damping; NOT one of the benchmark's cases) whose first storey is a
bilinear Steel01 spring, with the benchmark's control plant as the experimental
substructure at the first floor and its sample controller.  Prints the linear and
the yielding run side by side.

    python3 examples/06_rths_opensees.py [DATA]     # DATA: the benchmark files (El Centro x 0.4);
                                                     # none: a synthetic ground motion
"""

from __future__ import annotations

import sys
import time

import numpy as np

from servohydraulics import rths


def main(data: str | None = None) -> None:
    case = rths.shear_building()
    rec = rths.load_record(data, "elcentro") if data else rths.synthetic_record(duration=20.0, pga=6.0)
    sp = rths.nominal_plant().specimen()
    M, K = case.M.copy(), case.K.copy()
    M[0, 0] -= sp.m  # the numerical substructure: the building less the specimen at the first floor
    K[0, 0] -= sp.k
    a, b = np.linalg.lstsq(np.c_[case.M.ravel(), case.K.ravel()], case.C.ravel(), rcond=None)[0]
    k1 = K[0, 0] + K[0, 1]  # first storey less the specimen [N/m]
    fy = 1.5e-3 * k1         # yields at 1.5 mm of first-storey drift
    print(f"record={rec.name} synthetic={rec.synthetic} first_storey_k_MN_per_m={k1 / 1e6:.3f} "
          f"yield_force_kN={fy / 1e3:.3f}")
    for name, yielding in (("linear", None), ("yielding", {(0, 1): (fy, 0.02)})):
        osp = rths.OpenSeesSubstructure(rths.spring_model(M, K, rayleigh=(a, b), yielding=yielding),
                                        dofs=[(1, 1), (2, 1), (3, 1)], ground=np.diag(case.M))
        t0 = time.perf_counter()
        tr = rths.run_trial(case, rec, "sample", seed=0, numerical=osp, keep_signals=True)
        wall = time.perf_counter() - t0
        x1 = tr.signals["numerical"][:, 0]
        print(f"{name}: ok={tr.ok} J1_ms={tr.J[0]:.1f} J2_pct={tr.J[1]:.2f} J3_pct={tr.J[2]:.2f} "
              f"peak_drift_mm={1e3 * np.max(np.abs(x1)):.3f} residual_drift_mm={1e3 * np.mean(x1[-4096:]):.3f} "
              f"peak_actuator_force_kN={tr.max_force_N / 1e3:.3f} steps={x1.size} wall_s={wall:.1f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
