"""Digest of the outputs of the default and of RK4 over the accuracy evaluation's rig families
(docs/benchmarks.md, issue 26): run it against two cores and compare the lines to see that a
change of the integrators' checks left every result bit for bit as it was.

    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python studies/outputs_digest.py --rigs 100

One line per family and method: the rigs run, how many turned stiff (the default) or were skipped
(RK4 past evaluation/accuracy_random_rigs.py's substep cap), and a SHA-256 prefix
over every output channel of every run, in order (the runs that turned stiff and those that did
not hashed apart).
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "evaluation"))
import accuracy_random_rigs as ar  # noqa: E402

import servohydraulics as sh  # noqa: E402

CHANNELS = ("displacement", "velocity", "acceleration", "force", "pressure", "spool", "drive", "flow")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", type=int, default=100, help="rigs per family")
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--duration", type=float, default=1.0, help="record length [s]")
    args = ap.parse_args(argv)
    for family in ar.FAMILIES:
        rng = np.random.default_rng(args.seed)
        cases = [ar.family_case(sh, rng, args.duration, 5e-4, family) for _ in range(args.rigs)]
        for method in ("default", "rk4"):
            h = {True: hashlib.sha256(), False: hashlib.sha256()}
            stiff = skipped = refused = 0
            for rig, mode, u in cases:
                try:
                    if method == "rk4" and ar._rk4_substeps(sh, rig, mode, 5e-4) > ar.RK4_MAX_SUBSTEPS:
                        skipped += 1
                        continue
                    r = sh.simulate(rig, mode, u, options=ar._options(sh, method), raise_on_failure=False)
                except ValueError:
                    refused += 1
                    continue
                turned = r.work.stiff_samples > 0
                stiff += turned
                for c in CHANNELS:
                    h[turned].update(np.ascontiguousarray(r.channels[c]).tobytes())
            print(f"{family:9s} {method:7s} rigs {args.rigs}, stiff {stiff}, skipped {skipped}, refused {refused}: "
                  f"never stiff {h[False].hexdigest()[:16]}, turned stiff {h[True].hexdigest()[:16]}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
