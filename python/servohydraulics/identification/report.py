"""The markdown report of an identification."""

from __future__ import annotations

import numpy as np

from .stats import STATUS_WORDS, inseparable_groups, precision_order


def _v(x) -> str:
    return "-" if x is None else f"{x:.5g}"


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
    for b, a in zip(ident.before, ident.after):
        for c in a.channels:
            lines.append(f"| {a.name} | {c} | {b.nrmse(c):.2f} | {a.nrmse(c):.2f} | "
                         f"[overlay](overlay_{a.name}.png), [FRF](frf_{a.name}.png) |")
    notes = [f"- {a.name}: {w}" for a in ident.after for w in a.warnings]
    if notes:
        lines += ["", "## Warnings of the identified rig's runs", "", *notes]
    rt = ", ".join(f"{k} {v:.1f} s" for k, v in ident.runtime_s.items())
    lines += ["", f"Run time: {rt}; evaluations: {ident.nfev}.", ""]
    return "\n".join(lines)
