"""Claims -> table rows: one small ``value(results)`` function per claim of claims.py.

``results`` maps an experiment's name (a function of experiments.py) to its dataclass.
A value function returns a :class:`Measured`: the number checked, our value in words and,
where the claim's text depends on the rig, the numbers its placeholders need.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import excitations as ex
from .experiments import SWEEP_DURATION, T_EFT, T_LD

TWO_PI = 2.0 * math.pi
SWEEP = f"0-10 Hz sweep over {SWEEP_DURATION:g} s (duration not given in the paper)"


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


@dataclass(frozen=True)
class Measured:
    """Our counterpart of a claim."""

    value: float  #: the number checked (nan: the claim's precondition failed)
    ours: str  #: our value in words, with units
    interval: tuple[float, float] | None = None  #: replaces the claim's where it depends on the results
    fields: dict = field(default_factory=dict)  #: placeholders of the claim's texts
    paper_value: float | None = None  #: replaces the claim's where it is a Table I value of the rig


def row(claim, results: dict) -> Row:
    """The table row of ``claim`` (claims.Claim) from the experiments' ``results``."""
    m = claim.value(results)
    lo, hi = m.interval if m.interval is not None else claim.interval
    fmt = (lambda s: s.format(**m.fields)) if m.fields else (lambda s: s)
    return Row(key=claim.key, figure=claim.figure, statement=fmt(claim.statement), paper=fmt(claim.paper_text),
               ours=m.ours, tolerance=fmt(claim.tolerance_text), our_value=float(m.value), lo=float(lo),
               hi=float(hi), why=fmt(claim.why),
               paper_value=_float_or_none(m.paper_value if m.paper_value is not None else claim.paper_value))


def _float_or_none(v) -> float | None:
    return None if v is None else float(v)


def _identified(est, name: str, unit: str, scale: float, cap: float, paper: float, **fields) -> Measured:
    """An identified parameter: agree when the paper's value lies in our 95 % interval, whose half-width
    is capped at ``cap`` (so a vague estimate cannot agree)."""
    lo, hi = est.interval(name)
    v, lo, hi = scale * getattr(est, name), scale * lo, scale * hi
    hw = min(0.5 * (hi - lo), cap)
    return Measured(v, f"{v:.3f} {unit} (95 %: {lo:.3f}-{hi:.3f})", (paper - hw, paper + hw), fields, paper)


# --------------------------------------------------------------------------- structure (Fig 2b, p. 1779)
def natural_frequency(r) -> Measured:
    f = r["fig2b_free_vibration"].natural_frequency
    return Measured(f, f"{f:.3f} Hz (sqrt(k/m))")


def zeta_free(r) -> Measured:
    fv = r["fig2b_free_vibration"]
    z = 100 * fv.zeta_table
    return _identified(fv.estimate, "zeta", "%", 100.0, 0.1, z, zeta=z, c=fv.c_table)


def friction_free(r) -> Measured:
    return _identified(r["fig2b_free_vibration"].estimate, "F_c", "N", 1.0, 5.0, 95.7)


def crossing_frequency(r) -> Measured:
    f = r["fig2b_free_vibration"].crossing_frequency
    return Measured(f, f"{f:.3f} Hz (zero crossings)")


def zeta_attached(r) -> Measured:
    fv = r["forced_vibration"]
    z = 100 * fv.zeta_table
    return _identified(fv.estimate, "zeta", "%", 100.0, 0.2, z, zeta=z, c=fv.c_table)


def friction_attached(r) -> Measured:
    return _identified(r["forced_vibration"].estimate, "F_c", "N", 1.0, 5.0, 31.6)


def equivalent_damping(r) -> Measured:
    e = r["equivalent_damping"]
    z = 100 * e.zeta_attached
    return Measured(z, f"1.1 % -> {z:.2f} % (at X = {1e3 * e.amplitude:.1f} mm)")


# --------------------------------------------------------------------------- force control (Figs 3a, 4a, Eq 11)
def eft_drop(r) -> Measured:
    d = r["fig3a_direct_eft"]
    return Measured(d.min_frequency, f"minimum of |F/u| at {d.min_frequency:.2f} Hz (simulated sweep), "
                    f"{d.min_frequency_eq9:.2f} Hz (Eq 9); |F/u| = {d.min_gain:.2f}")


def eft_rolloff(r) -> Measured:
    b = r["eq11_force_loop"]
    return Measured(b.rolloff_hz, f"{b.rolloff_hz:.1f} Hz",
                    fields={"printed": b.rolloff_printed_hz, "gp_120": b.gain_for_120hz})


def piston_mass(r) -> Measured:
    b = r["eq11_force_loop"]
    return Measured(100 * b.piston_fraction, f"{b.piston_mass:.0f} kg, {100 * b.piston_fraction:.2f} %")


def flow_curve(r) -> Measured:
    c = r["fig4a_flow_curve"]
    dev10 = 100 * c.linear_deviation_10
    ok = c.non_increasing and c.slope[-1] < c.slope[0]
    return Measured(dev10 if ok else math.nan,
                    f"g(0.1)/0.1 - 1 = {dev10:+.2f} %; gain dg/dx {c.gain_at[0.05]:.2f} at 5 %, "
                    f"{c.gain_at[0.5]:.2f} at 50 %, {c.gain_at[0.95]:.2f} at 95 %; g(1) = {c.g_full:.2f}; "
                    f"gain never increases: {c.non_increasing}")


# --------------------------------------------------------------------------- EFT loops (Figs 3b, 4b, 4c, p. 1782)
def eft_3b_shallow(r) -> Measured:
    e = r["fig3_eft"]
    mn, fmn, mx, _, _ = e.runs["linear"].stats()
    return Measured(mn, f"min |F/P| = {mn:.3f} at {fmn:.2f} Hz, max {mx:.3f} (0.3-10 Hz; {SWEEP}; no "
                    f"compensation: min {e.runs['none'].stats()[0]:.3f})")


def eft_3b_band(r) -> Measured:
    fmn = r["fig3_eft"].runs["linear"].stats()[1]
    return Measured(fmn, f"minimum at {fmn:.2f} Hz")


def eft_3b_spool(r) -> Measured:
    e = r["fig3_eft"]
    spool, fast = e.runs["linear"].stats()[4], e.runs["linear_fast"].stats()[4]
    return Measured(100 * spool, f"{100 * spool:.1f} % ({SWEEP}); {100 * fast:.1f} % over "
                    f"{0.5 * SWEEP_DURATION:g} s", fields={"fast": 0.5 * SWEEP_DURATION})


def eft_4b_drop(r) -> Measured:
    e = r["fig3_eft"]
    mn, fmn, _, _, sp = e.runs["big_linear"].stats()
    f_n = e.natural_frequency
    return Measured(mn if abs(fmn - f_n) <= 0.2 else math.nan,
                    f"min |F/P| = {mn:.3f} at {fmn:.2f} Hz (f_n = {f_n:.3f} Hz), spool {100 * sp:.0f} %")


def eft_4b_flow_model(r) -> Measured:
    e = r["fig3_eft"]
    mn, fmn, _, _, sp = e.runs["big_linear_flowlin"].stats()
    return Measured(mn, f"flow curve linear (load pressure kept): min |F/P| = {mn:.3f} at {fmn:.2f} Hz, "
                    f"spool {100 * sp:.0f} %; preset's curve: {e.runs['big_linear'].stats()[0]:.3f}")


def eft_4c_nonlinear(r) -> Measured:
    e = r["fig3_eft"]
    mn, fmn, mx, _, sp = e.runs["big_nonlinear"].stats()
    return Measured(mn if mx <= 1.2 else math.nan,
                    f"min |F/P| = {mn:.3f} at {fmn:.2f} Hz, max {mx:.3f} (linear comp.: "
                    f"{e.runs['big_linear'].stats()[0]:.3f}), spool {100 * sp:.0f} %")


def eft_under(r) -> Measured:
    e = r["fig3_eft"]
    _, _, pk, fpk, _ = e.runs["lead0"].stats((0.5, 5.0))
    fp = e.pole_frequency
    return Measured(fpk, f"peak |F/P| = {pk:.2f} at {fpk:.2f} Hz (f_n = {e.natural_frequency:.3f} Hz); linear "
                    f"loop's structural pole {fp[None]:.3f} Hz (5 ms: {fp[T_EFT]:.3f} Hz)",
                    (0.0, e.natural_frequency))


def eft_over(r) -> Measured:
    e = r["fig3_eft"]
    _, _, pk, fpk, _ = e.runs["lead12"].stats((0.5, 5.0))
    return Measured(fpk, f"peak |F/P| = {pk:.2f} at {fpk:.2f} Hz; linear loop's structural pole "
                    f"{e.pole_frequency[0.012]:.3f} Hz", (e.natural_frequency, math.inf))


def eft_over_unstable(r) -> Measured:
    e = r["fig3_eft"]
    lin, full = e.runs["lead40_lin"].result, e.runs["lead40"].result
    diverged = bool(np.max(np.abs(lin.spool)) >= 0.999 * e.x_v_max)
    return Measured(1e3 * e.critical_lead if diverged else math.nan,
                    f"linearised loop unstable for a lead above {1e3 * e.critical_lead:.1f} ms; 40 ms on the linear "
                    f"model: spool {'saturates' if diverged else 'stays inside'}, max |x| "
                    f"{1e3 * np.max(np.abs(lin.displacement)):.0f} mm; 40 ms on the full model: max |F/P| "
                    f"{e.runs['lead40'].stats()[2]:.1f}, max |x| {1e3 * np.max(np.abs(full.displacement)):.0f} mm "
                    "(friction and the flow curve bound the growth within the 20 s record)")


def eft_notes(r) -> list[str]:
    e = r["fig3_eft"]
    return [f"EFT ({SWEEP}): " + "; ".join(
        "{}: min |F/P| {:.3f} at {:.2f} Hz, max {:.3f} at {:.2f} Hz, spool {:.1f} %".format(
            k, *s[:4], 100 * s[4]) for k, s in ((k, run.stats()) for k, run in e.runs.items()))]


# --------------------------------------------------------------------------- displacement control (Figs 5, 6a)
def rolloff_eq13(r) -> Measured:
    w = r["fig6a_amplitude_compensation"].omega_c
    return Measured(w / TWO_PI, f"{w / TWO_PI:.3f} Hz")


def delay_eq13(r) -> Measured:
    w = r["fig6a_amplitude_compensation"].omega_c
    return Measured(1e3 / w, f"{1e3 / w:.1f} ms")


def rolloff_identified(r) -> Measured:
    fo = r["fig5_displacement_sweeps"].first_order
    return Measured(fo.roll_off_hz, f"{fo.roll_off_hz:.2f} Hz (fit K/(tau s+1), 0.1-2 Hz, K = {fo.gain:.3f})")


def delay_identified(r) -> Measured:
    tau = r["fig5_displacement_sweeps"].first_order.tau
    return Measured(1e3 * tau, f"{1e3 * tau:.1f} ms")


def loss_2hz(r) -> Measured:
    loss = 100 * (1 - r["fig5_displacement_sweeps"].gain_2hz)
    return Measured(loss, f"{loss:.1f} %")


def oil_column(r) -> Measured:
    d = r["fig6a_amplitude_compensation"]
    f_cl, z_cl = d.closed_loop_mode
    return Measured(z_cl, f"{d.oil_column_hz:.1f} Hz (Eq 14); closed loop {f_cl:.1f} Hz, zeta = {z_cl:.3f}",
                    fields={"printed": d.oil_column_printed_hz})


def T_amplitude(r) -> Measured:
    d = r["fig6a_amplitude_compensation"]
    return Measured(1e3 * d.T_amplitude, f"{1e3 * d.T_amplitude:.1f} ms (worst deviation "
                    f"{100 * d.worst_deviation:.1f} %)")


def band_68ms(r) -> Measured:
    b = r["fig6a_amplitude_compensation"].band_68ms
    return Measured(b, f"{b:.2f} Hz")


def overshoot_5b(r) -> Measured:
    s = r["fig5_displacement_sweeps"]
    return Measured(s.peak_b, f"max |x/u| = {s.peak_b:.3f} over 0.2-5 Hz (linear model: {s.peak_b_linear:.3f})",
                    fields={"linear": s.peak_b_linear, "spool": 100 * s.spool_b, "pressure": 100 * s.pressure_b})


def capacity(r) -> Measured:
    c = r["capacity_limit"]
    ours = (f"supply-pressure limit (|p| >= 0.98 p_s) first reached at {c.limit} Hz, peak load-cell force "
            f"{c.peak_force_at_limit / 1e3:.0f} kN (p_s A = {c.supply_force / 1e3:.0f} kN)" if c.limit
            else "not reached up to 8 Hz")
    return Measured(c.limit if c.limit else 99.0, ours, fields={"grid": c.frequencies[1] - c.frequencies[0]})


# --------------------------------------------------------------------------- Fig 6(b): gain bound
def gp_falls_with_mass(r) -> Measured:
    g = r["fig6b_gain_bound"]
    monotone = bool(np.all(np.diff(g.gain_valve) < 0))
    return Measured(float(monotone and g.eigen_confirmed),
                    f"G_p,max {g.gain_valve[0]:.1f} at 54 kg -> {g.gain_valve[-1]:.2f} at {g.masses[-1]:.0f} kg, "
                    f"monotone: {monotone}; Routh = eigenvalue crossing: {g.eigen_confirmed}")


def gp_used_stable(r) -> Measured:
    g = r["fig6b_gain_bound"]
    return Measured(g.gain_valve[-1], f"G_p,max = {g.gain_valve[-1]:.2f}", (g.gain_used, math.inf),
                    fields={"printed": g.gain_printed})


def gain_bound_notes(r) -> list[str]:
    g = r["fig6b_gain_bound"]
    return ["Fig 6b: " + ", ".join(f"{m:.0f} kg: {v:.3g}" for m, v in zip(g.masses, g.gain_valve))]


# --------------------------------------------------------------------------- RPsD, linear analysis (Figs 8-10)
def _lin(r):
    d = r["fig10_pole_zero"]
    return d, {"z_model": 100 * d.zeta_model, "residual": 1e3 * d.residual_delay}


def T_ld_estimate(r) -> Measured:
    T = r["fig10_pole_zero"].T_estimate
    return Measured(1e3 * T, f"{1e3 * T:.1f} ms")


def T_ld_final(r) -> Measured:
    d, f = _lin(r)
    return Measured(1e3 * d.T_zero_phase, f"{1e3 * d.T_zero_phase:.1f} ms", fields=f)


def undercompensated_6ms(r) -> Measured:
    z = r["fig10_pole_zero"].zeta[0.006]
    return Measured(z, f"net zeta = {100 * z:.2f} % (linear loop)")


def compensated_11ms(r) -> Measured:
    d, f = _lin(r)
    z = 100 * d.zeta_model
    return Measured(100 * d.zeta[T_LD], f"net zeta = {100 * d.zeta[T_LD]:.2f} %", (z - 1, z + 1), f, z)


def overcompensated_16ms(r) -> Measured:
    d, f = _lin(r)
    return Measured(100 * d.zeta[0.016], f"net zeta = {100 * d.zeta[0.016]:.2f} % (vs {100 * d.zeta[T_LD]:.2f} % "
                    "at 11.2 ms)", (100 * d.zeta_model, math.inf), f)


def _shift(a, b) -> float:
    return abs(a[0] / b[0] - 1)


def force_direct(r) -> Measured:
    m = r["fig10_pole_zero"].modes
    fb, fc = m[("b", "measured_force")], m[("b", "force_corrected")]
    return Measured(100 * _shift(fb, fc), f"{fb[0]:.2f} Hz, zeta {100 * fb[1]:.1f} % vs corrected {fc[0]:.2f} Hz, "
                    f"zeta {100 * fc[1]:.1f} %")


def damping_term(r) -> Measured:
    m = r["fig10_pole_zero"].modes
    fd, fc = m[("b", "force_minus_inertia")], m[("b", "force_corrected")]
    return Measured(100 * abs(fd[1] - fc[1]), f"zeta {100 * fd[1]:.2f} % vs {100 * fc[1]:.2f} % corrected")


def piston_inertia(r) -> Measured:
    m = r["fig10_pole_zero"].modes
    fp, fc = m[("b", "force_minus_inertia_damping")], m[("b", "force_corrected")]
    return Measured(100 * _shift(fp, fc), f"{fp[0]:.4f} Hz vs {fc[0]:.4f} Hz")


def substructure_140kg(r) -> Measured:
    m = r["fig10_pole_zero"].modes
    full = _shift(m[("b", "measured_force")], m[("b", "force_corrected")])
    small = _shift(m[("c", "measured_force")], m[("c", "force_corrected")])
    return Measured(small / full, f"frequency shift {100 * small:.1f} % vs {100 * full:.1f} % at full mass")


# --------------------------------------------------------------------------- RPsD loops (Figs 8-10a)
def _fv(r):
    fv = r["fig9_free_vibration"]
    return fv, {"z_model": 100 * fv.zeta_model, "T_zero": 1e3 * fv.T_zero_phase,
                "z_zero": 100 * fv.runs["zero"].fit.damping_ratio}


def _released(fv) -> str:
    return f"record time, released at t = {fv.release.ramp + fv.release.hold:g} s"


def sim_undercompensated_6ms(r) -> Measured:
    fv, f = _fv(r)
    z = fv.zeta[0.006]
    warn = "; ".join(fv.runs[0.006].result.warnings()[:1]) or "no limit reached"
    return Measured(z, f"zeta = {100 * z:+.2f} % (fit over {fv.release.fit:g} s after release); {warn} "
                    f"({_released(fv)})")


def sim_compensated_11ms(r) -> Measured:
    fv, f = _fv(r)
    z = 100 * fv.zeta_model
    return Measured(100 * fv.zeta[T_LD], f"zeta = {100 * fv.zeta[T_LD]:+.2f} %", (z - 1, z + 1), f, z)


def sim_overcompensated_16ms(r) -> Measured:
    fv, f = _fv(r)
    zeta = fv.zeta
    return Measured(100 * zeta[0.016], "zeta = " + ", ".join(f"{100 * z:+.2f} % ({1e3 * T:g} ms)"
                                                              for T, z in zeta.items()),
                    (100 * fv.zeta_model, math.inf), f)


def spool_28(r) -> Measured:
    s, fv = r["fig8_rpsd_delay"], r["fig9_free_vibration"]

    def fsw(t: float) -> float:
        return ex.sweep_frequency(t, duration=SWEEP_DURATION)

    sp = s.spool_max[0.006]
    return Measured(100 * sp, f"{100 * sp:.0f} % in our Fig 8(a) run (RPsD, measured displacement, 68 ms + 6 ms "
                    f"leads, full model, 0.15 g sweep 0-10 Hz over {SWEEP_DURATION:g} s): 28 % passed "
                    f"at t = {s.t28:.2f} s ({fsw(s.t28):.2f} Hz), fully open at t = {s.t_saturated:.2f} s "
                    f"({fsw(s.t_saturated):.2f} Hz); 16 ms: {100 * s.spool_max[0.016]:.0f} %",
                    fields={"z_model": 100 * fv.zeta_model, "x_peak": 1e3 * np.max(np.abs(s.x_exact)),
                            "v_peak": np.max(np.abs(s.v_exact)), "need": s.need, "need_open": 100 * s.need_opening})


def rpsd_notes(r) -> list[str]:
    s = r["fig8_rpsd_delay"]
    return [f"Fig 8a run: 0.15 g sweep, T_ld 6 ms: {'; '.join(s.runs[0.006].warnings())}; T_ld 16 ms: "
            f"{'; '.join(s.runs[0.016].warnings())}"]


def fig9a_structural(r) -> Measured:
    fv, f = _fv(r)
    a = r["fig9a_structural"]
    fit = a.fit_calculated
    return Measured(100 * fit.damping_ratio, f"zeta = {100 * fit.damping_ratio:.3f} %, f_d = {fit.frequency:.4f} Hz; "
                    f"max |x_calc - exact| = {100 * a.max_error:.4f} % of 16 mm",
                    (100 * fv.zeta_model - 0.05, 100 * fv.zeta_model + 0.05), f, 100 * fv.zeta_model)


def fig9a_tracking(r) -> Measured:
    a = r["fig9a_structural"]
    return Measured(a.amplitude_ratio, f"amplitude ratio measured / calculated = {a.amplitude_ratio:.3f}, lag "
                    f"{1e3 * a.lag:.1f} ms")


def fig9b_error_11ms(r) -> Measured:
    fv, f = _fv(r)
    b = r["fig9b_force_error"]
    warn = "; ".join(fv.runs["err"].result.warnings()[:1]) or "no limits reached"
    return Measured(b.growth_err, f"envelope ratio 15-20 s / 10-15 s after release = {b.growth_err:.3g} with the "
                    f"error, {b.growth_no_err:.3g} without: {'grows' if b.growth_err > 1.25 else 'bounded'} "
                    f"({warn}; {_released(fv)})", fields={"z_11": 100 * fv.zeta[T_LD]})


def fig9b_error_equivalent(r) -> Measured:
    fv, f = _fv(r)
    b = r["fig9b_force_error"]
    return Measured(b.growth_zero_err,
                    f"envelope ratio 15-20 s / 10-15 s = {b.growth_zero_err:.2f} with the error ({b.growth_zero:.2f} "
                    f"without, zeta {100 * b.zeta_zero:+.2f} %); 20-25 s / 15-20 s = {b.growth_zero_err_late:.2f}, "
                    f"amplitude {1e3 * b.amplitude_late:.2f} mm at 20-25 s ({1e3 * b.amplitude_late_no_err:.2f} mm "
                    f"without the error) vs steady state 30 N / (2 zeta k) = {1e3 * b.steady_amplitude:.2f} mm",
                    fields={**f, "a_10": 1e3 * b.decay_at_10s, "a_ss": 1e3 * b.steady_amplitude})


def fig10a_force_vs_kx(r) -> Measured:
    d = r["fig10a_force"].force_vs_kx
    return Measured(d, f"rms(F - k x) / rms(k x) = {d:.2f} over {r['fig9_free_vibration'].release.fit:g} s after "
                    "release")


def fig10a_force_vs_input(r) -> Measured:
    d = 100 * r["fig10a_force"].force_vs_input
    return Measured(d, f"rms(F - P_ext) = {d:.1f} % of the 11.2 kN peak over the whole record")


# --------------------------------------------------------------------------- Table I
def table1_stability(r) -> Measured:
    t = r["table1"]
    return Measured(t.max_real_pole_calibrated, f"calibrated: max Re(pole) = {t.max_real_pole_calibrated:.2f} rad/s; "
                    f"printed: {t.max_real_pole_printed:+.2f} rad/s")


def table1_oil_volume(r) -> Measured:
    t = r["table1"]
    return Measured(t.oil_volume_calibrated / t.swept_volume,
                    f"printed needs V_t = {t.oil_volume_printed:.0f} L at 1 GPa vs {t.swept_volume:.2f} L swept; "
                    f"calibrated: {t.oil_volume_calibrated:.1f} L at 0.69 GPa")
