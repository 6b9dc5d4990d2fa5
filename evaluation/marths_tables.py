"""The maRTHS tables of docs/marths-benchmark.md:
    PYTHONPATH=python SERVOHYDRAULICS_CORE_DIR=build/dev python evaluation/marths_tables.py --data ../shared/marths-data
prints (markdown) the reference row as reproduced (El Centro x 0.4, nominal plant, RoDeAC, noise seed 123) against
BENCHMARK.md's values and tolerances; the nominal rows of the three records for rodeac, rodeac_fixed and none; the
other compensators on El Centro; the spread over ten other noise seeds; and the statistics of 20 perturbed trials."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from servohydraulics import marths
from servohydraulics.marths.report import execute, prepare

COMPONENTS = [(j, c, i) for j, cs in marths.J_COMPONENTS.items() for i, c in enumerate(cs)]


def reference_row(folder: Path) -> dict[tuple[str, str], tuple[float, float]]:
    text = (folder / "BENCHMARK.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (J\d+) \| (\w+) \| ([-\d.]+) \| ([\d.]+) \|$", text[text.index("## 10."):], flags=re.M)
    return {(j, c): (float(v), float(t)) for j, c, v, t in rows}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", required=True)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    folder = Path(a.data)
    data = marths.load_data(folder)
    st = marths.structures(data)
    recs = {r: marths.load_record(folder, r) for r in marths.RECORDS}

    def trial(rec, ctrl, **kw):
        return marths.run_trial(data, recs[rec], ctrl, structures_=st, **kw)

    # 1. the reference row
    ref = reference_row(folder)
    t = trial("elcentro", "rodeac")
    print("### Reference row: El Centro x 0.4, nominal plant, RoDeAC, noise seed 123\n")
    print("| J | component | this project | BENCHMARK.md | tolerance | inside |\n|---|---|---:|---:|---:|---|")
    for j, c, i in COMPONENTS:
        v, tol = ref[(j, c)]
        print(f"| {j} | {c} | {t.J[j][i]:.4f} | {v:.4f} | {tol:.3f} | {'yes' if abs(t.J[j][i] - v) <= tol else 'NO'} |")
    print(f"\nPeak command voltages {t.peak_voltage[0]:.3f} V, {t.peak_voltage[1]:.3f} V; realizable: "
          f"{'yes' if t.realizable else 'no'}.\n")

    # 2. the nominal rows of the records and the variants
    runs = {(r, c): trial(r, c) for r in marths.RECORDS for c in ("rodeac", "rodeac_fixed", "none")}
    print("### Nominal trials (noise seed 123), unrounded; J1, J4 in ms, the others in %\n")
    cols = list(runs)
    print("| J | component | " + " | ".join(f"{r} {c}" for r, c in cols) + " |")
    print("|---|---|" + "---:|" * len(cols))
    for j, c, i in COMPONENTS:
        print(f"| {j} | {c} | " + " | ".join(f"{runs[k].J[j][i]:.4f}" for k in cols) + " |")
    print("| peak v1 [V] | | " + " | ".join(f"{runs[k].peak_voltage[0]:.3f}" for k in cols) + " |")
    print("| peak v2 [V] | | " + " | ".join(f"{runs[k].peak_voltage[1]:.3f}" for k in cols) + " |\n")

    # 3. the other compensators on El Centro (and the DAQ blocks)
    others = ["rodeac", "decentralized-model", "decentralized-polynomial", "decentralized-ats", "decentralized-sample",
              "mimo-feedforward"]
    res = {c: trial("elcentro", c) for c in others}
    res["rodeac + DAQ blocks"] = trial("elcentro", "rodeac",
                                       config=marths.loop_config(daq_quantizer=True, daq_saturation=True))
    res["rodeac, exact kinematics"] = trial("elcentro", "rodeac", config=marths.loop_config(exact_kinematics=True))
    print("### El Centro x 0.4, nominal plant, noise seed 123: the other compensators\n")
    print("| compensator | J1 [ms] | J2 [%] | J3 [%] | J5 [%] | J7 [%] | J8 x_2nd [%] | peak v [V] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, r in res.items():
        def pair(j, r=r):
            return " / ".join(f"{v:.2f}" for v in r.J[j])
        print(f"| {name} | {pair('J1')} | {pair('J2')} | {pair('J3')} | {pair('J5')} | {pair('J7')} | "
              f"{r.J['J8'][0]:.2f} | {r.peak_voltage[0]:.3f} / {r.peak_voltage[1]:.3f} |")

    # 4. the spread over other noise seeds (what BENCHMARK.md's tolerances were made from)
    seeds = [trial("elcentro", "rodeac", seed=s).J for s in range(1, 11)]
    print("\n### El Centro RoDeAC, nominal plant, noise seeds 1-10 (Simulink generator): mean, std, 4 std vs the "
          "tolerance\n")
    print("| J | component | mean | std | 4 std | tolerance |\n|---|---|---:|---:|---:|---:|")
    for j, c, i in COMPONENTS:
        v = np.array([s[j][i] for s in seeds])
        print(f"| {j} | {c} | {v.mean():.4f} | {v.std(ddof=1):.4f} | {4 * v.std(ddof=1):.3f} | {ref[(j, c)][1]:.3f} |")

    # 5. perturbed statistics
    run = execute(prepare(folder, "elcentro", "rodeac", perturbed=20, seed=1, workers=a.workers), progress=False)
    p = run["results"]["runs"]["perturbed"]
    print("\n### El Centro RoDeAC, 20 perturbed plants (seed 1): mean ± std over the trials, S5's rounded mean\n")
    print("| J | component | mean | std | min | max | S5 (rounded mean) |\n|---|---|---:|---:|---:|---:|---:|")
    for j, c, i in COMPONENTS:
        print(f"| {j} | {c} | {p['J_mean'][j][i]:.4f} | {p['J_std'][j][i]:.4f} | {p['J_min'][j][i]:.4f} | "
              f"{p['J_max'][j][i]:.4f} | {p['J_mean_rounded'][j][i]:.1f} |")
    v = np.array(p["peak_voltage_V"])
    print(f"\nRan to the end: {p['ran_to_end']} of {p['runs']}; realizable (S5: the last trial decides): "
          f"{'yes' if p['realizable'] else 'no'}, every trial: {'yes' if p['realizable_all'] else 'no'}; peak "
          f"voltages up to {v[:, 0].max():.3f} V and {v[:, 1].max():.3f} V.")


if __name__ == "__main__":
    main()
