"""The accuracy tables of docs/benchmarks.md (issue 26) from the JSON files that
evaluation/accuracy_random_rigs.py wrote:

    python3 evaluation/accuracy_tables.py --method default evaluation/accuracy_wide_rigs.json ...
    python3 evaluation/accuracy_tables.py --method rk4 --sweep evaluation/accuracy_wide_rigs.json

Each file is one row (its run is named by ``LABEL=FILE``, else by the file's name): rigs compared
(and uncertain), within, flagged, silent, worst silent error, false alarms (within yet flagged)
and how many accurate runs had a flagged sample, precision, recall, CPU and wall time of the
method over the family.  ``--sweep``: one row per flag scale of the file's ``flag_sweep``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def _pct(a: int, b: int) -> str:
    return f"{a} of {b} ({100.0 * a / b:.0f} %)" if b else "-"


def _f(v, nd: int = 2) -> str:
    return "-" if v is None else f"{v:.{nd}f}"


def rows(files: list[str], method: str, sweep: bool) -> list[str]:
    out = []
    if sweep:
        out += ["| family | seed | flag bound (x configured) | misses | flagged | silent | false alarms (of accurate) "
                "| precision | recall |", "|---|---|---|---|---|---|---|---|---|"]
    else:
        out += ["| family | seed | run | rigs compared | within | misses | flagged | silent | worst silent "
                "| false alarms (of accurate) | accurate runs with a flagged sample | precision | recall "
                "| CPU [s] | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for spec in files:
        label, _, name = spec.rpartition("=")
        d = json.loads(Path(name).read_text())
        label = label or Path(name).stem
        if method not in d["counts"]:
            continue
        n = d["rigs"] - d["reference_failed"]
        if sweep:
            for sc, s in d.get("flag_sweep", {}).get(method, {}).items():
                out.append(f"| {d['family']} | {d['seed']} | {float(sc):g} | {s['flagged'] + s['silent']} | "
                           f"{s['flagged']} | {s['silent']} | {_pct(s['flagged_within'], s['within'])} | "
                           f"{_f(s['flag_precision'])} | {_f(s['flag_recall'])} |")
            continue
        c = d["counts"][method]
        compared = n - c["skipped"]
        sample = c.get("sample_flagged_within")
        out.append(f"| {d['family']} | {d['seed']} | {label} | {compared} ({d['reference_uncertain']} uncertain"
                   f"{', ' + str(c['skipped']) + ' skipped' if c['skipped'] else ''}) | {c['within']} | "
                   f"{c['flagged'] + c['silent']} | {c['flagged']} | {c['silent']} | {c['worst_silent']:.2e} | "
                   f"{_pct(c['flagged_within'], c['within'])} | {'-' if sample is None else sample} | "
                   f"{_f(c['flag_precision'])} | {_f(c['flag_recall'])} | "
                   f"{_f(c.get('cpu_s'), 0)} | {c['wall_s']:.0f} |")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", help="JSON files of accuracy_random_rigs.py, as FILE or LABEL=FILE")
    ap.add_argument("--method", choices=("default", "rk4"), default="default")
    ap.add_argument("--sweep", action="store_true", help="the flag-scale sweep instead of the counts")
    args = ap.parse_args(argv)
    print("\n".join(rows(args.files, args.method, args.sweep)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
