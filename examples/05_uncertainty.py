"""An uncertainty study: seeded Monte Carlo draws of the calibrated (least
certain) parameters, the compressibility K_a and the leakage C_l, +-20 %
uniform, and what they do to the displacement tracking error of a 1 Hz,
10 mm sine.

    python3 examples/05_uncertainty.py [n = 12]
"""

from __future__ import annotations

import sys

from scipy import stats

import servohydraulics as sh


def main(n: int = 12) -> None:
    rig = sh.zhao2003()
    df = sh.sweep(
        distributions={"actuator.K_a": stats.uniform(0.8 * rig.K_a, 0.4 * rig.K_a),
                       "actuator.C_l": stats.uniform(0.8 * rig.C_l, 0.4 * rig.C_l)},
        n=n, seed=2003,
        fixed={"amplitude": 0.01, "frequency": 1.0, "duration": 1.0},
        max_workers=2,
        progress=False,
    )
    err = df["rms_tracking_error"] * 1e3
    print(f"runs={len(df)} all_ok={bool(df['ok'].all())}")
    print(f"rms_tracking_error_mm_mean={err.mean():.4f} std={err.std():.4f} min={err.min():.4f} max={err.max():.4f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 12)
