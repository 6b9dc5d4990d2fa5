"""Matplotlib helpers for the analysis figures: Bode plots, pole-zero maps,
root loci and the note that every reproduced figure carries.

Figures are ``matplotlib.figure.Figure`` objects saved with ``fig.savefig``:
no pyplot state and no ``matplotlib.use``, so a notebook's backend is left as
it was (matplotlib's recommended pattern for libraries).

Axes are labelled with units; where the paper plots kN, mm or Hz the label says so.
"""

from __future__ import annotations

from pathlib import Path

import control as ct
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from .atomic import write_with
from .excitations import TWO_PI

NOTE = ("Simulated counterpart. The paper's measured curves are not available: "
        "compare with the paper's stated numbers (reproduction.md).")


def new_figure(title: str, nrows: int = 1, ncols: int = 1, figsize=(8.0, 5.0), **kw):
    """Figure with the paper-figure title and the 'measured curves not available' note."""
    fig = Figure(figsize=figsize)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    fig.suptitle(title, fontsize=11)
    fig.text(0.5, 0.005, NOTE, ha="center", va="bottom", fontsize=7, color="0.35", wrap=True)
    return fig, axes


def save(fig, path: Path) -> Path:
    """Tight layout (room for the note), save as PNG at 110 dpi."""
    fig.tight_layout(rect=(0, 0.04, 1, 0.96))
    return write_with(path, lambda tmp: fig.savefig(tmp, dpi=110))


def bode(ax_mag, ax_phase, sys_: ct.LTI, f: ArrayLike, label: str, db: bool = False, **style) -> None:
    """Magnitude (linear or dB) and phase [deg] of sys_ at frequencies f [Hz]."""
    h = np.asarray(sys_(1j * TWO_PI * np.asarray(f))).ravel()
    mag = 20 * np.log10(np.abs(h)) if db else np.abs(h)
    ax_mag.plot(f, mag, label=label, **style)
    if ax_phase is not None:
        ax_phase.plot(f, np.degrees(np.unwrap(np.angle(h))), **style)


def pole_zero(ax, sys_: ct.LTI, label: str, color: str, marker_size: float = 7.0,
              xlim: tuple[float, float] | None = None, ylim: tuple[float, float] | None = None) -> None:
    """Poles (x) and zeros (o) in rad/s of a SISO path of sys_."""
    p = np.asarray(sys_.poles())
    z = np.asarray(ct.zeros(sys_)) if sys_.ninputs == 1 and sys_.noutputs == 1 else np.array([])
    ax.plot(p.real, p.imag, "x", color=color, ms=marker_size, label=f"{label}: poles")
    if z.size:
        ax.plot(z.real, z.imag, "o", mfc="none", color=color, ms=marker_size, label=f"{label}: zeros")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.axhline(0.0, color="k", lw=0.4)
    ax.set_xlabel("real part [rad/s]")
    ax.set_ylabel("imaginary part [rad/s]")
    if xlim:
        ax.set_xlim(*xlim)
    if ylim:
        ax.set_ylim(*ylim)
    ax.grid(True, lw=0.3)


def root_locus(ax, poles: np.ndarray, gains: ArrayLike, marks: dict[str, float] | None = None) -> None:
    """Closed-loop poles (rows of ``poles``, one per gain) coloured by log gain."""
    g = np.repeat(np.log10(gains), poles.shape[1])
    sc = ax.scatter(poles.real.ravel(), poles.imag.ravel(), c=g, s=4, cmap="viridis")
    cb = ax.figure.colorbar(sc, ax=ax)
    cb.set_label("log10 G_p [-]")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_xlabel("real part [rad/s]")
    ax.set_ylabel("imaginary part [rad/s]")
    ax.grid(True, lw=0.3)
    for label, value in (marks or {}).items():
        ax.plot([], [], " ", label=f"{label} = {value:.3g}")
    if marks:
        ax.legend(fontsize=7)


__all__ = ["NOTE", "TWO_PI", "bode", "new_figure", "pole_zero", "root_locus", "save"]
