"""The paper's quantitative claims, one :class:`Claim` each, in the order of the table.

Each claim names the paper's statement and value, our acceptance rule (``tolerance_text`` in
words, ``interval`` in numbers, replaced by the value function where it depends on the rig),
the caveat or explanation shown with it (``why``), and the function of evaluate.py computing
our counterpart from the experiments. Texts may hold ``{placeholders}`` the value function fills.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from . import evaluate as ev
from .experiments import SWEEP_DURATION

INF = math.inf


@dataclass(frozen=True, kw_only=True)
class Claim:
    key: str  #: unique row key
    figure: str  #: figure, equation or page of the paper
    statement: str
    paper_text: str  #: the paper's value, as stated
    paper_value: float | None = None
    tolerance_text: str
    interval: tuple[float, float] = (-INF, INF)  #: acceptance interval of the value
    why: str = ""
    value: Callable[[dict], ev.Measured]


_ID_FREE = ("identification run on a record simulated with the paper's values plus 0.05 mm white noise: "
            "it checks the procedure, not the paper's test")
_ID_ATTACHED = ("forced-vibration record simulated in force control (2.3 kN sweep 0.3-4 Hz) with the paper's "
                "values, sampled at 2 ms, 0.05 mm and 2 N noise, load-cell force into Eq (5): checks the procedure")

STRUCTURE = (
    Claim(key="natural_frequency", figure="p. 1777", statement="initial natural frequency of the structure",
          paper_text="1.58 Hz", paper_value=1.58, tolerance_text="+-0.02 Hz", interval=(1.56, 1.60),
          value=ev.natural_frequency),
    Claim(key="zeta_free", figure="2b",
          statement="damping ratio of the structure alone (free vibration, least squares)",
          paper_text="0.8 % (Table I c = {c:g} N s/m: {zeta:.3f} %)", paper_value=None,
          tolerance_text="paper value inside our 95 % interval, half-width capped at 0.1 %",
          why=_ID_FREE + "; the paper's 0.8 % is c = {c:g} N s/m = {zeta:.3f} %", value=ev.zeta_free),
    Claim(key="friction_free", figure="2b", statement="Coulomb friction of the structure alone",
          paper_text="95.7 N", paper_value=95.7,
          tolerance_text="paper value inside our 95 % interval, half-width capped at 5 N", why=_ID_FREE,
          value=ev.friction_free),
    Claim(key="natural_frequency_free_vibration", figure="2b", statement="frequency of the free vibration",
          paper_text="1.58 Hz", paper_value=1.58, tolerance_text="+-0.02 Hz", interval=(1.56, 1.60),
          value=ev.crossing_frequency),
    Claim(key="zeta_attached", figure="p. 1779",
          statement="damping ratio with the actuator attached (forced vibration)",
          paper_text="1.5 % (Table I c = {c:g} N s/m: {zeta:.3f} %)", paper_value=None,
          tolerance_text="paper value inside our 95 % interval, half-width capped at 0.2 %",
          why=_ID_ATTACHED + "; the paper's 1.5 % is c = {c:g} N s/m = {zeta:.3f} %", value=ev.zeta_attached),
    Claim(key="friction_attached", figure="p. 1779", statement="Coulomb friction with the actuator attached",
          paper_text="31.6 N", paper_value=31.6,
          tolerance_text="paper value inside our 95 % interval, half-width capped at 5 N", why=_ID_ATTACHED,
          value=ev.friction_attached),
    Claim(key="equivalent_damping", figure="p. 1779",
          statement="equivalent viscous damping after attaching the actuator", paper_text="1.1 % -> 1.6 %",
          paper_value=1.6, tolerance_text="+-0.1 percentage point", interval=(1.5, 1.7),
          why="energy-equivalent damping 4 F_c/(pi w X); X is set by the 1.1 % of the free structure, the 1.6 % "
              "is then predicted", value=ev.equivalent_damping),
)

FORCE = (
    Claim(key="eft_drop", figure="3a", statement="direct EFT: applied force drops at the structure's natural "
          "frequency (its poles are zeros of G_fu, Eq 9)", paper_text="at 1.58 Hz", paper_value=1.58,
          tolerance_text="+-0.1 Hz", interval=(1.48, 1.68), value=ev.eft_drop),
    Claim(key="eft_rolloff", figure="Eq (11)", statement="roll-off of the compensated force loop",
          paper_text="above 120 Hz", paper_value=120.0, tolerance_text=">= 120 Hz", interval=(120.0, INF),
          why="with the calibrated K_a (docs/calibration.md) and G_p = 0.8059; Table I as printed gives "
              "{printed:.1f} Hz. 120 Hz needs a force-loop gain G_p >= {gp_120:.2f}: the paper's single G_p is the "
              "displacement gain (Eq 13). Still far above the 0-10 Hz band, as the paper concludes",
          value=ev.eft_rolloff),
    Claim(key="piston_mass", figure="p. 1782", statement="piston mass 54 kg, less than 1 % of the moving mass",
          paper_text="54 kg, < 1 %", paper_value=0.76, tolerance_text="< 1 %", interval=(0.0, 1.0),
          value=ev.piston_mass),
    Claim(key="flow_curve", figure="4a / p. 1780", statement="a constant initial flow gain is adequate below 10 % "
          "spool opening; the gain falls as the opening grows", paper_text="linear below 10 %, falling gain",
          tolerance_text="|g(0.1)/0.1 - 1| <= 2 % and a non-increasing gain", interval=(-2.0, 2.0),
          why="the preset's table is built on these two statements and the valve's rated flow "
              "(docs/calibration.md): a consistency check, not an independent confirmation",
          value=ev.flow_curve),
)

_SPOOL_WHY = ("the spool opening follows the structure's velocity at resonance, which grows with the time the sweep "
              "spends near 1.58 Hz: the paper does not give the sweep duration, and a {fast:g} s sweep stays below "
              "10 %. The finding (inside or near the linear range of the flow curve, so linear compensation works) "
              "holds")

EFT = (
    Claim(key="eft_3b_shallow", figure="3b", statement="linear velocity feedback compensation, 2.3 kN: required "
          "forces applied over the whole range, with a shallow drop", paper_text="shallow drop, forces applied 0-10 Hz",
          tolerance_text="shallow: 0.80 <= min |F/P| < 0.97", interval=(0.80, 0.97), value=ev.eft_3b_shallow),
    Claim(key="eft_3b_band", figure="3b", statement="the shallow drop lies between 1 and 4 Hz", paper_text="1-4 Hz",
          tolerance_text="1-4 Hz", interval=(1.0, 4.0), value=ev.eft_3b_band),
    Claim(key="eft_3b_spool", figure="3b / p. 1780", statement="the 2.3 kN test needs a small spool opening",
          paper_text="less than 10 %", paper_value=10.0, tolerance_text="< 10 %", interval=(0.0, 10.0),
          why=_SPOOL_WHY, value=ev.eft_3b_spool),
    Claim(key="eft_4b_drop", figure="4b", statement="8.9 kN with linear compensation: sharp drop at the natural "
          "frequency", paper_text="sharp drop at f_n", tolerance_text="sharp: min |F/P| < 0.70, within f_n +- 0.2 Hz",
          interval=(0.0, 0.70), value=ev.eft_4b_drop),
    Claim(key="eft_4b_flow_model", figure="4b", statement="the simulation with the nonlinear flow model explains the "
          "drop; with a linear flow model it does not", paper_text="nonlinear flow model needed",
          tolerance_text="no sharp drop without the flow nonlinearity: min |F/P| >= 0.70", interval=(0.70, INF),
          value=ev.eft_4b_flow_model),
    Claim(key="eft_4c_nonlinear", figure="4c", statement="nonlinear velocity feedback compensation (inverse flow curve "
          "and load pressure) greatly improves the applied force", paper_text="greatly improved",
          tolerance_text="no sharp drop: 0.80 <= min |F/P|, max <= 1.2", interval=(0.80, INF),
          value=ev.eft_4c_nonlinear),
    Claim(key="eft_under", figure="p. 1782", statement="under-compensated delay (no lead): force peak below the "
          "natural frequency", paper_text="peak below f_n", tolerance_text="< f_n", value=ev.eft_under),
    Claim(key="eft_over", figure="p. 1782", statement="over-compensated delay (12 ms lead): force peak above the "
          "natural frequency", paper_text="peak above f_n", tolerance_text="> f_n", value=ev.eft_over),
    Claim(key="eft_over_unstable", figure="p. 1782", statement="over-compensation of the delay might lead to "
          "instability", paper_text="possible instability",
          tolerance_text="a finite instability threshold above the tuned 5 ms, confirmed by a diverging simulation",
          interval=(1e3 * ev.T_EFT, 100.0), value=ev.eft_over_unstable),
)

DISPLACEMENT = (
    Claim(key="rolloff_eq13", figure="Eq (13)", statement="equivalent roll-off frequency K_v C_F K_s G_p / A",
          paper_text="1.96 Hz", paper_value=1.96, tolerance_text="+-0.02 Hz", interval=(1.94, 1.98),
          value=ev.rolloff_eq13),
    Claim(key="delay_eq13", figure="p. 1785", statement="total response delay 1/w_cRPD", paper_text="81 ms",
          paper_value=81.0, tolerance_text="+-1 ms", interval=(80.0, 82.0), value=ev.delay_eq13),
    Claim(key="rolloff_identified", figure="5a", statement="equivalent first-order roll-off identified from a 1.27 cm "
          "sweep", paper_text="1.96 Hz", paper_value=1.96, tolerance_text="+-5 %", interval=(0.95 * 1.96, 1.05 * 1.96),
          why="fit on the simulated sweep: the oil-column mode and the valve add lag above 1 Hz",
          value=ev.rolloff_identified),
    Claim(key="delay_identified", figure="5a", statement="equivalent response delay tau identified from the sweep",
          paper_text="81 ms", paper_value=81.0, tolerance_text="+-5 %", interval=(0.95 * 81, 1.05 * 81),
          value=ev.delay_identified),
    Claim(key="loss_2hz", figure="5a", statement="amplitude reduction at 2 Hz (uncompensated, 1.27 cm sweep)",
          paper_text="about 30 %", paper_value=30.0, tolerance_text="30 +- 5 %", interval=(25.0, 35.0),
          value=ev.loss_2hz),
    Claim(key="oil_column", figure="Eq (14)", statement="oil-column mode: 'slightly damped vibration mode'",
          paper_text="no value; slightly damped", tolerance_text="0 < zeta < 0.2", interval=(1e-6, 0.2),
          why="Table I as printed gives {printed:.1f} Hz by Eq (14) and an unstable closed-loop mode "
              "(docs/calibration.md)", value=ev.oil_column),
    Claim(key="T_amplitude", figure="6a", statement="amplitude-compensation time constant for 0-5 Hz (minimax)",
          paper_text="68 ms", paper_value=68.0, tolerance_text="+-3 ms", interval=(65.0, 71.0),
          why="K_a and C_l were calibrated with this as one target (docs/calibration.md)", value=ev.T_amplitude),
    Claim(key="band_68ms", figure="6a", statement="68 ms extends acceptable tracking to 5 Hz (|G_c| within 5 %)",
          paper_text="5 Hz", paper_value=5.0, tolerance_text="5-6 Hz (the sweep was stopped at 6 Hz)",
          interval=(5.0, 6.0), value=ev.band_68ms),
    Claim(key="overshoot_5b", figure="5b", statement="compensated 1.27 cm sweep: amplitude restored with a slight "
          "overshoot", paper_text="slight overshoot", tolerance_text="1.00-1.10", interval=(1.0, 1.10),
          why="the linear model overshoots ({linear:.3f}); in the nonlinear simulation the spool opens to "
              "{spool:.0f} % and |p| reaches {pressure:.0f} % of p_s below 5 Hz, where the flow gain (Fig 4a "
              "curve: linear to 10 %, 0.56 at full opening) and the load-pressure term of Eq (3) lower the gain: "
              "the mechanism the paper describes in its nonlinearity section; the flow curve is a modelling choice, "
              "not a measured one",
          value=ev.overshoot_5b),
    Claim(key="capacity", figure="5b", statement="required forces exceed the actuator capacity above 6 Hz (1.27 cm, "
          "68 ms compensation)", paper_text="above 6 Hz", paper_value=6.0,
          tolerance_text="6 +- 0.5 Hz (grid {grid:g} Hz)", interval=(5.5, 6.5),
          why="at p_s = 17 MPa the actuator delivers p_s A = 140 kN, below its 170 kN rating", value=ev.capacity),
)

GAIN_BOUND = (
    Claim(key="gp_falls_with_mass", figure="6b", statement="maximum P-gain falls as the physical mass grows",
          paper_text="decays with mass", tolerance_text="monotone decrease and Routh confirmed by the linearised model",
          interval=(1.0, 1.0), value=ev.gp_falls_with_mass),
    Claim(key="gp_used_stable", figure="6b", statement="the gain used, G_p = 0.8059, is below the Routh bound at full "
          "mass", paper_text="0.8059 ran stably", paper_value=0.8059, tolerance_text="> 0.8059",
          why="Table I as printed gives G_p,max = {printed:.3f}: unstable at 0.8059 (docs/calibration.md)",
          value=ev.gp_used_stable),
)

_DELAY_WHY = ("the model's residual delay after the 68 ms lead is {residual:.1f} ms at 1.58 Hz, not 81 - 68 = 13 ms: "
              "a lead with alpha = 0.1 advances only ~53 ms, and the valve/oil column add lag (docs/calibration.md "
              "s. 4)")

RPSD_LINEAR = (
    Claim(key="T_ld_estimate", figure="p. 1786", statement="delay compensation estimated as total delay minus 68 ms",
          paper_text="81 - 68 = 13 ms", paper_value=13.0, tolerance_text="+-1 ms", interval=(12.0, 14.0),
          value=ev.T_ld_estimate),
    Claim(key="T_ld_final", figure="p. 1786", statement="finalised delay compensation (zero residual phase at "
          "1.58 Hz)", paper_text="11.2 ms", paper_value=11.2, tolerance_text="+-2 ms", interval=(9.2, 13.2),
          why=_DELAY_WHY, value=ev.T_ld_final),
    Claim(key="undercompensated_6ms", figure="8a", statement="6 ms delay compensation: negative damping, unstable",
          paper_text="unstable", tolerance_text="net zeta < 0", interval=(-INF, 0.0), value=ev.undercompensated_6ms),
    Claim(key="compensated_11ms", figure="9b", statement="11.2 ms: structural damping close to the modelled "
          "{z_model:.2f} % (Fig 9b 'slightly different damping')", paper_text="~{z_model:.2f} %",
          tolerance_text="within +-1 percentage point of the model", why=_DELAY_WHY, value=ev.compensated_11ms),
    Claim(key="overcompensated_16ms", figure="8b", statement="16 ms: over-compensation increases the damping above "
          "the model's", paper_text="> {z_model:.2f} %", tolerance_text="> {z_model:.2f} %",
          why=_DELAY_WHY + "; the trend (more damping with more lead) agrees", value=ev.overcompensated_16ms),
    Claim(key="force_direct", figure="10b", statement="using the force measurement directly changes the structural "
          "response dramatically", paper_text="dramatic change", tolerance_text="frequency shift > 10 %",
          interval=(10.0, INF), value=ev.force_direct),
    Claim(key="damping_term", figure="10b", statement="keeping the damping term in the restoring force changes the "
          "damping", paper_text="incorrect damping", tolerance_text="> 0.5 percentage point", interval=(0.5, INF),
          value=ev.damping_term),
    Claim(key="piston_inertia", figure="10b", statement="ignoring the 54 kg piston in the inertial term slightly "
          "changes the dominant frequency", paper_text="slight change", tolerance_text="0 < |shift| < 2 %",
          interval=(1e-6, 2.0), value=ev.piston_inertia),
    Claim(key="substructure_140kg", figure="10c", statement="with 2 % installed mass (140 kg) the effect of the "
          "inertial term is greatly reduced", paper_text="greatly reduced", tolerance_text="shift ratio < 0.25",
          interval=(0.0, 0.25), value=ev.substructure_140kg),
)

_SIM_DELAY_WHY = ("the model's residual loop delay after the 68 ms lead is larger than the paper's 13 ms: zero "
                  "residual phase at 1.58 Hz needs T_ld = {T_zero:.1f} ms, which gives zeta = {z_zero:+.2f} % (rows "
                  "T_ld_final, compensated_11ms; docs/calibration.md s. 4, docs/methods.md)")

RPSD = (
    Claim(key="sim_undercompensated_6ms", figure="8a", statement="6 ms delay compensation: negative damping, the "
          "response becomes unstable (simulation of the full model, free vibration from 1.6 cm)", paper_text="unstable",
          tolerance_text="zeta < 0", interval=(-INF, 0.0), value=ev.sim_undercompensated_6ms),
    Claim(key="sim_compensated_11ms", figure="9b", statement="11.2 ms: damping only slightly different from the "
          "model's {z_model:.2f} % (simulation of the full model)", paper_text="~{z_model:.2f} %",
          tolerance_text="within +-1 percentage point of the model", why=_SIM_DELAY_WHY,
          value=ev.sim_compensated_11ms),
    Claim(key="sim_overcompensated_16ms", figure="8b", statement="16 ms: over-compensation increases the damping "
          "above the model's (simulation of the full model)", paper_text="> {z_model:.2f} %",
          tolerance_text="> {z_model:.2f} %", why=_SIM_DELAY_WHY + "; the trend (damping grows with T_ld) agrees",
          value=ev.sim_overcompensated_16ms),
    Claim(key="spool_28", figure="8a / p. 1787", statement="maximum spool opening in the Fig 8(a) test (0-10 Hz, "
          "0.15 g ground-acceleration sweep, T_ld = 6 ms)", paper_text="28 %", paper_value=28.0,
          tolerance_text="28 +- 5 %", interval=(23.0, 33.0),
          why="the solver's own SDOF (zeta {z_model:.2f} %) answers this sweep with a peak of {x_peak:.0f} mm and "
              "{v_peak:.2f} m/s (exact, no servo-system), which needs g(x_v) = A v / K_v = {need:.2f}, i.e. "
              "{need_open:.0f} % opening even at zero load pressure; the 28 % is passed near resonance for every "
              "T_ld, before the delay compensation matters. The paper gives neither the sweep duration nor when the "
              "unstable test was stopped, so its 28 % cannot be reproduced; the damping comparison is made on the "
              "free vibration (rows above)", value=ev.spool_28),
    Claim(key="fig9a_structural", figure="9a", statement="calculated displacements for the restoring force: the "
          "servo-system does not affect the structural response", paper_text="zeta = model {z_model:.2f} %",
          tolerance_text="+-0.05 percentage point of c_m / (2 sqrt(k m_m))",
          why="with calculated displacements the solver runs open loop, so this checks the loop's wiring and the "
              "central-difference solver against the closed form", value=ev.fig9a_structural),
    Claim(key="fig9a_tracking", figure="9a", statement="the measured response follows the expected (calculated) "
          "response closely with the 68 ms amplitude compensation", paper_text="follows closely", paper_value=1.0,
          tolerance_text="amplitude within +-5 % (the Fig 6a tolerance)", interval=(0.95, 1.05),
          why="the lag is the residual delay after the 68 ms lead (see the delay rows)", value=ev.fig9a_tracking),
    Claim(key="fig9b_error_11ms", figure="9b", statement="a restoring-force error 0.03 sin(w_n t - pi/2) kN makes the "
          "amplitude constant after 10 s (T_ld = 11.2 ms; t and the 10 s counted from release)",
          paper_text="constant amplitude after 10 s", tolerance_text="ratio within 0.8-1.25", interval=(0.8, 1.25),
          why="at 11.2 ms our loop has negative net damping ({z_11:+.2f} %), so the free vibration grows with or "
              "without the error; see the delay rows and the next row", value=ev.fig9b_error_11ms),
    Claim(key="fig9b_error_equivalent", figure="9b", statement="the same error with the delay compensation that "
          "gives our loop the paper's near-model damping (T_ld = {T_zero:.1f} ms, zero residual phase at 1.58 Hz)",
          paper_text="constant amplitude after 10 s", tolerance_text="ratio within 0.8-1.25", interval=(0.8, 1.25),
          why="the mechanism is confirmed (a force error at the structure's frequency sustains an amplitude of order "
              "F/(2 zeta k), whatever its phase) but not the timing: from 16 mm at zeta {z_zero:.2f} % the free decay "
              "is still {a_10:.2f} mm at 10 s, above the {a_ss:.2f} mm the error sustains. The same holds for any "
              "zeta near the model's 2.48 %; the paper's time origin in Fig 9b is not stated",
          value=ev.fig9b_error_equivalent),
    Claim(key="fig10a_force_vs_kx", figure="10a", statement="the load-cell reading is vastly different from the "
          "restoring force k x (calculated displacements, free vibration)", paper_text="vastly different",
          tolerance_text="> 0.5", interval=(0.5, INF), value=ev.fig10a_force_vs_kx),
    Claim(key="fig10a_force_vs_input", figure="10a", statement="the measured force should be the force input to the "
          "SDOF solver (external force), as the paper's simulation shows", paper_text="measured force = solver input",
          tolerance_text="< 10 % of the peak input", interval=(0.0, 10.0), value=ev.fig10a_force_vs_input),
)

TABLE1 = (
    Claim(key="table1_stability", figure="Table I", statement="displacement loop stable at G_p = 0.8059 (tests ran)",
          paper_text="stable", tolerance_text="max Re(pole) < 0 (calibrated preset)", interval=(-INF, 0.0),
          why="Table I as printed (K_a = 3e-12, C_l = 1e-12) is unstable; K_a = 1.36e-12, C_l = 3.4e-11 chosen in "
              "docs/calibration.md", value=ev.table1_stability),
    Claim(key="table1_oil_volume", figure="Table I", statement="K_a = V_t/(4 beta_e) consistent with the actuator's "
          "oil volume", paper_text="K_a = 3e-12 m^5/N", tolerance_text="V_t within 1-3x the swept volume (calibrated)",
          interval=(1.0, 3.0), why="printed K_a needs 5.7x the swept volume: rejected (docs/calibration.md s. 1)",
          value=ev.table1_oil_volume),
)

#: the claims of each section of the table, in the paper's figure order
CLAIMS = {"structure": STRUCTURE, "force": FORCE, "eft": EFT, "displacement": DISPLACEMENT,
          "gain_bound": GAIN_BOUND, "rpsd_linear": RPSD_LINEAR, "rpsd": RPSD, "table1": TABLE1}

__all__ = ["CLAIMS", "Claim", "SWEEP_DURATION"]
