// The controller side of the paper's two real-time test methods (Zhao et al.
// 2003, Figs 1 and 7), apart from the plant: the part a laboratory deploys on its
// own actuator.  Each controller reads the sensors at t_k and returns the command
// to hold over [t_k, t_k + dt]:
//
//   Output sensors;                 // from the rig's I/O (or Plant::observe/step)
//   double u = ctrl.command(sensors, ground_acceleration);
//   // write u to the servo controller; wait for the next sample
//
// Construct once (validates, throws Error, allocates the compute-delay buffer);
// reset() and command() are noexcept and allocation-free.  The simulated loops
// of loops.hpp are a controller composed with a Plant.  A config holds only what
// its controller uses: how the loops simulate the plant (its ODE integrator, the
// RPsD plant's mass) is their own EftLoopOptions / RpsdLoopOptions (loops.hpp).
//
// Symbols of the phase-lead time constants: Table I and the text of the paper
// swap T_d and T_ld.  We follow the text: T_d = 68 ms is the amplitude
// compensation (on the displacement command), T_ld = 11.2 ms the delay
// compensation (on the restoring force).  The EFT lead is Table I's T_d-hat = 5 ms.
#pragma once

#include <optional>
#include <variant>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/compensators.hpp"
#include "servohydraulics/config_fields.hpp"
#include "servohydraulics/integration.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/substructure.hpp"
#include "servohydraulics/tracking.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace servohydraulics {

// ---------------------------------------------------------------------------
// Effective force testing (force control, Fig 1a)
// ---------------------------------------------------------------------------

struct EftConfig {
  double dt = Zhao2003TestMethods{}.dt;  //!< controller sample time [s] (2 kHz DSP)
  std::optional<double> mass;            //!< m in P_eff = -m a_g [kg]; none = the rig's structural mass
  VelocityFeedbackCompensator::Kind compensation = VelocityFeedbackCompensator::Kind::Linear;
  double lead_T = Zhao2003TestMethods{}.eft_lead_T;  //!< phase lead on the compensation [s]; 0 = none
  double alpha = Zhao2003TestMethods{}.alpha;        //!< phase-lead constant (Table I)
  int compute_delay = 0;  //!< samples of compute delay on the command (0 or 1 usually)
  void validate() const;
};

//! EftConfig's fields (config_fields.hpp): the binding's attributes, EFT_CONFIG_FIELDS, the FMU's eft.*.
inline constexpr auto kEftConfigFields = std::make_tuple(
    config_field("dt", "s", "controller sample time", &EftConfig::dt),
    config_field("mass", "kg", "m in P_eff = -m a_g (none: the rig's m)", &EftConfig::mass),
    config_field("compensation", "", "velocity feedback compensation: none, linear, nonlinear", &EftConfig::compensation),
    config_field("lead_T", "s", "phase lead on the compensation (0: none)", &EftConfig::lead_T),
    config_field("alpha", "-", "phase-lead constant", &EftConfig::alpha),
    config_field("compute_delay", "samples", "compute delay on the command", &EftConfig::compute_delay));

//! Every channel of one EFT sample.
struct EftOutput {
  Output plant;                      //!< sensors at t_k (force = load cell) [SI]
  double ground_acceleration = 0.0;  //!< a_g(t_k) [m/s^2]
  double effective_force = 0.0;      //!< P_eff = -m a_g [N]
  double compensation = 0.0;         //!< velocity feedback compensation du [N]
  double compensation_opening = 0.0; //!< nonlinear compensator: total spool opening x_t [-]
  double command = 0.0;              //!< force command sent to the servo controller [N]
};

//! The channels of EftOutput beyond the plant's sensors (those are kPlantChannels of .plant).
inline constexpr ChannelInfoOf<EftOutput> kEftChannels[] = {
    {"ground_acceleration", "m/s^2", "ground acceleration a_g(t_k)", &EftOutput::ground_acceleration},
    {"effective_force", "N", "effective force P_eff = -m a_g", &EftOutput::effective_force},
    {"compensation", "N", "velocity feedback compensation du", &EftOutput::compensation},
    {"compensation_opening", "-", "nonlinear compensator: total spool opening x_t", &EftOutput::compensation_opening},
    {"command", "N", "force command sent to the servo controller", &EftOutput::command},
};

//! The EFT controller: P_eff = -m a_g through a tracking compensator (tracking.hpp;
//! default: the paper's velocity feedback compensation, Eqs 9-10), then the
//! optional compute delay.  The compensator reads desired = P_eff [N], the
//! measured force, velocity and pressure, and returns the force command [N].
class EftController {
 public:
  //! model: the controller's model of the rig, used by the compensator (A, K_v,
  //! K_s, C_F_force, G_p, flow curve and pressure factor) and, when
  //! config.mass is none, for m in P_eff = -m a_g.
  //! tracking: a compensator in place of the paper's (not owned; must outlive the
  //! controller); nullptr = VelocityFeedbackTracking of config.compensation.
  EftController(const EftConfig& config, const Rig& model, TrackingController* tracking = nullptr);

  void reset() noexcept;  //!< at rest
  //! sensors at t_k (velocity, load-cell force, pressure are read), a_g(t_k)
  //! [m/s^2]; returns the force command [N] to hold until t_{k+1}.  out, if
  //! given, receives every channel of the sample (out->plant = sensors).
  double command(const Output& sensors, double ground_acceleration, EftOutput* out = nullptr) noexcept;

  const EftConfig& config() const noexcept { return cfg_; }
  double mass() const noexcept { return mass_; }  //!< m in P_eff [kg]
  //! The paper's compensator (the one in use unless a tracking controller was given).
  const VelocityFeedbackCompensator& compensator() const noexcept { return paper_.compensator(); }
  TrackingController& tracking() noexcept { return user_ ? *user_ : paper_; }  //!< the compensator in use

 private:
  EftConfig cfg_;
  VelocityFeedbackTracking paper_;
  TrackingController* user_ = nullptr;
  SampleDelay delay_;
  double mass_;
};

// ---------------------------------------------------------------------------
// Real-time pseudodynamic testing (displacement control, Figs 1b, 7)
// ---------------------------------------------------------------------------

enum class RestoringForce {
  CalculatedDisplacement,  //!< (a) f = k_m d_k, the solver's own displacement (Fig 9a)
  MeasuredDisplacement,    //!< (b) f = k_m x_meas (Fig 7a, Figs 8, 9b)
  MeasuredForce,           //!< (c) f = F_meas directly (Fig 10b, c)
  MeasuredForceCorrected,  //!< (d) f = F_meas - m_s a_meas - c_s v_meas (Fig 7b)
};
enum class ForceMeasurement {
  LoadCell,          //!< the plant's load cell between piston and structure
  ActuatorPressure,  //!< p A, the force on the piston (includes the piston's inertia: the paper's "pA")
};
inline constexpr EnumName<RestoringForce> kRestoringForceNames[] = {
    {RestoringForce::CalculatedDisplacement, "calculated_displacement", "CalculatedDisplacement"},
    {RestoringForce::MeasuredDisplacement, "measured_displacement", "MeasuredDisplacement"},
    {RestoringForce::MeasuredForce, "measured_force", "MeasuredForce"},
    {RestoringForce::MeasuredForceCorrected, "measured_force_corrected", "MeasuredForceCorrected"},
};
static_assert(in_enum_order(kRestoringForceNames), "kRestoringForceNames: one row per enumerator, in order");
inline constexpr EnumName<ForceMeasurement> kForceMeasurementNames[] = {
    {ForceMeasurement::LoadCell, "load_cell", "LoadCell"},
    {ForceMeasurement::ActuatorPressure, "actuator_pressure", "ActuatorPressure"},
};
static_assert(in_enum_order(kForceMeasurementNames), "kForceMeasurementNames: one row per enumerator, in order");

struct RpsdConfig {
  double dt = Zhao2003TestMethods{}.dt;     //!< controller sample time [s]
  ModelSDOF model = Zhao2003TestMethods{}.model;  //!< m_m, c_m of Eq (15) (Table I)
  std::optional<double> k_m;                //!< stiffness for options (a), (b) [N/m]; none = the physical rig's k
  //! integrates Eq (15) online (the default 1-DOF substructure; unused when a substructure is given)
  StructuralScheme scheme = StructuralScheme::CentralDifference;
  RestoringForce restoring_force = RestoringForce::MeasuredDisplacement;
  ForceMeasurement force_measurement = ForceMeasurement::LoadCell;
  double amplitude_T = Zhao2003TestMethods{}.amplitude_T;  //!< amplitude compensation T_d on the command [s]; 0 = none
  double delay_T = Zhao2003TestMethods{}.delay_T;  //!< delay compensation T_ld on the restoring force [s]; 0 = none
  double alpha = Zhao2003TestMethods{}.alpha;      //!< phase-lead constant of both networks
  std::optional<double> subtract_mass;  //!< (d): mass times measured acceleration removed [kg]; none = the physical mass behind the force measurement
  std::optional<double> subtract_damping;  //!< (d): damping times measured velocity removed [N s/m]; none = the physical rig's c
  int compute_delay = 0;                //!< samples of compute delay on the command
  void validate() const;
};

//! RpsdConfig's fields (config_fields.hpp): the binding's attributes, RPSD_CONFIG_FIELDS, the FMU's rpsd.*.
inline constexpr auto kRpsdConfigFields = std::make_tuple(
    config_field("dt", "s", "controller sample time", &RpsdConfig::dt),
    config_field("model", "", "m_m [kg], c_m [N s/m] of Eq (15)", &RpsdConfig::model),
    config_field("k_m", "N/m", "stiffness for options (a), (b) (none: the physical rig's k)", &RpsdConfig::k_m),
    config_field("scheme", "", "Eq (15)'s integration scheme", &RpsdConfig::scheme),
    config_field("restoring_force", "", "restoring-force option (a)-(d)", &RpsdConfig::restoring_force),
    config_field("force_measurement", "", "load cell or actuator pressure p A", &RpsdConfig::force_measurement),
    config_field("amplitude_T", "s", "amplitude compensation T_d on the command (0: none)", &RpsdConfig::amplitude_T),
    config_field("delay_T", "s", "delay compensation T_ld on the restoring force (0: none)", &RpsdConfig::delay_T),
    config_field("alpha", "-", "phase-lead constant of both networks", &RpsdConfig::alpha),
    config_field("subtract_mass", "kg", "(d): mass times measured acceleration removed", &RpsdConfig::subtract_mass),
    config_field("subtract_damping", "N s/m", "(d): damping times measured velocity removed",
                 &RpsdConfig::subtract_damping),
    config_field("compute_delay", "samples", "compute delay on the command", &RpsdConfig::compute_delay));

//! Every channel of one RPsD sample.
struct RpsdOutput {
  Output plant;                        //!< sensors at t_k
  double ground_acceleration = 0.0;    //!< a_g [m/s^2]
  double external_force = 0.0;         //!< P_ext into the solver [N] (Fig 9 ramp)
  double measured_restoring_force = 0.0;  //!< f from the chosen option, before delay compensation [N]
  double restoring_force = 0.0;        //!< f used by the solver: after delay compensation, plus the error input [N]
  double calc_displacement = 0.0;      //!< solver d_k [m]
  double calc_velocity = 0.0;          //!< solver v_k [m/s]
  double calc_acceleration = 0.0;      //!< solver a_k [m/s^2]
  double target_displacement = 0.0;    //!< d_{k+1} [m]
  double command = 0.0;                //!< displacement command after amplitude compensation (and compute delay) [m]
};

//! The channels of RpsdOutput beyond the plant's sensors (those are kPlantChannels of .plant).
inline constexpr ChannelInfoOf<RpsdOutput> kRpsdChannels[] = {
    {"ground_acceleration", "m/s^2", "ground acceleration a_g(t_k)", &RpsdOutput::ground_acceleration},
    {"external_force", "N", "external force P_ext into the solver", &RpsdOutput::external_force},
    {"measured_restoring_force", "N", "f from the chosen option, before delay compensation",
     &RpsdOutput::measured_restoring_force},
    {"restoring_force", "N", "f used by the solver: after delay compensation, plus the error input",
     &RpsdOutput::restoring_force},
    {"calc_displacement", "m", "solver displacement d_k", &RpsdOutput::calc_displacement},
    {"calc_velocity", "m/s", "solver velocity v_k", &RpsdOutput::calc_velocity},
    {"calc_acceleration", "m/s^2", "solver acceleration a_k", &RpsdOutput::calc_acceleration},
    {"target_displacement", "m", "solver target d_{k+1}", &RpsdOutput::target_displacement},
    {"command", "m", "displacement command after amplitude compensation (and compute delay)", &RpsdOutput::command},
};

//! The RPsD controller: the restoring force from the sensors (options a-d), the
//! delay compensation T_ld on it, the Eq (15) integration scheme, and a tracking
//! compensator on the displacement command (tracking.hpp; default: the paper's
//! amplitude compensation T_d).  The compensator reads desired = d_{k+1}, the
//! solver's v_k and a_k, and the measured channels.
class RpsdController {
 public:
  //! physical: the rig under test as built (its m is the structural mass behind
  //! the load cell).  The controller reads from it only what its defaults need:
  //! k (k_m), m, m_p and effects.piston_mass (subtract_mass), c
  //! (subtract_damping) and A (force from the actuator pressure, p A).
  //! tracking: a compensator in place of the paper's amplitude lead (not owned; must
  //! outlive the controller); nullptr = AmplitudeLead(amplitude_T, alpha, dt).
  //! substructure: the numerical substructure in place of Eq (15)'s 1-DOF model (not owned;
  //! must outlive the controller; its sample time must be config.dt): any NumericalSubstructure
  //! (LinearSubstructure of any size, a Python one such as the OpenSeesPy adapter).  It is
  //! stepped with a_g held over the sample and f_in = f - P_ext on its interface DOF; the
  //! command's target is its interface displacement.  nullptr = Eq15Substructure(config.model,
  //! config.dt, config.scheme).
  RpsdController(const RpsdConfig& config, const Rig& physical, TrackingController* tracking = nullptr,
                 NumericalSubstructure* substructure = nullptr);

  void reset() noexcept;  //!< at rest, solver at d = 0
  //! sensors at t_k, a_g [m/s^2], external force P_ext into the solver [N],
  //! restoring_force_error added to f [N]; returns the displacement command [m]
  //! to hold until t_{k+1}.  out, if given, receives every channel of the sample.
  double command(const Output& sensors, double ground_acceleration, double external_force = 0.0,
                 double restoring_force_error = 0.0, RpsdOutput* out = nullptr) noexcept;

  const RpsdConfig& config() const noexcept { return cfg_; }
  //! The solver's d_k, v_k, a_k and target d_{k+1} (a given substructure: its interface DOF).
  const IntegratorState& integrator_state() const noexcept { return st_; }
  NumericalSubstructure& substructure() noexcept { return user_sub_ ? *user_sub_ : eq15_; }  //!< in use
  const NumericalSubstructure& substructure() const noexcept {
    return user_sub_ ? *user_sub_ : static_cast<const NumericalSubstructure&>(eq15_);
  }
  const TrackingController& tracking() const noexcept {
    return user_ ? *user_ : static_cast<const TrackingController&>(amplitude_);
  }
  double k_m() const noexcept { return k_m_; }
  double subtract_mass() const noexcept { return m_sub_; }
  double subtract_damping() const noexcept { return c_sub_; }
  TrackingController& tracking() noexcept { return user_ ? *user_ : amplitude_; }  //!< the compensator in use

 private:
  double restoring_force(const Output& sensors) const noexcept;
  RpsdConfig cfg_;
  Eq15Substructure eq15_;
  NumericalSubstructure* user_sub_ = nullptr;
  IntegratorState st_;
  AmplitudeLead amplitude_;
  TrackingController* user_ = nullptr;
  PhaseLead delay_comp_;
  SampleDelay delay_;
  double k_m_, m_sub_, c_sub_, A_;
};

}  // namespace servohydraulics
