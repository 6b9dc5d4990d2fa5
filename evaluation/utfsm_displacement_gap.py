"""Where the diagnosed UTFSM rig's displacement parts from the record (issue 25, item 2).

    PYTHONPATH=python python evaluation/utfsm_displacement_gap.py [--run may_0A_to_1A] [--out build/utfsm25]
        [--refit mr_alpha_a,mr_c0_a,mr_c1_a,p_s,K_v,K_a]

Reads the rig ``evaluation/utfsm_diagnose.py --run LABEL`` wrote (OUT/LABEL/rig_updated.toml: the
nominal rig with the diagnosed effects) and the run's record, and prints:

* per 4 s window of the record: the displacement gap (rms(sim - measured) / rms(measured)), the
  simulated over the measured amplitude (std) and the lag of the simulated displacement behind the
  measured one (the lag in samples that maximises their cross-correlation; negative: the model leads);
* the same for the nominal rig;
* what a least-squares re-fit of ``--refit`` (rig keys, log coordinates, from the diagnosed values)
  on the record leaves: the question is whether the loop's own parameters (the supply pressure of the
  load-pressure term, the flow gain, the oil column's compliance), re-fitted with the damper, close
  the displacement gap that the damper's force opens.

The windows from 1 s to 48 s are used (the sweep's command stops before the record ends).  The
runs are the diagnosis' search runs (dopri5 at rtol 1e-6, ``diagnosis.engine.run_options``).
"""

from __future__ import annotations

import argparse
import copy
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "evaluation"))


def _windows(t, x, xs, width=4.0, t_end=48.0):
    rows = []
    lags = np.arange(-20, 21)
    a = 4.0
    while a + width <= t_end + 1e-9:
        w = (t >= a) & (t < a + width)
        cc = [float(np.dot(xs[w], np.roll(x, -k)[w])) for k in lags]
        e = xs[w] - x[w]
        rows.append((a, float(np.sqrt(np.mean(e**2)) / np.sqrt(np.mean(x[w]**2))), float(np.std(xs[w]) / np.std(x[w])),
                     int(lags[int(np.argmax(cc))])))
        a += width
    return rows


def main() -> None:
    from utfsm_diagnose import RUNS, _record

    import servohydraulics as sh
    from servohydraulics.diagnosis import engine
    from servohydraulics.identification.records import simulate_record

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--run", default="may_0A_to_1A", choices=[r[0] for r in RUNS])
    p.add_argument("--out", default="build/utfsm25")
    p.add_argument("--refit", default="mr_alpha_a,mr_c0_a,mr_c1_a,p_s,K_v,K_a",
                   help="rig keys re-fitted together (empty: none)")
    a = p.parse_args()
    label, rig_from, record = next(r for r in RUNS if r[0] == a.run)
    updated = Path(a.out) / label / "rig_updated.toml"
    if not updated.exists():
        raise SystemExit(f"{updated} is absent: run `python evaluation/utfsm_diagnose.py --run {label} --end 0 "
                         f"--out {a.out}` first")
    nominal = sh.load_rig(ROOT / "evaluation" / "utfsm_rigs" / f"identified_from_{rig_from}.toml")
    diagnosed = sh.load_rig(updated)
    rec = _record(record, None)
    x, f, t = np.asarray(rec.channels["displacement"]), np.asarray(rec.channels["force"]), np.asarray(rec.time)
    opts = engine.run_options(True)
    m = (t > 1.0) & (t < 48.0)

    def run(rig):
        s = simulate_record(rig, rec, "displacement", options=opts)
        return np.asarray(s.displacement), np.asarray(s.force)

    def gaps(xs, fs):
        return (float(np.sqrt(np.mean((xs - x)[m] ** 2)) / np.sqrt(np.mean(x[m] ** 2))),
                float(np.sqrt(np.mean((fs - f)[m] ** 2)) / np.sqrt(np.mean(f[m] ** 2))))

    print(f"{label}: record {record}, nominal rig from {rig_from}; windows 1-48 s")
    for name, rig in (("nominal", nominal), ("diagnosed", diagnosed)):
        xs, fs = run(rig)
        g = gaps(xs, fs)
        print(f"\n{name}: displacement gap {100 * g[0]:.2f} %, force gap {100 * g[1]:.2f} %")
        print("| window [s] | displacement gap | amplitude sim/measured | lag of sim [samples of 1 ms] |")
        print("|---|---|---|---|")
        for a0, gap, amp, lag in _windows(t, x, xs):
            print(f"| {a0:.0f}-{a0 + 4:.0f} | {100 * gap:.1f} % | {amp:.3f} | {lag:+d} |")
    keys = [k for k in a.refit.split(",") if k]
    if not keys:
        return
    from scipy.optimize import least_squares

    for k in keys:
        if not hasattr(diagnosed, k):
            raise SystemExit(f"invalid --refit key {k!r}: not a rig key")
    v0 = np.array([float(getattr(diagnosed, k)) for k in keys])

    def rig_at(z):
        rg = copy.copy(diagnosed)
        for k, v in zip(keys, v0 * np.exp(z)):
            setattr(rg, k, float(v))
        return rg

    def residual(z):
        try:
            xs, fs = run(rig_at(z))
        except (sh.SimulationError, ValueError):
            return np.full(2 * int(m.sum()), 10.0)
        return np.concatenate([(xs - x)[m] / np.std(x[m]), (fs - f)[m] / np.std(f[m])])

    sol = least_squares(residual, np.zeros(len(keys)), diff_step=1e-3, max_nfev=40, bounds=(-3.0, 3.0))
    g = gaps(*run(rig_at(sol.x)))
    print(f"\nre-fit of {', '.join(keys)} (factors on the diagnosed values: "
          + ", ".join(f"{k} x{fac:.3g}" for k, fac in zip(keys, np.exp(sol.x)))
          + f"): displacement gap {100 * g[0]:.2f} %, force gap {100 * g[1]:.2f} % ({sol.nfev} residuals)")


if __name__ == "__main__":
    main()
