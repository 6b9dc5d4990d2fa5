"""Real-time pseudodynamic test with an OpenSeesPy numerical substructure on the paper's rig:
the 3-storey frame of 08_rpsd_frame.py, its upper storeys and floor masses an OpenSees model
(rths.spring_model: zeroLength springs, Rayleigh damping) stepped once per controller sample
through the same NumericalSubstructure interface as the linear one, the first storey the
physical structure of sh.zhao2003().  Runs the linear frame (which must give the linear
substructure's answer: the two differ only in OpenSees' own central difference) and one whose
second storey yields (Steel01, 2 % hardening).

    python3 examples/09_rpsd_opensees.py [DURATION_S]
"""

from __future__ import annotations

import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics import _core, rths
from servohydraulics.excitations import synthetic_earthquake

_spec = importlib.util.spec_from_file_location("ex07", Path(__file__).with_name("08_rpsd_frame.py"))
ex07 = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ex07)


def main(duration: float = 5.0) -> None:
    rig = sh.zhao2003()
    dt = _core.RpsdConfig().dt
    ag = synthetic_earthquake(duration=duration, pga=0.05 * 9.80665, seed=0)
    M, C, K = ex07.frame(rig.k)
    K_num = K - np.diag([rig.k, 0.0, 0.0])
    a, b = np.linalg.lstsq(np.c_[M.ravel(), K.ravel()], C.ravel(), rcond=None)[0]  # C = a M + b K
    lin = sh.run_rpsd(rig, ground_acceleration=ag, substructure=sh.linear_substructure(M, C, K_num, dt=dt),
                      k_m=rig.k)
    x_lin = np.asarray(lin.channels["calc_displacement"])
    print(f"linear_substructure_peak_mm={1e3 * np.max(np.abs(x_lin)):.3f}")
    drift_y = 1.0e-3  # the second storey yields at 1 mm of drift
    for name, yielding in (("opensees_linear", None), ("opensees_yielding", {(1, 2): (1.5 * rig.k * drift_y, 0.02)})):
        osp = rths.OpenSeesSubstructure(rths.spring_model(M, K_num, rayleigh=(a, b), yielding=yielding),
                                        dofs=[(1, 1), (2, 1), (3, 1)], ground=np.diag(M), interface=0, h=dt)
        t0 = time.perf_counter()
        r = sh.run_rpsd(rig, ground_acceleration=ag, substructure=osp, k_m=rig.k)
        wall = time.perf_counter() - t0
        x = np.asarray(r.channels["calc_displacement"])
        diff = np.sqrt(np.mean((x - x_lin) ** 2) / np.mean(x_lin**2))
        print(f"{name}_peak_mm={1e3 * np.max(np.abs(x)):.3f} {name}_vs_linear_pct={100 * diff:.2f} "
              f"{name}_us_per_sample={1e6 * wall / ag.size:.0f}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 5.0)
