"""Writes tests/data/rpsd_reference.npz: run_rpsd on the paper's rig (sh.zhao2003()) for both
Eq (15) schemes and every restoring-force option, as the code computed it before the 1-DOF
numerical substructure replaced the SDOF schemes (issue 22).  tests/python/test_rpsd_substructure.py
holds today's run_rpsd to these arrays.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python scripts/rpsd_reference.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics.excitations import synthetic_earthquake

CHANNELS = ("calc_displacement", "calc_velocity", "calc_acceleration", "command", "displacement", "force")
SCHEMES = ("central_difference", "explicit_newmark")
OPTIONS = (  # (name, run_rpsd keywords)
    ("calculated_displacement", {"restoring_force": "calculated_displacement"}),
    ("measured_displacement", {"restoring_force": "measured_displacement"}),
    ("measured_force", {"restoring_force": "measured_force", "physical_mass_fraction": 0.02}),
    ("measured_force_corrected", {"restoring_force": "measured_force_corrected", "physical_mass_fraction": 0.02,
                                  "force_measurement": "actuator_pressure"}),
    ("measured_displacement_k_m", {"restoring_force": "measured_displacement", "k_m": 2.0e6, "compute_delay": 1}),
)


def cases():
    """(key, run_rpsd keywords) of every reference case."""
    ag = synthetic_earthquake(duration=1.5, pga=2.0, seed=3, t_rise=0.2, t_strong=0.8)
    for scheme in SCHEMES:
        for name, kw in OPTIONS:
            yield f"{scheme}/{name}", dict(ground_acceleration=ag, scheme=scheme, **kw)


def main() -> None:
    rig = sh.zhao2003()
    out = {}
    for key, kw in cases():
        r = sh.run_rpsd(rig, **kw)
        for ch in CHANNELS:
            out[f"{key}/{ch}"] = np.asarray(r.channels[ch])
    path = Path(__file__).resolve().parents[1] / "tests" / "data" / "rpsd_reference.npz"
    np.savez_compressed(path, **out)
    print(f"wrote {len(out)} arrays to {path}")


if __name__ == "__main__":
    main()
