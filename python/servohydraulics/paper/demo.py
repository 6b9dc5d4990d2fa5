"""The main job on built-in defaults: the paper's rig in its three modes.

Writes ``OUT/demo.png`` (four panels), ``OUT/summary.md`` and ``OUT/rig.toml``.
The numbers come from the reproduction's experiments (experiments.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..atomic import write_text, write_with
from ..rig import save_rig, zhao2003
from . import experiments as xp


def _force_envelope(s: xp.DisplacementSweeps, width: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """Peak |load-cell force| of the uncompensated 1.27 cm sweep in bins of its instantaneous frequency."""
    f = 0.1 + (10.0 - 0.1) * s.time_a / s.duration_a
    edges = np.arange(0.25, 10.0 + width, width)
    peak = np.array([np.max(np.abs(s.force_a[(f >= a) & (f < b)])) for a, b in zip(edges[:-1], edges[1:])])
    return 0.5 * (edges[:-1] + edges[1:]), peak


def _plot(rig, fd: xp.FreeDecay, s: xp.DisplacementSweeps, w_c: float, d: xp.DirectEft) -> Figure:
    fig = Figure(figsize=(11, 8))
    ax = fig.subplots(2, 2)
    ax[0, 0].plot(fd.time, fd.displacement * 1e3)
    ax[0, 0].set(xlabel="time [s]", ylabel="displacement [mm]", title=f"Free vibration from 13 mm: "
                 f"{fd.frequency:.3f} Hz, fitted zeta {100 * fd.damping_ratio:.2f} % (friction incl.)")
    fo = s.first_order
    sel = fo.excited & (fo.frequency > 0.1) & (fo.frequency < 10.0)
    ax[0, 1].plot(fo.frequency[sel], np.abs(fo.response[sel]), label="simulated sweep (nonlinear model)")
    ff = np.linspace(0.01, 10.0, 200)
    ax[0, 1].plot(ff, 1 / np.sqrt(1 + (2 * np.pi * ff / w_c) ** 2), "--",
                  label=f"first order, Eq (13): {w_c / 2 / np.pi:.2f} Hz")
    ax[0, 1].set(xlabel="frequency [Hz]", ylabel="|x / u|",
                 title="Displacement control, 12.7 mm sweep, no compensation")
    sel = d.excited & (d.frequency > 0.1) & (d.frequency < 10.0)
    ax[1, 0].plot(d.frequency[sel], np.abs(d.response[sel]))
    ax[1, 0].axvline(fd.frequency, color="gray", ls=":", label=f"structure f_n = {fd.frequency:.2f} Hz")
    ax[1, 0].set(xlabel="frequency [Hz]", ylabel="|F / u|",
                 title="Force control, 2.3 kN sweep, no compensation (Fig 3a)")
    fe, peak = _force_envelope(s)
    ax[1, 1].plot(fe, peak / 1e3, "o-", ms=3, label="peak load-cell force")
    ax[1, 1].axhline(rig.F_cap / 1e3, color="r", ls="--", label="rated capacity 170 kN")
    ax[1, 1].axhline(rig.p_s * rig.A / 1e3, color="orange", ls=":", label="p_s A (supply limit)")
    ax[1, 1].set(xlabel="frequency [Hz]", ylabel="force [kN]", title="Force needed to track 12.7 mm")
    for a in ax.flat:
        a.grid(True, alpha=0.3)
        if a is not ax[0, 0]:
            a.legend()
    fig.suptitle("servohydraulics demo: Zhao et al. (2003) rig, calibrated preset")
    fig.tight_layout()
    return fig


def _summary_lines(out: Path, quick: bool, s: dict) -> list[str]:
    return [
        "# servohydraulics demo (calibrated Zhao 2003 preset)",
        "",
        "Command: `servohydraulics demo --out " + str(out) + ("` --quick" if quick else "`"),
        "",
        "| quantity | simulated | paper |",
        "|---|---|---|",
        f"| natural frequency, free vibration from 13 mm [Hz] | {s['natural_frequency_hz']:.3f} | 1.58 |",
        f"| equivalent damping of the first 4 s, incl. 95.7 N friction [% of critical] | "
        f"{100 * s['free_decay_damping_ratio']:.2f} | 0.8 % viscous + 95.7 N friction |",
        f"| Eq (13) roll-off [Hz] | {s['eq13_rolloff_hz']:.3f} | 1.96 |",
        f"| displacement amplitude ratio at 2 Hz, 12.7 mm sweep, no compensation | "
        f"{s['displacement_gain_at_2hz']:.3f} | about 0.7 (30 % loss, Fig 5a) |",
        f"| force-control amplitude ratio, minimum, 2.3 kN sweep, no compensation | {s['force_gain_min']:.3f} at "
        f"{s['force_gain_min_at_hz']:.2f} Hz | sharp drop at f_n (Fig 3a) |",
        "",
        "![demo](demo.png)",
    ]


def run_demo(out: str | Path = "demo_out", quick: bool = False) -> dict:
    """Runs the demo, writes the plot and the summary, returns the summary numbers (SI)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rig = zhao2003()
    save_rig(rig, out / "rig.toml")
    fd = xp.free_decay(zhao2003(actuator_attached=False), duration=6.0 if quick else 10.0)  # Fig 2b setting
    sweeps = xp.fig5_displacement_sweeps(rig, quick)  # Fig 5a setting
    w_c = xp.fig6a_amplitude_compensation(rig).omega_c  # Eq (13)
    direct = xp.fig3a_direct_eft(rig, quick)  # Fig 3a setting
    summary = {"natural_frequency_hz": fd.frequency, "free_decay_damping_ratio": fd.damping_ratio,
               "displacement_gain_at_2hz": sweeps.gain_2hz, "eq13_rolloff_hz": w_c / (2 * math.pi),
               "force_gain_min": direct.min_gain, "force_gain_min_at_hz": direct.min_frequency}
    fig = _plot(rig, fd, sweeps, w_c, direct)
    write_with(out / "demo.png", lambda tmp: fig.savefig(tmp, dpi=110))
    lines = _summary_lines(out, quick, summary)
    write_text(out / "summary.md", "\n".join(lines) + "\n")
    print("\n".join(lines[4:-2]))
    print(f"wrote {out / 'demo.png'}, {out / 'summary.md'}, {out / 'rig.toml'}")
    return summary
