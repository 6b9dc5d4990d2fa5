"""Flow-curve shapes against the paper's EFT and RPsD observations (docs/calibration.md).

For each candidate g(x_v): the minimum applied-force FRF of the 20 s 0-10 Hz EFT
sweeps (2.3 kN linear compensation: Fig 3b; 8.9 kN linear / nonlinear
compensation: Figs 4b-c) and the RPsD damping ratio after a ramp-and-release
to 1.6 cm at T_ld = 6 / 11.2 / 16 ms (Fig 8).  About 1 minute.

    python studies/flow_curve_study.py
"""

import servohydraulics as sh
from servohydraulics.paper import experiments as xp

RELEASE = xp.Release(free=4.0, fit=4.0)  # ramp 5 s, hold 1 s, 4 s of free vibration fitted


def rig_with(curve: dict):
    return sh.rig_from_dict({"servovalve": {"flow_curve": curve}})


def frf_min(rig, amp: float, **kw) -> float:
    """Minimum |F/P| over 0.3-10 Hz of the 20 s EFT sweep (experiments.eft_sweep)."""
    return float(xp.eft_sweep(rig, amp, **kw).ratio.min())


def damping(rig, T: float) -> float:
    """Damping ratio of the RPsD free vibration from 1.6 cm (experiments.rpsd_release)."""
    return xp.rpsd_release(rig, RELEASE, delay_T=T).fit.damping_ratio


CANDIDATES = {
    "linear (Eq 7)": {"kind": "rational", "b": 0.0},
    "rational b = 0.6": {"kind": "rational", "b": 0.6},
    "table (preset)": None,
}

print("| curve | Fig 3b 2.3 kN lin | Fig 4b 8.9 kN lin | Fig 4c 8.9 kN nonlin | zeta 6 / 11.2 / 16 ms [%] |")
print("|---|---|---|---|---|")
for name, curve in CANDIDATES.items():
    rig = sh.zhao2003() if curve is None else rig_with(curve)
    z = [100 * damping(rig, T) for T in (6e-3, 11.2e-3, 16e-3)]
    print(f"| {name} | {frf_min(rig, 2300.0):.3f} | {frf_min(rig, 8900.0):.3f} | "
          f"{frf_min(rig, 8900.0, compensation='nonlinear'):.3f} | {z[0]:+.2f} / {z[1]:+.2f} / {z[2]:+.2f} |")
