"""Figures of the lab workflow, for a lab engineer (docs/lab-records.md, "Figures"):

* :func:`overlay_figure`: measured and simulated records whole, with zoom windows
  where they part most (a 60 s record at 1 kHz is a band of ink otherwise);
* :func:`loops_figure`: force-displacement and force-velocity loops, measured and
  simulated (dampers and hysteretic specimens), whole and in the worst window;
* :func:`frf_figure`: gain and phase of the measured and simulated H1 estimates, the
  bands where the measured coherence is low greyed and the data not drawn there.

``matplotlib.figure.Figure`` objects (no pyplot state, no backend change); units in
the labels (mm, kN, mm/s, Hz, deg).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from .frf import FrequencyResponse, gain_phase

#: channel -> (SI-to-plot factor, plot unit)
PLOT_UNITS = {"displacement": (1e3, "mm"), "force": (1e-3, "kN"), "velocity": (1e3, "mm/s")}
#: coherence below which the measured estimate is not drawn (its band greyed)
MIN_COHERENCE = 0.8
MEASURED, SIMULATED, DIFFERENCE, SHADE = "0.15", "C1", "C3", "C0"


#: a whole-record trace is drawn through the extremes of this many equal runs of its samples (about
#: two per pixel column of the figures' 11 in at 110 dpi)
ENVELOPE_RUNS = 2500


def envelope(t: np.ndarray, y: np.ndarray, runs: int = ENVELOPE_RUNS) -> tuple[np.ndarray, np.ndarray]:
    """The samples of a long trace a plot needs: of each of ``runs`` equal runs of samples its first,
    lowest, highest and last, in time order (the trace as drawn at the figure's resolution: the same
    ink, its extremes kept); the trace itself when it has at most 4 ``runs`` samples.  A NaN in a run
    is kept (the line breaks there as it would)."""
    t, y = np.asarray(t), np.asarray(y)
    n = y.size
    if n <= 4 * runs:
        return t, y
    edges = np.linspace(0, n, runs + 1).astype(int)
    starts, size = edges[:-1], np.diff(edges)
    width = int(size.max())
    pad = np.full(runs * width, np.nan)
    cols = np.arange(width)
    valid = cols[None, :] < size[:, None]
    blocks = pad.reshape(runs, width)
    blocks[valid] = y
    lo = np.where(valid, blocks, np.inf).argmin(axis=1)  # a NaN in the run: its index (argmin's rule)
    hi = np.where(valid, blocks, -np.inf).argmax(axis=1)
    idx = np.column_stack([starts, starts + np.minimum(lo, hi), starts + np.maximum(lo, hi), starts + size - 1])
    idx = np.unique(idx.ravel())
    return t[idx], y[idx]


def _fixed_layout(fig: Figure, left: float, right: float, bottom: float, top: float, hspace: float,
                  wspace: float) -> None:
    """Margins and gaps in inches (room for the tick labels, axis labels and titles these figures draw):
    a fixed layout instead of ``tight_layout``, which measured every tick label of every axes once more
    before the figure was drawn (a third of the time of writing the three figures of a long record)."""
    w, h = fig.get_size_inches()
    gs = [ax.get_subplotspec().get_gridspec() for ax in fig.axes if ax.get_subplotspec() is not None]
    rows = max((g.nrows for g in gs), default=1)
    cols = max((g.ncols for g in gs), default=1)
    ax_h = max((h - bottom - top - hspace * (rows - 1)) / rows, 0.1)
    ax_w = max((w - left - right - wspace * (cols - 1)) / cols, 0.1)
    fig.subplots_adjust(left=left / w, right=1 - right / w, bottom=bottom / h, top=1 - top / h,
                        hspace=hspace / ax_h, wspace=wspace / ax_w)


def _moving_mean(y: np.ndarray, n: int) -> np.ndarray:
    c = np.cumsum(np.r_[0.0, y])
    out = np.empty_like(y)
    half = n // 2
    idx = np.arange(y.size)
    lo, hi = np.clip(idx - half, 0, y.size), np.clip(idx - half + n, 0, y.size)
    out[:] = (c[hi] - c[lo]) / np.maximum(hi - lo, 1)
    return out


def _local_period(u: np.ndarray, centre: int, dt: float, search: int) -> float:
    """The command's period [s] near sample ``centre``: from its zero crossings (about its local
    mean) within +-``search`` samples; inf when it does not cross."""
    a, b = max(0, centre - search), min(u.size, centre + search)
    seg = u[a:b] - np.mean(u[a:b])
    crossings = np.count_nonzero(np.diff(np.signbit(seg)))
    return 2.0 * (b - a) * dt / crossings if crossings >= 2 else np.inf


def zoom_windows(time: np.ndarray, measured: Mapping[str, np.ndarray], simulated: Mapping[str, np.ndarray],
                 command: np.ndarray | None = None, count: int = 3, cycles: float = 4.0) -> list[tuple[int, int]]:
    """Up to ``count`` windows (start, stop sample) where the simulated and measured records part
    most: the largest moving mean of the squared difference (each channel over its measured
    std), each about ``cycles`` periods of the command there (0.5 % to 25 % of the record), at
    least a tenth of the record (or a window) apart; in time order."""
    n = time.size
    dt = float(time[1] - time[0]) if n > 1 else 1.0
    e2 = np.zeros(n)
    for ch in simulated:
        sd = float(np.std(measured[ch])) or 1.0
        e2 += ((np.asarray(simulated[ch]) - np.asarray(measured[ch])) / sd) ** 2
    base = max(20, min(n // 20, int(round(2.0 / dt))))
    score = _moving_mean(e2, base)
    lo_len, hi_len = max(20, n // 200), max(20, n // 4)
    taken = np.zeros(n, dtype=bool)
    out = []
    for _ in range(count):
        s = np.where(taken, -np.inf, score)
        k = int(np.argmax(s))
        if not np.isfinite(s[k]) or s[k] <= 0:
            break
        length = base
        if command is not None:
            period = _local_period(np.asarray(command, dtype=float), k, dt, base)
            if np.isfinite(period):
                length = int(round(cycles * period / dt))
        length = int(np.clip(length, lo_len, hi_len))
        # the region found on the coarse score, the window's centre on a score of its own length
        lo, hi = max(0, k - base), min(n, k + base + 1)
        fine = np.where(taken[lo:hi], -np.inf, _moving_mean(e2, length)[lo:hi])
        k = lo + int(np.argmax(fine))
        a = int(np.clip(k - length // 2, 0, max(n - length, 0)))
        b = min(n, a + length)
        out.append((a, b))
        gap = max(length, n // 10)  # the next window elsewhere in the record, not next door
        taken[max(0, a - gap):min(n, b + gap)] = True
    return sorted(out)


def overlay_figure(time: np.ndarray, measured: Mapping[str, np.ndarray], simulated: Mapping[str, np.ndarray],
                   title: str, labels: Sequence[str] = ("measured", "simulated"), command: np.ndarray | None = None,
                   zooms: int = 3) -> Figure:
    """Per channel: the whole record (measured, simulated, their difference) with the zoom
    windows shaded and lettered, and below it the ``zooms`` windows where they part most
    (:func:`zoom_windows`), each titled with its time span and rms difference."""
    chans = list(simulated)
    t = np.asarray(time, dtype=float)
    t = t - t[0]
    wins = zoom_windows(t, measured, simulated, command, zooms) if zooms else []
    ncol = max(len(wins), 1)
    fig = Figure(figsize=(11, (2.3 + (2.1 if wins else 0.0)) * len(chans) + 0.5))
    rows = [2.3, 2.1] * len(chans) if wins else [2.3] * len(chans)
    gs = fig.add_gridspec(len(rows), ncol, height_ratios=rows)
    letters = "ABCDEFGH"
    for i, ch in enumerate(chans):
        f, unit = PLOT_UNITS.get(ch, (1.0, "SI"))
        m, s = f * np.asarray(measured[ch]), f * np.asarray(simulated[ch])
        r = (2 * i) if wins else i
        ax = fig.add_subplot(gs[r, :])
        ax.plot(*envelope(t, s - m), lw=0.5, color=DIFFERENCE, label="difference", alpha=0.6, zorder=1)
        ax.plot(*envelope(t, m), lw=0.6, color=MEASURED, label=labels[0], zorder=2)
        ax.plot(*envelope(t, s), lw=0.6, color=SIMULATED, label=labels[1], zorder=3)
        for j, (a, b) in enumerate(wins):
            ax.axvspan(t[a], t[b - 1], color=SHADE, alpha=0.12, lw=0)
            ax.text(0.5 * (t[a] + t[b - 1]), 1.0, letters[j], transform=ax.get_xaxis_transform(), ha="center",
                    va="bottom", fontsize=9, color=SHADE, fontweight="bold")
        ax.set_ylabel(f"{ch} [{unit}]")
        ax.set_xlim(t[0], t[-1])
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=3, framealpha=0.8)
        if i == len(chans) - 1 or wins:
            ax.set_xlabel("time [s] (whole record)")
        for j, (a, b) in enumerate(wins):
            z = fig.add_subplot(gs[r + 1, j])
            z.plot(t[a:b], m[a:b], lw=0.9, color=MEASURED)
            z.plot(t[a:b], s[a:b], lw=0.9, color=SIMULATED)
            z.plot(t[a:b], s[a:b] - m[a:b], lw=0.7, color=DIFFERENCE)
            rms = float(np.sqrt(np.mean((s[a:b] - m[a:b]) ** 2)))
            z.set_title(f"{letters[j]}: {t[a]:.2f}-{t[b - 1]:.2f} s, rms diff {rms:.3g} {unit}", fontsize=8)
            z.tick_params(labelsize=7)
            z.grid(alpha=0.3)
            z.set_xlabel("time [s]", fontsize=7)
            if j == 0:
                z.set_ylabel(f"{ch} [{unit}]", fontsize=8)
    fig.suptitle(title, fontsize=10)
    _fixed_layout(fig, left=0.8, right=0.15, bottom=0.5, top=0.55, hspace=0.75 if wins else 0.55, wspace=0.65)
    return fig


def velocity(x: np.ndarray, dt: float) -> np.ndarray:
    """dx/dt [m/s] of a measured displacement: Savitzky-Golay (cubic, 25 ms window, as the
    diagnosis's balance screen) so that sensor noise does not fill the force-velocity plane."""
    from scipy.signal import savgol_filter

    x = np.asarray(x, dtype=float)
    win = max(7, int(round(0.025 / dt)) | 1)
    if x.size <= win:
        return np.gradient(x, dt)
    return savgol_filter(x, win, 3, deriv=1, delta=dt)


def loops_figure(time: np.ndarray, measured: Mapping[str, np.ndarray], simulated: Mapping[str, np.ndarray],
                 title: str, command: np.ndarray | None = None, labels: Sequence[str] = ("measured", "simulated")
                 ) -> Figure:
    """Force against displacement and against velocity, measured and simulated: the whole
    record (top) and the window where the forces part most (bottom, about four cycles)."""
    t = np.asarray(time, dtype=float)
    dt = float(t[1] - t[0])
    xm, fm = np.asarray(measured["displacement"], float), np.asarray(measured["force"], float)
    xs, fs = np.asarray(simulated["displacement"], float), np.asarray(simulated["force"], float)
    vm, vs = velocity(xm, dt), velocity(xs, dt)
    wins = zoom_windows(t, {"force": fm}, {"force": fs}, command, 1)
    a, b = wins[0] if wins else (0, t.size)
    fig = Figure(figsize=(10.5, 8.0))
    axes = fig.subplots(2, 2)
    for row, (sl, what) in enumerate(((slice(None), "whole record"),
                                      (slice(a, b), f"window {t[a] - t[0]:.2f}-{t[b - 1] - t[0]:.2f} s "
                                                    "(where the forces part most)"))):
        for col, (xm_, xs_, xlabel, xf) in enumerate(((xm, xs, "displacement [mm]", 1e3),
                                                      (vm, vs, "velocity [mm/s]", 1e3))):
            ax = axes[row, col]
            lw = 0.4 if row == 0 else 1.0
            ax.plot(xf * xm_[sl], 1e-3 * fm[sl], lw=lw, color=MEASURED, label=labels[0], alpha=0.8)
            ax.plot(xf * xs_[sl], 1e-3 * fs[sl], lw=lw, color=SIMULATED, label=labels[1], alpha=0.8)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("force [kN]")
            ax.set_title(f"force-{xlabel.split()[0]}: {what}", fontsize=9)
            ax.grid(alpha=0.3)
            ax.axhline(0.0, color="0.6", lw=0.5)
            ax.axvline(0.0, color="0.6", lw=0.5)
    axes[0, 0].legend(loc="upper left", fontsize=8)
    fig.suptitle(title, fontsize=10)
    _fixed_layout(fig, left=0.8, right=0.15, bottom=0.55, top=0.55, hspace=0.8, wspace=0.85)
    return fig


def _bands(f: np.ndarray, bad: np.ndarray) -> list[tuple[float, float]]:
    """Contiguous frequency spans where ``bad`` holds (edges half-way to the neighbours)."""
    if not bad.any():
        return []
    d = np.diff(np.r_[0, bad.astype(np.int8), 0])
    out = []
    edges = np.r_[f[0], 0.5 * (f[1:] + f[:-1]), f[-1]]
    for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)):
        out.append((float(edges[a]), float(edges[b])))
    return out


def frf_figure(measured: Mapping[str, FrequencyResponse], simulated: Mapping[str, FrequencyResponse],
               f_max: float, title: str, input_unit: str = "m", min_coherence: float = MIN_COHERENCE) -> Figure:
    """Gain and phase of the measured and simulated H1 estimates (channel / command) up to
    f_max [Hz], the measured coherence on a second axis; where the measured coherence is below
    ``min_coherence`` the record carries no information: that band is greyed and the measured
    estimate is not drawn there."""
    chans = list(measured)
    fig = Figure(figsize=(11, 5.6))
    axes = fig.subplots(2, len(chans), squeeze=False, sharex=True)
    for j, ch in enumerate(chans):
        mes = measured[ch]
        sel = (mes.frequency > 0) & (mes.frequency <= f_max)
        f = mes.frequency[sel]
        coh = mes.coherence[sel] if mes.coherence is not None else np.asarray(mes.excited, float)[sel]
        bad = coh < min_coherence
        for est, label, color in ((mes, "measured", MEASURED), (simulated[ch], "simulated", SIMULATED)):
            s = (est.frequency > 0) & (est.frequency <= f_max)
            g, ph = gain_phase(est.response[s])
            if est is mes:
                g, ph = np.where(bad, np.nan, g), np.where(bad, np.nan, ph)
            axes[0, j].semilogy(est.frequency[s], g, color=color, lw=1.0, label=label)
            axes[1, j].plot(est.frequency[s], ph, color=color, lw=1.0, label=label)
        for ax in axes[:, j]:
            for k, (lo, hi) in enumerate(_bands(f, bad)):
                ax.axvspan(lo, hi, color="0.85", lw=0, zorder=0,
                           label=f"coherence < {min_coherence:g}: not drawn" if (k == 0 and ax is axes[0, j]) else None)
            ax.grid(alpha=0.3)
            ax.set_xlim(0, f_max)
        twin = axes[0, j].twinx()
        twin.plot(f, coh, color="C2", lw=0.6, alpha=0.7)
        twin.axhline(min_coherence, color="C2", lw=0.5, ls=":")
        twin.set_ylim(0, 1.05)
        twin.set_ylabel("coherence [-]", color="C2", fontsize=8)
        unit = {"displacement": "m", "force": "N"}.get(ch, "SI")
        axes[0, j].set_title(f"{ch} / command", fontsize=9)
        axes[0, j].set_ylabel(f"gain [{unit}/{input_unit}]")
        axes[1, j].set_ylabel("phase [deg]")
        axes[1, j].set_xlabel("frequency [Hz]")
        axes[0, j].legend(fontsize=7, loc="lower left")
    fig.suptitle(title, fontsize=10)
    _fixed_layout(fig, left=1.0, right=0.6, bottom=0.55, top=0.55, hspace=0.35, wspace=1.5)
    return fig


__all__ = ["MIN_COHERENCE", "PLOT_UNITS", "frf_figure", "loops_figure", "overlay_figure", "velocity", "zoom_windows"]
