"""Instructions the core spends on one record run, counted by valgrind's callgrind (issue 25, item 6).

    python benchmarks/core_instructions.py [--samples 6000] [--json FILE --label NAME]

The machine these benchmarks run on is shared: the same run's wall time moves by 30 % and more from
one minute to the next, which hides a change of 10 %.  An instruction count does not move: it
compares two builds of the core on the same runs exactly (a proxy for time: it does not see cache
misses or the latency of a division).  Each case runs the first ``--samples`` samples of the UTFSM
chirp (``chirp20Hz_0A``, 1 kHz) in displacement control through ``_core.run_record`` in a child
interpreter under ``valgrind --tool=callgrind``, counting from the entry into ``run_record`` to its
return (the interpreter, the import and the record's reading are not counted).  The rigs are those of
``studies/diagnose_run_costs.py``: the rig identified at 0 A (``evaluation/utfsm_rig_0A.toml``) and
the same with the diagnosis' Coulomb candidate at 700 N (``LIBRARY["coulomb_friction"]``), which makes
it stiff.  The integrators: RK4 at 4 substeps without its companion (identify's time stage on this
record), ROS2 at 16 substeps (the diagnosis' stiff fits) and the error-controlled pair at rtol 1e-6
(the search's reference).  Each case also prints a digest of the run's channels, so that a change
that should leave the results as they were can be seen to.

Needs valgrind (``apt-get install valgrind``); a case takes 10-60 s.  Which core is counted: the one
``import servohydraulics`` finds (``SERVOHYDRAULICS_CORE_DIR`` selects a build folder).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"
CASES = (("0 A rig", "rk4 x4"), ("0 A rig", "ros2 x16"), ("0 A rig", "pair 1e-6"),
         ("Coulomb F_c 700", "ros2 x16"), ("Coulomb F_c 700", "pair 1e-6"))

CHILD = r"""
import hashlib, sys
import numpy as np
import servohydraulics as sh
from servohydraulics import _core
from servohydraulics.diagnosis.effects import LIBRARY
from servohydraulics.records import read_record
from servohydraulics.simulate import make_plant, solver_options
record, rig_file, rig_name, method, samples = sys.argv[1:6]
rec = read_record(record)
u = np.asarray(rec.channels["command"], float)[: int(samples)]
rig = sh.load_rig(rig_file)
if rig_name.startswith("Coulomb"):
    rig = LIBRARY["coulomb_friction"].apply(rig, np.array([700.0]))
opts = {"rk4 x4": dict(method="rk4", rk4_substeps=4, rk4_flag_rtol=0.0),
        "ros2 x16": dict(method="ros2", ros2_substeps=16),
        "pair 1e-6": dict(method="dopri5", rtol=1e-6, stiff_check=False)}[method]
plant = make_plant(rig, "displacement", rec.dt, solver_options(**opts))
channels, s = _core.run_record(plant, u)
h = hashlib.blake2b(b"".join(np.ascontiguousarray(channels[c][: s.rows]).tobytes() for c in sorted(channels)),
                    digest_size=8).hexdigest()
print("digest", h, "rows", s.rows)
"""


def count(rig: str, method: str, samples: int) -> dict:
    """Instructions inside ``run_record`` and the digest of the run's channels."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", "--collect-atstart=no",
               "--toggle-collect=servohydraulics::run_record*", sys.executable, "-c", CHILD,
               str(DATA / "chirp20Hz_0A.csv"), str(ROOT / "evaluation" / "utfsm_rig_0A.toml"), rig, method,
               str(samples)]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        collected = re.search(r"Collected : (\d+)", proc.stderr)
        digest = re.search(r"digest (\w+) rows (\d+)", proc.stdout)
        if proc.returncode != 0 or not collected or not digest:
            raise SystemExit(f"{rig} / {method}: the child failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    return {"rig": rig, "method": method, "samples": samples, "instructions": int(collected.group(1)),
            "per_sample": int(collected.group(1)) / samples, "digest": digest.group(1), "rows": int(digest.group(2))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=6000, help="samples of the record to run (default 6000)")
    ap.add_argument("--json", help="append the rows to this JSON file under --label")
    ap.add_argument("--label", default="run", help="the rows' label in --json")
    args = ap.parse_args(argv)
    if shutil.which("valgrind") is None:
        raise SystemExit("valgrind is not installed (apt-get install valgrind)")
    if not (DATA / "chirp20Hz_0A.csv").exists():
        raise SystemExit(f"record {DATA / 'chirp20Hz_0A.csv'} is absent: set SH_SHARED_DIR to the folder that holds "
                         "real-data/")
    if args.samples < 100:
        raise SystemExit(f"invalid --samples = {args.samples}: at least 100")
    rows = []
    for rig, method in CASES:
        row = count(rig, method, args.samples)
        rows.append(row)
        print(f"{rig:16s} {method:10s} {row['instructions']:>13,d} instructions ({row['per_sample']:,.0f} per sample)"
              f"  digest {row['digest']}", flush=True)
    if args.json:
        path = Path(args.json)
        data = json.loads(path.read_text()) if path.exists() else {}
        data[args.label] = {"command": "python benchmarks/core_instructions.py " + " ".join(argv or sys.argv[1:]),
                            "rows": rows}
        path.write_text(json.dumps(data, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
