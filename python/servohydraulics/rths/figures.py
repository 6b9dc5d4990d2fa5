"""Figures of an RTHS benchmark run (``rths-benchmark``, docs/rths-benchmark.md), for a lab
engineer: each titled with the record, the controller and the case.

* :func:`tracking_figure`: per case, the desired displacement y_n(1) and the measured x_m
  over the whole record, the tracking error x_m - y_n(1) under it, and a 2 s zoom at the
  largest desired displacement;
* :func:`synchronization_figure`: per case, measured against desired (the synchronisation
  plot: on the diagonal when the actuator tracks; a delay opens it into an ellipse, an
  amplitude error tilts it), with J1 and J2;
* :func:`criteria_figure`: J1-J9 by name (``rths.J_LABELS``), per case, J1 [ms] apart
  from the errors [%].

``matplotlib.figure.Figure`` objects; every axis in mm, s, ms or %.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from .evaluation import J_LABELS, J_NAMES

DESIRED, MEASURED, ERROR, REFERENCE = "C0", "C1", "C3", "0.5"


def run_title(meta: Mapping[str, Any], what: str) -> str:
    """``RTHS benchmark: <what>: <record> x <intensity>, controller <name>`` (+ the embedded default's label)."""
    title = (f"RTHS benchmark (Silva et al. 2020): {what}\n{meta.get('record', '?')} x "
             f"{meta.get('eq_intensity', '?')}, controller {meta.get('controller', '?')}")
    if meta.get("synthetic"):
        title += "\nEMBEDDED DEFAULT with a SYNTHETIC ground motion: not the benchmark's records or results"
    return title


def tracking_figure(trials: Mapping[int, Any], meta: Mapping[str, Any]) -> Figure:
    """Per case: desired and measured over the whole record, the tracking error, a 2 s zoom."""
    n = len(trials)
    fig = Figure(figsize=(12, 3.0 * n + 0.8))
    gs = fig.add_gridspec(2 * n, 3, height_ratios=[1.6, 1.0] * n)
    for i, (case, trial) in enumerate(trials.items()):
        s = trial.signals
        t, xd, xm = s["time"], 1e3 * s["numerical"][:, 0], 1e3 * s["measured"]
        err = xm - xd
        top = fig.add_subplot(gs[2 * i, :2])
        top.plot(t, xm, lw=1.0, color=MEASURED, label="measured x_m")
        top.plot(t, xd, lw=0.5, color=DESIRED, label="desired y_n(1)")
        top.set_ylabel(f"case {case}\ndisplacement [mm]")
        top.set_title(f"case {case}: J1 {trial.J[0]:.2f} ms, J2 {trial.J[1]:.2f} %, J3 {trial.J[2]:.2f} %",
                      fontsize=9)
        top.legend(loc="upper right", fontsize=7, ncol=2)
        bottom = fig.add_subplot(gs[2 * i + 1, :2], sharex=top)
        bottom.plot(t, err, lw=0.5, color=ERROR)
        bottom.axhline(0.0, color="0.5", lw=0.5)
        bottom.set_ylabel("tracking error\nx_m - y_n(1) [mm]", fontsize=8)
        bottom.set_xlabel("time [s]")
        k = int(np.argmax(np.abs(xd)))
        win = (t > t[k] - 1.0) & (t < t[k] + 1.0)
        zoom = fig.add_subplot(gs[2 * i:2 * i + 2, 2])
        zoom.plot(t[win], xm[win], color=MEASURED, lw=1.8, label="measured x_m")
        zoom.plot(t[win], xd[win], color=DESIRED, lw=0.9, label="desired y_n(1)")
        zoom.plot(t[win], 1e3 * s["reference"][win, 0], "--", color=REFERENCE, lw=0.8, label="reference floor 1")
        zoom.set_title(f"zoom at the peak, t = {t[k]:.2f} s", fontsize=9)
        zoom.set_xlabel("time [s]")
        zoom.set_ylabel("[mm]")
        zoom.legend(loc="lower right", fontsize=6)
        for ax in (top, bottom, zoom):
            ax.grid(alpha=0.3)
    fig.suptitle(run_title(meta, "tracking"), fontsize=10)
    fig.tight_layout()
    return fig


def synchronization_figure(trials: Mapping[int, Any], meta: Mapping[str, Any]) -> Figure:
    """Per case: measured x_m against desired y_n(1), with the diagonal (perfect tracking)."""
    n = len(trials)
    fig = Figure(figsize=(3.8 * n + 0.6, 4.8))
    axes = fig.subplots(1, n, squeeze=False)[0]
    for ax, (case, trial) in zip(axes, trials.items()):
        s = trial.signals
        xd, xm = 1e3 * s["numerical"][:, 0], 1e3 * s["measured"]
        lim = 1.05 * max(float(np.max(np.abs(xd))), float(np.max(np.abs(xm))), 1e-9)
        ax.plot(xd, xm, lw=0.4, color=MEASURED)
        ax.plot([-lim, lim], [-lim, lim], color="0.3", lw=0.7, ls="--", label="x_m = y_n(1)")
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xlabel("desired y_n(1) [mm]")
        ax.set_ylabel("measured x_m [mm]")
        ax.set_title(f"case {case}: J1 {trial.J[0]:.2f} ms, J2 {trial.J[1]:.2f} %", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", fontsize=7)
    fig.suptitle(run_title(meta, "synchronisation (measured against desired)"), fontsize=10)
    fig.tight_layout()
    return fig


def criteria_figure(results: Mapping[str, Any]) -> Figure:
    """J1-J9 by name per case (nominal, or the perturbed mean +- std): J1 [ms] on its own axis."""
    cases = list(results["cases"].items())
    fig = Figure(figsize=(12, 4.6))
    a1, a2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 5]})
    width = 0.8 / max(1, len(cases))
    y = np.arange(len(J_NAMES) - 1)
    for j, (n, e) in enumerate(cases):
        per = "perturbed" in e
        mean = np.array(e["perturbed"]["J_mean"] if per else e["nominal"]["J"], dtype=float)
        std = np.array(e["perturbed"]["J_std"], dtype=float) if per else None
        label = f"case {n}" + (f" ({e['perturbed']['runs']} perturbed)" if per else " (nominal)")
        off = (j - (len(cases) - 1) / 2) * width
        bars = a1.bar(off, mean[0], width, yerr=None if std is None else std[0], label=label)
        a1.bar_label(bars, fmt="%.2f", fontsize=7)
        bars = a2.barh(y + off, mean[1:], width, xerr=None if std is None else std[1:], label=label)
        a2.bar_label(bars, fmt="%.2f", fontsize=7, padding=2)
    a1.set_xlim(-0.7, 0.7)
    a1.set_xticks([0.0])
    a1.set_xticklabels([J_LABELS[0]], fontsize=8)
    a1.set_ylabel("[ms]")
    a2.set_yticks(y)
    a2.set_yticklabels(J_LABELS[1:], fontsize=8)
    a2.invert_yaxis()
    a2.set_xlabel("[%]")
    a2.legend(fontsize=7, loc="lower right")
    for ax in (a1, a2):
        ax.grid(alpha=0.3, axis="y" if ax is a1 else "x")
    fig.suptitle(run_title(results.get("meta", {}), "criteria J1-J9"), fontsize=10)
    fig.tight_layout()
    return fig


__all__ = ["criteria_figure", "run_title", "synchronization_figure", "tracking_figure"]
