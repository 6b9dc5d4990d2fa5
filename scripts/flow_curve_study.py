"""Flow-curve shapes against the paper's EFT and RPsD observations (docs/calibration.md).

For each candidate g(x_v): the minimum applied-force FRF of the 20 s 0-10 Hz EFT
sweeps (2.3 kN linear compensation: Fig 3b; 8.9 kN linear / nonlinear
compensation: Figs 4b-c) and the RPsD damping ratio after a ramp-and-release
to 1.6 cm at T_ld = 6 / 11.2 / 16 ms (Fig 8).  About 1 minute.

    python scripts/flow_curve_study.py
"""


import servohydraulics as sh
from servohydraulics import excitations as ex
from servohydraulics.identify import fourier_ratio, identify_free_vibration

DT = ex.DT  # the core's controller sample time (0.5 ms)


def rig_with(curve: dict):
    return sh.rig_from_dict({"servovalve": {"flow_curve": curve}})


def frf_min(rig, amp: float, **kw) -> float:
    P = ex.sine_sweep(amp, duration=20.0)
    res = sh.run_eft(rig, effective_force=P, raise_on_failure=False, **kw)
    f, H = fourier_ratio(res.force, P, DT)
    band = (f > 0.3) & (f < 10)
    return float(H[band].min())


def damping(rig, T: float) -> float:
    pe = ex.ramp_and_release(rig.k * 0.016, 5.0, 1.0, 4.0)
    res = sh.run_rpsd(rig, external_force=pe, delay_T=T, raise_on_failure=False)
    fv = identify_free_vibration(res.calc_displacement, DT, start=ex.release_index(5.0, 1.0), duration=4.0)
    return fv.damping_ratio


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
