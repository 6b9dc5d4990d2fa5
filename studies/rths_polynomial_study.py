"""The polynomial extrapolation's order and stride (docs/rths-benchmark.md, "Polynomial
extrapolation: order and stride"): nominal J1/J2 per case and the 80 perturbed plants.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/rths_polynomial_study.py \
        --data ../shared/rths-data/mat [--seed 0]

Each design extrapolates the desired displacement tau = A1/A0 of the nominal plant
(25.1 ms) ahead with a Lagrange polynomial through order + 1 points stride samples
apart, plus the PI (as ``rths.make_controller("polynomial")``).  Printed per design:
the extrapolator's gain at the Nyquist frequency (sum of |weights|), the nominal
J1 [ms] / J2 [%] of cases 1-4 (El Centro x 0.4, seed 0 noise), the worst J2 over 20
perturbed plants per case (seed 0 draws), and the perturbed trials whose actuator
force passed the 8.9 kN capacity (diverged).  About 1 min per design on one core.
"""

from __future__ import annotations

import argparse
from functools import partial

import numpy as np

from servohydraulics import rths
from servohydraulics.rths import benchmark as B

DESIGNS = ((2, 16), (1, 16), (1, 32), (2, 32), (2, 48), (3, 32))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    rec = rths.load_record(a.data, "elcentro")
    cases = {c: rths.load_case(a.data, c) for c in (1, 2, 3, 4)}
    refs = {c: rths.case_reference(cases[c], rec) for c in cases}
    saved = B.CONTROLLERS["polynomial"]
    print("| order | stride | Nyquist gain | case 1 | case 2 | case 3 | case 4 | worst perturbed J2 | diverged |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    try:
        for order, stride in DESIGNS:
            B.CONTROLLERS["polynomial"] = (partial(B.polynomial_controller, order=order, stride=stride), saved[1])
            w = np.asarray(B.make_controller("polynomial").weights)
            nom = [rths.run_trial(cases[c], rec, "polynomial", seed=a.seed, reference=refs[c]).J for c in cases]
            worst, bad = 0.0, []
            for c in cases:
                for tr in range(1, 21):
                    t = rths.run_trial(cases[c], rec, "polynomial", plant=B.perturbed_plant(a.seed, c, tr),
                                       seed=a.seed, reference=refs[c])
                    worst = max(worst, t.J[1])
                    if t.max_force_N >= B.FORCE_LIMIT:
                        bad.append(f"{c}/{tr}")
            cells = " | ".join(f"{J[0]:.1f} / {J[1]:.2f}" for J in nom)
            print(f"| {order} | {stride} | {np.abs(w).sum():.1f} | {cells} | {worst:.2f} | "
                  f"{len(bad)} of 80{': ' + ', '.join(bad[:6]) + (' ...' if len(bad) > 6 else '') if bad else ''} |",
                  flush=True)
    finally:
        B.CONTROLLERS["polynomial"] = saved


if __name__ == "__main__":
    main()
