"""Writes a diagnosis: diagnosis.json, rig_updated.toml, report.md and its plots."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..atomic import FileSet, WriteError
from ..identification.report import checks_markdown
from ..identification.stats import STATUS_WORDS
from ..rig import save_rig
from . import engine


def _clean(o):
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    if isinstance(o, (np.floating, float)):
        return float(o) if math.isfinite(o) else None
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, np.bool_):
        return bool(o)
    return o


def write_outputs(d, out: Path) -> Path:
    """Writes the files together: all of them, or (on an OSError naming the file) none."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise WriteError(out, e.errno, f"[Errno {e.errno}] {e.strerror}") from None
    with FileSet() as files:
        files.write_text(out / "diagnosis.json", json.dumps(_clean(d.to_dict()), indent=2))
        save_rig(d.rig, files.path(out / "rig_updated.toml"))
        figs = _plots(d, out, files)
        files.write_text(out / "report.md", _markdown(d, figs))
    return out


def _plots(d, out: Path, files: FileSet) -> dict:
    """Draws the report's figures (``matplotlib.figure.Figure`` objects, saved
    as PNG to ``out``); returns their file names by kind."""
    if not d.plots:
        return {}
    figs = {"residual": _residual_figure(d), "signature": _signature_figure(d), "gap": _gap_figure(d),
            "overlay": _overlay_figure(d)}
    names = {"residual": "residual_before_after.png", "signature": "signature.png", "gap": "gap_closing.png",
             "overlay": "overlay.png"}
    for kind, fig in figs.items():
        if fig is not None:
            if kind != "overlay":  # the overlay is laid out by identification.figures
                fig.tight_layout()
            fig.savefig(files.path(out / names[kind]), dpi=110)
    return {kind: names[kind] for kind, fig in figs.items() if fig is not None}


def _residual_figure(d):
    """The normalised residual per channel before (nominal) and after (the effects added)."""
    from matplotlib.figure import Figure

    cases, before, after = d.plots["cases"], d.plots["sims_before"], d.plots["sims_after"]
    chans = list(cases[0].meas)
    fig = Figure(figsize=(9, 2.2 * len(chans)))
    axes = fig.subplots(len(chans), 1, sharex=True, squeeze=False)
    for ax, c in zip(axes[:, 0], chans):
        t0 = 0.0
        for case, sb, sa in zip(cases, before, after):
            t = case.t + t0
            ax.plot(t, (case.meas[c] - sb[c]) / case.scale[c], lw=0.6, color="tab:red",
                    label="before" if t0 == 0 else None)
            ax.plot(t, (case.meas[c] - sa[c]) / case.scale[c], lw=0.6, color="tab:blue",
                    label="after" if t0 == 0 else None)
            t0 = t[-1] + case.dt
        ax.set_ylabel(f"{c} residual\n/ rms({c})")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right")
    axes[-1, 0].set_xlabel("time [s] (records end to end)")
    return fig


def _overlay_figure(d):
    """The first record measured against the updated model (``identification.figures.overlay_figure``:
    the whole record and the windows where they still part most)."""
    from ..identification.figures import overlay_figure

    case, after = d.plots["cases"][0], d.plots["sims_after"][0]
    chans = [c for c in ("displacement", "force") if c in case.meas]
    return overlay_figure(case.t, {c: case.meas[c] for c in chans}, {c: after[c] for c in chans},
                          f"{case.name}: measured and the updated model (lettered: where they still part most)",
                          labels=("measured", "updated model"), command=case.u)


def _signature_figure(d):
    """Round 1's screening scores and the signature that named the first effect
    against the nominal residual (None without a screened candidate)."""
    from matplotlib.figure import Figure

    first = [c for c in d.candidates if c.round == 1 and c.screening_score is not None]
    if not first:
        return None
    cases, before = d.plots["cases"], d.plots["sims_before"]
    chans = list(cases[0].meas)
    fig = Figure(figsize=(11, 3.6))
    a1, a2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.6]})
    a1.barh([c.name for c in first], [c.screening_score for c in first],
            color=["tab:green" if c.accepted else "tab:gray" for c in first])
    a1.set_xlabel("share of the residual its signature explains (round 1)")
    a1.invert_yaxis()
    sig = d.plots["signatures"].get(d.effects[0]["name"]) if d.effects else None
    if sig is None:
        a2.text(0.5, 0.5, "no effect named", ha="center", va="center")
        return fig
    n = cases[0].t.size
    c0 = chans[0] if len(chans) == 1 else max(chans, key=lambda c: d.gap_before.get(c, 0))
    k = chans.index(c0)
    r = (cases[0].meas[c0] - before[0][c0]) / cases[0].scale[c0]
    a2.plot(cases[0].t, r, lw=0.6, color="tab:red", label="residual (nominal)")
    a2.plot(cases[0].t, sig[k * n:(k + 1) * n], lw=0.8, color="tab:green", label=f"signature of {d.effects[0]['name']}")
    a2.set_xlabel("time [s]")
    a2.set_ylabel(f"{c0} / rms")
    a2.legend(loc="upper right", fontsize=8)
    return fig


def _gap_figure(d):
    """The gap per channel after each step (nominal, each effect, joint re-fits) and the noise floor."""
    from matplotlib.figure import Figure

    hist, chans = d.plots["history"], list(d.plots["cases"][0].meas)
    fig = Figure(figsize=(7, 3.4))
    ax = fig.subplots()
    w = 0.8 / (len(hist) + 1)
    for i, (label, g) in enumerate(hist):
        ax.bar(np.arange(len(chans)) + i * w, [100 * g[c] for c in chans], w,
               label=label if i == 0 else f"+ {label}")
    ax.bar(np.arange(len(chans)) + len(hist) * w, [100 * d.noise_floor[c] for c in chans], w,
           color="k", alpha=0.3, label="noise floor")
    ax.set_xticks(np.arange(len(chans)) + 0.4 - w / 2)
    ax.set_xticklabels(chans)
    ax.set_ylabel("gap: normalised RMS error [%]")
    ax.legend(fontsize=8)
    return fig


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _status(p: dict) -> str:
    return STATUS_WORDS.get(p.get("status") or "identified", str(p.get("status")))


def _markdown(d, figs: dict) -> str:
    L = ["# Diagnosis", "", f"**Verdict: {d.verdict}.** {d.summary}", "",
         f"Mode: {d.mode}. Records: " + ", ".join(f"`{r}`" for r in d.records) + f". Runtime {d.runtime_s:.1f} s.",
         ""]
    L += checks_markdown(getattr(d, "checks", []))
    L += ["## Gap per channel (normalised RMS error, %)", "",
          "| channel | before | after | noise floor | gap closed (of the part above the floor) |",
          "|---|---|---|---|---|"]
    for c in d.gap_before:
        gc = d.gap_closed.get(c)
        L.append(f"| {c} | {100 * d.gap_before[c]:.2f} | {100 * d.gap_after[c]:.2f} | "
                 f"{100 * d.noise_floor[c]:.2f} | {'-' if gc is None else f'{100 * gc:.0f} %'} |")
    L.append("")
    w = d.gap_where
    if w:
        L += [f"Where the nominal gap sits (channel `{w['channel']}`, residual rms / channel rms): "
              f"by |displacement| quartile {', '.join(f'{v:.3f}' for v in w['abs_displacement_quartiles'])}; "
              f"near velocity reversal {w['velocity_magnitude']['near_reversal']:.3f} vs moving "
              f"{w['velocity_magnitude']['moving']:.3f}; residual power by band "
              + ", ".join(f"{k}: {100 * v:.0f} %" for k, v in w["frequency_share"].items()) + ".", ""]
    if d.effects:
        L += ["## Effects added (in order)", ""]
        for e in d.effects:
            L.append(f"### {e['name']}: {e['doc']}")
            L.append("")
            L.append("| parameter | value | unit | 95 % interval | status | absent | rig key |")
            L.append("|---|---|---|---|---|---|---|")
            for k, p in e["parameters"].items():
                L.append(f"| {k} | {_fmt(p['value'])} | {p['unit']} | [{_fmt(p['interval_95'][0])}, "
                         f"{_fmt(p['interval_95'][1])}] | {_status(p)} | {_fmt(p['absent'])} | {p['rig_key']} |")
            L.append("")
            L.append(f"BIC improvement {e['delta_bic']:.1f}; held-out error down "
                     f"{100 * e['heldout_improvement']:.1f} %." + (f" Note: {e['note']}" if "note" in e else ""))
            L.append("")
    if d.determined:
        L += ["## What the records determine (best first)", "",
              "Every fitted parameter, from the smallest relative standard error to the largest; parameters at a "
              "limit of their plausible range or not determined by the records last (their interval is that "
              "range, or none).", "", "| effect | parameter | value | unit | 95 % interval | rel. std. error | "
              "status |", "|---|---|---|---|---|---|---|"]
        for r in d.determined:
            rel = r["relative_sd"]
            L.append(f"| {r['effect']} | {r['key']} | {_fmt(r['value'])} | {r['unit']} | "
                     f"[{_fmt(r['interval_95'][0])}, {_fmt(r['interval_95'][1])}] | "
                     f"{'-' if rel is None else f'{100 * rel:.3g} %'} | {_status(r)} |")
        L.append("")
        if d.inseparable:
            L += ["Groups the records cannot tell apart (|correlation| > 0.95: only a combination of each group is "
                  "determined): " + "; ".join("{" + ", ".join(g) + "}" for g in d.inseparable) + ".", ""]
    if d.ambiguous_between:
        L += ["## Ambiguous", "", f"{d.ambiguous_between[0]} or {d.ambiguous_between[1]}: "
              f"{d.separating_experiment}.", ""]
    L += ["## Candidates", "", "Share closed: the largest share of the nominal model's gap above the noise floor the "
          f"candidate's fit closes on one channel (an effect must close {100 * engine.MATERIAL_MIN:g} %).", "",
          "| round | name | screening | balance eq. | ΔBIC | held-out | share closed | result |",
          "|---|---|---|---|---|---|---|---|"]
    for c in d.candidates:
        L.append(f"| {c.round} | {c.name} | {_fmt(c.screening_score)} | {_fmt(c.balance_score)} | "
                 f"{_fmt(c.delta_bic)} | {_fmt(c.heldout_improvement)} | {_fmt(c.share_closed)} | "
                 f"{'accepted' if c.accepted else c.rejection} |")
    L.append("")
    L += ["## Plots", ""]
    if "residual" in figs:
        L += ["Residual before (red) and after (blue):", "", f"![residual]({figs['residual']})", ""]
    if "signature" in figs:
        L += ["The signature that named the effect:", "", f"![signature]({figs['signature']})", ""]
    if "gap" in figs:
        L += ["The gap closing:", "", f"![gap]({figs['gap']})", ""]
    if "overlay" in figs:
        L += ["The first record against the updated model, with zooms where they still part most:", "",
              f"![overlay]({figs['overlay']})", ""]
    L += ["The updated rig is `rig_updated.toml`; the full result is `diagnosis.json`.", ""]
    return "\n".join(L)
