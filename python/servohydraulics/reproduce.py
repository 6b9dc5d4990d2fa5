"""``servohydraulics reproduce --out DIR``: the simulated counterpart of every
figure with results in Zhao, French, Shield & Posbergh (2003), and
``DIR/reproduction.md``: one row per quantitative statement of the paper, with
the paper's value, ours, the tolerance, agree or not, and why where not.

The paper's measured curves are not available: each figure says so, and the
comparison is to the numbers the paper states.  ``DIR/reproduction.json``
holds the same rows with their numeric acceptance intervals.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import control as ct
import numpy as np
from scipy import signal

from . import analysis as an
from . import plots
from .identify import (
    frequency_response,
    identify_damping_friction,
    identify_first_order,
    linear_chirp,
    simulate_structure,
)
from .rig import Rig, copy_rig, zhao2003
from .simulate import simulate

TWO_PI = 2.0 * math.pi
DT = 5e-4  #: controller sample time of the paper's DSP (2 kHz) [s]
T_AMP = 0.068  #: amplitude compensation (paper) [s]
T_LD = 0.0112  #: delay compensation (paper) [s]
T_EFT = 0.005  #: EFT phase lead (paper) [s]
M_M, C_M = 7084.0, 3.5e3  #: modelled SDOF of the RPsD solver (Table I) [kg], [N s/m]
SWEEP_X = 0.0127  #: displacement sweep amplitude (Fig 5) [m]
SWEEP_F = 2.3e3  #: direct-EFT sweep amplitude (Fig 3) [N]
SWEEP_F_LARGE = 8.9e3  #: large EFT sweep amplitude (Fig 4) [N]
SWEEP_DURATION_METHODS = 20.0  #: 0-10 Hz sweeps of the test-method loops (docs/methods.md) [s]


@dataclass
class Row:
    """One quantitative statement of the paper and our counterpart."""

    key: str
    figure: str
    statement: str
    paper: str  #: the paper's value, as stated
    ours: str  #: our value, formatted with units
    tolerance: str  #: the acceptance rule, in words
    our_value: float  #: the number checked [units of the row]
    lo: float  #: acceptance interval for our_value
    hi: float
    why: str = ""  #: explanation where we do not agree (or a caveat)
    paper_value: float | None = None

    @property
    def agree(self) -> bool:
        return bool(self.lo <= self.our_value <= self.hi)


def _row(key, figure, statement, paper, ours, tolerance, value, lo, hi, why="", paper_value=None) -> Row:
    return Row(key, figure, statement, paper, ours, tolerance, float(value), float(lo), float(hi), why,
               None if paper_value is None else float(paper_value))


def _identified_row(key, figure, statement, paper_text, paper, est, name, unit, scale, cap, why) -> Row:
    """Row for an identified parameter: agree when the paper's value lies in our
    95 % interval, whose half-width is capped at ``cap`` (so a vague estimate cannot agree)."""
    lo, hi = est.interval(name)
    v, lo, hi = scale * getattr(est, name), scale * lo, scale * hi
    hw = min(0.5 * (hi - lo), cap)
    return _row(key, figure, statement, paper_text, f"{v:.3f} {unit} (95 %: {lo:.3f}-{hi:.3f})",
                f"paper value inside our 95 % interval, half-width capped at {cap:g} {unit}", v, paper - hw,
                paper + hw, why, paper)


@dataclass
class Context:
    out: Path
    quick: bool
    rig: Rig
    rows: list
    figures: list
    notes: list


# --------------------------------------------------------------------------- helpers
def _lead_filter(u: np.ndarray, T: float, dt: float = DT, alpha: float = an.ALPHA) -> np.ndarray:
    """Tustin-discretised phase lead (T s+1)/(alpha T s+1) applied to a command array."""
    b, a = signal.bilinear([T, 1.0], [alpha * T, 1.0], fs=1.0 / dt)
    return signal.lfilter(b, a, u)


def _fmt(v: float, unit: str = "", digits: int = 3) -> str:
    return f"{v:.{digits}g}{(' ' + unit) if unit else ''}"


def _interp_response(f: np.ndarray, h: np.ndarray, f0: float) -> complex:
    ok = np.isfinite(h)
    return complex(np.interp(f0, f[ok], h[ok].real) + 1j * np.interp(f0, f[ok], h[ok].imag))


# --------------------------------------------------------------------------- Fig 2(b): structure
def section_structure(ctx: Context) -> None:
    """Natural frequency; identification of c, F_c (free and attached); equivalent damping."""
    rig = ctx.rig
    free = zhao2003(actuator_attached=False)
    f_n = an.natural_frequency(rig) / TWO_PI
    ctx.rows.append(_row("natural_frequency", "p. 1777", "initial natural frequency of the structure",
                         "1.58 Hz", f"{f_n:.3f} Hz (sqrt(k/m))", "+-0.02 Hz", f_n, 1.56, 1.60, paper_value=1.58))

    dt, dur = 2e-3, (6.0 if ctx.quick else 10.0)
    n = int(round(dur / dt)) + 1
    t = np.arange(n) * dt
    x_true = simulate_structure(free, free.c, free.F_c, n, dt, 0.013)
    rng = np.random.default_rng(2003)
    sigma = 5e-5  # LVDT noise of the synthetic record [m]
    x_meas = x_true + sigma * rng.standard_normal(n)
    est = identify_damping_friction(t, x_meas, free)
    why = ("identification run on a record simulated with the paper's values plus 0.05 mm white noise: "
           "it checks the procedure, not the paper's test")
    ctx.rows.append(_identified_row("zeta_free", "2b", "damping ratio of the structure alone (free vibration, "
                                    "least squares)",
                                    f"0.8 % (Table I c = {free.c:g} N s/m: {100 * an.damping_ratio(free):.3f} %)",
                                    100 * an.damping_ratio(free), est, "zeta", "%", 100.0,
                                    0.1, why + f"; the paper's 0.8 % is c = {free.c:g} N s/m = "
                                    f"{100 * an.damping_ratio(free):.3f} %"))
    ctx.rows.append(_identified_row("friction_free", "2b", "Coulomb friction of the structure alone", "95.7 N", 95.7,
                                    est, "F_c", "N", 1.0, 5.0, why))
    up = np.flatnonzero((x_true[:-1] < 0) & (x_true[1:] >= 0))
    f_fv = 1.0 / float(np.mean(np.diff(t[up])))
    ctx.rows.append(_row("natural_frequency_free_vibration", "2b", "frequency of the free vibration",
                         "1.58 Hz", f"{f_fv:.3f} Hz (zero crossings)", "+-0.02 Hz", f_fv, 1.56, 1.60,
                         paper_value=1.58))

    fig, ax = plots.new_figure("Fig 2(b): free vibration of the structure alone, released from 1.3 cm")
    ax = ax[0, 0]
    ax.plot(t, 1e3 * x_meas, color="0.6", lw=0.8, label="synthetic record (model + 0.05 mm noise)")
    ax.plot(t, 1e3 * est.fitted, color="C0", lw=1.0,
            label=f"fit: zeta = {100 * est.zeta:.2f} %, F_c = {est.F_c:.1f} N")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("displacement [mm]")
    ax.legend(fontsize=8)
    ax.grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig2b_free_vibration.png"))

    # Actuator attached: forced vibration under force control, measured force into the SDOF model.
    dur_f = 8.0 if ctx.quick else 12.0
    tt, u = linear_chirp(dur_f, DT, 0.3, 4.0, SWEEP_F, tail=1.0)
    res = simulate(rig, "force", u, DT)
    dec = 4  # fit at 2 ms, as the free-vibration record
    x_f = res.displacement[::dec] + sigma * rng.standard_normal(res.displacement[::dec].size)
    F_f = res.force[::dec] + 2.0 * rng.standard_normal(x_f.size)
    est_a = identify_damping_friction(tt[::dec], x_f, rig, force=F_f, x0=0.0)
    why_a = ("forced-vibration record simulated in force control (2.3 kN sweep 0.3-4 Hz) with the paper's "
             "values, sampled at 2 ms, 0.05 mm and 2 N noise, load-cell force into Eq (5): checks the procedure")
    ctx.rows.append(_identified_row("zeta_attached", "p. 1779", "damping ratio with the actuator attached (forced "
                                    "vibration)",
                                    f"1.5 % (Table I c = {rig.c:g} N s/m: {100 * an.damping_ratio(rig):.3f} %)",
                                    100 * an.damping_ratio(rig), est_a, "zeta", "%", 100.0,
                                    0.2, why_a + f"; the paper's 1.5 % is c = {rig.c:g} N s/m = "
                                    f"{100 * an.damping_ratio(rig):.3f} %"))
    ctx.rows.append(_identified_row("friction_attached", "p. 1779", "Coulomb friction with the actuator attached",
                                    "31.6 N", 31.6, est_a, "F_c", "N", 1.0, 5.0, why_a))

    # Equivalent viscous damping (Jacobsen) 1.1 % -> 1.6 %: amplitude fixed by the first, predicts the second.
    z_free, z_att = an.damping_ratio(free), an.damping_ratio(rig)
    X = 2.0 * free.F_c / (math.pi * free.k * (0.011 - z_free))
    z_eq = z_att + 2.0 * rig.F_c / (math.pi * rig.k * X)
    ctx.rows.append(_row("equivalent_damping", "p. 1779", "equivalent viscous damping after attaching the actuator",
                         "1.1 % -> 1.6 %", f"1.1 % -> {100 * z_eq:.2f} % (at X = {1e3 * X:.1f} mm)",
                         "+-0.1 percentage point", 100 * z_eq, 1.5, 1.7,
                         "energy-equivalent damping 4 F_c/(pi w X); X is set by the 1.1 % of the free "
                         "structure, the 1.6 % is then predicted", 1.6))
    ctx.notes.append(f"identification: free {est.nfev} simulations, attached {est_a.nfev}")


# --------------------------------------------------------------------------- Figs 3(a), 4(a): force control
def section_force(ctx: Context) -> None:
    """Direct EFT sweep (Fig 3a), Eqs (9)-(11), flow curve (Fig 4a), piston mass."""
    rig = ctx.rig
    lin = an.linear_analysis_rig(rig)
    dur = 20.0 if ctx.quick else 40.0
    t, u = linear_chirp(dur, DT, 0.1, 10.0, SWEEP_F, tail=2.0)
    res = simulate(rig, "force", u, DT)
    f, h, ok = frequency_response(t, u, res.force)
    band = ok & (f > 0.3) & (f < 5.0)
    f_min = float(f[band][np.argmin(np.abs(h[band]))])
    ff = np.linspace(0.3, 5.0, 2000)
    g = np.abs(np.asarray(an.G_fu(lin)(1j * TWO_PI * ff)))
    f_min_cf = float(ff[np.argmin(g)])
    ctx.rows.append(_row("eft_drop", "3a", "direct EFT: applied force drops at the structure's natural frequency "
                         "(its poles are zeros of G_fu, Eq 9)", "at 1.58 Hz",
                         f"minimum of |F/u| at {f_min:.2f} Hz (simulated sweep), {f_min_cf:.2f} Hz (Eq 9); "
                         f"|F/u| = {np.min(np.abs(h[band])):.2f}", "+-0.1 Hz", f_min, 1.48, 1.68, paper_value=1.58))
    w_eft = an.omega_cEFT(rig) / TWO_PI
    kf = rig.A * rig.K_v * rig.C_F_force * rig.K_s
    gp_120 = (TWO_PI * 120.0 * rig.K_a - rig.C_l) / kf
    ctx.rows.append(_row("eft_rolloff", "Eq (11)", "roll-off of the compensated force loop", "above 120 Hz",
                         f"{w_eft:.1f} Hz", ">= 120 Hz", w_eft, 120.0, math.inf,
                         f"with the calibrated K_a (docs/calibration.md) and G_p = 0.8059; Table I as printed gives "
                         f"{an.omega_cEFT(zhao2003('printed')) / TWO_PI:.1f} Hz. 120 Hz needs a force-loop gain "
                         f"G_p >= {gp_120:.2f}: the paper's single G_p is the displacement gain (Eq 13). Still far "
                         "above the 0-10 Hz band, as the paper concludes", 120.0))
    frac = rig.m_p / (rig.m + rig.m_p)
    ctx.rows.append(_row("piston_mass", "p. 1782", "piston mass 54 kg, less than 1 % of the moving mass",
                         "54 kg, < 1 %", f"{rig.m_p:.0f} kg, {100 * frac:.2f} %", "< 1 %", 100 * frac, 0.0, 1.0,
                         paper_value=0.76))

    fig, axes = plots.new_figure("Fig 3(a): direct EFT, 2.3 kN sine sweep 0-10 Hz (no compensation)", 2, 1,
                                 figsize=(8, 6.5))
    axes[0, 0].plot(t, res.force / 1e3, lw=0.5, color="C0", label="load-cell force")
    axes[0, 0].plot(t, u / 1e3, lw=0.5, color="0.6", label="effective force command")
    axes[0, 0].set_xlabel("time [s] (frequency rises linearly 0.1 -> 10 Hz)")
    axes[0, 0].set_ylabel("force [kN]")
    axes[0, 0].legend(fontsize=8)
    sel = ok & (f < 10.0)
    axes[1, 0].plot(f[sel], np.abs(h[sel]), color="C0", label="simulated sweep, |F/u|")
    fl = np.linspace(0.1, 10.0, 800)
    axes[1, 0].plot(fl, np.abs(np.asarray(an.G_fu(lin)(1j * TWO_PI * fl))), "k--", lw=0.8, label="Eq (9)")
    axes[1, 0].axvline(1.58, color="C3", lw=0.6, label="f_n = 1.58 Hz")
    axes[1, 0].set_xlabel("frequency [Hz]")
    axes[1, 0].set_ylabel("|applied / command force| [-]")
    axes[1, 0].legend(fontsize=8)
    for a in axes.ravel():
        a.grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig3a_direct_eft.png"))

    # Fig 4(a): the preset's flow curve g(x_v) and its gain, against the constant initial gain of Eq (7).
    fc = rig.flow_curve
    xs = np.linspace(0.0, 1.0, 201)
    g = np.array([fc.eval(x) for x in xs])
    slope = np.array([fc.slope(x) for x in xs])
    dev10 = 100 * (fc.eval(0.1) / 0.1 - 1)
    ctx.rows.append(_row("flow_curve", "4a / p. 1780", "a constant initial flow gain is adequate below 10 % spool "
                         "opening; the gain falls as the opening grows", "linear below 10 %, falling gain",
                         f"g(0.1)/0.1 - 1 = {dev10:+.2f} %; gain dg/dx {fc.slope(0.05):.2f} at 5 %, "
                         f"{fc.slope(0.5):.2f} at 50 %, {fc.slope(0.95):.2f} at 95 %; g(1) = {fc.eval(1.0):.2f}; "
                         f"gain never increases: {bool(np.all(np.diff(slope) <= 1e-9))}",
                         "|g(0.1)/0.1 - 1| <= 2 % and a non-increasing gain",
                         dev10 if np.all(np.diff(slope) <= 1e-9) and slope[-1] < slope[0] else math.nan, -2.0, 2.0,
                         "the preset's table is built on these two statements and the valve's rated flow "
                         "(docs/calibration.md): a consistency check, not an independent confirmation"))
    fig, axes = plots.new_figure("Fig 4(a): flow - spool opening relation of the servovalve model", 2, 1,
                                 figsize=(8, 6.5), sharex=True)
    axes[0, 0].plot(100 * xs, rig.K_v * g * 1e3, label="preset g(x_v): Q = K_v g(x_v) at zero load pressure")
    axes[0, 0].plot(100 * xs, rig.K_v * xs * 1e3, "k--", lw=0.8, label="constant initial flow gain (Eq 7)")
    axes[0, 0].set_ylabel("flow at zero load pressure [L/s]")
    axes[1, 0].plot(100 * xs, slope, label="flow gain dg/dx_v of the preset")
    axes[1, 0].axhline(1.0, color="k", ls="--", lw=0.8, label="Eq (7): K_v constant")
    axes[1, 0].set_ylabel("flow gain / K_v [-]")
    axes[1, 0].set_xlabel("spool opening [%]")
    for a in axes.ravel():
        a.axvline(10.0, color="0.5", lw=0.6, label="10 % opening (linear range, p. 1780)")
        a.legend(fontsize=8)
        a.grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig4a_flow_curve.png"))


# --------------------------------------------------------------------------- Figs 5, 6: displacement control
def section_displacement(ctx: Context) -> None:
    """Sweeps of Fig 5, Eqs (12)-(14), amplitude compensation (Fig 6a), capacity limit."""
    rig = ctx.rig
    lin = an.linear_analysis_rig(rig)
    g_lin = an.G_xu(lin) * an.zoh_delay(DT)
    w_c = an.omega_cRPD(rig)
    ctx.rows.append(_row("rolloff_eq13", "Eq (13)", "equivalent roll-off frequency K_v C_F K_s G_p / A", "1.96 Hz",
                         f"{w_c / TWO_PI:.3f} Hz", "+-0.02 Hz", w_c / TWO_PI, 1.94, 1.98, paper_value=1.96))
    ctx.rows.append(_row("delay_eq13", "p. 1785", "total response delay 1/w_cRPD", "81 ms", f"{1e3 / w_c:.1f} ms",
                         "+-1 ms", 1e3 / w_c, 80.0, 82.0, paper_value=81.0))

    dur = 20.0 if ctx.quick else 40.0
    t, u = linear_chirp(dur, DT, 0.1, 10.0, SWEEP_X, tail=2.0)
    res = simulate(rig, "displacement", u, DT)
    fo = identify_first_order(t, u, res.displacement)
    ctx.rows.append(_row("rolloff_identified", "5a", "equivalent first-order roll-off identified from a 1.27 cm sweep",
                         "1.96 Hz", f"{fo.roll_off_hz:.2f} Hz (fit K/(tau s+1), 0.1-2 Hz, K = {fo.gain:.3f})",
                         "+-5 %", fo.roll_off_hz, 0.95 * 1.96, 1.05 * 1.96,
                         "fit on the simulated sweep: the oil-column mode and the valve add lag above 1 Hz",
                         1.96))
    ctx.rows.append(_row("delay_identified", "5a", "equivalent response delay tau identified from the sweep",
                         "81 ms", f"{1e3 * fo.tau:.1f} ms", "+-5 %", 1e3 * fo.tau, 0.95 * 81, 1.05 * 81,
                         paper_value=81.0))
    h2 = abs(_interp_response(fo.frequency, fo.response, 2.0))
    ctx.rows.append(_row("loss_2hz", "5a", "amplitude reduction at 2 Hz (uncompensated, 1.27 cm sweep)",
                         "about 30 %", f"{100 * (1 - h2):.1f} %", "30 +- 5 %", 100 * (1 - h2), 25.0, 35.0,
                         paper_value=30.0))

    # Oil column, Eq (14), and the closed-loop mode.
    f_oc = an.omega_oil_column(rig) / TWO_PI
    f_cl, z_cl = an.dominant_modes(an.G_xu(lin))[-1]
    ctx.rows.append(_row("oil_column", "Eq (14)", "oil-column mode: 'slightly damped vibration mode'",
                         "no value; slightly damped", f"{f_oc:.1f} Hz (Eq 14); closed loop {f_cl:.1f} Hz, "
                         f"zeta = {z_cl:.3f}", "0 < zeta < 0.2", z_cl, 1e-6, 0.2,
                         "Table I as printed gives "
                         f"{an.omega_oil_column(zhao2003('printed')) / TWO_PI:.1f} Hz by Eq (14) and an unstable "
                         "closed-loop mode (docs/calibration.md)"))

    # Amplitude compensation, Fig 6(a).
    T_best, dev = an.amplitude_compensation_T(g_lin, (0.0, 5.0))
    ctx.rows.append(_row("T_amplitude", "6a", "amplitude-compensation time constant for 0-5 Hz (minimax)",
                         "68 ms", f"{1e3 * T_best:.1f} ms (worst deviation {100 * dev:.1f} %)", "+-3 ms",
                         1e3 * T_best, 65.0, 71.0,
                         "K_a and C_l were calibrated with this as one target (docs/calibration.md)", 68.0))
    band = an.acceptable_band(g_lin, T_AMP, 0.05)
    ctx.rows.append(_row("band_68ms", "6a", "68 ms extends acceptable tracking to 5 Hz (|G_c| within 5 %)",
                         "5 Hz", f"{band:.2f} Hz", "5-6 Hz (the sweep was stopped at 6 Hz)", band, 5.0, 6.0,
                         paper_value=5.0))

    # Compensated sweep, Fig 5(b), 0.1-6 Hz.
    t2, u2 = linear_chirp(dur * 0.6, DT, 0.1, 6.0, SWEEP_X, tail=2.0)
    res2 = simulate(rig, "displacement", _lead_filter(u2, T_AMP), DT)
    f2, h2c, ok2 = frequency_response(t2, u2, res2.displacement)
    sel = ok2 & (f2 >= 0.2) & (f2 <= 5.0)
    peak = float(np.max(np.abs(h2c[sel])))
    fl5 = np.linspace(0.2, 5.0, 400)
    peak_lin = float(np.max(np.abs(np.asarray((an.phase_lead(T_AMP) * g_lin)(1j * TWO_PI * fl5)))))
    in5 = t2 <= (5.0 - 0.1) / (6.0 - 0.1) * dur * 0.6  # the sweep below 5 Hz
    ctx.rows.append(_row("overshoot_5b", "5b", "compensated 1.27 cm sweep: amplitude restored with a slight overshoot",
                         "slight overshoot", f"max |x/u| = {peak:.3f} over 0.2-5 Hz (linear model: {peak_lin:.3f})",
                         "1.00-1.10", peak, 1.0, 1.10,
                         f"the linear model overshoots ({peak_lin:.3f}); in the nonlinear simulation the spool opens "
                         f"to {100 * np.max(np.abs(res2.spool[in5])):.0f} % and |p| reaches "
                         f"{100 * np.max(np.abs(res2.pressure[in5])) / rig.p_s:.0f} % of p_s below 5 Hz, where the "
                         "flow gain (Fig 4a curve: linear to 10 %, 0.56 at full opening) and the load-pressure "
                         "term of Eq (3) lower the gain: the "
                         "mechanism the paper describes in its nonlinearity section; the flow curve is a modelling "
                         "choice, not a measured one"))

    # Capacity: compensated 1.27 cm sines, first frequency at the force limit.
    freqs = np.arange(5.0, 8.01, 0.5 if ctx.quick else 0.25)
    limit = None
    peak_at_limit = 0.0
    for fq in freqs:
        tt = np.arange(int(round(max(1.5, 8.0 / fq) / DT)) + 1) * DT
        ramp = np.clip(tt / 0.3, 0, 1)
        uu = SWEEP_X * np.sin(TWO_PI * fq * tt) * (0.5 - 0.5 * np.cos(math.pi * ramp))
        rr = simulate(rig, "displacement", _lead_filter(uu, T_AMP), DT, raise_on_failure=False)
        if limit is None and (rr.supply_limited or rr.capacity_exceeded):
            limit, peak_at_limit = float(fq), float(np.max(np.abs(rr.force)))
    p_force = rig.p_s * rig.A
    ctx.rows.append(_row("capacity", "5b", "required forces exceed the actuator capacity above 6 Hz "
                         "(1.27 cm, 68 ms compensation)", "above 6 Hz",
                         f"supply-pressure limit (|p| >= 0.98 p_s) first reached at {limit} Hz, peak load-cell "
                         f"force {peak_at_limit / 1e3:.0f} kN (p_s A = {p_force / 1e3:.0f} kN)" if limit
                         else "not reached up to 8 Hz", f"6 +- 0.5 Hz (grid {freqs[1] - freqs[0]:g} Hz)",
                         limit if limit else 99.0, 5.5, 6.5,
                         "at p_s = 17 MPa the actuator delivers p_s A = 140 kN, below its 170 kN rating", 6.0))

    # Figures 5(a), 5(b), 6(a).
    for name, title, ff, hh, okk, comp in (
        ("fig5a_displacement_sweep.png", "Fig 5(a): 1.27 cm displacement sine sweep, no compensation", fo.frequency,
         fo.response, fo.excited, None),
        ("fig5b_compensated_sweep.png", "Fig 5(b): 1.27 cm sweep with amplitude compensation (68 ms), 0-6 Hz",
         f2, h2c, ok2, T_AMP)):
        fig, axes = plots.new_figure(title, 2, 1, figsize=(8, 6.5), sharex=True)
        s = okk & (ff > 0.1) & (ff < (10 if comp is None else 6))
        model = g_lin if comp is None else an.phase_lead(comp) * g_lin
        fl = np.linspace(0.1, 10 if comp is None else 6, 600)
        plots.bode(axes[0, 0], axes[1, 0], model, fl, "linear model, Eq (12) + valve + ZOH", color="k", ls="--",
                   lw=0.8)
        axes[0, 0].plot(ff[s], np.abs(hh[s]), color="C0", label="simulated sweep (nonlinear model)")
        axes[1, 0].plot(ff[s], np.degrees(np.unwrap(np.angle(hh[s]))), color="C0")
        if comp is None:
            plots.bode(axes[0, 0], axes[1, 0], ct.tf([fo.gain], [fo.tau, 1.0]), fl,
                       f"first order, tau = {1e3 * fo.tau:.0f} ms", color="0.5", lw=0.8)
            axes[0, 0].axvline(2.0, color="C3", lw=0.5)
            axes[0, 0].annotate(f"{100 * (1 - abs(_interp_response(ff, hh, 2.0))):.0f} % loss at 2 Hz",
                                (2.0, abs(_interp_response(ff, hh, 2.0))), fontsize=8)
        axes[0, 0].set_ylabel("|x / u| [mm/mm]")
        axes[1, 0].set_ylabel("phase [deg]")
        axes[1, 0].set_xlabel("frequency [Hz]")
        axes[0, 0].legend(fontsize=8)
        for a in axes.ravel():
            a.grid(True, lw=0.3)
        ctx.figures.append(plots.save(fig, ctx.out / name))

    fig, ax = plots.new_figure("Fig 6(a): amplitude compensation with the oil-column mode (linear analysis)")
    fl = np.linspace(0.05, 10.0, 800)
    first = ct.tf([1.0], [1.0 / w_c, 1.0])
    for sys_, label, style in ((g_lin, "G_xu (Eq 12 + valve + ZOH)", dict(color="C0", ls="--")),
                               (first, "first order, Eq (13)", dict(color="0.5", ls="--")),
                               (an.phase_lead(1.0 / w_c) * first, "first order + lead 81 ms", dict(color="0.5")),
                               (an.phase_lead(1.0 / w_c) * g_lin, "G_xu + lead 81 ms", dict(color="C1")),
                               (an.phase_lead(T_AMP) * g_lin, "G_xu + lead 68 ms", dict(color="C0"))):
        plots.bode(ax[0, 0], None, sys_, fl, label, **style)
    ax[0, 0].axhspan(0.95, 1.05, color="0.9")
    ax[0, 0].axvline(5.0, color="k", lw=0.6)
    ax[0, 0].set_xlabel("frequency [Hz]")
    ax[0, 0].set_ylabel("|x / u| [-]")
    ax[0, 0].set_ylim(0, 1.6)
    ax[0, 0].legend(fontsize=8)
    ax[0, 0].grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig6a_amplitude_compensation.png"))


def section_gain_bound(ctx: Context) -> None:
    """Routh bound on G_p against the installed mass (Fig 6b), root locus, Bode of the loop."""
    rig = ctx.rig
    lin = an.linear_analysis_rig(rig)
    masses = np.geomspace(54.0, rig.m + rig.m_p, 12 if ctx.quick else 30)
    g_valve = an.max_p_gain_curve(lin, masses, True)
    g_novalve = an.max_p_gain_curve(lin, masses, False)
    # Cross-check with the eigenvalues of the linearised C++ model at three masses.
    checks = []
    for m in (masses[0], masses[len(masses) // 2], masses[-1]):
        r = an.rig_with_mass(lin, m)
        gmax = an.max_p_gain(r)
        re = []
        for fac in (0.999, 1.001):
            r.G_p = fac * gmax
            re.append(float(np.max(np.real(np.linalg.eigvals(an.linearize(r).A)))))
        checks.append(re[0] < 0 < re[1])
    monotone = bool(np.all(np.diff(g_valve) < 0))
    ctx.rows.append(_row("gp_falls_with_mass", "6b", "maximum P-gain falls as the physical mass grows",
                         "decays with mass", f"G_p,max {g_valve[0]:.1f} at 54 kg -> {g_valve[-1]:.2f} at "
                         f"{masses[-1]:.0f} kg, monotone: {monotone}; Routh = eigenvalue crossing: {all(checks)}",
                         "monotone decrease and Routh confirmed by the linearised model",
                         float(monotone and all(checks)), 1.0, 1.0))
    ctx.rows.append(_row("gp_used_stable", "6b", "the gain used, G_p = 0.8059, is below the Routh bound at full mass",
                         "0.8059 ran stably", f"G_p,max = {g_valve[-1]:.2f}", "> 0.8059", g_valve[-1], rig.G_p,
                         math.inf, "Table I as printed gives G_p,max = "
                         f"{an.max_p_gain(zhao2003('printed')):.3f}: unstable at 0.8059 (docs/calibration.md)",
                         0.8059))

    fig, ax = plots.new_figure("Fig 6(b): maximum P-gain (Routh) vs physically installed mass")
    ax[0, 0].loglog(masses, g_valve, "o-", ms=3, label="with servovalve second order")
    ax[0, 0].loglog(masses, g_novalve, "s--", ms=3, label="static valve (Eq 6)")
    ax[0, 0].axhline(rig.G_p, color="C3", lw=0.6, label="G_p = 0.8059 (Table I)")
    ax[0, 0].set_xlabel("physically installed mass incl. 54 kg piston [kg]")
    ax[0, 0].set_ylabel("maximum stable G_p [-]")
    ax[0, 0].legend(fontsize=8)
    ax[0, 0].grid(True, which="both", lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig6b_max_gain_vs_mass.png"))
    ctx.notes.append("Fig 6b: " + ", ".join(f"{m:.0f} kg: {g:.3g}" for m, g in zip(masses, g_valve)))

    gains = np.geomspace(0.01, 10.0, 300)
    poles = an.root_locus_gains(lin, gains)
    fig, ax = plots.new_figure("Root locus of the displacement loop over G_p (valve on, 7138 kg)")
    plots.root_locus(ax[0, 0], poles, gains, {"G_p,max": g_valve[-1], "G_p used": rig.G_p})
    ax[0, 0].set_xlim(-120, 40)
    ax[0, 0].set_ylim(-150, 150)
    ctx.figures.append(plots.save(fig, ctx.out / "analysis_root_locus.png"))

    fig, axes = plots.new_figure("Bode plot of the linearised rig (C++ Jacobian), displacement and force control",
                                 2, 1, figsize=(8, 6.5), sharex=True)
    fl = np.geomspace(0.05, 100.0, 600)
    plots.bode(axes[0, 0], axes[1, 0], an.linearize(rig), fl, "x/u, displacement control", db=True)
    plots.bode(axes[0, 0], axes[1, 0], an.linearize(rig, "force", outputs=("force",)), fl,
               "F/u, force control (direct)", db=True)
    plots.bode(axes[0, 0], axes[1, 0], an.linearize(rig, "force", outputs=("force",), compensators=an.Compensation(
        velocity_feedback=True, velocity_feedback_T=T_EFT)), fl, "F/u, velocity feedback compensation + 5 ms lead",
        db=True)
    axes[0, 0].set_xscale("log")
    axes[0, 0].set_ylabel("magnitude [dB]")
    axes[1, 0].set_ylabel("phase [deg]")
    axes[1, 0].set_xlabel("frequency [Hz]")
    axes[0, 0].legend(fontsize=8)
    for a in axes.ravel():
        a.grid(True, which="both", lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "analysis_bode.png"))


# --------------------------------------------------------------------------- Figs 8-10: RPsD (linear analysis)
def section_rpsd_linear(ctx: Context) -> None:
    """Net damping of the RPsD loop vs delay compensation; pole-zero maps of Fig 10(b), (c)."""
    rig = ctx.rig
    lin = an.linear_analysis_rig(rig)
    w_n = an.natural_frequency(rig)
    z_model = C_M / (2.0 * math.sqrt(rig.k * M_M))
    zeta = {T: an.structural_mode(an.rpsd_loop(lin, M_M, C_M, delay_T=T or None), w_n)[1] for T in
            (0.0, 0.006, T_LD, 0.016)}
    T_est = an.delay_compensation_T(1.0 / an.omega_cRPD(rig), T_AMP)
    ctx.rows.append(_row("T_ld_estimate", "p. 1786", "delay compensation estimated as total delay minus 68 ms",
                         "81 - 68 = 13 ms", f"{1e3 * T_est:.1f} ms", "+-1 ms", 1e3 * T_est, 12.0, 14.0,
                         paper_value=13.0))
    comp = an.phase_lead(T_AMP) * an.G_xu(lin) * an.zoh_delay(DT)
    T_zero = an.delay_compensation_T(0.0, T_AMP, comp, 1.58)
    why_delay = ("the model's residual delay after the 68 ms lead is "
                 f"{1e3 * an.equivalent_delay(comp, 1.58):.1f} ms at 1.58 Hz, not 81 - 68 = 13 ms: a lead with "
                 "alpha = 0.1 advances only ~53 ms, and the valve/oil column add lag (docs/calibration.md s. 4)")
    ctx.rows.append(_row("T_ld_final", "p. 1786", "finalised delay compensation (zero residual phase at 1.58 Hz)",
                         "11.2 ms", f"{1e3 * T_zero:.1f} ms", "+-2 ms", 1e3 * T_zero, 9.2, 13.2, why_delay, 11.2))
    ctx.rows.append(_row("undercompensated_6ms", "8a", "6 ms delay compensation: negative damping, unstable",
                         "unstable", f"net zeta = {100 * zeta[0.006]:.2f} % (linear loop)", "net zeta < 0",
                         zeta[0.006], -math.inf, 0.0))
    ctx.rows.append(_row("compensated_11ms", "9b", "11.2 ms: structural damping close to the modelled "
                         f"{100 * z_model:.2f} % (Fig 9b 'slightly different damping')", f"~{100 * z_model:.2f} %",
                         f"net zeta = {100 * zeta[T_LD]:.2f} %", "within +-1 percentage point of the model",
                         100 * zeta[T_LD], 100 * z_model - 1, 100 * z_model + 1, why_delay, 100 * z_model))
    ctx.rows.append(_row("overcompensated_16ms", "8b", "16 ms: over-compensation increases the damping above the "
                         "model's", f"> {100 * z_model:.2f} %", f"net zeta = {100 * zeta[0.016]:.2f} % "
                         f"(vs {100 * zeta[T_LD]:.2f} % at 11.2 ms)", f"> {100 * z_model:.2f} %",
                         100 * zeta[0.016], 100 * z_model, math.inf,
                         why_delay + "; the trend (more damping with more lead) agrees"))

    modes = {}
    for mass, tag in ((rig.m, "b"), (0.02 * M_M, "c")):
        fig, ax = plots.new_figure(f"Fig 10({tag}): RPsD loop poles, physical mass = "
                                   f"{'modelled mass' if tag == 'b' else '2 % of modelled mass (140 kg)'} "
                                   "(linear analysis, 68 + 11.2 ms leads)", figsize=(8, 6))
        for (opt, kw), color in zip(an.fig10_variants(lin, mass).items(), ("k", "C3", "C1", "C2", "C0")):
            s = an.rpsd_loop(lin, M_M, C_M, physical_mass=mass, **kw)
            modes[(tag, opt)] = an.structural_mode(s, w_n)
            plots.pole_zero(ax[0, 0], s[0, 0], f"f = {opt.replace('_', ' ')}", color, xlim=(-6, 3), ylim=(-2, 16))
        ax[0, 0].legend(fontsize=7, ncol=2)
        ctx.figures.append(plots.save(fig, ctx.out / f"fig10{tag}_pole_zero.png"))
    fb, fc_ = modes[("b", "measured_force")], modes[("b", "force_corrected")]
    ctx.rows.append(_row("force_direct", "10b", "using the force measurement directly changes the structural response "
                         "dramatically", "dramatic change", f"{fb[0]:.2f} Hz, zeta {100 * fb[1]:.1f} % vs corrected "
                         f"{fc_[0]:.2f} Hz, zeta {100 * fc_[1]:.1f} %", "frequency shift > 10 %",
                         abs(fb[0] / fc_[0] - 1) * 100, 10.0, math.inf))
    fd = modes[("b", "force_minus_inertia")]
    ctx.rows.append(_row("damping_term", "10b", "keeping the damping term in the restoring force changes the damping",
                         "incorrect damping", f"zeta {100 * fd[1]:.2f} % vs {100 * fc_[1]:.2f} % corrected",
                         "> 0.5 percentage point", 100 * abs(fd[1] - fc_[1]), 0.5, math.inf))
    fp = modes[("b", "force_minus_inertia_damping")]
    ctx.rows.append(_row("piston_inertia", "10b", "ignoring the 54 kg piston in the inertial term slightly changes the "
                         "dominant frequency", "slight change", f"{fp[0]:.4f} Hz vs {fc_[0]:.4f} Hz",
                         "0 < |shift| < 2 %", 100 * abs(fp[0] / fc_[0] - 1), 1e-6, 2.0))
    fbc, fcc = modes[("c", "measured_force")], modes[("c", "force_corrected")]
    ratio = abs(fbc[0] / fcc[0] - 1) / abs(fb[0] / fc_[0] - 1)
    ctx.rows.append(_row("substructure_140kg", "10c", "with 2 % installed mass (140 kg) the effect of the inertial "
                         "term is greatly reduced", "greatly reduced",
                         f"frequency shift {100 * abs(fbc[0] / fcc[0] - 1):.1f} % vs "
                         f"{100 * abs(fb[0] / fc_[0] - 1):.1f} % at full mass", "shift ratio < 0.25", ratio,
                         0.0, 0.25))


# --------------------------------------------------------------------------- Figs 3(b), 4(b, c): EFT loops
def _with_effects(rig: Rig, **switches: bool) -> Rig:
    """A copy of ``rig`` with some effect switches changed."""
    r = copy_rig(rig)
    e = r.effects
    for name, on in switches.items():
        setattr(e, name, on)
    r.effects = e
    return r


def _eft_frf(rig: Rig, amplitude: float, duration: float = SWEEP_DURATION_METHODS, **kw):
    """EFT run on a 0-10 Hz effective-force sweep (excitations.sine_sweep) and its Fourier-amplitude
    ratio |F/P| over 0.3-10 Hz.  Returns (f [Hz], |F/P| [-], P [N], MethodResult)."""
    from . import excitations as ex
    from .methods import run_eft
    from .signals import fourier_ratio

    P = ex.sine_sweep(amplitude, duration=duration, dt=DT)
    res = run_eft(rig, effective_force=P, dt=DT, raise_on_failure=False, **kw)
    f, H = fourier_ratio(res.force, P, DT)
    b = (f > 0.3) & (f < 10.0)
    return f[b], H[b], P, res


def _eft_critical_lead(rig: Rig) -> float:
    """Smallest EFT lead time constant [s] at which the linearised velocity-feedback-compensated
    force loop becomes unstable (bisection on the largest real part of its poles), or nan."""
    lin = an.linear_analysis_rig(rig)

    def growth(T: float) -> float:
        s = an.linearize(lin, "force", outputs=("force",),
                         compensators=an.Compensation(velocity_feedback=True, velocity_feedback_T=T))
        return float(np.max(np.real(s.poles())))

    lo, hi = T_EFT, 0.2
    if growth(lo) >= 0 or growth(hi) < 0:
        return math.nan
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if growth(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def _eft_pole_frequency(rig: Rig, T: float | None) -> float:
    """Frequency [Hz] of the structural pole of the linearised EFT loop with lead T (None: no lead)."""
    lin = an.linear_analysis_rig(rig)
    s = an.linearize(lin, "force", outputs=("force",),
                     compensators=an.Compensation(velocity_feedback=True, velocity_feedback_T=T))
    return an.structural_mode(s, an.natural_frequency(rig))[0]


def section_eft(ctx: Context) -> None:
    """Effective force testing with the test-method loop (methods.run_eft): Figs 3(b), 4(a-c) and
    the EFT delay-compensation statements (p. 1782)."""
    rig = ctx.rig
    f_n = an.natural_frequency(rig, an.moving_mass(rig)) / TWO_PI  # structure + piston, attached
    flow_linear = _with_effects(rig, flow_nonlinearity=False)
    lin = _with_effects(rig, flow_nonlinearity=False, load_pressure=False, coulomb_friction=False,
                        spring_softening=False)
    runs = {}
    for key, r, amp, kw in (("none", rig, SWEEP_F, {"compensation": "none"}),
                            ("linear", rig, SWEEP_F, {}),
                            ("linear_fast", rig, SWEEP_F, {"duration": 0.5 * SWEEP_DURATION_METHODS}),
                            ("big_linear", rig, SWEEP_F_LARGE, {}),
                            ("big_linear_flowlin", flow_linear, SWEEP_F_LARGE, {}),
                            ("big_nonlinear", rig, SWEEP_F_LARGE, {"compensation": "nonlinear"}),
                            ("lead0", rig, SWEEP_F, {"lead_T": 0.0}),
                            ("lead12", rig, SWEEP_F, {"lead_T": 0.012}),
                            ("lead40_lin", lin, SWEEP_F, {"lead_T": 0.040}),
                            ("lead40", rig, SWEEP_F, {"lead_T": 0.040})):
        runs[key] = _eft_frf(r, amp, **kw)

    def stats(key: str, band: tuple[float, float] = (0.3, 10.0)):
        f, H, _, res = runs[key]
        s = (f >= band[0]) & (f <= band[1])
        i, j = np.argmin(H[s]), np.argmax(H[s])
        return float(H[s][i]), float(f[s][i]), float(H[s][j]), float(f[s][j]), float(np.max(np.abs(res.spool)))

    sweep = f"0-10 Hz sweep over {SWEEP_DURATION_METHODS:g} s (duration not given in the paper)"
    # Fig 3(b): linear compensation, 2.3 kN.
    mn, fmn, mx, _, spool = stats("linear")
    ctx.rows.append(_row("eft_3b_shallow", "3b", "linear velocity feedback compensation, 2.3 kN: required forces "
                         "applied over the whole range, with a shallow drop", "shallow drop, forces applied 0-10 Hz",
                         f"min |F/P| = {mn:.3f} at {fmn:.2f} Hz, max {mx:.3f} (0.3-10 Hz; {sweep}; no "
                         f"compensation: min {stats('none')[0]:.3f})",
                         "shallow: 0.80 <= min |F/P| < 0.97", mn, 0.80, 0.97))
    ctx.rows.append(_row("eft_3b_band", "3b", "the shallow drop lies between 1 and 4 Hz", "1-4 Hz",
                         f"minimum at {fmn:.2f} Hz", "1-4 Hz", fmn, 1.0, 4.0))
    spool_fast = stats("linear_fast")[4]
    ctx.rows.append(_row("eft_3b_spool", "3b / p. 1780", "the 2.3 kN test needs a small spool opening",
                         "less than 10 %", f"{100 * spool:.1f} % ({sweep}); {100 * spool_fast:.1f} % over "
                         f"{0.5 * SWEEP_DURATION_METHODS:g} s", "< 10 %", 100 * spool, 0.0, 10.0,
                         "the spool opening follows the structure's velocity at resonance, which grows with the "
                         "time the sweep spends near 1.58 Hz: the paper does not give the sweep duration, and a "
                         f"{0.5 * SWEEP_DURATION_METHODS:g} s sweep stays below 10 %. The finding (inside or near "
                         "the linear range of the flow curve, so linear compensation works) holds", 10.0))

    # Fig 4(b), (c): 8.9 kN.
    mn_b, fmn_b, _, _, sp_b = stats("big_linear")
    mn_bl, fmn_bl, _, _, sp_bl = stats("big_linear_flowlin")
    mn_c, fmn_c, mx_c, _, sp_c = stats("big_nonlinear")
    ctx.rows.append(_row("eft_4b_drop", "4b", "8.9 kN with linear compensation: sharp drop at the natural frequency",
                         "sharp drop at f_n", f"min |F/P| = {mn_b:.3f} at {fmn_b:.2f} Hz (f_n = {f_n:.3f} Hz), "
                         f"spool {100 * sp_b:.0f} %", "sharp: min |F/P| < 0.70, within f_n +- 0.2 Hz",
                         mn_b if abs(fmn_b - f_n) <= 0.2 else math.nan, 0.0, 0.70))
    ctx.rows.append(_row("eft_4b_flow_model", "4b", "the simulation with the nonlinear flow model explains the drop; "
                         "with a linear flow model it does not", "nonlinear flow model needed",
                         f"flow curve linear (load pressure kept): min |F/P| = {mn_bl:.3f} at {fmn_bl:.2f} Hz, "
                         f"spool {100 * sp_bl:.0f} %; preset's curve: {mn_b:.3f}",
                         "no sharp drop without the flow nonlinearity: min |F/P| >= 0.70", mn_bl, 0.70, math.inf))
    ctx.rows.append(_row("eft_4c_nonlinear", "4c", "nonlinear velocity feedback compensation (inverse flow curve and "
                         "load pressure) greatly improves the applied force", "greatly improved",
                         f"min |F/P| = {mn_c:.3f} at {fmn_c:.2f} Hz, max {mx_c:.3f} (linear comp.: {mn_b:.3f}), "
                         f"spool {100 * sp_c:.0f} %", "no sharp drop: 0.80 <= min |F/P|, max <= 1.2",
                         mn_c if mx_c <= 1.2 else math.nan, 0.80, math.inf))

    # EFT delay compensation, p. 1782 (simulations in the paper).
    _, _, pk0, fpk0, _ = stats("lead0", (0.5, 5.0))
    _, _, pk12, fpk12, _ = stats("lead12", (0.5, 5.0))
    fp = {T: _eft_pole_frequency(rig, T) for T in (None, T_EFT, 0.012)}
    ctx.rows.append(_row("eft_under", "p. 1782", "under-compensated delay (no lead): force peak below the natural "
                         "frequency", "peak below f_n", f"peak |F/P| = {pk0:.2f} at {fpk0:.2f} Hz (f_n = {f_n:.3f} "
                         f"Hz); linear loop's structural pole {fp[None]:.3f} Hz (5 ms: {fp[T_EFT]:.3f} Hz)",
                         "< f_n", fpk0, 0.0, f_n))
    ctx.rows.append(_row("eft_over", "p. 1782", "over-compensated delay (12 ms lead): force peak above the natural "
                         "frequency", "peak above f_n", f"peak |F/P| = {pk12:.2f} at {fpk12:.2f} Hz; linear loop's "
                         f"structural pole {fp[0.012]:.3f} Hz", "> f_n", fpk12, f_n, math.inf))
    T_crit = _eft_critical_lead(rig)
    res40l, res40 = runs["lead40_lin"][3], runs["lead40"][3]
    diverged = bool(np.max(np.abs(res40l.spool)) >= 0.999 * rig.x_v_max)
    ctx.rows.append(_row("eft_over_unstable", "p. 1782", "over-compensation of the delay might lead to instability",
                         "possible instability",
                         f"linearised loop unstable for a lead above {1e3 * T_crit:.1f} ms; 40 ms on the linear "
                         f"model: spool {'saturates' if diverged else 'stays inside'}, max |x| "
                         f"{1e3 * np.max(np.abs(res40l.displacement)):.0f} mm; 40 ms on the full model: max |F/P| "
                         f"{stats('lead40')[2]:.1f}, max |x| {1e3 * np.max(np.abs(res40.displacement)):.0f} mm "
                         "(friction and the flow curve bound the growth within the 20 s record)",
                         "a finite instability threshold above the tuned 5 ms, confirmed by a diverging simulation",
                         1e3 * T_crit if diverged else math.nan, 1e3 * T_EFT, 100.0))
    ctx.notes.append(f"EFT ({sweep}): " + "; ".join(
        f"{k}: min |F/P| {stats(k)[0]:.3f} at {stats(k)[1]:.2f} Hz, max {stats(k)[2]:.3f} at {stats(k)[3]:.2f} Hz, "
        f"spool {100 * stats(k)[4]:.1f} %" for k in runs))

    # Figure 3(b).
    fig, axes = plots.new_figure(f"Fig 3(b): EFT, 2.3 kN sine sweep 0-10 Hz ({SWEEP_DURATION_METHODS:g} s), "
                                 "velocity feedback compensation", 2, 1, figsize=(8, 6.5))
    for key, label, color in (("none", "no compensation (Fig 3a)", "0.6"),
                              ("linear", "linear compensation + 5 ms lead", "C0")):
        f, H, _, res = runs[key]
        axes[0, 0].plot(f, H, color=color, label=label)
        axes[1, 0].plot(res.time, 100 * res.spool, color=color, lw=0.5, label=label)
    axes[0, 0].axvline(f_n, color="C3", lw=0.6, label=f"f_n = {f_n:.2f} Hz")
    axes[0, 0].set_xlabel("frequency [Hz]")
    axes[0, 0].set_ylabel("|applied / effective force| [-]")
    axes[1, 0].axhline(10, color="C3", lw=0.6, ls="--")
    axes[1, 0].axhline(-10, color="C3", lw=0.6, ls="--", label="+-10 % opening")
    axes[1, 0].set_xlabel("time [s] (frequency rises linearly 0 -> 10 Hz)")
    axes[1, 0].set_ylabel("spool opening [%]")
    for a in axes.ravel():
        a.legend(fontsize=8)
        a.grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig3b_compensated_eft.png"))

    # Figures 4(b), 4(c).
    for name, title, keys in (
            ("fig4b_eft_8.9kN_linear.png", "Fig 4(b): EFT 8.9 kN, linear velocity feedback compensation",
             (("big_linear", "preset flow curve (nonlinear) + load pressure", "C0"),
              ("big_linear_flowlin", "linear flow curve, load pressure kept", "0.5"))),
            ("fig4c_eft_8.9kN_nonlinear.png", "Fig 4(c): EFT 8.9 kN, nonlinear velocity feedback compensation",
             (("big_nonlinear", "nonlinear compensation", "C0"),
              ("big_linear", "linear compensation (Fig 4b)", "0.6")))):
        fig, axes = plots.new_figure(title + f" (sweep 0-10 Hz, {SWEEP_DURATION_METHODS:g} s)", 2, 1,
                                     figsize=(8, 6.5))
        for key, label, color in keys:
            f, H, P, res = runs[key]
            axes[0, 0].plot(f, H, color=color, label=label)
            axes[1, 0].plot(res.time, res.force / 1e3, color=color, lw=0.4, label=f"load-cell force, {label}")
        axes[1, 0].plot(runs[keys[0][0]][3].time, runs[keys[0][0]][2] / 1e3, color="k", lw=0.3, alpha=0.5,
                        label="effective force P_eff")
        axes[0, 0].axvline(f_n, color="C3", lw=0.6, label=f"f_n = {f_n:.2f} Hz")
        axes[0, 0].set_xlabel("frequency [Hz]")
        axes[0, 0].set_ylabel("|applied / effective force| [-]")
        axes[1, 0].set_xlabel("time [s]")
        axes[1, 0].set_ylabel("force [kN]")
        for a in axes.ravel():
            a.legend(fontsize=7)
            a.grid(True, lw=0.3)
        ctx.figures.append(plots.save(fig, ctx.out / name))

    fig, ax = plots.new_figure("EFT delay compensation (p. 1782): lead time constant of the velocity feedback")
    for key, label, color in (("lead0", "no lead (under-compensated)", "C1"), ("linear", "5 ms (tuned)", "C0"),
                              ("lead12", "12 ms (over-compensated)", "C2")):
        f, H, _, _ = runs[key]
        s = (f > 0.5) & (f < 5.0)
        ax[0, 0].plot(f[s], H[s], color=color, label=label)
    ax[0, 0].axvline(f_n, color="C3", lw=0.6, label=f"f_n = {f_n:.2f} Hz")
    ax[0, 0].set_xlabel("frequency [Hz]")
    ax[0, 0].set_ylabel("|applied / effective force| [-]")
    ax[0, 0].legend(fontsize=8)
    ax[0, 0].grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "eft_delay_compensation.png"))


# --------------------------------------------------------------------------- Figs 8-10(a): RPsD loops
def section_rpsd(ctx: Context) -> None:
    """Real-time pseudodynamic tests with the test-method loop (methods.run_rpsd): delay compensation
    (Fig 8), free vibration with calculated / measured displacements (Fig 9), measured force vs
    restoring force (Fig 10a)."""
    from . import excitations as ex
    from .methods import run_rpsd
    from .signals import identify_free_vibration

    rig = ctx.rig
    k = rig.k
    w_n = math.sqrt(k / M_M)
    z_model = C_M / (2.0 * math.sqrt(k * M_M))
    ramp, hold, free, fit = 5.0, 1.0, 25.0, 4.0
    x_rel = 0.016  # release displacement of Fig 9 [m]
    pe = ex.ramp_and_release(k * x_rel, ramp, hold, free, dt=DT)
    i0 = ex.release_index(ramp, hold, dt=DT)
    t = np.arange(pe.size) * DT
    tr = t - t[i0]  # time after release [s]
    lin = an.linear_analysis_rig(rig)
    comp = an.phase_lead(T_AMP) * an.G_xu(lin) * an.zoh_delay(DT)
    T_zero = an.delay_compensation_T(0.0, T_AMP, comp, 1.58)  # the rule that gave the paper 11.2 ms
    err = np.where(tr >= 0.0, 30.0 * np.sin(w_n * tr - math.pi / 2), 0.0)  # Fig 9b, 0.03 kN

    def fv(**kw):
        res = run_rpsd(rig, external_force=pe, dt=DT, m_m=M_M, c_m=C_M, raise_on_failure=False, **kw)
        return res, identify_free_vibration(res.calc_displacement, DT, start=i0, duration=fit)

    T_list = (0.006, T_LD, 0.016, 0.020)
    runs = {T: fv(delay_T=T) for T in T_list}
    runs["a"] = fv(restoring_force="calculated_displacement")
    runs["err"] = fv(delay_T=T_LD, restoring_force_error=err)
    runs["zero"] = fv(delay_T=T_zero)
    runs["zero_err"] = fv(delay_T=T_zero, restoring_force_error=err)
    zeta = {T: runs[T][1].damping_ratio for T in T_list}

    # Fig 8: free-vibration damping vs T_ld (the comparison the 0.15 g sweep cannot give, see below).
    ctx.rows.append(_row("sim_undercompensated_6ms", "8a", "6 ms delay compensation: negative damping, the response "
                         "becomes unstable (simulation of the full model, free vibration from 1.6 cm)", "unstable",
                         f"zeta = {100 * zeta[0.006]:+.2f} % (fit over {fit:g} s after release); "
                         f"{'; '.join(runs[0.006][0].warnings[:1]) or 'no limit reached'} (record time, released "
                         f"at t = {ramp + hold:g} s)", "zeta < 0",
                         zeta[0.006], -math.inf, 0.0))
    why_delay = (f"the model's residual loop delay after the 68 ms lead is larger than the paper's 13 ms: zero "
                 f"residual phase at 1.58 Hz needs T_ld = {1e3 * T_zero:.1f} ms, which gives zeta = "
                 f"{100 * runs['zero'][1].damping_ratio:+.2f} % (rows T_ld_final, compensated_11ms; "
                 "docs/calibration.md s. 4, docs/methods.md)")
    ctx.rows.append(_row("sim_compensated_11ms", "9b", "11.2 ms: damping only slightly different from the model's "
                         f"{100 * z_model:.2f} % (simulation of the full model)", f"~{100 * z_model:.2f} %",
                         f"zeta = {100 * zeta[T_LD]:+.2f} %", "within +-1 percentage point of the model",
                         100 * zeta[T_LD], 100 * z_model - 1, 100 * z_model + 1, why_delay, 100 * z_model))
    ctx.rows.append(_row("sim_overcompensated_16ms", "8b", "16 ms: over-compensation increases the damping above the "
                         "model's (simulation of the full model)", f"> {100 * z_model:.2f} %",
                         "zeta = " + ", ".join(f"{100 * zeta[T]:+.2f} % ({1e3 * T:g} ms)" for T in T_list),
                         f"> {100 * z_model:.2f} %", 100 * zeta[0.016], 100 * z_model, math.inf,
                         why_delay + "; the trend (damping grows with T_ld) agrees"))

    # Fig 8(a) test itself: 0.15 g ground-acceleration sweep, 0-10 Hz, T_ld = 6 ms.
    ag = ex.sine_sweep(ex.SWEEP_GROUND_ACCELERATION, duration=SWEEP_DURATION_METHODS, dt=DT)
    ts = np.arange(ag.size) * DT
    sw = {T: run_rpsd(rig, ground_acceleration=ag, dt=DT, m_m=M_M, c_m=C_M, delay_T=T, raise_on_failure=False)
          for T in (0.006, 0.016)}
    sdof = ct.tf([1.0], [M_M, C_M, k])  # the solver's model, exact (no servo-system)
    x_exact = ct.forced_response(sdof, ts, -M_M * ag).outputs
    v_exact = np.gradient(x_exact, DT)
    need = rig.A * float(np.max(np.abs(v_exact))) / rig.K_v  # flow needed at the peak velocity, / K_v
    need_open = rig.flow_curve.inverse(min(need, rig.flow_curve.eval(rig.x_v_max)))
    sp = np.abs(sw[0.006].spool)
    i28, isat = np.flatnonzero(sp >= 0.28), np.flatnonzero(sp >= 0.999 * rig.x_v_max)
    t28 = ts[i28[0]] if i28.size else math.nan
    tsat = ts[isat[0]] if isat.size else math.nan
    fsw = ex.sweep_frequency
    ctx.rows.append(_row("spool_28", "8a / p. 1787", "maximum spool opening in the Fig 8(a) test (0-10 Hz, 0.15 g "
                         "ground-acceleration sweep, T_ld = 6 ms)", "28 %",
                         f"{100 * sp.max():.0f} % in our Fig 8(a) run (RPsD, measured displacement, 68 ms + 6 ms "
                         f"leads, full model, 0.15 g sweep 0-10 Hz over {SWEEP_DURATION_METHODS:g} s): 28 % passed "
                         f"at t = {t28:.2f} s ({fsw(t28, duration=SWEEP_DURATION_METHODS):.2f} Hz), fully open at "
                         f"t = {tsat:.2f} s ({fsw(tsat, duration=SWEEP_DURATION_METHODS):.2f} Hz); 16 ms: "
                         f"{100 * np.max(np.abs(sw[0.016].spool)):.0f} %", "28 +- 5 %", 100 * sp.max(), 23.0, 33.0,
                         f"the solver's own SDOF (zeta {100 * z_model:.2f} %) answers this sweep with a peak of "
                         f"{1e3 * np.max(np.abs(x_exact)):.0f} mm and {np.max(np.abs(v_exact)):.2f} m/s (exact, no "
                         f"servo-system), which needs g(x_v) = A v / K_v = {need:.2f}, i.e. "
                         f"{100 * need_open:.0f} % opening even at zero load pressure; the 28 % is passed near "
                         "resonance for every T_ld, before the delay compensation matters. The paper gives neither "
                         "the sweep duration nor when the unstable test was stopped, so its 28 % cannot be "
                         "reproduced; the damping comparison is made on the free vibration (rows above)", 28.0))
    ctx.notes.append(f"Fig 8a run: 0.15 g sweep, T_ld 6 ms: {'; '.join(sw[0.006].warnings)}; T_ld 16 ms: "
                     f"{'; '.join(sw[0.016].warnings)}")

    # Fig 9(a): calculated displacements for the restoring force.
    res_a, fv_a = runs["a"]
    fv_meas = identify_free_vibration(res_a.displacement, DT, start=i0, duration=fit)
    x0, v0 = res_a.calc_displacement[i0], res_a.calc_velocity[i0]
    wd = w_n * math.sqrt(1 - z_model**2)
    ta = tr[i0:]
    x_ex = np.exp(-z_model * w_n * ta) * (x0 * np.cos(wd * ta) + (v0 + z_model * w_n * x0) / wd * np.sin(wd * ta))
    e_calc = float(np.max(np.abs(res_a.calc_displacement[i0:] - x_ex)) / abs(x0))
    ctx.rows.append(_row("fig9a_structural", "9a", "calculated displacements for the restoring force: the "
                         "servo-system does not affect the structural response", f"zeta = model "
                         f"{100 * z_model:.2f} %", f"zeta = {100 * fv_a.damping_ratio:.3f} %, f_d = "
                         f"{fv_a.frequency:.4f} Hz; max |x_calc - exact| = {100 * e_calc:.4f} % of 16 mm",
                         "+-0.05 percentage point of c_m / (2 sqrt(k m_m))", 100 * fv_a.damping_ratio,
                         100 * z_model - 0.05, 100 * z_model + 0.05,
                         "with calculated displacements the solver runs open loop, so this checks the loop's "
                         "wiring and the central-difference solver against the closed form", 100 * z_model))
    amp_ratio = fv_meas.amplitude / fv_a.amplitude
    lag = ((np.angle(np.sum(res_a.calc_displacement[i0:i0 + 8000] * np.exp(-1j * 2 * math.pi * fv_a.frequency
                                                                              * ta[:8000])))
            - np.angle(np.sum(res_a.displacement[i0:i0 + 8000] * np.exp(-1j * 2 * math.pi * fv_a.frequency
                                                                          * ta[:8000])))) % (2 * math.pi))
    ctx.rows.append(_row("fig9a_tracking", "9a", "the measured response follows the expected (calculated) response "
                         "closely with the 68 ms amplitude compensation", "follows closely",
                         f"amplitude ratio measured / calculated = {amp_ratio:.3f}, lag "
                         f"{1e3 * lag / (2 * math.pi * fv_a.frequency):.1f} ms", "amplitude within +-5 % (the "
                         "Fig 6a tolerance)", amp_ratio, 0.95, 1.05,
                         "the lag is the residual delay after the 68 ms lead (see the delay rows)", 1.0))

    # Fig 9(b): restoring-force error 0.03 sin(w_n t - pi/2) kN.
    def envelope(x, a, b):
        s = (tr >= a) & (tr < b)
        return float(np.max(np.abs(x[s])))

    def growth(res, start=10.0):
        x = res.calc_displacement
        return envelope(x, start + 5, start + 10) / envelope(x, start, start + 5)

    g_err, g_no = growth(runs["err"][0]), growth(runs[T_LD][0])
    g_zero_err, g_zero = growth(runs["zero_err"][0]), growth(runs["zero"][0])
    g_late = growth(runs["zero_err"][0], 15.0)
    a_late = envelope(runs["zero_err"][0].calc_displacement, 20.0, 25.0)
    a_late_no = envelope(runs["zero"][0].calc_displacement, 20.0, 25.0)
    z_zero = runs["zero"][1].damping_ratio
    a_ss = 30.0 / (2 * max(z_zero, 1e-9) * k)
    a_10 = x_rel * math.exp(-z_zero * w_n * 10.0)
    ctx.rows.append(_row("fig9b_error_11ms", "9b", "a restoring-force error 0.03 sin(w_n t - pi/2) kN makes the "
                         "amplitude constant after 10 s (T_ld = 11.2 ms; t and the 10 s counted from release)",
                         "constant amplitude after 10 s",
                         f"envelope ratio 15-20 s / 10-15 s after release = {g_err:.3g} with the error, "
                         f"{g_no:.3g} without: {'grows' if g_err > 1.25 else 'bounded'} "
                         f"({'; '.join(runs['err'][0].warnings[:1]) or 'no limits reached'}; record time, "
                         f"released at t = {ramp + hold:g} s)",
                         "ratio within 0.8-1.25", g_err, 0.8, 1.25,
                         f"at 11.2 ms our loop has negative net damping ({100 * zeta[T_LD]:+.2f} %), so the free "
                         "vibration grows with or without the error; see the delay rows and the next row"))
    ctx.rows.append(_row("fig9b_error_equivalent", "9b", "the same error with the delay compensation that gives "
                         f"our loop the paper's near-model damping (T_ld = {1e3 * T_zero:.1f} ms, zero residual "
                         "phase at 1.58 Hz)", "constant amplitude after 10 s",
                         f"envelope ratio 15-20 s / 10-15 s = {g_zero_err:.2f} with the error ({g_zero:.2f} "
                         f"without, zeta {100 * z_zero:+.2f} %); 20-25 s / 15-20 s = {g_late:.2f}, amplitude "
                         f"{1e3 * a_late:.2f} mm at 20-25 s ({1e3 * a_late_no:.2f} mm without the error) vs "
                         f"steady state 30 N / (2 zeta k) = {1e3 * a_ss:.2f} mm", "ratio within 0.8-1.25",
                         g_zero_err, 0.8, 1.25,
                         "the mechanism is confirmed (a force error at the structure's frequency sustains an "
                         "amplitude of order F/(2 zeta k), whatever its phase) but not the timing: from 16 mm at zeta "
                         f"{100 * z_zero:.2f} % the free decay is still {1e3 * a_10:.2f} mm at 10 s, above the "
                         f"{1e3 * a_ss:.2f} mm the error sustains. The same holds for any zeta near the model's "
                         "2.48 %; the paper's time origin in Fig 9b is not stated"))

    # Fig 10(a): load-cell force vs restoring force k x, calculated displacements (Fig 9a test).
    s = (tr >= 0) & (tr < fit)
    F, kx = res_a.force, k * res_a.displacement

    def rms(y: np.ndarray) -> float:
        return float(np.sqrt(np.mean(y[s] ** 2)))

    d_kx = rms(F - kx) / rms(kx)
    d_in = float(np.sqrt(np.mean((F - pe) ** 2)) / np.max(np.abs(pe)))
    ctx.rows.append(_row("fig10a_force_vs_kx", "10a", "the load-cell reading is vastly different from the restoring "
                         "force k x (calculated displacements, free vibration)", "vastly different",
                         f"rms(F - k x) / rms(k x) = {d_kx:.2f} over {fit:g} s after release", "> 0.5", d_kx, 0.5,
                         math.inf))
    ctx.rows.append(_row("fig10a_force_vs_input", "10a", "the measured force should be the force input to the SDOF "
                         "solver (external force), as the paper's simulation shows", "measured force = solver input",
                         f"rms(F - P_ext) = {100 * d_in:.1f} % of the 11.2 kN peak over the whole record",
                         "< 10 % of the peak input", 100 * d_in, 0.0, 10.0))

    # Figures.
    for name, T, title in (("fig8a_rpsd_6ms.png", 0.006, "Fig 8(a): RPsD, delay compensation T_ld = 6 ms"),
                           ("fig8b_rpsd_16ms.png", 0.016, "Fig 8(b): RPsD, delay compensation T_ld = 16 ms")):
        fig, axes = plots.new_figure(title + " (68 ms amplitude compensation, full model)", 2, 1, figsize=(8, 7))
        r = sw[T]
        axes[0, 0].plot(ts, 1e3 * r.calc_displacement, color="C0", lw=0.6, label="calculated (solver)")
        axes[0, 0].plot(ts, 1e3 * r.displacement, color="C1", lw=0.6, label="measured (LVDT)")
        axes[0, 0].plot(ts, 1e3 * x_exact, "k--", lw=0.6, label="exact SDOF, no servo-system")
        axes[0, 0].set_ylim(-200, 200)
        axes[0, 0].set_xlabel(f"time [s] (0.15 g ground-acceleration sweep 0-10 Hz over "
                              f"{SWEEP_DURATION_METHODS:g} s)")
        axes[0, 0].set_ylabel("displacement [mm] (clipped at +-200)")
        ax2 = axes[0, 0].twinx()
        ax2.plot(ts, 100 * np.abs(r.spool), color="C3", lw=0.4, alpha=0.6)
        ax2.axhline(28, color="C3", ls=":", lw=0.8)
        ax2.set_ylabel("|spool opening| [%] (red; dotted: paper's 28 %)")
        r2 = runs[T][0]
        axes[1, 0].plot(tr, 1e3 * r2.calc_displacement, color="C0", lw=0.7, label="calculated (solver)")
        axes[1, 0].plot(tr, 1e3 * r2.displacement, color="C1", lw=0.5, label="measured (LVDT)")
        axes[1, 0].set_xlim(-1, 10)
        axes[1, 0].set_ylim(-50, 50)
        axes[1, 0].set_xlabel(f"time after release [s] (free vibration from 1.6 cm; zeta = "
                              f"{100 * zeta[T]:+.2f} %, model {100 * z_model:.2f} %)")
        axes[1, 0].set_ylabel("displacement [mm]")
        for a in axes.ravel():
            a.legend(fontsize=7, loc="upper left")
            a.grid(True, lw=0.3)
        ctx.figures.append(plots.save(fig, ctx.out / name))

    fig, ax = plots.new_figure("Figs 8, 9(b): damping of the RPsD free vibration vs delay compensation T_ld")
    Tg = np.linspace(0.004, 0.024, 11)
    z_lin = [an.structural_mode(an.rpsd_loop(lin, M_M, C_M, delay_T=T), an.natural_frequency(rig))[1] for T in Tg]
    ax[0, 0].plot(1e3 * Tg, 100 * np.array(z_lin), "k--", lw=0.8, label="linear analysis (rpsd_loop)")
    ax[0, 0].plot([1e3 * T for T in T_list] + [1e3 * T_zero], [100 * zeta[T] for T in T_list]
                  + [100 * z_zero], "o", color="C0", label="simulation, full model (fit to free vibration)")
    ax[0, 0].axhline(100 * z_model, color="C3", lw=0.6, label=f"model zeta = {100 * z_model:.2f} %")
    ax[0, 0].axhline(0.0, color="k", lw=0.5)
    for T, lab in ((6, "6 ms (8a)"), (11.2, "11.2 ms (paper)"), (16, "16 ms (8b)")):
        ax[0, 0].axvline(T, color="0.6", lw=0.5)
        ax[0, 0].annotate(lab, (T, ax[0, 0].get_ylim()[0]), fontsize=7, rotation=90, va="bottom")
    ax[0, 0].set_xlabel("delay compensation T_ld [ms]")
    ax[0, 0].set_ylabel("damping ratio of the structural response [%]")
    ax[0, 0].legend(fontsize=8)
    ax[0, 0].grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig8_damping_vs_T_ld.png"))

    fig, axes = plots.new_figure("Fig 9: free vibration in displacement control (release from 1.6 cm)", 3, 1,
                                 figsize=(8, 9), sharex=True)
    for a, (key, label) in zip(axes[:, 0], (
            ("a", "(a) calculated displacements for the restoring force, no delay compensation"),
            (T_LD, "(b) measured displacements, T_ld = 11.2 ms; and with the 0.03 kN error"),
            ("zero_err", f"(b) measured displacements, T_ld = {1e3 * T_zero:.1f} ms, with the 0.03 kN error"))):
        r = runs[key][0]
        a.plot(tr, 1e3 * r.calc_displacement, color="C0", lw=0.7, label="calculated")
        a.plot(tr, 1e3 * r.displacement, color="C1", lw=0.5, label="measured")
        if key == "a":
            a.plot(ta, 1e3 * x_ex, "k--", lw=0.6, label="exact SDOF")
        if key == T_LD:
            a.plot(tr, 1e3 * runs["err"][0].calc_displacement, color="C2", lw=0.5, label="calculated, with error")
        a.set_ylim(-25, 25)
        a.set_title(label, fontsize=9)
        a.set_ylabel("displacement [mm]")
        a.legend(fontsize=7, loc="upper right")
        a.grid(True, lw=0.3)
    axes[-1, 0].set_xlim(-2, free)
    axes[-1, 0].set_xlabel("time after release [s]")
    ctx.figures.append(plots.save(fig, ctx.out / "fig9_free_vibration_rpsd.png"))

    fig, ax = plots.new_figure("Fig 10(a): measured force vs restoring force (calculated displacements)")
    ax[0, 0].plot(tr, F / 1e3, color="C0", lw=0.7, label="load cell F")
    ax[0, 0].plot(tr, kx / 1e3, color="C1", lw=0.7, label="restoring force k x (measured x)")
    ax[0, 0].plot(tr, pe / 1e3, "k--", lw=0.7, label="solver input P_ext")
    ax[0, 0].set_xlim(-6.5, 5)
    ax[0, 0].set_xlabel("time after release [s]")
    ax[0, 0].set_ylabel("force [kN]")
    ax[0, 0].legend(fontsize=8)
    ax[0, 0].grid(True, lw=0.3)
    ctx.figures.append(plots.save(fig, ctx.out / "fig10a_force_vs_restoring.png"))


# --------------------------------------------------------------------------- Table I contradictions
def section_table1(ctx: Context) -> None:
    """The contradictions of Table I as printed, with the calibrated preset beside them."""
    printed = an.linear_analysis_rig(zhao2003("printed"))
    cal = an.linear_analysis_rig(ctx.rig)
    re_p = float(np.max(np.real(an.G_xu(printed).poles())))
    re_c = float(np.max(np.real(an.G_xu(cal).poles())))
    ctx.rows.append(_row("table1_stability", "Table I", "displacement loop stable at G_p = 0.8059 (tests ran)",
                         "stable", f"calibrated: max Re(pole) = {re_c:.2f} rad/s; printed: {re_p:+.2f} rad/s",
                         "max Re(pole) < 0 (calibrated preset)", re_c, -math.inf, 0.0,
                         "Table I as printed (K_a = 3e-12, C_l = 1e-12) is unstable; K_a = 1.36e-12, C_l = 3.4e-11 "
                         "chosen in docs/calibration.md"))
    vt = 4.0 * zhao2003("printed").K_a * 1.0e9 * 1e3
    swept = ctx.rig.A * 0.254 * 1e3
    ctx.rows.append(_row("table1_oil_volume", "Table I",
                         "K_a = V_t/(4 beta_e) consistent with the actuator's oil volume",
                         "K_a = 3e-12 m^5/N", f"printed needs V_t = {vt:.0f} L at 1 GPa vs {swept:.2f} L swept; "
                         f"calibrated: {4 * ctx.rig.K_a * 0.69e9 * 1e3:.1f} L at 0.69 GPa",
                         "V_t within 1-3x the swept volume (calibrated)",
                         4 * ctx.rig.K_a * 0.69e9 * 1e3 / swept, 1.0, 3.0,
                         "printed K_a needs 5.7x the swept volume: rejected (docs/calibration.md s. 1)"))


#: sections in the table's order (the paper's figure order); each is independent of the others
SECTIONS: dict[str, Callable[[Context], None]] = {
    "structure": section_structure,
    "force": section_force,
    "eft": section_eft,
    "displacement": section_displacement,
    "gain_bound": section_gain_bound,
    "rpsd_linear": section_rpsd_linear,
    "rpsd": section_rpsd,
    "table1": section_table1,
}


# --------------------------------------------------------------------------- driver
#: expected relative cost of each section, to hand the longest ones out first
COST = {"eft": 10, "structure": 9, "rpsd": 8, "displacement": 5, "force": 3, "gain_bound": 1, "rpsd_linear": 1,
        "table1": 0}


@dataclass
class Reproduction:
    rows: list
    figures: list
    runtime: float
    section_times: dict  #: wall time of each section in its worker [s]

    @property
    def agree_count(self) -> int:
        return sum(r.agree for r in self.rows)


def write_markdown(rep: Reproduction, path: Path, notes: Sequence[str]) -> Path:
    lines = [
        "# Reproduction of Zhao, French, Shield & Posbergh (2003)",
        "",
        "Generated by `servohydraulics reproduce --out DIR` (python: `sh.reproduce(out=DIR)`).",
        "The paper's measured curves are not available: every row compares with a number or",
        "statement of the paper's text. Rig: calibrated preset `zhao2003()` (docs/calibration.md).",
        "",
        f"**{rep.agree_count} of {len(rep.rows)} rows agree**; runtime {rep.runtime:.1f} s.",
        "",
        "| # | fig. | statement | paper | ours | tolerance | agree | why / note |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for i, r in enumerate(rep.rows, 1):
        lines.append(f"| {i} | {r.figure} | {r.statement} | {r.paper} | {r.ours} | {r.tolerance} | "
                     f"{'yes' if r.agree else '**no**'} | {r.why} |")
    lines += ["", "## Figures", ""] + [f"- `{Path(f).name}`" for f in rep.figures]
    lines += ["", "## Notes", ""] + [f"- {n}" for n in notes]
    lines.append("- section wall times [s]: " + ", ".join(f"{k} {v:.1f}" for k, v in rep.section_times.items()))
    path.write_text("\n".join(lines) + "\n")
    return path


def _run_section(name: str, out: Path, quick: bool, rig: Rig) -> tuple[list, list, list, float]:
    """Runs one section (in a worker process or in-process) -> (rows, figures, notes, wall time [s])."""
    t0 = time.perf_counter()
    ctx = Context(out=out, quick=quick, rig=rig, rows=[], figures=[], notes=[])
    SECTIONS[name](ctx)
    return ctx.rows, ctx.figures, ctx.notes, time.perf_counter() - t0


def reproduce(out: str | Path = "reproduction", quick: bool = False, sections: Sequence[str] | None = None,
              progress: bool = True, rig: Rig | None = None, workers: int = 2) -> Reproduction:
    """Regenerates every figure and ``reproduction.md`` / ``reproduction.json`` in ``out``.

    quick: shorter sweeps in the structure and displacement sections (for tests; the
    test-method sections always use the 20 s sweeps their rows need); sections: subset
    of the section names (default all); rig: default the calibrated preset; workers:
    processes running independent sections at once (1: all in this process).
    """
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from tqdm import tqdm

    t0 = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = list(SECTIONS) if sections is None else list(sections)
    for n in names:
        if n not in SECTIONS:
            raise ValueError(f"invalid section = {n!r}: expected one of {list(SECTIONS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"invalid workers = {workers!r}: must be an integer >= 1")
    rig = rig if rig is not None else zhao2003()
    results: dict = {}
    order = sorted(names, key=lambda n: -COST.get(n, 1))
    with tqdm(total=len(names), desc="reproduce", unit="section", disable=not progress) as bar:
        if workers == 1 or len(names) == 1:
            for n in order:
                results[n] = _run_section(n, out, quick, rig)
                bar.update()
        else:
            with ProcessPoolExecutor(max_workers=min(workers, len(names))) as pool:
                futures = {pool.submit(_run_section, n, out, quick, rig): n for n in order}
                for fut in as_completed(futures):
                    results[futures[fut]] = fut.result()
                    bar.set_postfix_str(futures[fut])
                    bar.update()
    rows, figures, notes = [], [], []
    for n in names:  # the table's order does not depend on which worker finished first
        rows += results[n][0]
        figures += results[n][1]
        notes += results[n][2]
    rep = Reproduction(rows=rows, figures=figures, runtime=time.perf_counter() - t0,
                       section_times={n: results[n][3] for n in names})
    write_markdown(rep, out / "reproduction.md", notes)
    (out / "reproduction.json").write_text(json.dumps(
        {"runtime_s": rep.runtime, "agree": rep.agree_count, "section_times_s": rep.section_times, "rows": [
            {**asdict(r), "agree": r.agree, "lo": _json_num(r.lo), "hi": _json_num(r.hi),
             "our_value": _json_num(r.our_value)} for r in rep.rows],
         "figures": [str(f) for f in rep.figures]}, indent=1))
    return rep


def _json_num(v: float):
    if math.isnan(v):
        return "nan"
    return v if math.isfinite(v) else ("inf" if v > 0 else "-inf")


__all__ = ["Reproduction", "Row", "SECTIONS", "reproduce"]
