"""The markdown report of an identification."""

from __future__ import annotations

import numpy as np

from .stats import STATUS_WORDS, inseparable_groups, precision_order


def _v(x) -> str:
    return "-" if x is None else f"{x:.5g}"


def checks_markdown(checks) -> list[str]:
    """The plausibility checks as a markdown section (nothing without checks)."""
    if not checks:
        return []
    out = ["## Checks of the records and runs (docs/lab-records.md, 'Checks')", "",
           "| level | code | file | channel | finding |", "|---|---|---|---|---|"]
    for c in checks:
        level = f"{c.level} (acknowledged)" if c.acknowledged else c.level
        out.append(f"| {level} | `{c.code}` | {c.file} | {c.channel or '-'} | {c.message} |")
    return out + [""]


def identification_markdown(ident) -> str:
    d = ident.to_dict()
    start = "the generic rig scaled from the first record (docs/lab-records.md)" if ident.generic_start \
        else "the given rig"
    lines = [f"# Identified rig ({ident.mode} control)", "",
             f"Start: {start}. Stage 1 (frequency response, linearised model) then stage 2 (time domain, "
             f"nonlinear simulation); the result is the {ident.kept} (the best by the time-domain cost).  "
             f"Intervals: {int(100 * d['level'])} %, the HAC sandwich at the result (autocorrelated residuals: "
             f"lag-1 rho = {ident.rho1:.3f}, AR(1) effective samples {ident.n_eff:.0f}); a key the records do not "
             "determine, or at a bound (or collapsed to zero), has its whole range.  Listed from the best "
             "determined (smallest relative standard error) to the worst.", "",
             "| key | unit | start | stage 1 | identified | status | 95 % interval | rel. std. error |",
             "|---|---|---|---|---|---|---|---|"]
    if d["field"] is not None:
        f = d["field"]
        values = ", ".join(f"{v:g}" for v in f["values"])
        lines[3:3] = [f"MR damper field law `{f['law']}` fitted across the records at {f['input']}s {values} "
                      f"{f['unit']} (in the records' order; each record simulated at its own {f['input']}, one "
                      f"actuator loop for all; the law identified on {f['range'][0]:g} ... {f['range'][1]:g} "
                      f"{f['unit']}: specimen.mr_law_min/max).", ""]
    params = d["parameters"]
    keys = list(params)
    rel = [params[k]["std"] / abs(params[k]["value"]) if params[k]["value"] else np.inf for k in keys]
    for i in precision_order(rel, [params[k]["status"] for k in keys]):
        k, p = keys[i], params[keys[i]]
        lo, hi = p["interval"]
        r = f"{100 * rel[i]:.3g} %" if np.isfinite(rel[i]) else "-"
        lines.append(f"| `{k}` | {p['unit']} | {_v(p['start'])} | {_v(p['stage1'])} | {_v(p['value'])} | "
                     f"{STATUS_WORDS.get(p['status'], p['status'])} | [{lo:.5g}, {hi:.5g}] | {r} |")
    groups = inseparable_groups(ident.correlation)
    if groups:
        lines += ["", "Groups the records cannot tell apart (|correlation| > 0.95: only a combination of each "
                  "group is determined): " + "; ".join("{" + ", ".join(f"`{keys[i]}`" for i in g) + "}"
                                                      for g in groups) + "."]
    for k, v in d["derived"].items():
        lines.append(f"\nDerived: `{k}` = {v:.5g}")
    lines += ["", "## Correlations", "", "| | " + " | ".join(ident.keys) + " |",
              "|---" * (len(ident.keys) + 1) + "|"]
    for i, k in enumerate(ident.keys):
        lines.append(f"| `{k}` | " + " | ".join("-" if np.isnan(c) else f"{c:+.2f}"
                                                 for c in np.asarray(ident.correlation)[i]) + " |")
    lines += ["", "## What the data cannot separate", ""]
    lines += [f"- {f}" for f in ident.flags] or ["- nothing: every key is determined and no pair has |corr| > 0.95"]
    lines += ["", "## Records (NRMSE = 100 rms(sim - measured) / std(measured), %)", "",
              "| record | channel | start | identified | plots |", "|---|---|---|---|---|"]
    label = (lambda i, a: a.name) if ident.field_input is None else \
        (lambda i, a: f"{a.name} ({ident.field_input.values[i]:g} {ident.field_input.unit})")
    for i, (b, a) in enumerate(zip(ident.before, ident.after)):
        for c in a.channels:
            lines.append(f"| {label(i, a)} | {c} | {b.nrmse(c):.2f} | {a.nrmse(c):.2f} | "
                         + ", ".join(f"[{n}]({n}_{a.name}.png)" for n in a.figure_names()) + " |")
    lines += [""] + checks_markdown(ident.checks)
    rt = ", ".join(f"{k} {v:.1f} s" for k, v in ident.runtime_s.items())
    lines += ["", f"Run time: {rt}; evaluations: {ident.nfev}.", ""]
    return "\n".join(lines)
