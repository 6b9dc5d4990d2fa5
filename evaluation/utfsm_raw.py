"""The UTFSM raw DAQ exports read with the committed layouts against the CSVs made from them
(docs/lab-records.md, "The UTFSM raw files reproduce the shared CSVs"): prints the markdown table.

    SH_SHARED_DIR=../shared PYTHONPATH=python python evaluation/utfsm_raw.py
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

import servohydraulics as sh

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"
PAIRS = [("2022-06-29_chirp20Hz_0A.txt", "chirp20Hz_0A.csv", "utfsm_daq_2022-06.toml", 9806.65),
         ("2022-05-25_sweep15Hz_0p5A.txt", "sweep15Hz_0p5A.csv", "utfsm_daq_2022-05.toml", 980.665)]


def main() -> None:
    print("| raw file | layout | samples | max diff time [s] | command [m] | displacement [m] | force [N] | "
          "offsets removed, disp / force / cmd [V] |")
    print("|---|---|---|---|---|---|---|---|")
    for raw, csv, layout, force_scale in PAIRS:
        rec = sh.read_record(DATA / "raw" / raw, layout=ROOT / "examples" / "layouts" / layout)
        ref = sh.read_record(DATA / csv)
        d = {c: float(np.max(np.abs(rec.channels[c] - ref.channels[c]))) for c in ("time", "command",
                                                                                    "displacement", "force")}
        off = rec.metadata["offsets"]
        volts = (off["displacement"] / 0.01, off["force"] / force_scale, off["command"] / 0.01)
        print(f"| `raw/{raw}` | `{layout}` | {len(rec)} | {d['time']:.1e} | {d['command']:.1e} | "
              f"{d['displacement']:.1e} | {d['force']:.3f} | " + ", ".join(f"{v:.5f}" for v in volts) + " |")


if __name__ == "__main__":
    main()
