"""Diagnose a real record: the UTFSM MTS frame driving an MR damper at 1 A,
starting from the rig identified at 0 A (docs/utfsm_diagnose.md).

    PYTHONPATH=python python evaluation/utfsm_diagnose.py [--rig RIG_0A.toml] [--record chirp20Hz_1A]
        [--end 20] [--max-effects 2] [--out build/utfsm_diagnose] [--doc docs/utfsm_diagnose.md]

Without ``--rig`` the 0 A rig is identified first from ``chirp20Hz_0A`` with
``sh.identify(..., mode="displacement", specimen="mr_damper")`` (the generic
start: nothing about the frame is known) and written to OUT/rig_0A.toml.  Then
``sh.diagnose`` runs on the 1 A record (its first ``--end`` seconds: the record
starts at rest, as the diagnosis' initial state assumes) with that rig as the
nominal model: the 0 A model lacks what the coil current adds to the damper's
force.  Prints and writes what it names, the fitted values and the gap
before/after (diagnosis.json, rig_updated.toml, report.md under OUT), and the
section between the markers of ``--doc``.

The data are read from ../shared/real-data/utfsm-mts-mrdamper (or
$SH_SHARED_DIR/real-data/...); they are never copied into the repository.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SH_SHARED_DIR", ROOT.parent / "shared")) / "real-data" / "utfsm-mts-mrdamper"


def markers(label: str) -> tuple[str, str]:
    return f"<!-- utfsm-diagnose:{label}:start -->", f"<!-- utfsm-diagnose:{label}:end -->"


def _record(name: str, end: float | None):
    """The record ``name`` (its first ``end`` seconds, or all of it)."""
    from servohydraulics.records import Record, read_record

    path = DATA / f"{name}.csv"
    if not path.exists():
        raise SystemExit(f"record {path} is absent: the UTFSM data live in ../shared/real-data (see its README); "
                         "set SH_SHARED_DIR to the folder that holds real-data/")
    rec = read_record(path)
    if end is None:
        return rec
    n = int(round(end / rec.dt)) + 1
    return Record({k: np.asarray(v)[:n] for k, v in rec.channels.items()})


def _rig_0a(rig_path: str | None, out: Path):
    """The nominal rig: the given TOML, or identified from the 0 A chirp (written to OUT/rig_0A.toml)."""
    import servohydraulics as sh

    if rig_path:
        return sh.load_rig(rig_path), f"given: `{rig_path}`", 0.0
    t0 = time.perf_counter()
    ident = sh.identify([_record("chirp20Hz_0A", None)], mode="displacement", specimen="mr_damper", progress=False)
    seconds = time.perf_counter() - t0
    sh.save_rig(ident.rig, out / "rig_0A.toml")
    return ident.rig, ("identified from `chirp20Hz_0A` by `sh.identify(..., mode=\"displacement\", "
                       "specimen=\"mr_damper\")`"), seconds


def _fmt(v: float | None, unit: str) -> str:
    if v is None:
        return "-"
    return f"{v:.4g} {unit}"


def section(js: dict, how: str, record: str, end: float | None, cmd: str, t_ident: float, label: str) -> str:
    """The Markdown section for the doc."""
    START, END = markers(label)
    L = [START, "", f"Made by: `{cmd}`", "",
         f"Nominal rig: {how}" + (f" ({t_ident:.0f} s)" if t_ident else "") + ".",
         f"Record: `{record}`" + (f", its first {end:g} s" if end else "")
         + f"; diagnosis run time {js['runtime_s']:.0f} s.",
         "", f"Verdict: **{js['verdict']}**: {js['summary']}", "",
         "| effect | parameter | fitted | 95 % interval | absent (0 A model) | BIC change | "
         "gap after (displacement / force) |",
         "|---|---|---|---|---|---|---|"]
    for e in js["effects"]:
        for i, (k, p) in enumerate(e["parameters"].items()):
            lo, hi = p["interval_95"]
            L.append(f"| {e['name'] if i == 0 else ''} | {k} | {_fmt(p['value'], p['unit'])} | "
                     f"[{_fmt(lo, '')}, {_fmt(hi, '')}] | {_fmt(p['absent'], p['unit'])} | "
                     + (f"{e['delta_bic']:.0f} | {100 * e['gap_after'].get('displacement', float('nan')):.2f} % / "
                        f"{100 * e['gap_after'].get('force', float('nan')):.2f} % |" if i == 0 else " | |"))
    if not js["effects"]:
        L.append("| (none) | | | | | | |")
    L += ["", "| channel | gap before (0 A model) | gap after | noise floor | "
          "share of the gap above the floor closed |",
          "|---|---|---|---|---|"]
    for c in js["gap_before"]:
        closed = js["gap_closed"].get(c)
        L.append(f"| {c} | {100 * js['gap_before'][c]:.2f} % | {100 * js['gap_after'][c]:.2f} % | "
                 f"{100 * js['noise_floor'][c]:.2f} % | {'-' if closed is None else f'{100 * closed:.0f} %'} |")
    L += ["", "Candidates of each round (BIC change; why not accepted):", ""]
    for c in js["candidates"]:
        if c.get("delta_bic") is not None or c.get("accepted"):
            L.append(f"- round {c['round']} `{c['name']}`: BIC change {c['delta_bic']:.0f}"
                     + (" (accepted)" if c.get("accepted") else f"; {c.get('rejection')}"))
    L += ["", "(gap: rms(measured - simulated) / rms(measured) over the record; the model is driven by the "
          "record's command alone)", "", END]
    return "\n".join(L)


#: the runs of issue 25's table: (label, the rig's record, the diagnosed record); the rigs are the committed
#: identifications evaluation/utfsm_rigs/identified_from_<record>.toml (``servohydraulics identify REC.csv --mode
#: displacement --specimen mr_damper``, made by evaluation/utfsm_eval.py)
RUNS = (("june_0A_to_1A", "chirp20Hz_0A", "chirp20Hz_1A"), ("june_1A_to_0A", "chirp20Hz_1A", "chirp20Hz_0A"),
        ("may_0A_to_1A", "sweep15Hz_0A", "sweep15Hz_1A"), ("may_1A_to_0A", "sweep15Hz_1A", "sweep15Hz_0A"))
SUMMARY = "summary"


def summary_section(out: Path) -> str:
    """The table of every run of ``RUNS`` whose JSON is under OUT/<label>/ (between the summary markers)."""
    START, END = markers(SUMMARY)
    L = [START, "", "| campaign, direction | record (window) | verdict: effects named | force gap: nominal -> "
         "diagnosed (closed) | displacement gap: nominal -> diagnosed | run time |", "|---|---|---|---|---|---|"]
    for label, rig_from, record in RUNS:
        path = out / label / "utfsm_diagnose.json"
        if not path.exists():
            L.append(f"| {label} | `{record}` | (not run) | | | |")
            continue
        saved = json.loads(path.read_text())
        js = saved["diagnosis"]
        g0, g1, closed = js["gap_before"], js["gap_after"], js["gap_closed"]
        names = ", ".join(f"`{e['name']}`" for e in js["effects"]) or "-"
        window = f"first {saved['end']:g} s" if saved["end"] else "all"
        fc = closed.get("force")
        L.append(f"| {label.replace('_', ' ')} (rig from `{rig_from}`) | `{record}` ({window}) | {js['verdict']}: "
                 f"{names} | {100 * g0['force']:.1f} % -> {100 * g1['force']:.1f} % "
                 f"({'-' if fc is None else f'{100 * fc:.0f} %'}) | {100 * g0['displacement']:.2f} % -> "
                 f"{100 * g1['displacement']:.2f} % | {js['runtime_s']:.0f} s |")
    L += ["", "(gap: rms(measured - simulated) / rms(measured), the model driven by the record's command alone; "
          "closed: the share of the force gap above the noise floor the named effects close)", "", END]
    return "\n".join(L)


def main() -> None:
    import servohydraulics as sh

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rig", help="the 0 A rig TOML (default: identify it from chirp20Hz_0A)")
    p.add_argument("--record", default="chirp20Hz_1A", help="the 1 A record (file name without .csv)")
    p.add_argument("--end", type=float, default=20.0, help="use the record's first END seconds (0: all) [s]")
    p.add_argument("--max-effects", type=int, default=2)
    p.add_argument("--out", default="build/utfsm_diagnose")
    p.add_argument("--doc", default="docs/utfsm_diagnose.md")
    p.add_argument("--no-doc", action="store_true")
    p.add_argument("--effect-off", action="append", default=[],
                   help="switch this effect of the nominal rig off first (repeatable), e.g. load_pressure")
    p.add_argument("--label", default="main", help="which section of the doc to write (its markers)")
    p.add_argument("--render", action="store_true", help="only re-write the doc section from OUT/utfsm_diagnose.json")
    p.add_argument("--run", choices=[r[0] for r in RUNS],
                   help="one run of issue 25's table: its rig (evaluation/utfsm_rigs/), record and label; OUT is "
                        "then the folder of the table (OUT/<label>/) and the table is re-written after the run")
    p.add_argument("--summary", action="store_true", help="only re-write the table of the runs found under OUT")
    p.add_argument("--stiff-steps", type=int, default=None, metavar="N",
                   help="the diagnosis' error-controlled pair hands a sample to its stiff integrator past N "
                        "dopri5 steps (diagnosis.engine.STIFF_STEPS; default: the package's, 100)")
    a = p.parse_args()
    if a.stiff_steps is not None:
        from servohydraulics.diagnosis import engine

        engine.STIFF_STEPS = a.stiff_steps
    out = Path(a.out)
    if a.summary:
        write_section(Path(a.doc), SUMMARY, summary_section(out))
        return
    table = None
    if a.run:
        table = out
        label, rig_from, a.record = next(r for r in RUNS if r[0] == a.run)
        a.rig = a.rig or f"evaluation/utfsm_rigs/identified_from_{rig_from}.toml"
        a.label, out = label, out / label
    out.mkdir(parents=True, exist_ok=True)
    if a.render:
        saved = json.loads((out / "utfsm_diagnose.json").read_text())
        write_section(Path(a.doc), a.label, section(saved["diagnosis"], saved["nominal"], saved["record"],
                                                      saved["end"], saved["command"], saved["identify_s"], a.label))
        return
    rig, how, t_ident = _rig_0a(a.rig, out)
    for eff in a.effect_off:
        if not hasattr(rig.effects, eff):
            raise SystemExit(f"invalid --effect-off {eff!r}: not an effect switch")
        setattr(rig.effects, eff, False)
        how += f", with `effects.{eff}` switched off"
    end = a.end or None
    rec = _record(a.record, end)
    d = sh.diagnose(rec, rig, mode="displacement", max_effects=a.max_effects, progress=True)
    d.write(out)
    js = d.to_dict()
    print(f"{js['verdict']}: {js['summary']}")
    for e in js["effects"]:
        pars = ", ".join(f"{k} = {_fmt(v['value'], v['unit'])}" for k, v in e["parameters"].items())
        print(f"  + {e['name']}: {pars}")
    for c in js["gap_before"]:
        print(f"  gap {c}: {100 * js['gap_before'][c]:.2f} % -> {100 * js['gap_after'][c]:.2f} % "
              f"(noise floor {100 * js['noise_floor'][c]:.2f} %)")
    given = [("run", a.run)] if a.run else [("rig", a.rig), ("record", a.record)]
    given += [("end", a.end), ("max-effects", a.max_effects), ("out", table or a.out), ("stiff-steps", a.stiff_steps)]
    given += [] if a.run else [("label", a.label)]
    args = " ".join(f"--{k} {v:g}" if k == "end" else f"--{k} {v}" for k, v in given if v is not None and v != "")
    args += "".join(f" --effect-off {e}" for e in a.effect_off)
    cmd = f"PYTHONPATH=python python evaluation/utfsm_diagnose.py {args}"
    (out / "utfsm_diagnose.json").write_text(json.dumps({"command": cmd, "nominal": how, "identify_s": t_ident,
                                                         "record": a.record, "end": end, "diagnosis": js},
                                                        indent=1, default=str))
    if not a.no_doc:
        write_section(Path(a.doc), a.label, section(js, how, a.record, end, cmd, t_ident, a.label))
        if table is not None:
            write_section(Path(a.doc), SUMMARY, summary_section(table))


def write_section(doc: Path, label: str, text_section: str) -> None:
    """Replaces the section between the label's markers in ``doc`` (appends the markers if absent)."""
    START, END = markers(label)
    text = doc.read_text() if doc.exists() else "# Diagnose on real data\n"
    if START not in text:
        text += f"\n{START}\n{END}\n"
    i, j = text.index(START), text.index(END) + len(END)
    doc.write_text(text[:i] + text_section + text[j:])
    print(f"wrote {doc}")


if __name__ == "__main__":
    main()
