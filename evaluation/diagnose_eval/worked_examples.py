"""The worked examples of docs/diagnose.md, from the paper's own experiments.

    python evaluation/diagnose_eval/worked_examples.py --out build/diagnose_examples

1. Fig 2(b): free vibration from 1.3 cm of the structure alone; the nominal model
   has the identified viscous damping (0.8 %, c = 1.1 kN s/m) but no friction.  The
   "lab" record is made by the independent simulator with F_c = 95.7 N (Table I)
   and 40 dB noise.  Expected: coulomb_friction, F_c near 95.7 N.
2. Fig 4(b): a large-amplitude (8.9 kN) EFT sine sweep with linear velocity-feedback
   compensation through the natural frequency.  The "lab" rig is the calibrated
   preset with its tabulated flow curve (zhao2003_flow_curve: linear below 10 %
   opening, g(1) = 0.56); the nominal model's flow gain is linear (the paper's
   linear analysis: the preset with flow_nonlinearity off).  The record is made with methods.run_eft (force
   control); its command column is the force command actually sent (effective
   force + compensation), so the plant's force mode replays it.  Expected:
   flow_gain_nonlinearity, g_1 near the preset's g(1) = 0.56 and the knee x_k
   near 0.1 (the truth is the preset's curve).

Writes OUT/<example>/ (record.csv, nominal.toml, diagnosis.json, rig_updated.toml,
report.md) and OUT/examples.json (the numbers quoted in docs/diagnose.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import independent_plant as ip  # noqa: E402

DT = 5e-4


def _noise(y: np.ndarray, snr: float, rng) -> np.ndarray:
    return y + rng.normal(0.0, float(np.sqrt(np.mean(y ** 2))) * 10 ** (-snr / 20), y.size)


def fig2b(out: Path, rng) -> dict:
    import servohydraulics as sh

    n = int(10.0 / DT) + 1
    ch = ip.simulate(replace(ip.Truth(c=1.1e3), friction="coulomb", F_c=95.7), "free", np.zeros(n), DT, x0=0.013)
    rec = {"time": ch["time"], "command": ch["command"], "displacement": _noise(ch["displacement"], 40, rng),
           "force": ch["force"]}
    out.mkdir(parents=True, exist_ok=True)
    sh.write_record(out / "record.csv", rec)
    nominal = sh.zhao2003(actuator_attached=False)
    nominal.effects.coulomb_friction = False
    sh.save_rig(nominal, out / "nominal.toml")
    d = sh.diagnose([out / "record.csv"], sh.load_rig(out / "nominal.toml"), mode="free", progress=False)
    d.write(out)
    return d.to_dict()


def fig4b(out: Path, rng) -> dict:
    import servohydraulics as sh

    t = np.arange(int(12.0 / DT) + 1) * DT
    f0, f1 = 0.5, 3.5  # sweep through f_n = 1.58 Hz [Hz]
    phase = 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / t[-1] * t ** 2)
    peff = 8.9e3 * np.minimum(t / 0.5, 1.0) * np.sin(phase)
    lab = sh.zhao2003()  # falling flow gain on (the preset's table, g(1) = 0.56)
    res = sh.run_eft(lab, effective_force=peff, dt=DT, compensation="linear")  # CVODE, the default
    ch = res.channels
    rec = {"time": ch["time"], "command": ch["command"], "displacement": _noise(ch["displacement"], 30, rng),
           "force": _noise(ch["force"], 30, rng)}
    out.mkdir(parents=True, exist_ok=True)
    sh.write_record(out / "record.csv", rec)
    nominal = sh.zhao2003()
    nominal.effects.flow_nonlinearity = False
    sh.save_rig(nominal, out / "nominal.toml")
    d = sh.diagnose([out / "record.csv"], sh.load_rig(out / "nominal.toml"), mode="force", progress=False)
    d.write(out)
    js = d.to_dict()
    # the force drop near f_n: applied over effective force amplitude, 1.4-1.8 Hz
    inst_f = f0 + (f1 - f0) * t / t[-1]
    band = (inst_f > 1.4) & (inst_f < 1.8)
    js["force_ratio_near_fn"] = float(np.sqrt(np.mean(ch["force"][band] ** 2) / np.mean(peff[band] ** 2)))
    js["peak_spool"] = float(np.max(np.abs(ch["spool"])))
    fc = lab.flow_curve
    js["truth"] = {"g_1": float(fc.eval(1.0)), "opening": list(fc.opening), "flow": list(fc.flow)}
    if js["effects"] and js["effects"][0]["name"] == "flow_gain_nonlinearity":
        p = js["effects"][0]["parameters"]
        g1, xk = p["g_1"]["value"], p["x_k"]["value"] if "x_k" in p else 0.0
        from servohydraulics.diagnosis.effects import knee_flow_curve

        op, fl = knee_flow_curve(g1, xk)
        s = np.linspace(0.0, js["peak_spool"], 200)
        # largest difference of the fitted curve from the truth over the openings the record reached
        js["curve_error_to_peak"] = float(np.max(np.abs(np.interp(s, op, fl) - [fc.eval(v) for v in s])))
    return js


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="build/diagnose_examples")
    a = p.parse_args()
    out = Path(a.out)
    rng = np.random.default_rng(1773)
    res = {"fig2b": fig2b(out / "fig2b", rng), "fig4b": fig4b(out / "fig4b", rng)}
    res["fig2b"]["truth"] = {"F_c": 95.7, "c": 1100.0}
    (out / "examples.json").write_text(json.dumps(res, indent=1, default=str))
    for k, d in res.items():
        print(k, d["verdict"], [(e["name"], {n: v["value"] for n, v in e["parameters"].items()})
                                for e in d["effects"]], d["gap_before"], d["gap_after"], f"{d['runtime_s']:.1f} s")


if __name__ == "__main__":
    main()
