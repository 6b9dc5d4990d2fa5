// Parameters of a servo-hydraulic test rig: Eqs (1)-(5) of Zhao, French, Shield,
// Posbergh (2003), "Considerations for the development of real-time dynamic
// testing using servo-hydraulic actuation", EESD 32:1773-1794.
//
// Everything is SI: m, kg, s, N, Pa, V. The defaults are the calibrated preset
// of the paper's rig (see presets.hpp and docs/calibration.md).
#pragma once

#include <string>
#include <vector>

#include "servohydraulics/enum_name.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics {

//! Longest digital delay (command or measurement) a plant accepts, in samples of its dt.
constexpr int kMaxDelaySamples = 64;

//! Normalised flow-spool opening curve g(x_v) of Fig 4(a): Q = K_v g(x_v) at
//! zero load pressure, with g odd, g(0) = 0 and g'(0) = 1 so that K_v is the
//! initial (null) flow gain of Eq (7).  The curve must be strictly increasing
//! so that the nonlinear velocity-feedback compensator can invert it.
struct FlowCurve {
  enum class Kind {
    Rational,  //!< g(x) = x / (1 + b |x|): gain falls from 1 to 1/(1+b)^2 at full opening
    Table,     //!< piecewise linear through (opening[i], flow[i]), mirrored for x < 0
  };
  Kind kind = Kind::Rational;
  double b = 0.6;                  //!< Rational shape factor [-]; g(1) = 1/(1+b)
  std::vector<double> opening;     //!< Table: spool openings in [0, 1], first 0, increasing [-]
  std::vector<double> flow;        //!< Table: normalised flow Q/K_v at those openings [-]

  double eval(double x) const noexcept;     //!< g(x)
  double slope(double x) const noexcept;    //!< g'(x)
  double inverse(double q) const noexcept;  //!< x with g(x) = q (clamped to the curve's range)
  void validate() const;                    //!< throws Error naming the bad field
};
//! servovalve.flow_curve.kind of a rig file.
inline constexpr EnumName<FlowCurve::Kind> kFlowCurveKindNames[] = {
    {FlowCurve::Kind::Rational, "rational", "Rational"},
    {FlowCurve::Kind::Table, "table", "Table"},
};
static_assert(in_enum_order(kFlowCurveKindNames), "kFlowCurveKindNames: one row per enumerator, in order");

//! The flow curve of the preset: linear (g = x) below 10 % opening, where the
//! paper found the constant initial gain adequate (p. 1780), bending to the
//! rated flow at full opening: the MTS 256.09 is rated 5.7 l/s (90 gpm) at the
//! standard 6.9 MPa valve drop, i.e. 5.7 sqrt(17 / 6.9) = 8.95 l/s at the
//! 17 MPa supply with no load, g(1) = 8.95 / 16 = 0.56.  Slopes fall
//! monotonically (concave), so the curve is invertible.  docs/calibration.md.
FlowCurve zhao2003_flow_curve();

//! The MR damper's field input u (rig file: [specimen] mr_input): the coil current mr_current [A]
//! or the command voltage mr_voltage [V]; the law's coefficients are per unit of it.
enum class MrInput {
  Voltage,  //!< u = mr_voltage [V] (Spencer et al. 1997 drive a current driver by a voltage)
  Current,  //!< u = mr_current [A] (a damper driven by a current-controlled amplifier)
};
inline constexpr EnumName<MrInput> kMrInputNames[] = {
    {MrInput::Voltage, "voltage", "Voltage"},
    {MrInput::Current, "current", "Current"},
};
static_assert(in_enum_order(kMrInputNames), "kMrInputNames: one row per enumerator, in order");

//! The law of the MR damper's field-dependent parameters (rig file: [specimen] mr_law).
enum class MrLaw {
  //! Spencer et al. (1997): alpha, c0, c1 = (.)_a + (.)_b u; beta, gamma constant
  Spencer,
  //! Quiroz (2022, UTFSM MSc thesis, chapter 7): alpha = alpha_a + alpha_b u + alpha_c u^2, c0 and
  //! c1 as Spencer's, beta and gamma times exp(-mr_bw_decay u) (the thesis: beta = gamma)
  Quiroz2022,
};
inline constexpr EnumName<MrLaw> kMrLawNames[] = {
    {MrLaw::Spencer, "spencer", "Spencer"},
    {MrLaw::Quiroz2022, "quiroz2022", "Quiroz2022"},
};
static_assert(in_enum_order(kMrLawNames), "kMrLawNames: one row per enumerator, in order");

//! Which physical effects are on.  Off gives the paper's linear-analysis model
//! (Eqs 6-8) piece by piece.
struct Effects {
  bool servovalve_dynamics = true;  //!< Eq (2) second order; off: static valve v = k_ev x_v (Eq 6)
  bool load_pressure = true;        //!< square-root load-pressure term of Eq (3); off: Eq (7)
  bool flow_nonlinearity = true;    //!< flow gain falling with opening (Fig 4a); off: linear g(x) = x
  bool coulomb_friction = true;     //!< F_c term of Eq (5)
  bool spring_softening = true;     //!< stiffness k_2 beyond +-x_contact (springs lose contact)
  bool piston_mass = true;          //!< piston mass m_p moves with the structure, seen by the load cell
  bool drive_saturation = true;     //!< valve drive limited to +-v_max (controller output stage)
  bool spool_saturation = true;     //!< metering opening limited to [-x_v_max, x_v_max] (spool end stops)
  //! friction is the LuGre model (bristle deflection z, presliding stiffness sigma_0) instead of the
  //! static law g(v) tanh(v / v_stick); acts only with coulomb_friction on.  Off by default: Table I
  //! gives no presliding data.
  bool lugre_friction = false;
  //! a Bouc-Wen hysteretic specimen in parallel with the structure (state bw_z; docs/specimens.md)
  bool bouc_wen_hysteresis = false;
  //! an MR damper (Spencer et al. 1997, states mr_y, mr_z) in parallel with the structure
  bool mr_damper = false;
  //! a transport delay of loop_delay [s] on the valve drive, as a Pade approximant of order
  //! loop_delay_order (states delay_1..N; inactive in free mode)
  bool loop_delay = false;
  //! a nonlinear viscous fluid damper in series with a Maxwell stiffness, in parallel with the
  //! structure (state fd_u; docs/specimens.md)
  bool fluid_damper = false;
};

//! Parameters of the rig.  Field names follow the paper's symbols (Table I).
struct Rig {
  // --- Structure, Eq (5) -----------------------------------------------------
  double m = 7084.0;        //!< mass of the structure [kg] (Table I)
  double c = 2.1e3;         //!< viscous damping [N s/m] (Table I, actuator attached: 1.5 %)
  double k = 700.8e3;       //!< initial stiffness [N/m] (Table I; 4 springs x 175.2 kN/m)
  double k_2 = 350.4e3;     //!< stiffness beyond +-x_contact [N/m] (p. 1777: one pair loses contact)
  double x_contact = 0.025; //!< displacement where one spring pair loses contact [m] (2.5 cm precompression)
  double F_c = 31.6;        //!< Coulomb friction [N] (Table I, actuator attached)
  //! friction regularisation velocity: F = g(v) tanh(v / v_stick) [m/s]; 0 chooses the exact law
  //! (stick at v = 0 while the other forces stay within g(0), the switches located in time: ExactCoulomb)
  double v_stick = 1e-4;
  double stribeck_ratio = 1.0;  //!< static to sliding friction F_s / F_c >= 1; g(v) = F_c (1 + (ratio - 1) exp(-(v/v_s)^2)) [-]
  double v_s = 0.01;        //!< Stribeck velocity [m/s]
  double sigma_0 = 1e6;     //!< LuGre bristle (presliding) stiffness [N/m]
  double sigma_1 = 0.0;     //!< LuGre bristle (micro-)damping [N s/m]
  double m_p = 54.0;        //!< actuator piston mass [kg] (p. 1782)

  // --- Actuator, Eq (4) ------------------------------------------------------
  double A = 82.1e-4;       //!< piston area [m^2] (Table I)
  double K_a = 1.36e-12;    //!< compressibility coefficient V_t/(4 beta_e) [m^5/N] (calibrated; printed 3e-12)
  double C_l = 3.4e-11;     //!< total flow-pressure coefficient, valve null K_c0 + leakage [m^3/(s Pa)] (calibrated; printed 1e-12)
  double p_s = 1.7e7;       //!< supply pressure [Pa] (Table I)
  double F_cap = 170e3;     //!< rated actuator capacity [N] (p. 1777), reported when exceeded
  double stroke = 0.127;    //!< actuator half-stroke [m] (C_F = 78.74 V/m: 10 V at 127 mm), reported when exceeded

  // --- Servovalve, Eqs (2), (3), (6), (7) ------------------------------------
  double K_v = 1.6e-2;      //!< main-stage flow gain at null [m^3/s per unit opening] (Table I)
  double K_s = 0.1;         //!< static valve gain 1/k_ev [1/V] (Table I)
  double f_v = 70.7;        //!< servovalve natural frequency [Hz] (chosen: 4.5 ms group delay, -3 dB at 45 Hz; docs/calibration.md)
  double zeta_v = 1.0;      //!< servovalve damping ratio [-] ("highly damped": critically damped)
  double x_v_max = 1.0;     //!< metering opening limit (spool end stop) [-] (Eq 2: -1 <= x_v <= 1)
  FlowCurve flow_curve = zhao2003_flow_curve();  //!< g(x_v) of Fig 4(a)

  // --- Servo controller, Eq (1) ----------------------------------------------
  double C_F_disp = 78.74;     //!< conversion factor, displacement control [V/m] (Table I)
  double C_F_force = 0.056e-3; //!< conversion factor, force control [V/N] (Table I: 0.056 V/kN)
  double G_p = 0.8059;         //!< proportional gain [-] (Table I)
  double G_d = 0.0;            //!< derivative gain [s] (Table I)
  double v_max = 10.0;         //!< valve drive limit [V]

  // --- Specimen: Bouc-Wen hysteresis (effects.bouc_wen_hysteresis) ------------
  // F_bw = bw_k z,  z' = bw_A v - bw_beta |v| |z|^(n-1) z - bw_gamma v |z|^n  (Wen 1976)
  double bw_k = 350.4e3;    //!< Bouc-Wen stiffness: small-amplitude stiffness is bw_k bw_A [N/m]
  double bw_A = 1.0;        //!< Bouc-Wen A [-]
  double bw_beta = 50.0;    //!< Bouc-Wen beta [1/m^n]
  double bw_gamma = 50.0;   //!< Bouc-Wen gamma [1/m^n]
  double bw_n = 1.0;        //!< Bouc-Wen exponent n >= 1 [-]

  // --- Specimen: MR damper, Spencer, Dyke, Sain, Carlson (1997) (effects.mr_damper) ---
  // F = c1 y' + k1 (x - x0),  y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1),
  // z' = -gamma |x' - y'| z |z|^(n-1) - beta (x' - y') |z|^n + A (x' - y'),
  // alpha, c0, c1 = (.)_a + (.)_b u (+ alpha_c u^2) with u the field input (mr_input: the voltage or
  // the current, held constant per run) by the law mr_law (mr_damper_law in elements/mr_damper.hpp).
  double mr_alpha_a = 140e2;   //!< alpha_a [N/m] (Spencer 1997 Table 1: 140 N/cm)
  double mr_alpha_b = 695e2;   //!< alpha_b [N/(m V)] (695 N/(cm V))
  double mr_c0_a = 21.0e2;     //!< c0a [N s/m] (21.0 N s/cm)
  double mr_c0_b = 3.50e2;     //!< c0b [N s/(m V)] (3.50 N s/(cm V))
  double mr_c1_a = 283e2;      //!< c1a [N s/m] (283 N s/cm)
  double mr_c1_b = 2.95e2;     //!< c1b [N s/(m V)] (2.95 N s/(cm V))
  double mr_k0 = 46.9e2;       //!< k0 [N/m] (46.9 N/cm)
  double mr_k1 = 5.00e2;       //!< k1, accumulator stiffness [N/m] (5.00 N/cm)
  double mr_x0 = 14.3e-2;      //!< x0, accumulator initial displacement [m] (14.3 cm)
  double mr_A = 301.0;         //!< A [-] (301)
  double mr_beta = 363e4;      //!< beta [1/m^2] (363 cm^-2)
  double mr_gamma = 363e4;     //!< gamma [1/m^2] (363 cm^-2)
  double mr_n = 2.0;           //!< n >= 1 [-] (2)
  double mr_voltage = 0.0;     //!< command voltage u, constant over a run [V] (mr_input = voltage)
  double mr_current = 0.0;     //!< coil current u, constant over a run [A] (mr_input = current)
  double mr_alpha_c = 0.0;     //!< alpha's curvature [N/(m u^2)] (mr_law = quiroz2022; thesis: -38.152 N/(mm A^2))
  double mr_bw_decay = 0.0;    //!< beta, gamma times exp(-mr_bw_decay u) [1/u] (quiroz2022; thesis: 3.6561 /A)
  double mr_law_min = 0.0;     //!< field input range the law was identified on: a run outside is
  double mr_law_max = 2.25;    //!< reported as an extrapolation [u] (Spencer et al. 1997 tested 0-2.25 V)
  MrInput mr_input = MrInput::Voltage;  //!< which field input u is
  MrLaw mr_law = MrLaw::Spencer;        //!< the law of alpha, c0, c1, beta, gamma in u

  // --- Specimen: nonlinear viscous fluid damper (effects.fluid_damper) ----------
  // F = fd_k (x - u) = fd_c |u'|^fd_alpha sign(u')  (the dashpot in series with its stiffness)
  double fd_c = 20e3;       //!< damping coefficient [N (s/m)^alpha]
  double fd_alpha = 0.5;    //!< velocity exponent, 0 < alpha <= 1 [-]
  double fd_k = 20e6;       //!< series (Maxwell) stiffness: brace, fluid and seals [N/m]

  // --- Delays inside the loop --------------------------------------------------
  //! digital command delay [s] (computation/communication latency): the held command
  //! switches at t_k + command_delay; at most kMaxDelaySamples samples (checked by the plant)
  double command_delay = 0.0;
  double measurement_delay_displacement = 0.0;  //!< acquisition delay of the displacement channel [s]
  double measurement_delay_force = 0.0;         //!< acquisition delay of the force channel [s]
  double loop_delay = 2e-3;        //!< analog transport delay on the valve drive [s] (effects.loop_delay)
  double loop_delay_order = 3.0;   //!< its Pade order, an integer in 1..kMaxPadeOrder [-]

  Effects effects;

  //! Throws Error naming the first invalid field and its value.
  void validate() const;
};

}  // namespace servohydraulics
