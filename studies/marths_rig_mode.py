"""The calibrated two-actuator rig's mode above the identified band, and RoDeAC's oscillation there.

docs/multi-actuator.md ("What the difference teaches", point 1): RoDeAC on the nonlinear rig oscillates at
about 167 Hz from t ~ 9 s of El Centro.  This script gives the evidence behind that paragraph:

* the diagonal gains and phases of the identified plant (plantFRAME_SS) and of the rig's linearisation
  (``MultiActuatorRig.frequency_response``, friction left out) from 50 to 512 Hz;
* the first ``--seconds`` of El Centro x 0.4 with RoDeAC on the rig, integrated by dopri5 (the default) and by
  CVODE at rtol 1e-9 (an independent integrator): J2 over that span, the frequency of the tracking error's
  largest spectral line after 9.5 s, and the largest command after 9 s.

    python studies/marths_rig_mode.py [--data ../shared/marths-data] [--seconds 11] [--write]

(``--write``: the output also between ``<!-- marths_rig_mode -->`` markers, if docs/multi-actuator.md has them.)
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import servohydraulics as sh
from servohydraulics import marths
from servohydraulics.atomic import replace_marked
from servohydraulics.rths.data import Record

ROOT = Path(__file__).resolve().parents[1]
FREQS = (50.0, 100.0, 150.0, 167.0, 200.0, 300.0, 512.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "marths-data")
    ap.add_argument("--seconds", type=float, default=11.0)
    ap.add_argument("--write", action="store_true", help="also into docs/multi-actuator.md")
    args = ap.parse_args()
    ss = json.loads((args.data / "ID_Control_plant_100Hz_plantFRAME_SS.json").read_text())
    A, B, C = (np.asarray(ss[k], dtype=float) for k in "ABC")
    f = np.asarray(FREQS)
    H_id = np.stack([C @ np.linalg.solve(2j * np.pi * fk * np.eye(A.shape[0]) - A, B) for fk in f])
    rig = sh.marths_rig()
    H_rig = rig.frequency_response(f)
    lines = ["| f [Hz] | identified H11 | rig H11 | identified H22 | rig H22 |", "|---:|---:|---:|---:|---:|"]
    for k, fk in enumerate(f):
        cells = [f"{abs(H[k][i, i]):.4f} ∠ {np.degrees(np.angle(H[k][i, i])):.0f}°" for i in (0, 1)
                 for H in (H_id, H_rig)]
        lines.append(f"| {fk:g} | " + " | ".join(cells) + " |")
    data = marths.load_data(args.data)
    rec = marths.load_record(args.data, "elcentro")
    keep = rec.time <= args.seconds
    part = Record(f"elcentro_{args.seconds:g}s", rec.time[keep].copy(), rec.acceleration[keep].copy())
    lines += ["", f"RoDeAC on the rig, El Centro × 0.4, the first {args.seconds:g} s:", ""]
    for name, opt in (("dopri5 (default)", None), ("cvode rtol 1e-9", sh.solver_options("cvode", rtol=1e-9))):
        plant = rig.make_plant(marths.DT, opt) if opt is not None else rig
        t = marths.run_trial(data, part, "rodeac", plant=plant, keep_signals=True)
        s = t.response.channels
        time = s["time"]
        e = s["measured_1"] - s["target_1"]
        w = time > 9.5
        spec = np.abs(np.fft.rfft(e[w]))
        freq = np.fft.rfftfreq(int(w.sum()), marths.DT)
        peak = freq[1 + int(np.argmax(spec[1:]))]
        lines.append(f"- {name}: J2 = {t.J['J2'][0]:.1f} / {t.J['J2'][1]:.1f} %, tracking error's largest line after "
                     f"9.5 s at {peak:.1f} Hz, largest command after 9 s "
                     f"{1e3 * np.max(np.abs(s['command_1'][time > 9])):.1f} mm")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write:
        replace_marked(ROOT / "docs" / "multi-actuator.md", "marths_rig_mode", text)


if __name__ == "__main__":
    main()
