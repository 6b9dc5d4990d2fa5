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

``--evaluations`` counts instead what one evaluation of the plant's model costs: instructions per call
of ``Dynamics::rhs`` (the right-hand side) and ``Dynamics::jacobian`` (its analytic Jacobian by the
core's forward-mode derivatives, every state at once), each called ``--calls`` times from Python at
the states and commands of the 0 A rig's RK4 x4 run of the record's first samples (that run made
before the counted child starts).  These are the unit costs of a cost model of forward sensitivities
against difference columns (docs/benchmarks.md, lab speed).

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

EVAL_CHILD = r"""
import sys
import numpy as np
import servohydraulics as sh
from servohydraulics import _core
rig_file, states_file = sys.argv[1], sys.argv[2]
data = np.load(states_file)
dyn = _core.Dynamics(sh.load_rig(rig_file), _core.ControlMode.Displacement)
for y, v in zip(data["states"].tolist(), data["inputs"].tolist()):
    dyn.{what}(y, v)
print("states", data["states"].shape[1])
"""


def run_states(calls: int, path: Path) -> None:
    """The plant's states and inputs at the first ``calls`` samples of the 0 A rig's RK4 x4 run, saved to ``path``
    (made here, not in the counted child: the run's own right-hand sides would be counted)."""
    import numpy as np

    import servohydraulics as sh
    from servohydraulics.records import read_record
    from servohydraulics.simulate import make_plant, solver_options

    rec = read_record(DATA / "chirp20Hz_0A.csv")
    u = np.asarray(rec.channels["command"], float)[:calls]
    rig = sh.load_rig(ROOT / "evaluation" / "utfsm_rig_0A.toml")
    plant = make_plant(rig, "displacement", rec.dt, solver_options(method="rk4", rk4_substeps=4, rk4_flag_rtol=0.0))
    states = []
    for v in u:
        plant.step(float(v))
        states.append(np.asarray(plant.state, float))
    np.savez(path, states=np.array(states), inputs=u)


#: the plant's evaluations --evaluations counts (the Python name; the C++ symbol callgrind toggles on)
EVALUATIONS = (("rhs", "servohydraulics::Dynamics::rhs(*"), ("jacobian", "servohydraulics::Dynamics::jacobian(*"))


def callgrind(symbol: str, args: list[str]) -> tuple[int, str]:
    """Instructions counted inside the C++ functions matching ``symbol`` (and what they call) while
    ``python args`` runs under callgrind, and the child's standard output."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={Path(tmp) / 'callgrind.out'}",
               "--collect-atstart=no", f"--toggle-collect={symbol}", sys.executable, *args]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    collected = re.search(r"Collected : (\d+)", proc.stderr)
    if proc.returncode != 0 or not collected:
        raise SystemExit(f"{' '.join(args[2:])}: the child failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    return int(collected.group(1)), proc.stdout


def count_evaluation(what: str, symbol: str, calls: int) -> dict:
    """Instructions per call of one of the plant's evaluations (``EVALUATIONS``)."""
    with tempfile.TemporaryDirectory() as tmp:
        states_file = Path(tmp) / "states.npz"
        run_states(calls, states_file)
        n, stdout = callgrind(symbol, ["-c", EVAL_CHILD.replace("{what}", what),
                                       str(ROOT / "evaluation" / "utfsm_rig_0A.toml"), str(states_file)])
    states = re.search(r"states (\d+)", stdout)
    if not states:
        raise SystemExit(f"{what}: the child printed no state count:\n{stdout[-2000:]}")
    return {"evaluation": what, "calls": calls, "instructions": n, "per_call": n / calls,
            "states": int(states.group(1))}


def count(rig: str, method: str, samples: int) -> dict:
    """Instructions inside ``run_record`` and the digest of the run's channels."""
    n, stdout = callgrind("servohydraulics::run_record*",
                          ["-c", CHILD, str(DATA / "chirp20Hz_0A.csv"), str(ROOT / "evaluation" / "utfsm_rig_0A.toml"),
                           rig, method, str(samples)])
    digest = re.search(r"digest (\w+) rows (\d+)", stdout)
    if not digest:
        raise SystemExit(f"{rig} / {method}: the child printed no digest:\n{stdout[-2000:]}")
    return {"rig": rig, "method": method, "samples": samples, "instructions": n,
            "per_sample": n / samples, "digest": digest.group(1), "rows": int(digest.group(2))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=6000, help="samples of the record to run (default 6000)")
    ap.add_argument("--json", help="append the rows to this JSON file under --label")
    ap.add_argument("--label", default="run", help="the rows' label in --json")
    ap.add_argument("--evaluations", action="store_true",
                    help="count instructions per call of the plant's rhs and jacobian instead of record runs")
    ap.add_argument("--calls", type=int, default=2000, help="calls of each evaluation (--evaluations; default 2000)")
    args = ap.parse_args(argv)
    if shutil.which("valgrind") is None:
        raise SystemExit("valgrind is not installed (apt-get install valgrind)")
    if not (DATA / "chirp20Hz_0A.csv").exists():
        raise SystemExit(f"record {DATA / 'chirp20Hz_0A.csv'} is absent: set SH_SHARED_DIR to the folder that holds "
                         "real-data/")
    if args.samples < 100:
        raise SystemExit(f"invalid --samples = {args.samples}: at least 100")
    if args.evaluations and args.calls < 100:
        raise SystemExit(f"invalid --calls = {args.calls}: at least 100")
    rows = []
    for what, symbol in (EVALUATIONS if args.evaluations else ()):
        row = count_evaluation(what, symbol, args.calls)
        rows.append(row)
        print(f"{what:10s} {row['per_call']:>9,.0f} instructions per call ({row['calls']} calls, "
              f"{row['states']} states)", flush=True)
    for rig, method in (() if args.evaluations else CASES):
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
