"""The reproduction's figures, drawn from the experiments' dataclasses.

Each figure is a ``matplotlib.figure.Figure`` saved with ``fig.savefig`` (no pyplot state).
"""

from __future__ import annotations

from pathlib import Path

import control as ct
import numpy as np
from matplotlib.figure import Figure

from .. import analysis as an
from ..plots import bode, new_figure, pole_zero, save
from ..plots import root_locus as plot_root_locus
from . import experiments as xp

TWO_PI = 2.0 * np.pi


def _finish(axes, fontsize: int = 8, legend: bool = True, **grid) -> None:
    for a in np.ravel(axes):
        if legend:
            a.legend(fontsize=fontsize)
        a.grid(True, lw=0.3, **grid)


# --------------------------------------------------------------------------- structure, force control
def fig2b(fv: xp.FreeVibrationFit) -> Figure:
    fig, ax = new_figure("Fig 2(b): free vibration of the structure alone, released from 1.3 cm")
    ax = ax[0, 0]
    ax.plot(fv.time, 1e3 * fv.x_meas, color="0.6", lw=0.8, label="synthetic record (model + 0.05 mm noise)")
    ax.plot(fv.time, 1e3 * fv.estimate.fitted, color="C0", lw=1.0,
            label=f"fit: zeta = {100 * fv.estimate.zeta:.2f} %, F_c = {fv.estimate.F_c:.1f} N")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("displacement [mm]")
    _finish(ax)
    return fig


def fig3a(d: xp.DirectEft) -> Figure:
    fig, axes = new_figure("Fig 3(a): direct EFT, 2.3 kN sine sweep 0-10 Hz (no compensation)", 2, 1,
                           figsize=(8, 6.5))
    axes[0, 0].plot(d.time, d.force / 1e3, lw=0.5, color="C0", label="load-cell force")
    axes[0, 0].plot(d.time, d.command / 1e3, lw=0.5, color="0.6", label="effective force command")
    axes[0, 0].set_xlabel("time [s] (frequency rises linearly 0.1 -> 10 Hz)")
    axes[0, 0].set_ylabel("force [kN]")
    sel = d.excited & (d.frequency < 10.0)
    axes[1, 0].plot(d.frequency[sel], np.abs(d.response[sel]), color="C0", label="simulated sweep, |F/u|")
    fl = np.linspace(0.1, 10.0, 800)
    axes[1, 0].plot(fl, np.abs(np.asarray(d.g_fu(1j * TWO_PI * fl))), "k--", lw=0.8, label="Eq (9)")
    axes[1, 0].axvline(1.58, color="C3", lw=0.6, label="f_n = 1.58 Hz")
    axes[1, 0].set_xlabel("frequency [Hz]")
    axes[1, 0].set_ylabel("|applied / command force| [-]")
    _finish(axes)
    return fig


def fig4a(c: xp.FlowCurve) -> Figure:
    fig, axes = new_figure("Fig 4(a): flow - spool opening relation of the servovalve model", 2, 1,
                           figsize=(8, 6.5), sharex=True)
    x = 100 * c.opening
    axes[0, 0].plot(x, c.K_v * c.g * 1e3, label="preset g(x_v): Q = K_v g(x_v) at zero load pressure")
    axes[0, 0].plot(x, c.K_v * c.opening * 1e3, "k--", lw=0.8, label="constant initial flow gain (Eq 7)")
    axes[0, 0].set_ylabel("flow at zero load pressure [L/s]")
    axes[1, 0].plot(x, c.slope, label="flow gain dg/dx_v of the preset")
    axes[1, 0].axhline(1.0, color="k", ls="--", lw=0.8, label="Eq (7): K_v constant")
    axes[1, 0].set_ylabel("flow gain / K_v [-]")
    axes[1, 0].set_xlabel("spool opening [%]")
    for a in axes.ravel():
        a.axvline(10.0, color="0.5", lw=0.6, label="10 % opening (linear range, p. 1780)")
    _finish(axes)
    return fig


# --------------------------------------------------------------------------- EFT loops
def _force_ratio_axes(ax, f_n: float) -> None:
    ax.axvline(f_n, color="C3", lw=0.6, label=f"f_n = {f_n:.2f} Hz")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|applied / effective force| [-]")


def fig3b(e: xp.EftStudy) -> Figure:
    fig, axes = new_figure(f"Fig 3(b): EFT, 2.3 kN sine sweep 0-10 Hz ({xp.SWEEP_DURATION:g} s), "
                           "velocity feedback compensation", 2, 1, figsize=(8, 6.5))
    for key, label, color in (("none", "no compensation (Fig 3a)", "0.6"),
                              ("linear", "linear compensation + 5 ms lead", "C0")):
        run = e.runs[key]
        axes[0, 0].plot(run.frequency, run.ratio, color=color, label=label)
        axes[1, 0].plot(run.result.time, 100 * run.result.spool, color=color, lw=0.5, label=label)
    _force_ratio_axes(axes[0, 0], e.natural_frequency)
    axes[1, 0].axhline(10, color="C3", lw=0.6, ls="--")
    axes[1, 0].axhline(-10, color="C3", lw=0.6, ls="--", label="+-10 % opening")
    axes[1, 0].set_xlabel("time [s] (frequency rises linearly 0 -> 10 Hz)")
    axes[1, 0].set_ylabel("spool opening [%]")
    _finish(axes)
    return fig


def fig4bc(e: xp.EftStudy, title: str, keys) -> Figure:
    fig, axes = new_figure(title + f" (sweep 0-10 Hz, {xp.SWEEP_DURATION:g} s)", 2, 1, figsize=(8, 6.5))
    for key, label, color in keys:
        run = e.runs[key]
        axes[0, 0].plot(run.frequency, run.ratio, color=color, label=label)
        axes[1, 0].plot(run.result.time, run.result.force / 1e3, color=color, lw=0.4,
                        label=f"load-cell force, {label}")
    first = e.runs[keys[0][0]]
    axes[1, 0].plot(first.result.time, first.effective_force / 1e3, color="k", lw=0.3, alpha=0.5,
                    label="effective force P_eff")
    _force_ratio_axes(axes[0, 0], e.natural_frequency)
    axes[1, 0].set_xlabel("time [s]")
    axes[1, 0].set_ylabel("force [kN]")
    _finish(axes, fontsize=7)
    return fig


def eft_delay(e: xp.EftStudy) -> Figure:
    fig, ax = new_figure("EFT delay compensation (p. 1782): lead time constant of the velocity feedback")
    for key, label, color in (("lead0", "no lead (under-compensated)", "C1"), ("linear", "5 ms (tuned)", "C0"),
                              ("lead12", "12 ms (over-compensated)", "C2")):
        run = e.runs[key]
        s = (run.frequency > 0.5) & (run.frequency < 5.0)
        ax[0, 0].plot(run.frequency[s], run.ratio[s], color=color, label=label)
    _force_ratio_axes(ax[0, 0], e.natural_frequency)
    _finish(ax)
    return fig


# --------------------------------------------------------------------------- displacement control
def _sweep_bode(title: str, f, h, ok, model, f_max: float):
    fig, axes = new_figure(title, 2, 1, figsize=(8, 6.5), sharex=True)
    s = ok & (f > 0.1) & (f < f_max)
    fl = np.linspace(0.1, f_max, 600)
    bode(axes[0, 0], axes[1, 0], model, fl, "linear model, Eq (12) + valve + ZOH", color="k", ls="--", lw=0.8)
    axes[0, 0].plot(f[s], np.abs(h[s]), color="C0", label="simulated sweep (nonlinear model)")
    axes[1, 0].plot(f[s], np.degrees(np.unwrap(np.angle(h[s]))), color="C0")
    axes[0, 0].set_ylabel("|x / u| [mm/mm]")
    axes[1, 0].set_ylabel("phase [deg]")
    axes[1, 0].set_xlabel("frequency [Hz]")
    return fig, axes, fl


def fig5a(s: xp.DisplacementSweeps, d: xp.DisplacementLoop) -> Figure:
    fo = s.first_order
    fig, axes, fl = _sweep_bode("Fig 5(a): 1.27 cm displacement sine sweep, no compensation", fo.frequency,
                                fo.response, fo.excited, d.g_lin, 10.0)
    bode(axes[0, 0], axes[1, 0], ct.tf([fo.gain], [fo.tau, 1.0]), fl, f"first order, tau = {1e3 * fo.tau:.0f} ms",
         color="0.5", lw=0.8)
    axes[0, 0].axvline(2.0, color="C3", lw=0.5)
    axes[0, 0].annotate(f"{100 * (1 - s.gain_2hz):.0f} % loss at 2 Hz", (2.0, s.gain_2hz), fontsize=8)
    axes[0, 0].legend(fontsize=8)
    _finish(axes, legend=False)
    return fig


def fig5b(s: xp.DisplacementSweeps, d: xp.DisplacementLoop) -> Figure:
    fig, axes, _ = _sweep_bode("Fig 5(b): 1.27 cm sweep with amplitude compensation (68 ms), 0-6 Hz", s.frequency_b,
                               s.response_b, s.excited_b, an.phase_lead(xp.T_AMP) * d.g_lin, 6.0)
    axes[0, 0].legend(fontsize=8)
    _finish(axes, legend=False)
    return fig


def fig6a(d: xp.DisplacementLoop) -> Figure:
    fig, ax = new_figure("Fig 6(a): amplitude compensation with the oil-column mode (linear analysis)")
    fl = np.linspace(0.05, 10.0, 800)
    first = ct.tf([1.0], [1.0 / d.omega_c, 1.0])
    lead81 = an.phase_lead(1.0 / d.omega_c)
    for sys_, label, style in ((d.g_lin, "G_xu (Eq 12 + valve + ZOH)", dict(color="C0", ls="--")),
                               (first, "first order, Eq (13)", dict(color="0.5", ls="--")),
                               (lead81 * first, "first order + lead 81 ms", dict(color="0.5")),
                               (lead81 * d.g_lin, "G_xu + lead 81 ms", dict(color="C1")),
                               (an.phase_lead(xp.T_AMP) * d.g_lin, "G_xu + lead 68 ms", dict(color="C0"))):
        bode(ax[0, 0], None, sys_, fl, label, **style)
    ax[0, 0].axhspan(0.95, 1.05, color="0.9")
    ax[0, 0].axvline(5.0, color="k", lw=0.6)
    ax[0, 0].set_xlabel("frequency [Hz]")
    ax[0, 0].set_ylabel("|x / u| [-]")
    ax[0, 0].set_ylim(0, 1.6)
    _finish(ax)
    return fig


# --------------------------------------------------------------------------- gain bound
def fig6b(g: xp.GainBound) -> Figure:
    fig, ax = new_figure("Fig 6(b): maximum P-gain (Routh) vs physically installed mass")
    ax[0, 0].loglog(g.masses, g.gain_valve, "o-", ms=3, label="with servovalve second order")
    ax[0, 0].loglog(g.masses, g.gain_static_valve, "s--", ms=3, label="static valve (Eq 6)")
    ax[0, 0].axhline(g.gain_used, color="C3", lw=0.6, label="G_p = 0.8059 (Table I)")
    ax[0, 0].set_xlabel("physically installed mass incl. 54 kg piston [kg]")
    ax[0, 0].set_ylabel("maximum stable G_p [-]")
    _finish(ax, which="both")
    return fig


def root_locus(g: xp.GainBound) -> Figure:
    fig, ax = new_figure("Root locus of the displacement loop over G_p (valve on, 7138 kg)")
    plot_root_locus(ax[0, 0], g.locus_poles, g.locus_gains, {"G_p,max": g.gain_valve[-1], "G_p used": g.gain_used})
    ax[0, 0].set_xlim(-120, 40)
    ax[0, 0].set_ylim(-150, 150)
    return fig


def loop_bode(g: xp.GainBound) -> Figure:
    fig, axes = new_figure("Bode plot of the linearised rig (C++ Jacobian), displacement and force control",
                           2, 1, figsize=(8, 6.5), sharex=True)
    fl = np.geomspace(0.05, 100.0, 600)
    for label, sys_ in g.bode.items():
        bode(axes[0, 0], axes[1, 0], sys_, fl, label, db=True)
    axes[0, 0].set_xscale("log")
    axes[0, 0].set_ylabel("magnitude [dB]")
    axes[1, 0].set_ylabel("phase [deg]")
    axes[1, 0].set_xlabel("frequency [Hz]")
    axes[0, 0].legend(fontsize=8)
    _finish(axes, legend=False, which="both")
    return fig


def fig10bc(d: xp.RpsdLinear, tag: str) -> Figure:
    what = "modelled mass" if tag == "b" else "2 % of modelled mass (140 kg)"
    fig, ax = new_figure(f"Fig 10({tag}): RPsD loop poles, physical mass = {what} (linear analysis, 68 + 11.2 ms "
                         "leads)", figsize=(8, 6))
    options = [opt for t, opt in d.loops if t == tag]  # the Fig 10 variants, in the paper's order
    for opt, color in zip(options, ("k", "C3", "C1", "C2", "C0")):
        pole_zero(ax[0, 0], d.loops[(tag, opt)][0, 0], f"f = {opt.replace('_', ' ')}", color, xlim=(-6, 3),
                  ylim=(-2, 16))
    ax[0, 0].legend(fontsize=7, ncol=2)
    return fig


# --------------------------------------------------------------------------- RPsD loops
def fig8ab(s: xp.RpsdSweeps, fv: xp.RpsdFreeVibrations, T: float, title: str) -> Figure:
    fig, axes = new_figure(title + " (68 ms amplitude compensation, full model)", 2, 1, figsize=(8, 7))
    r, top = s.runs[T], axes[0, 0]
    top.plot(s.time, 1e3 * r.calc_displacement, color="C0", lw=0.6, label="calculated (solver)")
    top.plot(s.time, 1e3 * r.displacement, color="C1", lw=0.6, label="measured (LVDT)")
    top.plot(s.time, 1e3 * s.x_exact, "k--", lw=0.6, label="exact SDOF, no servo-system")
    top.set_ylim(-200, 200)
    top.set_xlabel(f"time [s] (0.15 g ground-acceleration sweep 0-10 Hz over {xp.SWEEP_DURATION:g} s)")
    top.set_ylabel("displacement [mm] (clipped at +-200)")
    ax2 = top.twinx()
    ax2.plot(s.time, 100 * np.abs(r.spool), color="C3", lw=0.4, alpha=0.6)
    ax2.axhline(28, color="C3", ls=":", lw=0.8)
    ax2.set_ylabel("|spool opening| [%] (red; dotted: paper's 28 %)")
    r2, tr = fv.runs[T].result, fv.time_after_release
    axes[1, 0].plot(tr, 1e3 * r2.calc_displacement, color="C0", lw=0.7, label="calculated (solver)")
    axes[1, 0].plot(tr, 1e3 * r2.displacement, color="C1", lw=0.5, label="measured (LVDT)")
    axes[1, 0].set_xlim(-1, 10)
    axes[1, 0].set_ylim(-50, 50)
    axes[1, 0].set_xlabel(f"time after release [s] (free vibration from 1.6 cm; zeta = {100 * fv.zeta[T]:+.2f} %, "
                          f"model {100 * fv.zeta_model:.2f} %)")
    axes[1, 0].set_ylabel("displacement [mm]")
    for a in axes.ravel():
        a.legend(fontsize=7, loc="upper left")
        a.grid(True, lw=0.3)
    return fig


def fig8_damping(fv: xp.RpsdFreeVibrations, delays: np.ndarray, zeta_linear: np.ndarray) -> Figure:
    fig, ax = new_figure("Figs 8, 9(b): damping of the RPsD free vibration vs delay compensation T_ld")
    ax = ax[0, 0]
    ax.plot(1e3 * delays, 100 * zeta_linear, "k--", lw=0.8, label="linear analysis (rpsd_loop)")
    z_zero = fv.runs["zero"].fit.damping_ratio
    ax.plot([1e3 * T for T in fv.zeta] + [1e3 * fv.T_zero_phase], [100 * z for z in fv.zeta.values()]
            + [100 * z_zero], "o", color="C0", label="simulation, full model (fit to free vibration)")
    ax.axhline(100 * fv.zeta_model, color="C3", lw=0.6, label=f"model zeta = {100 * fv.zeta_model:.2f} %")
    ax.axhline(0.0, color="k", lw=0.5)
    for T, lab in ((6, "6 ms (8a)"), (11.2, "11.2 ms (paper)"), (16, "16 ms (8b)")):
        ax.axvline(T, color="0.6", lw=0.5)
        ax.annotate(lab, (T, ax.get_ylim()[0]), fontsize=7, rotation=90, va="bottom")
    ax.set_xlabel("delay compensation T_ld [ms]")
    ax.set_ylabel("damping ratio of the structural response [%]")
    _finish(ax)
    return fig


def fig9(fv: xp.RpsdFreeVibrations, a9: xp.Fig9a) -> Figure:
    fig, axes = new_figure("Fig 9: free vibration in displacement control (release from 1.6 cm)", 3, 1,
                           figsize=(8, 9), sharex=True)
    tr = fv.time_after_release
    for a, (key, label) in zip(axes[:, 0], (
            ("a", "(a) calculated displacements for the restoring force, no delay compensation"),
            (xp.T_LD, "(b) measured displacements, T_ld = 11.2 ms; and with the 0.03 kN error"),
            ("zero_err", f"(b) measured displacements, T_ld = {1e3 * fv.T_zero_phase:.1f} ms, with the 0.03 kN "
             "error"))):
        r = fv.runs[key].result
        a.plot(tr, 1e3 * r.calc_displacement, color="C0", lw=0.7, label="calculated")
        a.plot(tr, 1e3 * r.displacement, color="C1", lw=0.5, label="measured")
        if key == "a":
            a.plot(tr[fv.release.index:], 1e3 * a9.exact, "k--", lw=0.6, label="exact SDOF")
        if key == xp.T_LD:
            a.plot(tr, 1e3 * fv.runs["err"].result.calc_displacement, color="C2", lw=0.5,
                   label="calculated, with error")
        a.set_ylim(-25, 25)
        a.set_title(label, fontsize=9)
        a.set_ylabel("displacement [mm]")
        a.legend(fontsize=7, loc="upper right")
        a.grid(True, lw=0.3)
    axes[-1, 0].set_xlim(-2, fv.release.free)
    axes[-1, 0].set_xlabel("time after release [s]")
    return fig


def fig10a(fv: xp.RpsdFreeVibrations) -> Figure:
    fig, ax = new_figure("Fig 10(a): measured force vs restoring force (calculated displacements)")
    r, tr = fv.runs["a"].result, fv.time_after_release
    ax[0, 0].plot(tr, r.force / 1e3, color="C0", lw=0.7, label="load cell F")
    ax[0, 0].plot(tr, fv.k * r.displacement / 1e3, color="C1", lw=0.7, label="restoring force k x (measured x)")
    ax[0, 0].plot(tr, fv.external_force / 1e3, "k--", lw=0.7, label="solver input P_ext")
    ax[0, 0].set_xlim(-6.5, 5)
    ax[0, 0].set_xlabel("time after release [s]")
    ax[0, 0].set_ylabel("force [kN]")
    _finish(ax)
    return fig


# --------------------------------------------------------------------------- dispatch
def _figures(name: str, r: dict, rig) -> dict:
    """File name -> figure of one section (built lazily: only the section's own)."""
    if name == "structure":
        return {"fig2b_free_vibration.png": lambda: fig2b(r["fig2b_free_vibration"])}
    if name == "force":
        return {"fig3a_direct_eft.png": lambda: fig3a(r["fig3a_direct_eft"]),
                "fig4a_flow_curve.png": lambda: fig4a(r["fig4a_flow_curve"])}
    if name == "eft":
        e = r["fig3_eft"]
        return {"fig3b_compensated_eft.png": lambda: fig3b(e),
                "fig4b_eft_8.9kN_linear.png": lambda: fig4bc(
                    e, "Fig 4(b): EFT 8.9 kN, linear velocity feedback compensation",
                    (("big_linear", "preset flow curve (nonlinear) + load pressure", "C0"),
                     ("big_linear_flowlin", "linear flow curve, load pressure kept", "0.5"))),
                "fig4c_eft_8.9kN_nonlinear.png": lambda: fig4bc(
                    e, "Fig 4(c): EFT 8.9 kN, nonlinear velocity feedback compensation",
                    (("big_nonlinear", "nonlinear compensation", "C0"),
                     ("big_linear", "linear compensation (Fig 4b)", "0.6"))),
                "eft_delay_compensation.png": lambda: eft_delay(e)}
    if name == "displacement":
        s, d = r["fig5_displacement_sweeps"], r["fig6a_amplitude_compensation"]
        return {"fig5a_displacement_sweep.png": lambda: fig5a(s, d), "fig5b_compensated_sweep.png": lambda: fig5b(s, d),
                "fig6a_amplitude_compensation.png": lambda: fig6a(d)}
    if name == "gain_bound":
        g = r["fig6b_gain_bound"]
        return {"fig6b_max_gain_vs_mass.png": lambda: fig6b(g), "analysis_root_locus.png": lambda: root_locus(g),
                "analysis_bode.png": lambda: loop_bode(g)}
    if name == "rpsd_linear":
        return {f"fig10{t}_pole_zero.png": (lambda t=t: fig10bc(r["fig10_pole_zero"], t)) for t in ("b", "c")}
    if name == "rpsd":
        return _rpsd_figures(r, rig)
    return {}


def _rpsd_figures(r: dict, rig) -> dict:
    s, fv = r["fig8_rpsd_delay"], r["fig9_free_vibration"]
    delays = np.linspace(0.004, 0.024, 11)
    return {"fig8a_rpsd_6ms.png": lambda: fig8ab(s, fv, 0.006, "Fig 8(a): RPsD, delay compensation T_ld = 6 ms"),
            "fig8b_rpsd_16ms.png": lambda: fig8ab(s, fv, 0.016, "Fig 8(b): RPsD, delay compensation T_ld = 16 ms"),
            "fig8_damping_vs_T_ld.png": lambda: fig8_damping(fv, delays, xp.rpsd_damping_curve(rig, delays)),
            "fig9_free_vibration_rpsd.png": lambda: fig9(fv, r["fig9a_structural"]),
            "fig10a_force_vs_restoring.png": lambda: fig10a(fv)}


def draw(name: str, results: dict, rig, out: Path) -> list[Path]:
    """Draws and saves the figures of section ``name`` in ``out`` -> their paths."""
    return [save(make(), Path(out) / fname) for fname, make in _figures(name, results, rig).items()]
