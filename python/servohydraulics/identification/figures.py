"""Figures of the lab workflow: overlays of measured and simulated records and
their frequency responses.  ``matplotlib.figure.Figure`` objects (no pyplot
state, no backend change); units in the labels (mm, kN, Hz, deg)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from .frf import FrequencyResponse, gain_phase

#: channel -> (SI-to-plot factor, plot unit)
PLOT_UNITS = {"displacement": (1e3, "mm"), "force": (1e-3, "kN")}


def overlay_figure(time: np.ndarray, measured: Mapping[str, np.ndarray], simulated: Mapping[str, np.ndarray],
                   title: str, labels: Sequence[str] = ("measured", "simulated")) -> Figure:
    """One row per channel: the measured and simulated records and their difference."""
    chans = list(simulated)
    fig = Figure(figsize=(10, 2.6 * len(chans)))
    axes = fig.subplots(len(chans), 1, squeeze=False, sharex=True)[:, 0]
    for ax, ch in zip(axes, chans):
        f, unit = PLOT_UNITS.get(ch, (1.0, "SI"))
        ax.plot(time, f * measured[ch], lw=0.7, color="0.2", label=labels[0])
        ax.plot(time, f * simulated[ch], lw=0.7, color="C1", label=labels[1])
        ax.plot(time, f * (simulated[ch] - measured[ch]), lw=0.5, color="C3", label="difference")
        ax.set_ylabel(f"{ch} [{unit}]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=3)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def frf_figure(measured: Mapping[str, FrequencyResponse], simulated: Mapping[str, FrequencyResponse],
               f_max: float, title: str, input_unit: str = "m") -> Figure:
    """Gain and phase of the measured and simulated H1 estimates (channel / command),
    the measured coherence on a second axis, up to f_max [Hz]."""
    chans = list(measured)
    fig = Figure(figsize=(10, 5.0))
    axes = fig.subplots(2, len(chans), squeeze=False, sharex=True)
    for j, ch in enumerate(chans):
        for est, label, color in ((measured[ch], "measured", "0.2"), (simulated[ch], "simulated", "C1")):
            sel = (est.frequency > 0) & (est.frequency <= f_max)
            g, ph = gain_phase(est.response[sel])
            axes[0, j].semilogy(est.frequency[sel], g, color=color, lw=0.9, label=label)
            axes[1, j].plot(est.frequency[sel], ph, color=color, lw=0.9, label=label)
        sel = (measured[ch].frequency > 0) & (measured[ch].frequency <= f_max)
        twin = axes[0, j].twinx()
        twin.plot(measured[ch].frequency[sel], measured[ch].coherence[sel], color="C2", lw=0.6, alpha=0.6)
        twin.set_ylim(0, 1.05)
        twin.set_ylabel("coherence [-]", color="C2", fontsize=8)
        unit = {"displacement": "m", "force": "N"}.get(ch, "SI")
        axes[0, j].set_title(f"{ch} / command", fontsize=9)
        axes[0, j].set_ylabel(f"gain [{unit}/{input_unit}]")
        axes[1, j].set_ylabel("phase [deg]")
        axes[1, j].set_xlabel("frequency [Hz]")
        axes[0, j].legend(fontsize=7)
        for ax in axes[:, j]:
            ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


__all__ = ["PLOT_UNITS", "frf_figure", "overlay_figure"]
