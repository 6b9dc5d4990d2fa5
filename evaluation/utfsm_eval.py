"""Real-data evaluation on the UTFSM MTS/MR-damper records (docs/lab-records.md).

    PYTHONPATH=python python evaluation/utfsm_eval.py [--data ../shared/real-data/utfsm-mts-mrdamper]
                                                     [--out utfsm_out] [--no-docs]

For each current with a chirp and a sweep (0 A and 1 A): identify the rig
(displacement control, the damper as the Spencer MR element, the generic start)
from the chirp and predict the sweep from its command alone, and the other way
round; at 0.5 A (one sweep only) the fit alone.  Every record is also predicted by the thesis' baselines: its linear
G(s) for displacement (lsim of the command) and its modified Bouc-Wen model for
force (driven by the MEASURED displacement).  Writes the table between the
markers of docs/lab-records.md (unless --no-docs), the identification reports
under --out, and prints the run times.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from doc_tables import UTFSM_DATA, utfsm_start, write_between  # evaluation/ (the script's own folder)

ROOT = Path(__file__).resolve().parents[1]
DATA = UTFSM_DATA
RECORDS = {"chirp20Hz_0A": 0.0, "chirp20Hz_1A": 1.0, "sweep15Hz_0A": 0.0, "sweep15Hz_0p5A": 0.5,
           "sweep15Hz_1A": 1.0}
PAIRS = (("chirp20Hz_0A", "sweep15Hz_0A"), ("sweep15Hz_0A", "chirp20Hz_0A"),
         ("chirp20Hz_1A", "sweep15Hz_1A"), ("sweep15Hz_1A", "chirp20Hz_1A"), ("sweep15Hz_0p5A", None))
SPECIMEN = "mr_damper"
#: the identified rigs, committed: tests/python/test_lab_utfsm.py predicts the held-out records with them
RIGS = ROOT / "evaluation" / "utfsm_rigs"
START, END = "<!-- utfsm-table:start -->", "<!-- utfsm-table:end -->"


def baselines(records: dict) -> dict:
    from servohydraulics.identification import baselines as b
    from servohydraulics.identification import nrmse_demeaned_pct, nrmse_pct

    out = {}
    for name, rec in records.items():
        x = b.thesis_displacement(rec.time, rec.command)
        f = b.thesis_mr_force(rec.displacement, rec.dt, RECORDS[name])
        out[name] = {"displacement": nrmse_pct(x, rec.displacement),
                     "displacement_demeaned": nrmse_demeaned_pct(x, rec.displacement),
                     "force": nrmse_pct(f, rec.force)}
        print(f"  thesis baselines {name}: displacement {out[name]['displacement']:.2f} % "
              f"(mean removed {out[name]['displacement_demeaned']:.2f} %), force {out[name]['force']:.2f} %")
    return out


def identify_and_predict(records: dict, out: Path) -> tuple[list, dict]:
    import servohydraulics as sh
    from servohydraulics.identification import compare, simulate_record
    from servohydraulics.identification.fit import fit_options

    rows, times = [], {}
    for train, test in PAIRS:
        t0, c0 = time.perf_counter(), time.process_time()
        ident = sh.identify([records[train]], mode="displacement", specimen=SPECIMEN, progress=False)
        times[train] = {"wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0}
        ident.write(out / f"identified_from_{train}")
        RIGS.mkdir(exist_ok=True)
        sh.save_rig(ident.rig, RIGS / f"identified_from_{train}.toml")
        fit = ident.after[0]
        roles = [("fit", fit)]
        if test is not None:
            opts = fit_options(ident.rig, [records[test]], "displacement")
            pred = compare(records[test], ident.rig, "displacement",
                           simulated=simulate_record(ident.rig, records[test], "displacement", options=opts))
            pred.write(out / f"{test}_from_{train}")
            roles.append(("held out", pred))
        for role, c in roles:
            rows.append({"identified_from": train, "record": c.name, "role": role,
                         **{ch: c.channels[ch]["nrmse_pct"] for ch in c.channels},
                         **{f"{ch}_demeaned": c.channels[ch]["nrmse_demeaned_pct"] for ch in c.channels}})
        print(f"  identified from {train} in {times[train]['wall_s']:.1f} s: "
              + ", ".join(f"{k} = {v:.4g}" for k, v in ident.values.items()))
        if ident.flags:
            print("    flags: " + "; ".join(ident.flags))
        print("    " + "; ".join(f"{role} {c.name}: displacement {c.nrmse('displacement'):.2f} %, force "
                                f"{c.nrmse('force'):.2f} %" for role, c in roles))
    return rows, times


def table(rows: list, base: dict, times: dict, n_samples: dict) -> str:
    lines = ["| identified from | record | role | displacement: ours | thesis G(s) | ours, mean removed | "
             "thesis, mean removed | force: ours (MR damper) | thesis Bouc-Wen (measured x) | ours <= thesis |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        b = base[r["record"]]
        wins = [ch for ch in ("displacement", "force") if r[ch] <= b[ch]]
        verdict = "both" if len(wins) == 2 else (f"{wins[0]} only" if wins else "neither")
        lines.append(f"| {r['identified_from']} | {r['record']} | {r['role']} | {r['displacement']:.2f} | "
                     f"{b['displacement']:.2f} | {r['displacement_demeaned']:.2f} | {b['displacement_demeaned']:.2f} | "
                     f"{r['force']:.2f} | {b['force']:.2f} | {verdict} |")
    lines += ["", "NRMSE in % = 100 rms(sim - measured) / std(measured); 'mean removed': the error's mean "
              "subtracted first (the README's figure).", "",
              f"Identification run times (wall clock, generic start, `--specimen {SPECIMEN}`, {os.cpu_count()} cores "
              f"shared with other jobs, load average {os.getloadavg()[0]:.1f} at the end): "
              + ", ".join(f"{k} ({n_samples[k]} samples) {v['wall_s']:.1f} s wall, {v['cpu_s']:.1f} s CPU (all threads)"
                          for k, v in times.items()) + "."]
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", default=str(DATA))
    p.add_argument("--out", default="utfsm_out")
    p.add_argument("--no-docs", action="store_true", help="do not rewrite docs/lab-records.md")
    args = p.parse_args(argv)
    start = utfsm_start(args.data, RECORDS, args.out)
    if start is None:
        return 2
    sh, records, out = start
    t0 = time.perf_counter()
    base = baselines(records)
    rows, times = identify_and_predict(records, out)
    text = table(rows, base, times, {k: len(v) for k, v in records.items()})
    (out / "utfsm_eval.json").write_text(json.dumps({"baselines": base, "rows": rows, "identify_s": times,
                                                     "cpus": os.cpu_count()}, indent=2) + "\n")
    print(text)
    if not args.no_docs:
        doc = ROOT / "docs" / "lab-records.md"
        write_between(doc, START, END, text)
        print(f"wrote the table into {doc}")
    print(f"total {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
