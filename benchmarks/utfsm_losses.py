"""Why two held-out forces of the UTFSM table still lose (docs/lab-records.md).

    SH_SHARED_DIR=../shared PYTHONPATH=python python benchmarks/utfsm_losses.py [--extra-keys]

For each held-out pair, the committed rig (benchmarks/utfsm_rigs/, made by
benchmarks/utfsm_eval.py) predicts the held-out record's force from its
command; printed: the NRMSE, the least-squares gain g of measured ~ g x
predicted and the NRMSE at that gain (a level difference between the records),
and, over six equal stretches of the record (the sweep's frequency rises with
time), the time shift of the predicted force in whole samples (-6 ... 6 ms)
that fits best (a lag or lead of the hysteresis).  A diagnostic only: the gain
and shifts are not part of the model.  ``--extra-keys`` also identifies the 1 A
chirp again with a force measurement delay, ``mr_n`` and ``mr_k0`` fitted too
(start 1 ms, 2, 1 kN/m) and prints its held-out sweep NRMSE, then again with
the default keys from the thesis' 1 A parameters as the start (about 3 min).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"
PAIRS = (("chirp20Hz_0A", "sweep15Hz_0A"), ("sweep15Hz_0A", "chirp20Hz_0A"),
         ("chirp20Hz_1A", "sweep15Hz_1A"), ("sweep15Hz_1A", "chirp20Hz_1A"))


def best_shift(sim: np.ndarray, meas: np.ndarray, idx: np.ndarray, span: int = 6) -> int:
    """The shift d [samples] minimising sum((sim[k - d] - meas[k])^2) over idx (d > 0: sim delayed)."""
    return min(range(-span, span + 1), key=lambda d: float(np.sum((np.roll(sim, d)[idx] - meas[idx]) ** 2)))


def main() -> int:
    sys.path.insert(0, str(ROOT / "python"))
    import servohydraulics as sh
    from servohydraulics import lab
    from servohydraulics.lab.fitting import fit_options

    if not DATA.is_dir():
        print(f"UTFSM records not found in {DATA}", file=sys.stderr)
        return 2
    for train, test in PAIRS:
        rec = sh.read_record(DATA / f"{test}.csv")
        rig = sh.load_rig(ROOT / "benchmarks" / "utfsm_rigs" / f"identified_from_{train}.toml")
        sim = lab.simulate_record(rig, rec, "displacement", options=fit_options(rig, [rec], "displacement"))["force"]
        meas = np.asarray(rec.force, dtype=float)
        g = float(sim @ meas / (sim @ sim))
        stretches = np.array_split(np.arange(2000, meas.size - 2000), 6)
        shifts = [best_shift(sim, meas, s) for s in stretches]
        print(f"{train} -> {test}: force NRMSE {lab.nrmse_pct(sim, meas):.2f} %, best gain {g:.3f} "
              f"(NRMSE {lab.nrmse_pct(g * sim, meas):.2f} %), best shift per sixth of the record [ms]: {shifts}")
    if "--extra-keys" in sys.argv[1:]:
        extra_keys(sh, lab, fit_options)
    return 0


def extra_keys(sh, lab, fit_options) -> None:
    from servohydraulics.lab import generic, keys

    from servohydraulics.lab import baselines

    train, test = (sh.read_record(DATA / f"{n}.csv") for n in ("chirp20Hz_1A", "sweep15Hz_1A"))
    default = keys.LOOP_KEYS["displacement"] + keys.SPECIMEN_KEYS["mr_damper"]
    extra = ("measurement_delay_force", "mr_n", "mr_k0")
    for label, start, fit in (("extra keys", {"measurement_delay_force": 1e-3, "mr_k0": 1e3}, default + extra),
                              ("thesis start", baselines.spencer_rig_keys(baselines.thesis_mr_parameters(1.0)),
                               default)):
        rig = generic.generic_rig(train)
        generic.mr_damper_start(rig, train)
        rig.effects.mr_damper = True
        for k, v in start.items():
            setattr(rig, k, v)
        ident = sh.identify([train], rig=rig, fit=fit, mode="displacement", specimen="mr_damper", progress=False)
        pred = lab.compare(test, ident.rig, "displacement", options=fit_options(ident.rig, [test], "displacement"))
        print(f"chirp20Hz_1A, {label}: " + ", ".join(f"{k} = {ident.values[k]:.4g}" for k in fit[3:])
              + f"; fit force {ident.after[0].nrmse('force'):.2f} %, held-out sweep15Hz_1A force "
              f"{pred.nrmse('force'):.2f} %, displacement {pred.nrmse('displacement'):.2f} %")


if __name__ == "__main__":
    sys.exit(main())
