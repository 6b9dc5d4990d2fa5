"""The simulations and closed forms behind each figure and table of Zhao et al. (2003).

One function per figure or table; each returns a frozen dataclass of numbers and arrays:
no plotting, no prose (figures.py draws them, evaluate.py turns them into table rows).
Test-method constants (leads, alpha, dt, the solver's SDOF model) come from the core's
defaults (``_core.EftConfig()``, ``_core.RpsdConfig()``), the closed forms from ``sh.analysis``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control as ct
import numpy as np

import servohydraulics as sh  # public names, looked up at call time

from .. import _core
from .. import analysis as an
from .. import excitations as ex
from ..identification.frf import dft_ratio
from ..identification.paper import (
    FirstOrderEstimate,
    FreeVibration,
    FrictionEstimate,
    identify_damping_friction,
    identify_first_order,
    identify_free_vibration,
    linear_chirp,
    simulate_structure,
)
from ..rig import Rig
from ..timegrid import uniform_dt

TWO_PI = 2.0 * math.pi
_EFT = _core.EftConfig()
_RPSD = _core.RpsdConfig()
DT = _RPSD.dt  #: controller sample time of the paper's DSP (2 kHz) [s]
ALPHA = _RPSD.alpha  #: constant of the paper's phase leads [-]
T_AMP = _RPSD.amplitude_T  #: amplitude compensation (paper, 68 ms) [s]
T_LD = _RPSD.delay_T  #: delay compensation (paper, 11.2 ms) [s]
T_EFT = _EFT.lead_T  #: EFT phase lead (paper, 5 ms) [s]
M_M, C_M = _RPSD.model.m_m, _RPSD.model.c_m  #: modelled SDOF of the RPsD solver (Table I) [kg], [N s/m]
SWEEP_X = 0.0127  #: displacement sweep amplitude (Fig 5) [m]
SWEEP_F = 2.3e3  #: direct-EFT sweep amplitude (Fig 3) [N]
SWEEP_F_LARGE = 8.9e3  #: large EFT sweep amplitude (Fig 4) [N]
SWEEP_DURATION = 20.0  #: 0-10 Hz sweeps of the test-method loops (docs/methods.md) [s]
NOISE_X, NOISE_F = 5e-5, 2.0  #: LVDT [m] and load-cell [N] noise of the synthetic identification records
X_RELEASE = 0.016  #: release displacement of the RPsD free vibrations (Fig 9) [m]


def lead(u: np.ndarray, T: float) -> np.ndarray:
    """The paper's phase lead (T s+1)/(alpha T s+1) at the controller rate applied to a command array."""
    return np.asarray(_core.PhaseLead(T, ALPHA, DT).filter(np.asarray(u, dtype=float)))


def with_effects(rig: Rig, **switches: bool) -> Rig:
    """A copy of ``rig`` with some effect switches changed."""
    r = sh.copy_rig(rig)
    for name, on in switches.items():
        setattr(r.effects, name, on)
    return r


def linear_effects(rig: Rig) -> Rig:
    """A copy of ``rig`` with the flow curve, load pressure, friction and softening off."""
    return with_effects(rig, flow_nonlinearity=False, load_pressure=False, coulomb_friction=False,
                        spring_softening=False)


def model_damping_ratio(rig: Rig) -> float:
    """Damping ratio c_m / (2 sqrt(k m_m)) of the RPsD solver's SDOF model [-]."""
    return C_M / (2.0 * math.sqrt(rig.k * M_M))


def compensated_loop(rig: Rig) -> ct.TransferFunction:
    """G_xu with the 68 ms amplitude lead and the ZOH (friction off)."""
    return an.phase_lead(T_AMP) * an.G_xu(an.linear_analysis_rig(rig)) * an.zoh_delay(DT)


def zero_phase_delay_T(rig: Rig) -> float:
    """The delay lead giving zero residual phase at 1.58 Hz after the 68 ms lead (the paper's rule) [s]."""
    return an.delay_compensation_T(0.0, T_AMP, compensated_loop(rig), 1.58)


def interp_response(f: np.ndarray, h: np.ndarray, f0: float) -> complex:
    """Complex response h at f0 [Hz], linear interpolation over the finite samples."""
    ok = np.isfinite(h)
    return complex(np.interp(f0, f[ok], h[ok].real) + 1j * np.interp(f0, f[ok], h[ok].imag))


# --------------------------------------------------------------------------- Fig 2(b), p. 1777-1779: structure
@dataclass(frozen=True)
class FreeVibrationFit:
    """Fig 2(b): free vibration of the structure alone and its least-squares identification."""

    natural_frequency: float  #: sqrt(k/m) of the attached rig [Hz]
    zeta_table: float  #: Table I damping ratio of the free structure [-]
    c_table: float  #: Table I damping of the free structure [N s/m]
    time: np.ndarray
    x_true: np.ndarray  #: simulated record [m]
    x_meas: np.ndarray  #: with LVDT noise [m]
    estimate: FrictionEstimate
    crossing_frequency: float  #: from the zero up-crossings of x_true [Hz]


def fig2b_free_vibration(rig: Rig, quick: bool = False) -> FreeVibrationFit:
    """Free vibration from 1.3 cm of the structure alone (2 ms samples, 0.05 mm noise), fitted for c and F_c."""
    free = sh.zhao2003(actuator_attached=False)
    dt, dur = 2e-3, (6.0 if quick else 10.0)
    n = int(round(dur / dt)) + 1
    t = np.arange(n) * dt
    x_true = simulate_structure(free, free.c, free.F_c, n, dt, 0.013)
    x_meas = x_true + NOISE_X * np.random.default_rng(2003).standard_normal(n)
    est = identify_damping_friction(t, x_meas, free)
    up = np.flatnonzero((x_true[:-1] < 0) & (x_true[1:] >= 0))
    return FreeVibrationFit(natural_frequency=an.natural_frequency(rig) / TWO_PI, zeta_table=an.damping_ratio(free),
                            c_table=free.c,
                            time=t, x_true=x_true, x_meas=x_meas, estimate=est,
                            crossing_frequency=1.0 / float(np.mean(np.diff(t[up]))))


@dataclass(frozen=True)
class ForcedVibrationFit:
    """p. 1779: damping and friction with the actuator attached, from a force-controlled sweep."""

    zeta_table: float  #: Table I damping ratio of the attached structure [-]
    c_table: float  #: Table I damping with the actuator [N s/m]
    estimate: FrictionEstimate


def forced_vibration(rig: Rig, quick: bool = False) -> ForcedVibrationFit:
    """2.3 kN force-control sweep 0.3-4 Hz, sampled at 2 ms with 0.05 mm and 2 N noise, load-cell force
    into Eq (5). The noise continues the stream of ``fig2b_free_vibration`` (seed 2003)."""
    rng = np.random.default_rng(2003)
    rng.standard_normal(int(round((6.0 if quick else 10.0) / 2e-3)) + 1)  # the free-vibration record's draws
    tt, u = linear_chirp(8.0 if quick else 12.0, DT, 0.3, 4.0, SWEEP_F, tail=1.0)
    res = sh.simulate(rig, "force", u, DT)
    dec = 4  # fit at 2 ms, as the free-vibration record
    x_f = res.displacement[::dec] + NOISE_X * rng.standard_normal(res.displacement[::dec].size)
    F_f = res.force[::dec] + NOISE_F * rng.standard_normal(x_f.size)
    est = identify_damping_friction(tt[::dec], x_f, rig, force=F_f, x0=0.0)
    return ForcedVibrationFit(zeta_table=an.damping_ratio(rig), c_table=rig.c, estimate=est)


@dataclass(frozen=True)
class EquivalentDamping:
    """p. 1779: Jacobsen's equivalent viscous damping (Eq 8) before and after attaching the actuator."""

    amplitude: float  #: X at which the free structure shows 1.1 % [m]
    zeta_attached: float  #: predicted equivalent damping ratio with the actuator [-]


def equivalent_damping(rig: Rig, zeta_free_measured: float = 0.011) -> EquivalentDamping:
    """The amplitude X is fixed by the free structure's measured 1.1 %; the attached ratio follows (Eq 8)."""
    free = sh.zhao2003(actuator_attached=False)
    per_metre = an.damping_ratio(free, an.equivalent_viscous_damping(free, 1.0))  # zeta_eq X [m]
    X = per_metre / (zeta_free_measured - an.damping_ratio(free))
    z = an.damping_ratio(rig) + an.damping_ratio(rig, an.equivalent_viscous_damping(rig, X))
    return EquivalentDamping(amplitude=X, zeta_attached=z)


@dataclass(frozen=True)
class FreeDecay:
    """Free vibration from x0 in free mode and its damped-cosine fit (friction shows as extra damping)."""

    time: np.ndarray
    displacement: np.ndarray  #: [m]
    frequency: float  #: damped frequency [Hz]
    damping_ratio: float  #: equivalent damping of the fit window [-]


def free_decay(rig: Rig, x0: float = 0.013, duration: float = 10.0, fit: float = 4.0) -> FreeDecay:
    """Free vibration of ``rig`` from x0 [m], fitted over the first ``fit`` seconds."""
    res = sh.simulate(rig, mode="free", duration=duration, dt=DT, x0=x0)
    fv = identify_free_vibration(res.displacement, DT, duration=fit)
    return FreeDecay(res.time, res.displacement, fv.frequency, fv.damping_ratio)


# --------------------------------------------------------------------------- Figs 3(a), 4(a), Eq (11): force control
@dataclass(frozen=True)
class DirectEft:
    """Fig 3(a): direct EFT, 2.3 kN sweep without compensation, against Eq (9)."""

    time: np.ndarray
    command: np.ndarray  #: effective force command [N]
    force: np.ndarray  #: load-cell force [N]
    frequency: np.ndarray  #: FRF frequencies [Hz]
    response: np.ndarray  #: F/u [-]
    excited: np.ndarray  #: frequencies the sweep excites
    min_frequency: float  #: minimum of |F/u| over 0.3-5 Hz, simulated [Hz]
    min_gain: float  #: that minimum [-]
    min_frequency_eq9: float  #: minimum of |G_fu| over 0.3-5 Hz, Eq (9) [Hz]
    g_fu: ct.TransferFunction  #: Eq (9), friction off


def fig3a_direct_eft(rig: Rig, quick: bool = False) -> DirectEft:
    lin = an.linear_analysis_rig(rig)
    t, u = linear_chirp(20.0 if quick else 40.0, DT, 0.1, 10.0, SWEEP_F, tail=2.0)
    res = sh.simulate(rig, "force", u, DT)
    est = dft_ratio(u, res.force, uniform_dt(t, "invalid time", min_rows=10))
    f, h, ok = est.frequency, est.response, est.excited
    band = ok & (f > 0.3) & (f < 5.0)
    ff = np.linspace(0.3, 5.0, 2000)
    g_fu = an.G_fu(lin)
    g = np.abs(np.asarray(g_fu(1j * TWO_PI * ff)))
    return DirectEft(time=t, command=u, force=res.force, frequency=f, response=h, excited=ok,
                     min_frequency=float(f[band][np.argmin(np.abs(h[band]))]), min_gain=float(np.min(np.abs(h[band]))),
                     min_frequency_eq9=float(ff[np.argmin(g)]), g_fu=g_fu)


@dataclass(frozen=True)
class ForceLoopBounds:
    """Eq (11) roll-off of the compensated force loop and the piston-mass fraction (p. 1782)."""

    rolloff_hz: float  #: omega_cEFT / 2 pi, calibrated preset [Hz]
    rolloff_printed_hz: float  #: the same with Table I as printed [Hz]
    gain_for_120hz: float  #: force-loop G_p needed for a 120 Hz roll-off [-]
    piston_mass: float  #: [kg]
    piston_fraction: float  #: m_p / (m + m_p) [-]


def eq11_force_loop(rig: Rig) -> ForceLoopBounds:
    per_gain = an.loop_gain_force(rig) / rig.G_p  # K_v C_F K_s A-free part of Eq (9) [m^3/s per N]
    return ForceLoopBounds(rolloff_hz=an.omega_cEFT(rig) / TWO_PI,
                           rolloff_printed_hz=an.omega_cEFT(sh.zhao2003("printed")) / TWO_PI,
                           gain_for_120hz=(TWO_PI * 120.0 * rig.K_a - rig.C_l) / (rig.A * per_gain),
                           piston_mass=rig.m_p, piston_fraction=rig.m_p / (rig.m + rig.m_p))


@dataclass(frozen=True)
class FlowCurve:
    """Fig 4(a): the preset's flow curve g(x_v) and its gain dg/dx_v."""

    opening: np.ndarray  #: x_v / x_v,max [-]
    g: np.ndarray
    slope: np.ndarray
    K_v: float
    linear_deviation_10: float  #: g(0.1)/0.1 - 1 [-]
    gain_at: dict  #: dg/dx at 5, 50, 95 % opening
    g_full: float  #: g(1)
    non_increasing: bool  #: the gain never increases with the opening


def fig4a_flow_curve(rig: Rig) -> FlowCurve:
    fc = rig.flow_curve
    xs = np.linspace(0.0, 1.0, 201)
    slope = np.array([fc.slope(x) for x in xs])
    return FlowCurve(opening=xs, g=np.array([fc.eval(x) for x in xs]), slope=slope, K_v=rig.K_v,
                     linear_deviation_10=fc.eval(0.1) / 0.1 - 1, gain_at={x: fc.slope(x) for x in (0.05, 0.5, 0.95)},
                     g_full=fc.eval(1.0), non_increasing=bool(np.all(np.diff(slope) <= 1e-9)))


# --------------------------------------------------------------------------- Figs 3(b), 4(b, c), p. 1782: EFT loops
@dataclass(frozen=True)
class EftSweep:
    """One EFT run on a 0-10 Hz effective-force sweep and its Fourier-amplitude ratio |F/P| over 0.3-10 Hz."""

    frequency: np.ndarray  #: [Hz]
    ratio: np.ndarray  #: |F/P| [-]
    effective_force: np.ndarray  #: P [N]
    result: object  #: the loop's result (channels time, force, spool, displacement, ...)

    def stats(self, band: tuple[float, float] = (0.3, 10.0)) -> tuple[float, float, float, float, float]:
        """(min |F/P|, its frequency, max |F/P|, its frequency, max |spool|) over ``band`` [Hz]."""
        s = (self.frequency >= band[0]) & (self.frequency <= band[1])
        i, j = np.argmin(self.ratio[s]), np.argmax(self.ratio[s])
        return (float(self.ratio[s][i]), float(self.frequency[s][i]), float(self.ratio[s][j]),
                float(self.frequency[s][j]), float(np.max(np.abs(self.result.spool))))


def eft_sweep(rig: Rig, amplitude: float, duration: float = SWEEP_DURATION, **kw) -> EftSweep:
    """``run_eft`` on ``excitations.sine_sweep(amplitude)`` (keywords go to run_eft)."""
    P = ex.sine_sweep(amplitude, duration=duration, dt=DT)
    res = sh.run_eft(rig, effective_force=P, dt=DT, raise_on_failure=False, **kw)
    est = dft_ratio(P[: res.force.size], res.force, DT, min_level=0.0, from_rest=False)
    f, H = est.frequency, np.abs(est.response)
    b = (f > 0.3) & (f < 10.0)
    return EftSweep(frequency=f[b], ratio=H[b], effective_force=P, result=res)


def eft_pole_frequency(rig: Rig, T: float | None) -> float:
    """Frequency [Hz] of the structural pole of the linearised EFT loop with lead T (None: no lead)."""
    s = an.linearize(an.linear_analysis_rig(rig), "force", outputs=("force",),
                     compensators=an.Compensation(velocity_feedback=True, velocity_feedback_T=T))
    return an.structural_mode(s, an.natural_frequency(rig))[0]


def eft_critical_lead(rig: Rig) -> float:
    """Smallest EFT lead [s] at which the linearised compensated force loop is unstable (bisection), or nan."""
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


#: the EFT runs of Figs 3(b), 4(b, c) and p. 1782: key -> (rig variant, amplitude [N], run_eft keywords)
EFT_RUNS = {"none": ("full", SWEEP_F, {"compensation": "none"}),
            "linear": ("full", SWEEP_F, {}),
            "linear_fast": ("full", SWEEP_F, {"duration": 0.5 * SWEEP_DURATION}),
            "big_linear": ("full", SWEEP_F_LARGE, {}),
            "big_linear_flowlin": ("flow_linear", SWEEP_F_LARGE, {}),
            "big_nonlinear": ("full", SWEEP_F_LARGE, {"compensation": "nonlinear"}),
            "lead0": ("full", SWEEP_F, {"lead_T": 0.0}),
            "lead12": ("full", SWEEP_F, {"lead_T": 0.012}),
            "lead40_lin": ("linear", SWEEP_F, {"lead_T": 0.040}),
            "lead40": ("full", SWEEP_F, {"lead_T": 0.040})}


@dataclass(frozen=True)
class EftStudy:
    """Figs 3(b), 4(b, c) and the EFT delay-compensation statements (p. 1782)."""

    natural_frequency: float  #: structure + piston [Hz]
    runs: dict  #: key of EFT_RUNS -> EftSweep
    pole_frequency: dict  #: lead T (None: none) -> structural pole of the linear loop [Hz]
    critical_lead: float  #: [s]
    x_v_max: float


def fig3_eft(rig: Rig) -> EftStudy:
    rigs = {"full": rig, "flow_linear": with_effects(rig, flow_nonlinearity=False), "linear": linear_effects(rig)}
    runs = {k: eft_sweep(rigs[v], amp, **kw) for k, (v, amp, kw) in EFT_RUNS.items()}
    return EftStudy(natural_frequency=an.natural_frequency(rig, an.moving_mass(rig)) / TWO_PI, runs=runs,
                    pole_frequency={T: eft_pole_frequency(rig, T) for T in (None, T_EFT, 0.012)},
                    critical_lead=eft_critical_lead(rig), x_v_max=rig.x_v_max)


# --------------------------------------------------------------------------- Figs 5, 6(a), Eqs (12)-(14)
@dataclass(frozen=True)
class DisplacementLoop:
    """Eqs (12)-(14) and Fig 6(a): the linear displacement loop and its amplitude compensation."""

    omega_c: float  #: Eq (13) roll-off [rad/s]
    g_lin: ct.TransferFunction  #: G_xu (Eq 12 + valve) with the ZOH
    oil_column_hz: float  #: Eq (14) [Hz]
    oil_column_printed_hz: float  #: Eq (14), Table I as printed [Hz]
    closed_loop_mode: tuple  #: (frequency [Hz], damping ratio) of the highest mode of G_xu
    T_amplitude: float  #: minimax amplitude-compensation time constant for 0-5 Hz [s]
    worst_deviation: float  #: its worst |G_c| deviation [-]
    band_68ms: float  #: upper edge of the 5 % band with the 68 ms lead [Hz]


def fig6a_amplitude_compensation(rig: Rig) -> DisplacementLoop:
    lin = an.linear_analysis_rig(rig)
    g_lin = an.G_xu(lin) * an.zoh_delay(DT)
    T_best, dev = an.amplitude_compensation_T(g_lin, (0.0, 5.0))
    return DisplacementLoop(omega_c=an.omega_cRPD(rig), g_lin=g_lin, oil_column_hz=an.omega_oil_column(rig) / TWO_PI,
                            oil_column_printed_hz=an.omega_oil_column(sh.zhao2003("printed")) / TWO_PI,
                            closed_loop_mode=an.dominant_modes(an.G_xu(lin))[-1], T_amplitude=T_best,
                            worst_deviation=dev, band_68ms=an.acceptable_band(g_lin, T_AMP, 0.05))


@dataclass(frozen=True)
class DisplacementSweeps:
    """Fig 5: 1.27 cm displacement sweeps, (a) uncompensated 0.1-10 Hz, (b) with the 68 ms lead 0.1-6 Hz."""

    first_order: FirstOrderEstimate  #: fit of (a) over 0.1-2 Hz (frequency, response, excited inside)
    gain_2hz: float  #: |x/u| of (a) at 2 Hz [-]
    time_a: np.ndarray
    force_a: np.ndarray  #: load-cell force of (a) [N]
    duration_a: float  #: (a) sweeps 0.1 -> 10 Hz linearly over this time [s]
    time_b: np.ndarray
    frequency_b: np.ndarray
    response_b: np.ndarray
    excited_b: np.ndarray
    peak_b: float  #: max |x/u| of (b) over 0.2-5 Hz
    peak_b_linear: float  #: the same for the linear model with the lead
    spool_b: float  #: max |spool| of (b) below 5 Hz [-]
    pressure_b: float  #: max |p| / p_s of (b) below 5 Hz [-]


def fig5_displacement_sweeps(rig: Rig, quick: bool = False) -> DisplacementSweeps:
    dur = 20.0 if quick else 40.0
    t, u = linear_chirp(dur, DT, 0.1, 10.0, SWEEP_X, tail=2.0)
    res = sh.simulate(rig, "displacement", u, DT)
    fo = identify_first_order(t, u, res.displacement)
    t2, u2 = linear_chirp(dur * 0.6, DT, 0.1, 6.0, SWEEP_X, tail=2.0)
    res2 = sh.simulate(rig, "displacement", lead(u2, T_AMP), DT)
    est = dft_ratio(u2, res2.displacement, uniform_dt(t2, "invalid time", min_rows=10))
    f2, h2, ok2 = est.frequency, est.response, est.excited
    sel = ok2 & (f2 >= 0.2) & (f2 <= 5.0)
    g_lead = an.phase_lead(T_AMP) * an.G_xu(an.linear_analysis_rig(rig)) * an.zoh_delay(DT)
    peak_lin = float(np.max(np.abs(np.asarray(g_lead(1j * TWO_PI * np.linspace(0.2, 5.0, 400))))))
    in5 = t2 <= (5.0 - 0.1) / (6.0 - 0.1) * dur * 0.6  # the sweep below 5 Hz
    return DisplacementSweeps(first_order=fo, gain_2hz=abs(interp_response(fo.frequency, fo.response, 2.0)),
                              time_a=t, force_a=res.force, duration_a=dur,
                              time_b=t2, frequency_b=f2, response_b=h2, excited_b=ok2,
                              peak_b=float(np.max(np.abs(h2[sel]))), peak_b_linear=peak_lin,
                              spool_b=float(np.max(np.abs(res2.spool[in5]))),
                              pressure_b=float(np.max(np.abs(res2.pressure[in5]))) / rig.p_s)


@dataclass(frozen=True)
class Capacity:
    """Fig 5(b), p. 1784: compensated 1.27 cm sines; the first frequency at the supply or capacity limit."""

    frequencies: np.ndarray  #: [Hz]
    limit: float | None  #: first frequency with a limit flag [Hz]
    peak_force_at_limit: float  #: [N]
    supply_force: float  #: p_s A [N]


def capacity_limit(rig: Rig, quick: bool = False) -> Capacity:
    freqs = np.arange(5.0, 8.01, 0.5 if quick else 0.25)
    for fq in freqs:
        tt = np.arange(int(round(max(1.5, 8.0 / fq) / DT)) + 1) * DT
        ramp = np.clip(tt / 0.3, 0, 1)
        uu = SWEEP_X * np.sin(TWO_PI * fq * tt) * (0.5 - 0.5 * np.cos(math.pi * ramp))
        rr = sh.simulate(rig, "displacement", lead(uu, T_AMP), DT, raise_on_failure=False)
        if rr.supply_limited or rr.capacity_exceeded:
            return Capacity(freqs, float(fq), float(np.max(np.abs(rr.force))), rig.p_s * rig.A)
    return Capacity(freqs, None, 0.0, rig.p_s * rig.A)


# --------------------------------------------------------------------------- Fig 6(b): Routh bound on G_p
@dataclass(frozen=True)
class GainBound:
    """Fig 6(b): maximum stable G_p against the installed mass; root locus and Bode plots of the loop."""

    masses: np.ndarray  #: [kg]
    gain_valve: np.ndarray  #: Routh bound with the servovalve second order
    gain_static_valve: np.ndarray  #: with the static valve (Eq 6)
    eigen_confirmed: bool  #: the linearised C++ model crosses at the Routh bound at three masses
    gain_used: float  #: G_p of the rig
    gain_printed: float  #: Routh bound of Table I as printed, full mass
    locus_gains: np.ndarray
    locus_poles: np.ndarray
    bode: dict  #: label -> linearised system (for the Bode figure)


def routh_matches_eigenvalues(rig: Rig, mass: float) -> bool:
    """The linearised model's largest real part changes sign across the Routh bound (+-0.1 %)."""
    r = an.rig_with_mass(rig, mass)
    gmax = an.max_p_gain(r)
    re = []
    for fac in (0.999, 1.001):
        r.G_p = fac * gmax
        re.append(float(np.max(np.real(np.linalg.eigvals(an.linearize(r).A)))))
    return re[0] < 0 < re[1]


def fig6b_gain_bound(rig: Rig, quick: bool = False) -> GainBound:
    lin = an.linear_analysis_rig(rig)
    masses = np.geomspace(54.0, rig.m + rig.m_p, 12 if quick else 30)
    gains = np.geomspace(0.01, 10.0, 300)
    vfb = an.Compensation(velocity_feedback=True, velocity_feedback_T=T_EFT)
    bode = {"x/u, displacement control": an.linearize(rig),
            "F/u, force control (direct)": an.linearize(rig, "force", outputs=("force",)),
            "F/u, velocity feedback compensation + 5 ms lead": an.linearize(rig, "force", outputs=("force",),
                                                                            compensators=vfb)}
    return GainBound(masses=masses, gain_valve=an.max_p_gain_curve(lin, masses, True),
                     gain_static_valve=an.max_p_gain_curve(lin, masses, False),
                     eigen_confirmed=all(routh_matches_eigenvalues(lin, m)
                                         for m in (masses[0], masses[len(masses) // 2], masses[-1])),
                     gain_used=rig.G_p, gain_printed=an.max_p_gain(sh.zhao2003("printed")), locus_gains=gains,
                     locus_poles=an.root_locus_gains(lin, gains), bode=bode)


# --------------------------------------------------------------------------- Figs 8-10: RPsD, linear analysis
@dataclass(frozen=True)
class RpsdLinear:
    """Net damping of the linear RPsD loop against the delay lead; pole-zero maps of Fig 10(b), (c)."""

    zeta_model: float  #: c_m / (2 sqrt(k m_m)) [-]
    zeta: dict  #: delay lead T [s] (0: none) -> net damping ratio of the structural mode [-]
    T_estimate: float  #: 1/omega_cRPD - 68 ms, the paper's estimate [s]
    T_zero_phase: float  #: zero residual phase at 1.58 Hz [s]
    residual_delay: float  #: equivalent delay after the 68 ms lead at 1.58 Hz [s]
    loops: dict  #: (tag "b" | "c", restoring force) -> RPsD loop (state space)
    modes: dict  #: same keys -> (frequency [Hz], damping ratio) of the structural mode
    masses: dict  #: tag -> physical mass [kg]


def fig10_pole_zero(rig: Rig) -> RpsdLinear:
    lin = an.linear_analysis_rig(rig)
    w_n = an.natural_frequency(rig)
    zeta = {T: an.structural_mode(an.rpsd_loop(lin, M_M, C_M, delay_T=T or None), w_n)[1]
            for T in (0.0, 0.006, T_LD, 0.016)}
    masses = {"b": rig.m, "c": 0.02 * M_M}
    loops = {(tag, opt): an.rpsd_loop(lin, M_M, C_M, physical_mass=mass, **kw)
             for tag, mass in masses.items() for opt, kw in an.fig10_variants(lin, mass).items()}
    return RpsdLinear(zeta_model=model_damping_ratio(rig), zeta=zeta,
                      T_estimate=an.delay_compensation_T(1.0 / an.omega_cRPD(rig), T_AMP),
                      T_zero_phase=zero_phase_delay_T(rig),
                      residual_delay=an.equivalent_delay(compensated_loop(rig), 1.58), loops=loops,
                      modes={k: an.structural_mode(s, w_n) for k, s in loops.items()}, masses=masses)


def rpsd_damping_curve(rig: Rig, delays: np.ndarray) -> np.ndarray:
    """Net damping ratio of the linear RPsD loop's structural mode at each delay lead [-]."""
    lin = an.linear_analysis_rig(rig)
    return np.array([an.structural_mode(an.rpsd_loop(lin, M_M, C_M, delay_T=T), an.natural_frequency(rig))[1]
                     for T in delays])


# --------------------------------------------------------------------------- Figs 8-10(a): RPsD loops
@dataclass(frozen=True)
class Release:
    """Ramp-and-release timing of the RPsD free vibrations (Fig 9): times in seconds."""

    ramp: float = 5.0
    hold: float = 1.0
    free: float = 25.0
    fit: float = 4.0  #: damped-cosine fit window after release

    @property
    def index(self) -> int:
        return ex.release_index(self.ramp, self.hold, dt=DT)

    def force(self, rig: Rig) -> np.ndarray:
        return ex.ramp_and_release(rig.k * X_RELEASE, self.ramp, self.hold, self.free, dt=DT)


@dataclass(frozen=True)
class RpsdRelease:
    """One RPsD free vibration and the damped-cosine fit of its calculated displacement."""

    result: object
    fit: FreeVibration


def rpsd_release(rig: Rig, release: Release = Release(), **kw) -> RpsdRelease:
    """``run_rpsd`` on the ramp-and-release external force from 1.6 cm (keywords go to run_rpsd)."""
    kw = {"m_m": M_M, "c_m": C_M, **kw}
    res = sh.run_rpsd(rig, external_force=release.force(rig), dt=DT, raise_on_failure=False, **kw)
    return RpsdRelease(res, identify_free_vibration(res.calc_displacement, DT, start=release.index,
                                                    duration=release.fit))


FORCE_ERROR = 30.0  #: amplitude of the Fig 9(b) restoring-force error [N]
DELAYS = (0.006, T_LD, 0.016, 0.020)  #: delay leads of the Fig 8 / 9 free vibrations [s]


@dataclass(frozen=True)
class RpsdFreeVibrations:
    """Figs 8, 9, 10(a): RPsD free vibrations from 1.6 cm with the full model."""

    release: Release
    time_after_release: np.ndarray  #: [s]
    external_force: np.ndarray  #: P_ext [N]
    zeta_model: float
    T_zero_phase: float  #: [s]
    runs: dict  #: delay T [s], "a" (calculated displacement), "err", "zero", "zero_err" -> RpsdRelease
    k: float

    @property
    def zeta(self) -> dict:
        return {T: self.runs[T].fit.damping_ratio for T in DELAYS}


def fig9_free_vibration(rig: Rig) -> RpsdFreeVibrations:
    rel = Release()
    t = np.arange(rel.force(rig).size) * DT
    tr = t - t[rel.index]  # time after release [s]
    T_zero = zero_phase_delay_T(rig)  # the rule that gave the paper 11.2 ms
    w_n = math.sqrt(rig.k / M_M)
    err = np.where(tr >= 0.0, FORCE_ERROR * np.sin(w_n * tr - math.pi / 2), 0.0)  # Fig 9b, 0.03 kN
    runs = {T: rpsd_release(rig, rel, delay_T=T) for T in DELAYS}
    runs["a"] = rpsd_release(rig, rel, restoring_force="calculated_displacement")
    runs["err"] = rpsd_release(rig, rel, delay_T=T_LD, restoring_force_error=err)
    runs["zero"] = rpsd_release(rig, rel, delay_T=T_zero)
    runs["zero_err"] = rpsd_release(rig, rel, delay_T=T_zero, restoring_force_error=err)
    return RpsdFreeVibrations(release=rel, time_after_release=tr, external_force=rel.force(rig),
                              zeta_model=model_damping_ratio(rig), T_zero_phase=T_zero, runs=runs, k=rig.k)


@dataclass(frozen=True)
class Fig9a:
    """Fig 9(a): calculated displacements for the restoring force (the solver runs open loop)."""

    exact: np.ndarray  #: closed-form SDOF free vibration after release [m]
    max_error: float  #: max |x_calc - exact| / x0 [-]
    fit_calculated: FreeVibration
    amplitude_ratio: float  #: measured / calculated amplitude of the fitted free vibrations [-]
    lag: float  #: phase lag of the measured behind the calculated displacement [s]


def fig9a_structural(fv: RpsdFreeVibrations) -> Fig9a:
    """Checks the calculated-displacement run against the closed-form damped SDOF response."""
    res, fit = fv.runs["a"].result, fv.runs["a"].fit
    i0, z, w_n = fv.release.index, fv.zeta_model, math.sqrt(fv.k / M_M)
    x0, v0 = res.calc_displacement[i0], res.calc_velocity[i0]
    wd = w_n * math.sqrt(1 - z**2)
    ta = fv.time_after_release[i0:]
    exact = np.exp(-z * w_n * ta) * (x0 * np.cos(wd * ta) + (v0 + z * w_n * x0) / wd * np.sin(wd * ta))
    meas = identify_free_vibration(res.displacement, DT, start=i0, duration=fv.release.fit)
    rot = np.exp(-1j * 2 * math.pi * fit.frequency * ta[:8000])
    lag = (np.angle(np.sum(res.calc_displacement[i0:i0 + 8000] * rot))
           - np.angle(np.sum(res.displacement[i0:i0 + 8000] * rot))) % (2 * math.pi)
    return Fig9a(exact=exact, max_error=float(np.max(np.abs(res.calc_displacement[i0:] - exact)) / abs(x0)),
                 fit_calculated=fit, amplitude_ratio=meas.amplitude / fit.amplitude,
                 lag=lag / (2 * math.pi * fit.frequency))


@dataclass(frozen=True)
class Fig9b:
    """Fig 9(b): envelope growth with the 0.03 kN restoring-force error (ratios of 5 s windows after release)."""

    growth_err: float  #: 11.2 ms with the error, 15-20 s / 10-15 s
    growth_no_err: float  #: 11.2 ms without
    growth_zero_err: float  #: zero-phase lead with the error
    growth_zero: float  #: zero-phase lead without
    growth_zero_err_late: float  #: zero-phase lead with the error, 20-25 s / 15-20 s
    amplitude_late: float  #: envelope 20-25 s, zero-phase lead with the error [m]
    amplitude_late_no_err: float  #: the same without the error [m]
    zeta_zero: float  #: fitted damping at the zero-phase lead [-]
    steady_amplitude: float  #: F / (2 zeta k) [m]
    decay_at_10s: float  #: free decay from 1.6 cm at zeta_zero after 10 s [m]


def fig9b_force_error(fv: RpsdFreeVibrations) -> Fig9b:
    tr = fv.time_after_release

    def envelope(x: np.ndarray, a: float, b: float) -> float:
        s = (tr >= a) & (tr < b)
        return float(np.max(np.abs(x[s])))

    def growth(key, start: float = 10.0) -> float:
        x = fv.runs[key].result.calc_displacement
        return envelope(x, start + 5, start + 10) / envelope(x, start, start + 5)

    z_zero = fv.runs["zero"].fit.damping_ratio
    return Fig9b(growth_err=growth("err"), growth_no_err=growth(T_LD), growth_zero_err=growth("zero_err"),
                 growth_zero=growth("zero"), growth_zero_err_late=growth("zero_err", 15.0),
                 amplitude_late=envelope(fv.runs["zero_err"].result.calc_displacement, 20.0, 25.0),
                 amplitude_late_no_err=envelope(fv.runs["zero"].result.calc_displacement, 20.0, 25.0),
                 zeta_zero=z_zero, steady_amplitude=FORCE_ERROR / (2 * max(z_zero, 1e-9) * fv.k),
                 decay_at_10s=X_RELEASE * math.exp(-z_zero * math.sqrt(fv.k / M_M) * 10.0))


@dataclass(frozen=True)
class Fig10a:
    """Fig 10(a): load-cell force against the restoring force k x and the solver's input."""

    force_vs_kx: float  #: rms(F - k x) / rms(k x) over the fit window after release [-]
    force_vs_input: float  #: rms(F - P_ext) / max |P_ext| over the whole record [-]


def fig10a_force(fv: RpsdFreeVibrations) -> Fig10a:
    res = fv.runs["a"].result
    s = (fv.time_after_release >= 0) & (fv.time_after_release < fv.release.fit)
    F, kx, pe = res.force, fv.k * res.displacement, fv.external_force

    def rms(y: np.ndarray) -> float:
        return float(np.sqrt(np.mean(y[s] ** 2)))

    return Fig10a(force_vs_kx=rms(F - kx) / rms(kx),
                  force_vs_input=float(np.sqrt(np.mean((F - pe) ** 2)) / np.max(np.abs(pe))))


@dataclass(frozen=True)
class RpsdSweeps:
    """Fig 8(a, b): 0.15 g ground-acceleration sweeps 0-10 Hz with 6 and 16 ms delay leads."""

    time: np.ndarray
    runs: dict  #: delay T [s] -> loop result
    x_exact: np.ndarray  #: the solver's SDOF alone (no servo-system) [m]
    v_exact: np.ndarray  #: [m/s]
    need: float  #: g(x_v) = A max|v| / K_v needed at zero load pressure [-]
    need_opening: float  #: the spool opening giving it [-]
    spool_max: dict  #: T -> max |spool| [-]
    t28: float  #: first time |spool| >= 28 % at 6 ms [s]
    t_saturated: float  #: first time the spool is fully open at 6 ms [s]


def fig8_rpsd_delay(rig: Rig) -> RpsdSweeps:
    ag = ex.sine_sweep(ex.SWEEP_GROUND_ACCELERATION, duration=SWEEP_DURATION, dt=DT)
    ts = np.arange(ag.size) * DT
    sw = {T: sh.run_rpsd(rig, ground_acceleration=ag, dt=DT, m_m=M_M, c_m=C_M, delay_T=T, raise_on_failure=False)
          for T in (0.006, 0.016)}
    x_exact = ct.forced_response(ct.tf([1.0], [M_M, C_M, rig.k]), ts, -M_M * ag).outputs
    v_exact = np.gradient(x_exact, DT)
    need = rig.A * float(np.max(np.abs(v_exact))) / rig.K_v
    sp = np.abs(sw[0.006].spool)
    i28, isat = np.flatnonzero(sp >= 0.28), np.flatnonzero(sp >= 0.999 * rig.x_v_max)
    return RpsdSweeps(time=ts, runs=sw, x_exact=x_exact, v_exact=v_exact, need=need,
                      need_opening=rig.flow_curve.inverse(min(need, rig.flow_curve.eval(rig.x_v_max))),
                      spool_max={T: float(np.max(np.abs(r.spool))) for T, r in sw.items()},
                      t28=ts[i28[0]] if i28.size else math.nan, t_saturated=ts[isat[0]] if isat.size else math.nan)


# --------------------------------------------------------------------------- Table I
@dataclass(frozen=True)
class Table1:
    """The contradictions of Table I as printed, with the calibrated preset beside them."""

    max_real_pole_calibrated: float  #: of G_xu [rad/s]
    max_real_pole_printed: float
    oil_volume_printed: float  #: V_t = 4 K_a beta_e, printed K_a at 1 GPa [L]
    oil_volume_calibrated: float  #: calibrated K_a at 0.69 GPa [L]
    swept_volume: float  #: A x 0.254 m stroke [L]


def table1(rig: Rig) -> Table1:
    printed = sh.zhao2003("printed")
    re = [float(np.max(np.real(an.G_xu(an.linear_analysis_rig(r)).poles()))) for r in (rig, printed)]
    return Table1(max_real_pole_calibrated=re[0], max_real_pole_printed=re[1],
                  oil_volume_printed=4.0 * printed.K_a * 1.0e9 * 1e3, oil_volume_calibrated=4 * rig.K_a * 0.69e9 * 1e3,
                  swept_volume=rig.A * 0.254 * 1e3)


# --------------------------------------------------------------------------- 1.27 cm tracking sweep
@dataclass(frozen=True)
class TrackingSweep:
    """``run_tracking`` (68 ms lead) on the 1.27 cm 0-10 Hz sweep: where the supply or capacity limit is hit."""

    result: object
    first_limit_time: float | None  #: [s]
    first_limit_frequency: float | None  #: instantaneous sweep frequency then [Hz]


def tracking_sweep(rig: Rig, duration: float = SWEEP_DURATION) -> TrackingSweep:
    res = sh.run_tracking(rig, ex.sine_sweep(SWEEP_X, duration=duration, dt=DT), DT, raise_on_failure=False)
    hit = np.flatnonzero(res.flags & (_core.FLAG_SUPPLY_LIMITED | _core.FLAG_CAPACITY_EXCEEDED))
    if not hit.size:
        return TrackingSweep(res, None, None)
    t = float(res.time[hit[0]])
    return TrackingSweep(res, t, float(ex.sweep_frequency(t, duration=duration)))
