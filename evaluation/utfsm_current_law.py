"""The MR damper's current law identified across the UTFSM records (docs/lab-records.md, issue 25).

    SH_SHARED_DIR=../shared PYTHONPATH=python python evaluation/utfsm_current_law.py [--out utfsm_law_out]
        [--laws spencer,quiroz2022] [--sets may,june] [--no-docs]

(a) **May sweeps 0 A + 1 A -> the held-out 0.5 A sweep.**  ``sh.identify([sweep 0 A, sweep 1 A],
    currents=[0, 1], law=...)`` (generic start, displacement control, one actuator loop for both,
    the damper's law across them), then the 0.5 A sweep predicted from its command alone
    (``compare(..., current=0.5)``: the law at 0.5 A, outside nothing it was fitted on) against the
    thesis' models on that record: its G(s) driven by the command, its Bouc-Wen driven by the
    measured displacement at 0.5 A (``identification.baselines``).  Acceptance: ours no worse on
    both channels.  Both laws (Spencer's linear law, the thesis' law).
(b) **June chirps 0 A + 1 A -> each May sweep (0, 0.5, 1 A)**, the same way; beside it the
    measured-vs-measured evidence of the campaign difference (H1 of the measured force over the
    measured displacement, June chirp / May sweep, at 0 A and 1 A; as a control the thesis' one
    model driven by each record's measured displacement).

Writes the tables between the markers of docs/lab-records.md (unless ``--no-docs``), the
identified rigs into ``evaluation/utfsm_rigs/law_<set>_<law>.toml`` (tests/python/test_lab_law.py
predicts the 0.5 A sweep with the May rig), the identification reports and comparisons under
``--out``, the figure ``docs/figures/utfsm_law_0p5A.png`` (measured and predicted force at
0.5 A: the force-velocity loop and a time window) and prints the run times.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from doc_tables import UTFSM_DATA, utfsm_start, write_between  # evaluation/ (the script's own folder)

ROOT = Path(__file__).resolve().parents[1]
DATA = UTFSM_DATA
SWEEPS = {"sweep15Hz_0A": 0.0, "sweep15Hz_0p5A": 0.5, "sweep15Hz_1A": 1.0}
CHIRPS = {"chirp20Hz_0A": 0.0, "chirp20Hz_1A": 1.0}
#: training set -> (records, the records predicted)
SETS = {"may": (("sweep15Hz_0A", "sweep15Hz_1A"), ("sweep15Hz_0p5A",)),
        "june": (("chirp20Hz_0A", "chirp20Hz_1A"), tuple(SWEEPS))}
CURRENT = {**SWEEPS, **CHIRPS}
LAWS = ("spencer", "quiroz2022")
RIGS = ROOT / "evaluation" / "utfsm_rigs"
FIGURE = ROOT / "docs" / "figures" / "utfsm_law_0p5A.png"
START, END = "<!-- utfsm-law-table:start -->", "<!-- utfsm-law-table:end -->"
#: frequencies of the measured-vs-measured comparison [Hz] (inside both campaigns' bands)
FREQUENCIES = np.array([2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0])


def thesis_baselines(records: dict) -> dict:
    """The thesis' models on every record: G(s) from the command, Bouc-Wen from the measured x."""
    from servohydraulics.identification import baselines as b
    from servohydraulics.identification import nrmse_pct

    out = {}
    for name, rec in records.items():
        x = b.thesis_displacement(rec.time, rec.command)
        f = b.thesis_mr_force(rec.displacement, rec.dt, CURRENT[name])
        out[name] = {"displacement": nrmse_pct(x, rec.displacement), "force": nrmse_pct(f, rec.force), "F": f}
    return out


def identify_set(sh, records: dict, train: tuple, law: str, out: Path) -> tuple:
    """The law identified on the training records; (identification, wall s, CPU s)."""
    t0, c0 = time.perf_counter(), time.process_time()
    ident = sh.identify([records[n] for n in train], mode="displacement", currents=[CURRENT[n] for n in train],
                        law=law, progress=False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return ident, wall, cpu


def predict(records: dict, rig, name: str):
    """The record predicted from its command alone, the rig's law at the record's current."""
    from servohydraulics.identification import compare, simulate_record
    from servohydraulics.identification.fit import fit_options
    from servohydraulics.identification.law import predict_at

    at = predict_at(rig, current=CURRENT[name])
    rec = records[name]
    opts = fit_options(at, [rec], "displacement")
    return compare(rec, at, "displacement", simulated=simulate_record(at, rec, "displacement", options=opts))


def campaign_evidence(sh, records: dict) -> dict:
    """Measured force over measured displacement (H1, 4096-point segments), June chirp / May sweep
    at 0 A and 1 A: gain ratio and phase difference per frequency; the control: the thesis' one
    model driven by each record's measured displacement."""
    from servohydraulics.identification import baselines, h1

    out = {}
    for cur, amps in (("0A", 0.0), ("1A", 1.0)):
        h = {}
        for name in (f"chirp20Hz_{cur}", f"sweep15Hz_{cur}"):
            rec = records[name]
            model = baselines.thesis_mr_force(rec.displacement, rec.dt, amps)
            h[name] = [h1(rec.displacement, y, rec.dt, nperseg=4096).at(FREQUENCIES)[0] for y in (rec.force, model)]
        (june, june_model), (may, may_model) = h.values()
        out[cur] = {"june_N_per_mm": np.abs(june) / 1e3, "may_N_per_mm": np.abs(may) / 1e3,
                    "ratio": np.abs(june / may), "phase_deg": np.degrees(np.angle(june / may)),
                    "model_ratio": np.abs(june_model / may_model),
                    "model_phase_deg": np.degrees(np.angle(june_model / may_model))}
    return out


def law_summary(parameters: dict) -> list[str]:
    """The fitted law's keys with their 95 % intervals, one line each, from the identification's
    JSON ``parameters`` (key -> value, unit, status, interval)."""
    def unit(text: str) -> str:  # the law's units per unit of the field input: here amperes
        return "" if text == "-" else text.replace("(m u)", "(m A)").replace("u^2", "A^2").replace("1/u", "1/A")

    lines = []
    for k, p in parameters.items():
        lo, hi = p["interval"]
        iv = f"[{lo:.4g}, {hi:.4g}]" if p["status"] == "identified" else f"({p['status']})"
        lines.append(f"`{k}` = {p['value']:.4g} {unit(p['unit'])} {iv}".replace("  ", " "))
    return lines


def figure(records: dict, preds: dict, base: dict, path: Path, window=(30.0, 31.0)) -> None:
    """Measured and predicted force at 0.5 A over a time window: the force-velocity loop (velocity
    from the displacement low-passed at 200 Hz, measured or simulated) and the time history."""
    from matplotlib.figure import Figure

    from servohydraulics.identification.baselines import smoothed_motion

    rec = records["sweep15Hz_0p5A"]
    t = np.asarray(rec.time)
    w = (t >= window[0]) & (t <= window[1])
    _, v = smoothed_motion(rec.displacement, rec.dt)
    x = np.asarray(rec.displacement)[w]
    f_hz = np.count_nonzero(np.diff(np.sign(x - x.mean())) > 0) / (window[1] - window[0])
    fig = Figure(figsize=(11, 4.6), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2, width_ratios=(1, 1.6))
    styles = {"spencer": ("tab:blue", "-"), "quiroz2022": ("tab:orange", "--")}
    for law, c in preds.items():
        sim = np.asarray(c.simulated["force"])
        _, vs = smoothed_motion(c.simulated["displacement"], rec.dt)
        col, ls = styles[law]
        ax1.plot(1e3 * vs[w], sim[w] / 1e3, color=col, ls=ls, lw=1.0, label=f"ours, {law} law (from the command)")
        ax2.plot(t[w], sim[w] / 1e3, color=col, ls=ls, lw=1.2, label=f"ours, {law} law")
    thesis = base["sweep15Hz_0p5A"]["F"]
    ax1.plot(1e3 * v[w], thesis[w] / 1e3, color="tab:green", ls=":", lw=1.0, label="thesis Bouc-Wen (measured x)")
    ax2.plot(t[w], thesis[w] / 1e3, color="tab:green", ls=":", lw=1.2, label="thesis Bouc-Wen (measured x)")
    ax1.plot(1e3 * v[w], rec.force[w] / 1e3, color="k", lw=0.8, label="measured")
    ax2.plot(t[w], rec.force[w] / 1e3, color="k", lw=1.0, label="measured")
    span = f"{window[0]:g}-{window[1]:g} s (about {f_hz:.0f} Hz)"
    ax1.set(xlabel="velocity [mm/s]", ylabel="force [kN]", title=f"force-velocity, {span}")
    ax2.set(xlabel="time [s]", ylabel="force [kN]", title=f"force, {span}")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    ax1.legend(fontsize=7, loc="upper left")
    ax2.legend(fontsize=7, loc="upper right")
    fig.suptitle("Held-out 0.5 A sweep (May): identified on the 0 A and 1 A sweeps, predicted from the command alone")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def law_at_currents(results: dict) -> list[str]:
    """The identified laws (the committed rigs) and the thesis' at 0, 0.5 and 1 A: alpha, c0, c1,
    beta + gamma, the Bouc-Wen saturation z_u = (A / (beta + gamma))^(1/n) and the force level
    alpha z_u it gives (the damper's yield force, about)."""
    import servohydraulics as sh
    from servohydraulics import _core
    from servohydraulics.identification.baselines import thesis_law_keys
    from servohydraulics.identification.law import predict_at

    rigs = {f"{s}, {law}": sh.load_rig(RIGS / f"law_{s}_{law}.toml") for s, per in results.items() for law in per}
    thesis = sh.rig_from_dict({"specimen": thesis_law_keys()})
    thesis.effects.mr_damper = True
    rigs["the thesis' law (May sinusoids, 0-1 A)"] = thesis
    lines = ["The laws at 0 / 0.5 / 1 A (the damper's yield force is about alpha z_u, z_u = (A / (beta + "
             "gamma))^(1/n) the Bouc-Wen saturation):", "",
             "| law | alpha [kN/m] | c0 [kN s/m] | c1 [kN s/m] | z_u [mm] | alpha z_u [N] |",
             "|---|---|---|---|---|---|"]
    for name, rig in rigs.items():
        v = [_core.mr_damper_law(predict_at(rig, current=i)) for i in (0.0, 0.5, 1.0)]
        z_u = [(rig.mr_A / (w["beta"] + w["gamma"])) ** (1.0 / rig.mr_n) for w in v]
        j = lambda a, f: " / ".join(format(x, f) for x in a)  # noqa: E731
        lines.append(f"| {name} | {j([w['alpha'] / 1e3 for w in v], '.1f')} | {j([w['c0'] / 1e3 for w in v], '.2f')} | "
                     f"{j([w['c1'] / 1e3 for w in v], '.0f')} | {j([1e3 * z for z in z_u], '.1f')} | "
                     f"{j([w['alpha'] * z for w, z in zip(v, z_u)], '.0f')} |")
    return lines + [""]


def force_levels(records: dict, base: dict) -> list[str]:
    """How far the measured 0.5 A force lies between 0 A and 1 A (std of the measured force of the
    May sweeps), and the gain g of measured ~ g (the thesis' Bouc-Wen) on each sweep."""
    sd = {n: float(np.std(records[n].force)) for n in SWEEPS}
    gain = {n: float(np.asarray(records[n].force) @ base[n]["F"] / (base[n]["F"] @ base[n]["F"])) for n in SWEEPS}
    frac = (sd["sweep15Hz_0p5A"] - sd["sweep15Hz_0A"]) / (sd["sweep15Hz_1A"] - sd["sweep15Hz_0A"])
    return [f"The May sweeps' measured force (std) at 0 / 0.5 / 1 A: {' / '.join(f'{v:.0f}' for v in sd.values())} N: "
            f"0.5 A lies {100 * frac:.0f} % of the way from 0 A to 1 A (a law linear in the current: 50 %).  The "
            "gain g of measured ~ g x the thesis' Bouc-Wen (measured x) on them: "
            f"{' / '.join(f'{v:.2f}' for v in gain.values())}.", ""]


def tables(results: dict, base: dict, evidence: dict | None, times: dict, levels: list[str] = ()) -> str:
    lines = []
    if "may" in results:
        lines += ["**(a) May sweeps 0 A + 1 A -> the held-out 0.5 A sweep, from its command alone** (NRMSE %; the "
                  "thesis' G(s) from the command, its Bouc-Wen from the measured displacement):", "",
                  "| law | displacement: ours | thesis G(s) | force: ours | thesis Bouc-Wen | ours <= thesis | "
                  "gain g of measured ~ g ours | fit: 0 A disp / force | fit: 1 A disp / force |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for law, r in results["may"].items():
            p = r["predicted"]["sweep15Hz_0p5A"]
            b = base["sweep15Hz_0p5A"]
            wins = [ch for ch in ("displacement", "force") if p[ch] <= b[ch]]
            verdict = "both" if len(wins) == 2 else (f"{wins[0]} only" if wins else "neither")
            f0, f1 = (r["fit"][n] for n in SETS["may"][0])
            lines.append(f"| {law} | {p['displacement']:.2f} | {b['displacement']:.2f} | {p['force']:.2f} | "
                         f"{b['force']:.2f} | {verdict} | {p['gain']:.2f} | {f0['displacement']:.2f} / "
                         f"{f0['force']:.2f} | {f1['displacement']:.2f} / {f1['force']:.2f} |")
        lines.append("")
        lines += list(levels)
    if "june" in results:
        lines += ["**(b) June chirps 0 A + 1 A -> each May sweep** (NRMSE %; the thesis' models as in (a), fitted "
                  "to May tests):", "",
                  "| law | May record | displacement: ours | thesis G(s) | force: ours | thesis Bouc-Wen | "
                  "gain g of measured ~ g ours |", "|---|---|---|---|---|---|---|"]
        for law, r in results["june"].items():
            for name, p in r["predicted"].items():
                b = base[name]
                lines.append(f"| {law} | {name} | {p['displacement']:.2f} | {b['displacement']:.2f} | "
                             f"{p['force']:.2f} | {b['force']:.2f} | {p['gain']:.2f} |")
        lines.append("")
    if evidence is not None:
        f = ", ".join(f"{x:g}" for x in FREQUENCIES)
        lines += [f"Measured against measured (H1 of the measured force over the measured displacement, at {f} Hz, "
                  "June chirp / May sweep; the control: the thesis' one model driven by each record's measured "
                  "displacement):", "",
                  "| current | June abs(F/x) [N/mm] | May abs(F/x) [N/mm] | ratio June/May | phase June - May [deg] | "
                  "control: ratio | control: phase [deg] |", "|---|---|---|---|---|---|---|"]
        for cur, e in evidence.items():
            j = lambda a, s: " ".join(format(float(x), s) for x in a)  # noqa: E731
            lines.append(f"| {cur} | {j(e['june_N_per_mm'], '.0f')} | {j(e['may_N_per_mm'], '.0f')} | "
                         f"{j(e['ratio'], '.2f')} | {j(e['phase_deg'], '.1f')} | {j(e['model_ratio'], '.2f')} | "
                         f"{j(e['model_phase_deg'], '.1f')} |")
        lines.append("")
    lines += law_at_currents(results)
    for s, per in results.items():
        for law, r in per.items():
            lines.append(f"Law identified on the {s} records, `{law}` (95 % intervals; SI units, per A): "
                         + "; ".join(r["law"]) + ".")
            lines.append("")
    load = lambda v: f" (load average {v['load']:.1f} at its end)" if "load" in v else ""  # noqa: E731
    lines.append(f"Identification run times (wall clock / CPU over all threads, generic start, {os.cpu_count()} "
                 "cores shared with other jobs): "
                 + ", ".join(f"{k} {v['wall_s']:.0f} s / {v['cpu_s']:.0f} s{load(v)}" for k, v in times.items()) + ".")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", default=str(DATA))
    p.add_argument("--out", default="utfsm_law_out")
    p.add_argument("--laws", default=",".join(LAWS), help="comma-separated laws (default: both)")
    p.add_argument("--sets", default="may,june",
                   help="training sets: may (a), june (b); \"\": only the tables, from an earlier run into --out")
    p.add_argument("--no-docs", action="store_true", help="do not rewrite docs/lab-records.md or the figure")
    args = p.parse_args(argv)
    start = utfsm_start(args.data, CURRENT, args.out)
    if start is None:
        return 2
    sh, records, out = start
    laws = [x.strip() for x in args.laws.split(",") if x.strip()]
    sets = [x.strip() for x in args.sets.split(",") if x.strip()]
    saved = out / "utfsm_current_law.json"
    # the sets and laws of an earlier run into the same --out are kept (one table from both runs)
    earlier = json.loads(saved.read_text()) if saved.exists() else {}
    t_all = time.perf_counter()
    base = thesis_baselines(records)
    results: dict = earlier.get("results", {})
    times: dict = earlier.get("identify_s", {})
    for s in sets:
        train, tests = SETS[s]
        results.setdefault(s, {})
        for law in laws:
            ident, wall, cpu = identify_set(sh, records, train, law, out)
            times[f"{s} {law}"] = {"wall_s": wall, "cpu_s": cpu, "load": os.getloadavg()[0]}
            ident.write(out / f"identified_{s}_{law}")
            RIGS.mkdir(exist_ok=True)
            sh.save_rig(ident.rig, RIGS / f"law_{s}_{law}.toml")
            r = {"fit": {a.name: {c: a.channels[c]["nrmse_pct"] for c in a.channels} for a in ident.after},
                 "predicted": {}, "flags": ident.flags}
            for name in tests:
                c = predict(records, ident.rig, name)
                c.write(out / f"{name}_from_{s}_{law}")
                m, q = np.asarray(records[name].force), np.asarray(c.simulated["force"])
                r["predicted"][name] = {"displacement": c.nrmse("displacement"), "force": c.nrmse("force"),
                                        "gain": float(m @ q / (q @ q)), "warnings": c.warnings}
            results[s][law] = r
            print(f"{s} {law}: identified in {wall:.0f} s wall ({cpu:.0f} s CPU); "
                  + "; ".join(f"{n}: displacement {v['displacement']:.2f} %, force {v['force']:.2f} %"
                              for n, v in r["predicted"].items()), flush=True)
            for f in ident.flags:
                print("    flag:", f)
    for s, per in results.items():  # the laws with their intervals, from each identification's JSON
        for law, r in per.items():
            r["law"] = law_summary(json.loads((out / f"identified_{s}_{law}" / "identification.json").read_text())
                                   ["parameters"])
            print(f"{s} {law}:", "; ".join(r["law"]))
    evidence = campaign_evidence(sh, records) if "june" in results else None
    text = tables(results, base, evidence, times, force_levels(records, base))
    saved.write_text(json.dumps(
        {"baselines": {k: {c: v[c] for c in ("displacement", "force")} for k, v in base.items()},
         "results": results, "identify_s": times,
         "evidence": None if evidence is None else {k: {q: np.asarray(w).tolist() for q, w in v.items()}
                                                    for k, v in evidence.items()}}, indent=2) + "\n")
    print(text)
    if not args.no_docs:
        if "may" in results:  # the 0.5 A predictions of the May rigs (one simulation each)
            preds = {law: predict(records, sh.load_rig(RIGS / f"law_may_{law}.toml"), "sweep15Hz_0p5A")
                     for law in results["may"]}
            figure(records, preds, base, FIGURE)
            print(f"wrote {FIGURE}")
        doc = ROOT / "docs" / "lab-records.md"
        write_between(doc, START, END, text)
        print(f"wrote the tables into {doc}")
    print(f"total {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
