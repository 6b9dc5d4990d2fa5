"""``diagnose`` of a 1 kHz record of a 2 kHz rig, without and with the controller's sample
(docs/diagnose.md, ``--dt``): the record of tests/python/test_diagnose_dt.py (the preset's
2 kHz run of a 0.5-8.5 Hz chirp, every second sample kept, 2 um and 20 N of noise), the
delay candidates only.

    PYTHONPATH=python python evaluation/diagnose_dt.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import servohydraulics as sh

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
import test_diagnose_dt as case  # noqa: E402 - the test's record, one definition


def main() -> None:
    rig, rec = case.decimated.__wrapped__()
    for dt in (None, 5e-4):
        t0 = time.time()
        d = sh.diagnose([rec], rig, mode="displacement", progress=False, candidates=case.DELAYS, dt=dt)
        effects = ", ".join(f"{e['name']} (" + ", ".join(f"{k} = {v['value']:.4g}" for k, v in e["parameters"].items())
                            + ")" for e in d.effects) or "none"
        pct = lambda g: ", ".join(f"{k} {100 * v:.3f} %" for k, v in g.items())  # noqa: E731
        print(f"dt = {dt}: {d.verdict}; effects: {effects}; gap before {pct(d.gap_before)}, after "
              f"{pct(d.gap_after)}, noise floor {pct(d.noise_floor)} ({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
