// The rig's parameters, one table: section and key of the rig file, unit, meaning,
// source, the bound that Rig::validate() checks, and the member of Rig.  The
// bindings (def_readwrite, _core.RIG_PARAMETERS), Python's rig.PARAMETERS, the
// rig-file reader and the README's key table are all generated from it.
// Adding a parameter = one field in Rig (rig.hpp) + one row here.
#pragma once

#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! What Rig::validate() requires of a parameter (finite, always).
enum class Bound {
  Positive,     //!< > 0
  NonNegative,  //!< >= 0
  AtLeastOne,   //!< >= 1
  PadeOrder,    //!< an integer in 1..kMaxPadeOrder
  Finite,       //!< any finite value (a signed coefficient)
};

struct ParameterInfo {
  const char* section;  //!< rig-file table: structure, actuator, servovalve, controller
  const char* key;      //!< the field's name (the paper's symbol)
  const char* unit;     //!< SI unit
  const char* doc;      //!< meaning
  const char* source;   //!< where the default comes from (Table I, page, calibration)
  Bound bound;          //!< validation
  double Rig::*member;
};

inline constexpr ParameterInfo kRigParameters[] = {
    {"structure", "m", "kg", "mass of the structure", "Table I (7084 kg)", Bound::Positive, &Rig::m},
    {"structure", "c", "N s/m", "viscous damping", "Table I: 2.1 kN s/m attached, 1.1 free", Bound::NonNegative,
     &Rig::c},
    {"structure", "k", "N/m", "initial stiffness", "Table I; p. 1777: 4 x 175.2 kN/m", Bound::Positive, &Rig::k},
    {"structure", "k_2", "N/m", "stiffness beyond +-x_contact", "p. 1777: 350.4 kN/m", Bound::NonNegative,
     &Rig::k_2},
    {"structure", "x_contact", "m", "displacement where a spring pair loses contact", "p. 1777: 2.5 cm",
     Bound::Positive, &Rig::x_contact},
    {"structure", "F_c", "N", "Coulomb friction", "Table I: 31.6 N attached, 95.7 N free", Bound::NonNegative,
     &Rig::F_c},
    {"structure", "v_stick", "m/s", "friction regularisation: F = g(v) tanh(v/v_stick); 0: the exact stick-slip law",
     "modelling choice, docs/model.md", Bound::NonNegative, &Rig::v_stick},
    {"structure", "stribeck_ratio", "-", "static to sliding friction F_s/F_c (Stribeck peak; 1: none)",
     "not in the paper: 1", Bound::AtLeastOne, &Rig::stribeck_ratio},
    {"structure", "v_s", "m/s", "Stribeck velocity", "not in the paper: 0.01 m/s", Bound::Positive, &Rig::v_s},
    {"structure", "sigma_0", "N/m", "LuGre bristle (presliding) stiffness (effects.lugre_friction)",
     "not in the paper: 1e6 N/m", Bound::Positive, &Rig::sigma_0},
    {"structure", "sigma_1", "N s/m", "LuGre bristle damping (effects.lugre_friction)", "not in the paper: 0",
     Bound::NonNegative, &Rig::sigma_1},
    {"structure", "m_p", "kg", "actuator piston mass", "p. 1782: 54 kg", Bound::NonNegative, &Rig::m_p},
    {"actuator", "A", "m^2", "piston area", "Table I: 82.1 cm^2", Bound::Positive, &Rig::A},
    {"actuator", "K_a", "m^5/N", "compressibility coefficient V_t/(4 beta_e)", "calibrated, docs/calibration.md",
     Bound::Positive, &Rig::K_a},
    {"actuator", "C_l", "m^3/(s Pa)", "total flow-pressure (leakage) coefficient", "calibrated, docs/calibration.md",
     Bound::NonNegative, &Rig::C_l},
    {"actuator", "p_s", "Pa", "supply pressure", "Table I: 1.7e4 kN/m^2", Bound::Positive, &Rig::p_s},
    {"actuator", "F_cap", "N", "rated actuator capacity (reported when exceeded)", "p. 1777: 170 kN",
     Bound::Positive, &Rig::F_cap},
    {"actuator", "stroke", "m", "half-stroke (reported when exceeded; no end stop modelled)",
     "C_F = 78.74 V/m: 10 V at 127 mm", Bound::Positive, &Rig::stroke},
    {"servovalve", "K_v", "m^3/s", "main-stage flow gain at null", "Table I: 1.6e-2 m^3/s", Bound::Positive,
     &Rig::K_v},
    {"servovalve", "K_s", "1/V", "static valve gain 1/k_ev", "Table I: 0.1", Bound::Positive, &Rig::K_s},
    {"servovalve", "f_v", "Hz", "servovalve natural frequency (Eq 2)", "chosen, docs/calibration.md",
     Bound::Positive, &Rig::f_v},
    {"servovalve", "zeta_v", "-", "servovalve damping ratio (Eq 2)", "chosen: 'highly damped', docs/calibration.md",
     Bound::Positive, &Rig::zeta_v},
    {"servovalve", "x_v_max", "-", "spool opening limit (end stops)", "Eq (2): |x_v| <= 1", Bound::Positive,
     &Rig::x_v_max},
    {"controller", "C_F_disp", "V/m", "conversion factor, displacement control", "Table I: 78.74 V/m",
     Bound::Positive, &Rig::C_F_disp},
    {"controller", "C_F_force", "V/N", "conversion factor, force control", "Table I: 0.056 V/kN", Bound::Positive,
     &Rig::C_F_force},
    {"controller", "G_p", "-", "proportional gain", "Table I: 0.8059", Bound::NonNegative, &Rig::G_p},
    {"controller", "G_d", "s", "derivative gain", "Table I: 0.0", Bound::NonNegative, &Rig::G_d},
    {"controller", "v_max", "V", "valve drive limit", "MTS 407: +-10 V", Bound::Positive, &Rig::v_max},
    {"specimen", "bw_k", "N/m", "Bouc-Wen stiffness (F_bw = bw_k z; small-amplitude stiffness bw_k bw_A)",
     "not in the paper: a specimen as stiff as two springs", Bound::NonNegative, &Rig::bw_k},
    {"specimen", "bw_A", "-", "Bouc-Wen A", "Wen (1976): 1", Bound::Positive, &Rig::bw_A},
    {"specimen", "bw_beta", "1/m^n", "Bouc-Wen beta", "not in the paper: z_u = 1 cm with gamma",
     Bound::NonNegative, &Rig::bw_beta},
    {"specimen", "bw_gamma", "1/m^n", "Bouc-Wen gamma", "not in the paper: z_u = 1 cm with beta",
     Bound::NonNegative, &Rig::bw_gamma},
    {"specimen", "bw_n", "-", "Bouc-Wen exponent n", "Wen (1976): n >= 1; 1 (smooth yield)", Bound::AtLeastOne,
     &Rig::bw_n},
    {"specimen", "mr_alpha_a", "N/m", "MR damper alpha = alpha_a + alpha_b u (+ alpha_c u^2: mr_law)",
     "Spencer et al. 1997 Table 1", Bound::NonNegative, &Rig::mr_alpha_a},
    {"specimen", "mr_alpha_b", "N/(m u)", "MR damper alpha's slope by the field input u (V or A: mr_input)",
     "Spencer et al. 1997 Table 1 (per V)", Bound::NonNegative, &Rig::mr_alpha_b},
    {"specimen", "mr_c0_a", "N s/m", "MR damper viscous c0 = c0_a + c0_b u (high velocity)",
     "Spencer et al. 1997 Table 1", Bound::Positive, &Rig::mr_c0_a},
    {"specimen", "mr_c0_b", "N s/(m u)", "MR damper c0's slope by the field input u (V or A: mr_input)",
     "Spencer et al. 1997 Table 1 (per V)", Bound::NonNegative, &Rig::mr_c0_b},
    {"specimen", "mr_c1_a", "N s/m", "MR damper c1 = c1_a + c1_b u (roll-off at low velocity)",
     "Spencer et al. 1997 Table 1", Bound::Positive, &Rig::mr_c1_a},
    {"specimen", "mr_c1_b", "N s/(m u)", "MR damper c1's slope by the field input u (V or A: mr_input)",
     "Spencer et al. 1997 Table 1 (per V)", Bound::NonNegative, &Rig::mr_c1_b},
    {"specimen", "mr_k0", "N/m", "MR damper stiffness k0 (large velocities)", "Spencer et al. 1997 Table 1",
     Bound::NonNegative, &Rig::mr_k0},
    {"specimen", "mr_k1", "N/m", "MR damper accumulator stiffness k1", "Spencer et al. 1997 Table 1",
     Bound::NonNegative, &Rig::mr_k1},
    {"specimen", "mr_x0", "m", "MR damper accumulator initial displacement x0", "Spencer et al. 1997 Table 1",
     Bound::NonNegative, &Rig::mr_x0},
    {"specimen", "mr_A", "-", "MR damper Bouc-Wen A", "Spencer et al. 1997 Table 1", Bound::NonNegative,
     &Rig::mr_A},
    {"specimen", "mr_beta", "1/m^n", "MR damper Bouc-Wen beta (on (x'-y') abs(z)^n)", "Spencer et al. 1997 Table 1",
     Bound::NonNegative, &Rig::mr_beta},
    {"specimen", "mr_gamma", "1/m^n", "MR damper Bouc-Wen gamma (on abs(x'-y') z abs(z)^(n-1))",
     "Spencer et al. 1997 Table 1", Bound::NonNegative, &Rig::mr_gamma},
    {"specimen", "mr_n", "-", "MR damper Bouc-Wen exponent n", "Spencer et al. 1997 Table 1", Bound::AtLeastOne,
     &Rig::mr_n},
    {"specimen", "mr_voltage", "V", "MR damper command voltage u (constant over a run; mr_input = voltage)",
     "Spencer et al. 1997 tested 0-2.25 V", Bound::NonNegative, &Rig::mr_voltage},
    {"specimen", "mr_current", "A", "MR damper coil current u (constant over a run; mr_input = current)",
     "not in the paper: 0", Bound::NonNegative, &Rig::mr_current},
    {"specimen", "mr_alpha_c", "N/(m u^2)", "MR damper alpha's curvature in u (mr_law = quiroz2022)",
     "Quiroz 2022 (UTFSM thesis): -38.152 N/(mm A^2); 0 under spencer", Bound::Finite, &Rig::mr_alpha_c},
    {"specimen", "mr_bw_decay", "1/u", "MR damper beta, gamma times exp(-mr_bw_decay u) (mr_law = quiroz2022)",
     "Quiroz 2022 (UTFSM thesis): 3.6561 1/A; 0 under spencer", Bound::Finite, &Rig::mr_bw_decay},
    {"specimen", "mr_law_min", "u", "lowest field input the MR damper law was identified on (below: reported)",
     "Spencer et al. 1997 tested 0-2.25 V", Bound::NonNegative, &Rig::mr_law_min},
    {"specimen", "mr_law_max", "u", "highest field input the MR damper law was identified on (above: reported)",
     "Spencer et al. 1997 tested 0-2.25 V", Bound::NonNegative, &Rig::mr_law_max},
    {"delays", "command_delay", "s", "digital command delay (held command switches at t_k + delay)",
     "not in the paper: 0; at most 64 samples", Bound::NonNegative, &Rig::command_delay},
    {"delays", "measurement_delay_displacement", "s", "acquisition delay of the displacement channel",
     "not in the paper: 0; at most 64 samples", Bound::NonNegative, &Rig::measurement_delay_displacement},
    {"delays", "measurement_delay_force", "s", "acquisition delay of the force channel",
     "not in the paper: 0; at most 64 samples", Bound::NonNegative, &Rig::measurement_delay_force},
    {"delays", "loop_delay", "s", "analog transport delay on the valve drive (effects.loop_delay, Pade)",
     "not in the paper: 2 ms", Bound::Positive, &Rig::loop_delay},
    {"delays", "loop_delay_order", "-", "Pade order of loop_delay", "modelling choice: 3", Bound::PadeOrder,
     &Rig::loop_delay_order},
    {"specimen", "fd_c", "N (s/m)^alpha", "fluid damper coefficient: F = fd_c abs(u')^fd_alpha sign(u')",
     "not in the paper: 20 kN at 1 m/s", Bound::Positive, &Rig::fd_c},
    {"specimen", "fd_alpha", "-", "fluid damper velocity exponent, in (0, 1]",
     "not in the paper: 0.5 (fluid viscous dampers: 0.3-1)", Bound::Positive, &Rig::fd_alpha},
    {"specimen", "fd_k", "N/m", "fluid damper series (Maxwell) stiffness",
     "not in the paper: 20 MN/m", Bound::Positive, &Rig::fd_k},
};

struct EffectInfo {
  const char* key;  //!< the switch's name in [effects] of a rig file
  const char* doc;  //!< what it switches
  bool Effects::*member;
};

//! A rig-file key whose value is a name (an enum of the rig): section, key, meaning, source.  Its
//! names come from the enum's table (rig.hpp); the binding, the rig file and the FMU each spell
//! out the two (mr_input: kMrInputNames, mr_law: kMrLawNames).
struct ChoiceInfo {
  const char* section;
  const char* key;
  const char* doc;
  const char* source;
};

inline constexpr ChoiceInfo kMrInputChoice = {
    "specimen", "mr_input", "MR damper field input u: \"voltage\" (mr_voltage [V]) or \"current\" (mr_current [A])",
    "Spencer et al. 1997: voltage"};
inline constexpr ChoiceInfo kMrLawChoice = {
    "specimen", "mr_law",
    "MR damper law of alpha, c0, c1, beta, gamma in u: \"spencer\" (linear) or \"quiroz2022\" (the UTFSM thesis)",
    "Spencer et al. 1997: spencer"};

inline constexpr EffectInfo kEffects[] = {
    {"servovalve_dynamics", "Eq (2) second-order valve; off: static valve (Eq 6)", &Effects::servovalve_dynamics},
    {"load_pressure", "square-root load-pressure term of Eq (3); off: Eq (7)", &Effects::load_pressure},
    {"flow_nonlinearity", "flow gain falling with opening (Fig 4a); off: g(x) = x", &Effects::flow_nonlinearity},
    {"coulomb_friction", "F_c term of Eq (5)", &Effects::coulomb_friction},
    {"spring_softening", "stiffness k_2 beyond +-x_contact", &Effects::spring_softening},
    {"piston_mass", "piston mass m_p moves with the structure", &Effects::piston_mass},
    {"drive_saturation", "valve drive limited to +-v_max", &Effects::drive_saturation},
    {"spool_saturation", "spool opening limited to +-x_v_max", &Effects::spool_saturation},
    {"lugre_friction", "LuGre presliding friction instead of the static law", &Effects::lugre_friction},
    {"bouc_wen_hysteresis", "Bouc-Wen hysteretic specimen (state bw_z)", &Effects::bouc_wen_hysteresis},
    {"mr_damper", "MR damper, Spencer et al. 1997 (states mr_y, mr_z)", &Effects::mr_damper},
    {"loop_delay", "Pade transport delay loop_delay on the valve drive", &Effects::loop_delay},
    {"fluid_damper", "nonlinear viscous fluid damper with a series stiffness (state fd_u)", &Effects::fluid_damper},
};

//! The requirement of a bound, for messages and docs: "finite and > 0".
const char* bound_text(Bound b) noexcept;
//! Whether v meets the bound (finite, and the bound).
bool within(Bound b, double v) noexcept;

}  // namespace servohydraulics
