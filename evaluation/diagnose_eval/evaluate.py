"""Evaluation of the diagnose workflow on records with hidden effects.

    python evaluation/diagnose_eval/generate.py --out build/diagnose_eval
    python evaluation/diagnose_eval/evaluate.py --data build/diagnose_eval --jobs 2

Runs ``sh.diagnose`` on every record of the manifest (the workflow sees only the
record, the mode and the nominal rig), then, and only then, reads the answer key
and writes docs/diagnose_eval.md and docs/diagnose_eval.json: naming precision and
recall, false-positive rate on no-effect records, confusion matrix, parameter
error and interval coverage, fraction of the gap closed, runtime.

``--only SUBSET`` diagnoses and reports the records of one subset (``SUBSETS``,
chosen by the answer key's labels: e.g. ``issue25``) into its own ``--doc``, ``--ids``
the records named;
``--before JSON`` adds the same records diagnosed by earlier code.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

TARGETS = {"recall_single": 0.90, "false_positive": 0.05, "param_error": 0.20, "gap_closed": 0.80}


def run_one(args: tuple) -> dict:
    """One diagnosis: (id, record, rig, mode[, stiff_steps[, fit_step_gain]]): the last two set
    ``diagnosis.engine.STIFF_STEPS`` and ``FIT_STEP_GAIN`` (None: the package's default) in the worker."""
    rid, record, rig_path, mode = args[:4]
    import servohydraulics as sh
    from servohydraulics.diagnosis import engine

    if len(args) > 4 and args[4] is not None:
        engine.STIFF_STEPS = args[4]
    if len(args) > 5 and args[5] is not None:
        engine.FIT_STEP_GAIN = args[5]

    t0 = time.time()
    d = sh.diagnose([record], sh.load_rig(rig_path), mode=mode, progress=False)
    js = d.to_dict()
    closed = [v for v in js["gap_closed"].values() if v is not None]
    main = max(js["gap_before"], key=lambda c: js["gap_before"][c] - js["noise_floor"][c])
    return {"id": rid, "verdict": js["verdict"], "named": [e["name"] for e in js["effects"]],
            "ambiguous": js["ambiguous_between"],
            "parameters": [{k: v for k, v in e["parameters"].items()} for e in js["effects"]],
            "gap_before": js["gap_before"], "gap_after": js["gap_after"], "noise_floor": js["noise_floor"],
            "gap_closed_main": js["gap_closed"][main], "gap_closed_mean": float(np.mean(closed)) if closed else None,
            "main_channel": main, "runtime": time.time() - t0}


def _fitted(params: dict, pk: str, answer: dict) -> dict:
    """The fitted value and 95 % interval of truth parameter pk.  ``g_peak`` (the flow ratio
    g(x_peak) at the record's peak spool opening, for tabulated curves whose g(1) the
    record never reaches) is derived from the fitted g_1 and knee x_k (no interval)."""
    if pk != "g_peak":
        return params[pk]
    from servohydraulics.diagnosis.effects import knee_flow_curve

    g_1 = params["g_1"]["value"]
    x_k = params.get("x_k", {"value": 0.0})["value"] or 0.0
    if g_1 is None:
        return {"value": None, "interval_95": [None, None]}
    opening, flow = knee_flow_curve(g_1, x_k)
    return {"value": float(np.interp(answer["opening"], opening, flow)), "interval_95": [None, None]}


#: the subsets the metrics are computed over (label, which answer-key rows)
SUBSETS = (("snr>=30", lambda k: k["snr"] >= 30), ("snr=55", lambda k: k["snr"] == 55),
           ("snr=40", lambda k: k["snr"] == 40), ("snr=30", lambda k: k["snr"] == 30),
           ("snr=20", lambda k: k["snr"] == 20), ("all", lambda k: True),
           ("issue13", lambda k: k.get("set") == "issue13"),
           ("issue13 snr>=30", lambda k: k.get("set") == "issue13" and k["snr"] >= 30),
           ("issue25", lambda k: k.get("set") == "issue25"),
           ("issue25 snr>=30", lambda k: k.get("set") == "issue25" and k["snr"] >= 30),
           ("issue25 pairs", lambda k: k.get("set") == "issue25" and k["kind"] == "pair"),
           ("issue25 moving mass", lambda k: k.get("set") == "issue25"
            and any(a["name"] == "moving_mass" for a in k["answers"])))


def coverage_rows(results: list[dict], key: list[dict], snr_min: float = 30) -> list[dict]:
    """Every in-library parameter of a correctly named single effect (SNR >= ``snr_min``): its truth,
    value, 95 % interval, status and whether the interval covers the truth (the coverage figure's
    parameters; a parameter "at bound" or "not identified" has no interval to cover with)."""
    ans = {k["id"]: k for k in key}
    out = []
    for r in results:
        k = ans[r["id"]]
        if k["snr"] < snr_min or k["kind"] != "single" or k["runtime_check"]:
            continue
        a = k["answers"][0]
        if a["name"] not in r["named"] or not a.get("in_library", True):
            continue
        i = r["named"].index(a["name"])
        for pk, tv in a["parameters"].items():
            p = _fitted(r["parameters"][i], pk, a)
            lo, hi = p["interval_95"]
            status = p.get("status", "identified")
            covers = (lo <= tv <= hi) if status == "identified" and lo is not None and hi is not None else None
            out.append({"id": r["id"], "form": k["forms"][0].split(":")[0], "rig": k.get("rig", "paper"),
                        "snr": k["snr"], "key": pk, "truth": tv, "value": p["value"], "interval": [lo, hi],
                        "status": status, "covers": covers})
    return out


def _frac(a, b) -> float | None:
    return a / b if b else None


def metrics(results: list[dict], key: list[dict]) -> dict:
    ans = {k["id"]: k for k in key}
    rows = []
    for r in results:
        k = ans[r["id"]]
        rows.append((r, k))
    out: dict = {}
    names = sorted({a["name"] for k in key for a in k["answers"]})
    for label, sel in SUBSETS:
        rs = [(r, k) for r, k in rows if sel(k) and not k["runtime_check"]]
        singles = [(r, k) for r, k in rs if k["kind"] == "single"]
        nones = [(r, k) for r, k in rs if k["kind"] == "none"]
        pairs = [(r, k) for r, k in rs if k["kind"] == "pair"]
        right = [(r, k) for r, k in singles if r["named"][:1] == [k["answers"][0]["name"]]]
        right_any = [(r, k) for r, k in singles if k["answers"][0]["name"] in r["named"]]
        amb = [(r, k) for r, k in singles if r["verdict"] == "ambiguous" and not r["named"]]
        fp = [(r, k) for r, k in nones if r["named"]]
        perr, cover, inlib, inlib_c, perr_alt, unsure = [], [], [], [], [], []
        for r, k in right_any:
            a = k["answers"][0]
            i = r["named"].index(a["name"])
            for pk, tv in a["parameters"].items():
                p = _fitted(r["parameters"][i], pk, a)
                if p["value"] is not None and tv:
                    perr.append(abs(p["value"] - tv) / abs(tv))
                    inlib.append(a.get("in_library", True))
                    lo, hi = p["interval_95"]
                    if p.get("status", "identified") != "identified":
                        unsure.append(a.get("in_library", True))  # at bound / not identified: no interval
                    elif lo is not None and hi is not None:
                        cover.append(lo <= tv <= hi)
                        inlib_c.append(a.get("in_library", True))
            for pk, tv in a.get("alt_parameters", {}).items():
                p = _fitted(r["parameters"][i], pk, a)
                if p["value"] is not None and tv:
                    perr_alt.append(abs(p["value"] - tv) / abs(tv))
        inlib_a, inlib_ca = np.array(inlib, bool), np.array(inlib_c, bool)
        perr_a, cover_a = np.array(perr, float), np.array(cover, bool)
        closed = [r["gap_closed_main"] for r, k in right_any if r["gap_closed_main"] is not None]
        pair_err, pair_cover = [], []
        for r, k in pairs:
            for a in k["answers"]:
                if a["name"] not in r["named"] or not a.get("in_library", True):
                    continue
                i = r["named"].index(a["name"])
                for pk, tv in a["parameters"].items():
                    p = _fitted(r["parameters"][i], pk, a)
                    if p["value"] is not None and tv:
                        pair_err.append(abs(p["value"] - tv) / abs(tv))
                        lo, hi = p["interval_95"]
                        if p.get("status", "identified") == "identified":
                            pair_cover.append(lo is not None and hi is not None and lo <= tv <= hi)
        pair_both = [(r, k) for r, k in pairs if all(a["name"] in r["named"] for a in k["answers"])]
        pair_one = [(r, k) for r, k in pairs if any(a["name"] in r["named"] for a in k["answers"])]
        per_name = {}
        for n in names:
            truth_n = [(r, k) for r, k in rs if any(a["name"] == n for a in k["answers"])]
            named_n = [(r, k) for r, k in rs if n in r["named"]]
            tp = [(r, k) for r, k in named_n if any(a["name"] == n for a in k["answers"])]
            per_name[n] = {"recall": _frac(len([1 for r, k in truth_n if n in r["named"]]), len(truth_n)),
                           "precision": _frac(len(tp), len(named_n)), "n_truth": len(truth_n),
                           "n_named": len(named_n)}
        out[label] = {
            "n_single": len(singles), "n_none": len(nones), "n_pair": len(pairs),
            "single_right_first": _frac(len(right), len(singles)),
            "single_right_any": _frac(len(right_any), len(singles)),
            "single_ambiguous": _frac(len(amb), len(singles)),
            "false_positive_rate": _frac(len(fp), len(nones)),
            "param_error_median": float(np.median(perr)) if perr else None,
            "param_within_20pct": _frac(sum(e <= 0.2 for e in perr), len(perr)),
            "interval_coverage": _frac(sum(cover), len(cover)),
            "interval_coverage_in_library": _frac(int(cover_a[inlib_ca].sum()), int(inlib_ca.sum())),
            "interval_coverage_out_of_library": _frac(int(cover_a[~inlib_ca].sum()), int((~inlib_ca).sum())),
            "param_within_20pct_in_library": _frac(int((perr_a[inlib_a] <= 0.2).sum()), int(inlib_a.sum())),
            "param_within_20pct_out_of_library": _frac(int((perr_a[~inlib_a] <= 0.2).sum()), int((~inlib_a).sum())),
            "n_param_in_library": int(inlib_a.sum()), "n_param_out_of_library": int((~inlib_a).sum()),
            "n_interval_in_library": int(inlib_ca.sum()),
            "n_at_bound_or_unidentified_in_library": int(sum(unsure)),
            "friction_alt_truth_within_20pct": _frac(sum(e <= 0.2 for e in perr_alt), len(perr_alt)),
            "gap_closed_median": float(np.median(closed)) if closed else None,
            "gap_closed_at_least_80pct": _frac(sum(c >= 0.8 for c in closed), len(closed)),
            "pair_both_named": _frac(len(pair_both), len(pairs)), "pair_one_named": _frac(len(pair_one), len(pairs)),
            "pair_param_error_median": float(np.median(pair_err)) if pair_err else None,
            "pair_param_within_20pct": _frac(sum(e <= 0.2 for e in pair_err), len(pair_err)),
            "pair_interval_coverage": _frac(sum(pair_cover), len(pair_cover)), "n_pair_param": len(pair_err),
            "per_name": per_name,
        }
    # confusion matrix over single-effect and no-effect records (first name, or verdict)
    labels = names + ["none"]
    named = sorted({n for r, _ in rows for n in r["named"][:1]} - set(names))  # names outside the answer key
    preds = names + named + ["no_effect", "ambiguous"]
    cm = {t: {p: 0 for p in preds} for t in labels}
    for r, k in rows:
        if k["kind"] == "pair" or k["runtime_check"]:
            continue
        t = k["answers"][0]["name"] if k["answers"] else "none"
        p = r["named"][0] if r["named"] else ("ambiguous" if r["verdict"] == "ambiguous" else "no_effect")
        cm[t][p] += 1
    out["confusion"] = cm
    rt = [r["runtime"] for r, k in rows if not k["runtime_check"]]
    out["runtime"] = {"median_s": float(np.median(rt)), "max_s": float(np.max(rt)), "total_s": float(np.sum(rt))}
    big = [(r, k) for r, k in rows if k["runtime_check"]]
    if big:
        r, k = big[0]
        out["runtime"]["record_10s_2kHz_s"] = r["runtime"]
        out["runtime"]["record_10s_2kHz_named"] = r["named"]
    return out


def _p(v) -> str:
    return "-" if v is None else f"{100 * v:.0f} %"


#: the sections of the cases added for an issue: (subset label, heading, what they are)
CASE_SETS = {
    "issue13": ("The cases added for issue 13",
                "In-loop (true transport) and command delays, load pressure with 400 N of Coulomb friction, Bouc-Wen "
                "specimens, and two rigs other than the paper's (rigB: 2.5 t, 250 kN/m, 50 cm^2, 40 Hz valve; rigC: "
                "80 kg, 20 kN/m, 10 cm^2, 120 Hz valve) in displacement and force control "
                "(`plan_new` in evaluation/diagnose_eval/generate.py)."),
    "issue25": ("The cases added for issue 25 (the kinds of the two blind misses)",
                "A piston mass that is a large share of a small rig's moving mass (rigD: 150 kg, 50 kN/m, 6 cm^2, "
                "50 Hz valve; m_p 30, 60 and 120 kg in displacement control, 60 kg in force control; rigC, 40 kg), "
                "a mass the load cell sees (the blind miss itself: 25 and 60 kg on rigD in displacement control, "
                "60 kg in force control, 40 kg on rigC; truth: moving_mass), at 40 and 30 dB, "
                "and the load-pressure term with a second effect (Coulomb friction 250-600 N, viscous damping "
                "4 kN s/m) on records of large forces (the standard command enlarged 1.3-1.7 times: forces to "
                "65-95 kN on the paper's rig, load pressures to 0.8-1.2 of the supply) at 55 and 40 dB, on the "
                "paper's rig and rigB; no-effect records of rigD (`plan_issue25` in "
                "evaluation/diagnose_eval/generate.py)."),
}


def _case_section(m: dict, label: str) -> list[str]:
    """The cases added for an issue: their own recall, false positives, gap closed, pairs."""
    head, what = CASE_SETS[label]
    L = ["", f"## {head}", "", what, "",
         "| subset | single: right first | right anywhere | false positives | param within 20 % | gap closed "
         "(median) | pairs: both named |", "|---|---|---|---|---|---|---|"]
    for lab in (f"{label} snr>=30", label):
        s = m[lab]
        L.append(f"| {lab.replace(label, 'these cases').replace('cases snr', 'cases, SNR')} "
                 f"({s['n_single']} single, {s['n_none']} none, {s['n_pair']} pairs) | {_p(s['single_right_first'])} | "
                 f"{_p(s['single_right_any'])} | {_p(s['false_positive_rate'])} | {_p(s['param_within_20pct'])} | "
                 f"{_p(s['gap_closed_median'])} | {_p(s['pair_both_named'])} |")
    L += ["", "| name | recall | precision | records with it | times named |", "|---|---|---|---|---|"]
    for n, v in m[label]["per_name"].items():
        if v["n_truth"] or v["n_named"]:
            L.append(f"| {n} | {_p(v['recall'])} | {_p(v['precision'])} | {v['n_truth']} | {v['n_named']} |")
    return L


def _coverage_section(results: list[dict], key: list[dict]) -> list[str]:
    """The coverage figure's parameters, one by one: the misses and those without an interval."""
    rows = coverage_rows(results, key)
    judged = [r for r in rows if r["covers"] is not None]
    L = ["", "## Coverage of the 95 % intervals, parameter by parameter", "",
         "Coverage (the figure above): of the in-library parameters of correctly named single effects at SNR >= "
         "30 dB, the share whose 95 % interval contains the truth; a parameter reported \"at bound / not "
         f"identified\" has no interval and is counted apart.  {sum(r['covers'] for r in judged)} of "
         f"{len(judged)} intervals cover; {len(rows) - len(judged)} parameters without an interval.", "",
         "| record | form | rig | SNR | parameter | truth | fitted | 95 % interval | status |",
         "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["covers"] is not False and r["status"] == "identified":
            continue
        lo, hi = r["interval"]
        iv = f"[{lo:.5g}, {hi:.5g}]" if lo is not None and hi is not None else "-"
        val = "-" if r["value"] is None else f"{r['value']:.5g}"
        L.append(f"| {r['id']} | {r['form']} | {r['rig']} | {r['snr']} | {r['key']} | {r['truth']:.5g} | {val} | "
                 f"{iv} | {r['status'] if r['covers'] is None else 'misses'} |")
    return L


#: the headline figures of the before/after table: (label, subset, metric key)
HEADLINE = (("single effects: right name first", "snr>=30", "single_right_first"),
            ("single effects: right name first (all SNR)", "all", "single_right_first"),
            ("no-effect records: false names", "all", "false_positive_rate"),
            ("pairs: both named (all SNR)", "all", "pair_both_named"),
            ("95 % coverage, in-library (SNR >= 30)", "snr>=30", "interval_coverage_in_library"),
            ("95 % coverage, out-of-library (SNR >= 30)", "snr>=30", "interval_coverage_out_of_library"),
            ("issue-25 cases: singles right first", "issue25", "single_right_first"),
            ("issue-25 cases: pairs both named", "issue25", "pair_both_named"),
            ("issue-25 cases: false names", "issue25", "false_positive_rate"))


def _before_after_section(m: dict, per: list[dict], before: dict, key: list[dict]) -> list[str]:
    """The same records diagnosed before this issue's changes (``before``: that run's JSON) and now."""
    mb = metrics(before["records"], key)
    L = ["", "## Before and after (issue 25)", "",
         f"Before: the same records, diagnosed by the code before issue 25 "
         f"(`{before.get('code', 'the base commit')}`); both columns computed by this script's metrics.", "",
         "| measure | before | after |", "|---|---|---|"]
    for label, sub, k in HEADLINE:
        L.append(f"| {label} | {_p(mb[sub][k])} | {_p(m[sub][k])} |")
    cb = [r for r in coverage_rows(before["records"], key) if r["covers"] is not None]
    ca = [r for r in coverage_rows(per, key) if r["covers"] is not None]
    L.append(f"| coverage counts (SNR >= 30, in-library) | {sum(r['covers'] for r in cb)} of {len(cb)} | "
             f"{sum(r['covers'] for r in ca)} of {len(ca)} |")
    ans = {k["id"]: k for k in key}
    old = {r["id"]: r for r in before["records"]}
    L += ["", "Records whose names changed:", "", "| record | hidden | before | after |", "|---|---|---|---|"]
    for r in per:
        b = old.get(r["id"])
        if b is None or (b["named"] == r["named"] and b["verdict"] == r["verdict"]):
            continue
        k = ans[r["id"]]

        def said(x):
            return ", ".join(x["named"]) or ("/".join(x["ambiguous"]) + " (ambiguous)" if x["ambiguous"] else
                                             x["verdict"])
        L.append(f"| {r['id']} ({k.get('rig', 'paper')} {k['mode']}, {k['snr']} dB) | "
                 f"{'; '.join(f.split(':')[0] for f in k['forms']) or 'none'} | {said(b)} | {said(r)} |")
    return L


def write_doc(m: dict, per: list[dict], key: list[dict], doc: Path, cmd: str, wall: float, jobs: int,
              before: dict | None = None) -> None:
    ans = {k["id"]: k for k in key}
    L = ["# Diagnose: evaluation on hidden effects", "",
         "Made by (every number below):", "", "```", cmd, "```", "",
         f"Wall time {wall:.0f} s with {jobs} worker processes. Records: 2 kHz, "
         f"{key[0]['duration']:g} s each (one extra 10 s record for the runtime check), made by "
         "`evaluation/diagnose_eval/independent_plant.py` (plain-Python RK4 of Eqs 1-5, no code shared with the "
         "core) with white noise on displacement and force. The workflow sees the record, the mode and the "
         "nominal rig only; the answer key is read after all diagnoses are done.", "",
         "## Against the targets (SNR >= 30 dB)", "",
         "| measure | target | measured |", "|---|---|---|"]
    s = m["snr>=30"]
    L.append(f"| right name (first effect) on single-effect records | >= 90 % | {_p(s['single_right_first'])} "
             f"({s['n_single']} records) |")
    L.append(f"| false positives on no-effect records | <= 5 % | {_p(s['false_positive_rate'])} "
             f"({s['n_none']} records) |")
    L.append(f"| fitted parameter within 20 % of truth (right name) | all | {_p(s['param_within_20pct'])} "
             f"(median error {_p(s['param_error_median'])}) |")
    L.append(f"| gap closed (main channel, of the part above the noise floor) | >= 80 % | median "
             f"{_p(s['gap_closed_median'])}; >= 80 % in {_p(s['gap_closed_at_least_80pct'])} of records |")
    L.append(f"| 95 % interval covers the truth, in-library forms | (95 %) | "
             f"{_p(s['interval_coverage_in_library'])} ({s['n_param_in_library']} parameters) |")
    L.append(f"| 95 % interval covers the truth, out-of-library forms | (report) | "
             f"{_p(s['interval_coverage_out_of_library'])} ({s['n_param_out_of_library']} parameters) |")
    L.append(f"| parameter within 20 %: in-library / out-of-library forms | | "
             f"{_p(s['param_within_20pct_in_library'])} / {_p(s['param_within_20pct_out_of_library'])} |")
    L.append(f"| second truths within 20 % (Stribeck sliding level, g(1) of a table never reached) | (report) | "
             f"{_p(s['friction_alt_truth_within_20pct'])} |")
    L.append(f"| two-effect records, in-library parameters (named): median error / within 20 % / interval "
             f"covers | (report) | {_p(s['pair_param_error_median'])} / {_p(s['pair_param_within_20pct'])} / "
             f"{_p(s['pair_interval_coverage'])} ({s['n_pair_param']} parameters) |")
    rt = m["runtime"]
    L.append(f"| runtime, 10 s 2 kHz record | < 120 s | {rt.get('record_10s_2kHz_s', float('nan')):.1f} s |")
    s = m["snr>=30"]
    unmet = []
    if (s["single_right_first"] or 0) < TARGETS["recall_single"]:
        unmet.append("right name on single-effect records")
    if (s["false_positive_rate"] or 0) > TARGETS["false_positive"]:
        unmet.append(f"false-positive rate ({s['n_none']} no-effect records: one false positive is "
                     f"{_p(1 / max(s['n_none'], 1))})")
    # the misses, record by record (SNR >= 30 dB, right name found)
    miss_p, miss_g = [], []
    for r in per:
        k = ans[r["id"]]
        if k["snr"] < 30 or k["runtime_check"] or k["kind"] != "single":
            continue
        a0 = k["answers"][0]
        if a0["name"] not in r["named"]:
            continue
        i = r["named"].index(a0["name"])
        for pk, tv in a0["parameters"].items():
            v = _fitted(r["parameters"][i], pk, a0)["value"]
            if v is not None and tv and abs(v - tv) / abs(tv) > 0.2:
                miss_p.append(f"{r['id']} ({k['forms'][0].split(':')[0]}: {pk} {v:.4g} against {tv:.4g})")
        if r["gap_closed_main"] is not None and r["gap_closed_main"] < 0.8:
            miss_g.append(f"{r['id']} ({k['forms'][0].split(':')[0]}: {_p(r['gap_closed_main'])})")
    if miss_p:
        unmet.append("parameter within 20 % of truth on every correctly named record; misses: " + ", ".join(miss_p))
    if miss_g:
        unmet.append("gap closed >= 80 % on every correctly named record; misses: " + ", ".join(miss_g))
    if (s["interval_coverage_in_library"] or 0) < 0.90:
        unmet.append("95 % interval coverage on in-library forms below 90 % (HAC sandwich intervals do not "
                     "include the bias of an unconverged or bound-limited fit, nor the nuisance initial state)")
    L += ["", "Not met, or met only in part: " + ("; ".join(unmet) if unmet else "none") + "."]
    L += ["", "Truth for forms outside the library (fixed in evaluation/diagnose_eval/generate.py before any "
          "diagnosis): Stribeck friction -> the energy-equivalent Coulomb force "
          "F_eq = sum(F_fr v) / sum(|v|) over the record (second truth, reported above: the sliding Coulomb "
          "level F_c); LuGre friction (with a Stribeck peak F_s = 1.3 F_c that the library's LuGre does not "
          "have) -> lugre_friction with its sigma_0 and sliding level F_c; flow curves -> the full-opening flow "
          "ratio g_1 = g(1) (rational: 1 / (1 + b); the preset-kind table, linear below 10 % opening, run with "
          "a 75 kN force sweep that opens the spool to about 0.35, beyond the knee as in Fig 4b: its last "
          "entry), except the table bending from 2 % opening, whose 15 kN sweep opens the spool to about 0.07 "
          "only: its truth is g_peak = g(x_peak) at the record's peak opening (g(1) is outside the record; "
          "shown as the second truth); filter delay -> the Bessel filter's DC group delay."]
    for label in CASE_SETS:
        if m[label]["n_single"] + m[label]["n_none"] + m[label]["n_pair"]:
            L += _case_section(m, label)
    L += _coverage_section(per, key)
    if before is not None:
        L += _before_after_section(m, per, before, key)
    L += ["", "## By noise level", "",
          "| SNR | single: right first | right anywhere | ambiguous | false positives | param within 20 % | "
          "coverage | gap closed (median) | pairs: both named | pairs: one named |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for lab in ("snr=55", "snr=40", "snr=30", "snr=20", "all"):
        s = m[lab]
        L.append(f"| {lab} | {_p(s['single_right_first'])} | {_p(s['single_right_any'])} | "
                 f"{_p(s['single_ambiguous'])} | {_p(s['false_positive_rate'])} | {_p(s['param_within_20pct'])} | "
                 f"{_p(s['interval_coverage'])} | {_p(s['gap_closed_median'])} | {_p(s['pair_both_named'])} | "
                 f"{_p(s['pair_one_named'])} |")
    L += ["", "## Precision and recall per name (all SNR)", "", "| name | recall | precision | records with it | "
          "times named |", "|---|---|---|---|---|"]
    for n, v in m["all"]["per_name"].items():
        L.append(f"| {n} | {_p(v['recall'])} | {_p(v['precision'])} | {v['n_truth']} | {v['n_named']} |")
    cm = m["confusion"]
    preds = list(next(iter(cm.values())))
    short = {p: p.replace("_", " ") for p in preds}
    L += ["", "## Confusion matrix (single-effect and no-effect records, all SNR; rows: truth, columns: first "
          "name or verdict)", "", "| truth \\ named | " + " | ".join(short[p] for p in preds) + " |",
          "|---|" + "---|" * len(preds)]
    for t, row in cm.items():
        L.append(f"| {t} | " + " | ".join(str(row[p]) if row[p] else "." for p in preds) + " |")
    L += ["", f"Runtime per record: median {rt['median_s']:.1f} s, max {rt['max_s']:.1f} s.", "",
          "## Every record", "", "| id | mode | SNR | hidden (form) | verdict | named | parameter (truth) | gap "
          "closed |", "|---|---|---|---|---|---|---|---|"]
    for r in per:
        k = ans[r["id"]]
        par = []
        for a in k["answers"]:
            if a["name"] in r["named"]:
                i = r["named"].index(a["name"])
                for pk, tv in a["parameters"].items():
                    v = _fitted(r["parameters"][i], pk, a)["value"]
                    par.append(f"{pk} {v:.4g} ({tv:.4g})" if v is not None else f"{pk} - ({tv:.4g})")
                for pk, tv in a.get("alt_parameters", {}).items():
                    v = _fitted(r["parameters"][i], pk, a)["value"]
                    what = a.get("alt_label", "second truth")
                    par[-1] += f" [{what}: {pk} {v:.4g} ({tv:.4g})]" if v is not None else f" [{what} {tv:.4g}]"
        L.append(f"| {r['id']} | {k.get('rig', 'paper')} {k['mode']} | {k['snr']} | "
                 f"{'; '.join(k['forms']) or 'none'} | {r['verdict']} | "
                 f"{', '.join(r['named']) or ('/'.join(r['ambiguous']) if r['ambiguous'] else '-')} | "
                 f"{'; '.join(par) or '-'} | {_p(r['gap_closed_main'])} |")
    doc.write_text("\n".join(L) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--data", default="build/diagnose_eval")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--doc", default="docs/diagnose_eval.md")
    p.add_argument("--from-json", action="store_true", help="re-render the doc from the saved JSON (no diagnoses)")
    p.add_argument("--before", help="the JSON of the same evaluation before issue 25 (its before/after section)")
    p.add_argument("--cache", help="a JSON-lines file of the diagnoses done so far: each result is appended as it "
                                   "comes, and records already in it are not diagnosed again (a long run resumes)")
    p.add_argument("--only", choices=[label for label, _ in SUBSETS],
                   help="diagnose and report only the records of this subset (write the doc elsewhere with --doc)")
    p.add_argument("--ids", help="diagnose and report only these records (comma-separated ids, e.g. r003,r004; "
                                 "write the doc elsewhere with --doc)")
    p.add_argument("--stiff-steps", type=int, default=None, metavar="N",
                   help="the diagnosis' error-controlled pair hands a sample to its stiff integrator past N "
                        "dopri5 steps (diagnosis.engine.STIFF_STEPS; default: the package's, 100)")
    p.add_argument("--fit-step-gain", type=float, default=None, metavar="G",
                   help="a diagnosis fit stops where a step gains less than G of -2 log L "
                        "(diagnosis.engine.FIT_STEP_GAIN; default: the package's, 0.01)")
    p.add_argument("--cached-only", action="store_true",
                   help="report only the records already in --cache (a run cut short; the doc says how many)")
    a = p.parse_args()
    from servohydraulics.workers import check_workers, process_pool

    try:  # 1 .. cpu_count, before any work (a large count forks without bound)
        check_workers(a.jobs, "--jobs")
    except ValueError as e:
        p.error(str(e))
    data = Path(a.data)
    doc = Path(a.doc)
    before = json.loads(Path(a.before).read_text()) if a.before else None
    if a.from_json:
        saved = json.loads(doc.with_suffix(".json").read_text())
        key = json.loads((data / "answer_key.json").read_text())
        key = [k for k in key if k["id"] in {r["id"] for r in saved["records"]}]
        write_doc(metrics(saved["records"], key), saved["records"], key, doc, saved["command"], saved["wall_s"],
                  a.jobs, before)
        return
    manifest = json.loads((data / "manifest.json").read_text())
    if a.only:  # the subset's rows are chosen by the answer key's labels (set, snr), not by any result
        keep = dict(SUBSETS)[a.only]
        ids = {k["id"] for k in json.loads((data / "answer_key.json").read_text()) if keep(k)}
        manifest = [m for m in manifest if m["id"] in ids]
    if a.ids:
        ids = [i.strip() for i in a.ids.split(",") if i.strip()]
        unknown = sorted(set(ids) - {m["id"] for m in manifest})
        if unknown or not ids:
            p.error(f"invalid --ids = {a.ids!r}: {unknown or 'no id'} not in {data / 'manifest.json'}"
                    + (f" (with --only '{a.only}')" if a.only else ""))
        manifest = [m for m in manifest if m["id"] in set(ids)]
    done = {}
    if a.cache and Path(a.cache).exists():
        for line in Path(a.cache).read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                done[r["id"]] = r
    if a.cached_only:
        manifest = [m for m in manifest if m["id"] in done]
    jobs = [(m["id"], str(data / m["record"]), str(data / m["rig"]), m["mode"], a.stiff_steps, a.fit_step_gain)
            for m in manifest if m["id"] not in done]
    t0 = time.time()
    from tqdm import tqdm

    with process_pool(a.jobs, "--jobs") as ex:  # workers that die with this process
        for r in tqdm(ex.map(run_one, jobs), total=len(jobs), file=sys.stderr, desc="diagnose"):
            done[r["id"]] = r
            if a.cache:
                with open(a.cache, "a") as f:
                    f.write(json.dumps(r, default=str) + "\n")
    results = [done[m["id"]] for m in manifest]
    wall = time.time() - t0 + sum(r["runtime"] for r in done.values() if r["id"] not in {j[0] for j in jobs})
    key = json.loads((data / "answer_key.json").read_text())  # read only now, after every diagnosis
    key = [k for k in key if k["id"] in {r["id"] for r in results}]
    m = metrics(results, key)
    gen = data / "generate.json"
    gen_cmd = (json.loads(gen.read_text())["command"] if gen.exists()
               else f"python evaluation/diagnose_eval/generate.py --out {a.data}")
    cmd = (f"{gen_cmd} --jobs {a.jobs}\n"
           f"python evaluation/diagnose_eval/evaluate.py --data {a.data} --jobs {a.jobs}"
           + (f" --only '{a.only}'" if a.only else "") + (f" --ids {a.ids}" if a.ids else "")
           + (f" --doc {a.doc}" if a.only or a.ids or a.doc != "docs/diagnose_eval.md" else "")
           + (f" --stiff-steps {a.stiff_steps}" if a.stiff_steps is not None else "")
           + (f" --fit-step-gain {a.fit_step_gain:g}" if a.fit_step_gain is not None else "")
           + (f" --cache {a.cache} --cached-only: {len(manifest)} records of the set" if a.cached_only else ""))
    write_doc(m, results, key, doc, cmd, wall, a.jobs, before)
    doc.with_suffix(".json").write_text(json.dumps({"metrics": m, "records": results, "command": cmd,
                                                    "wall_s": wall}, indent=1, default=str))
    print(f"wrote {doc} ({wall:.0f} s)")


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
