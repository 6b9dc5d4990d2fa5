// The virtual multi-axial RTHS loop of the maRTHS benchmark (Condori Uribe et al., Front. Built Environ.
// 2023; BENCHMARK.md), with any MultiActuatorSystem behind the two actuators (the identified plant,
// marths/plant.hpp, or N nonlinear servo-hydraulic actuators coupled through the fixture) and any
// MultiTrackingController.  Per sample k, in the order of the model (section 7's last line):
//   1. a_g(t_k): the record, linearly interpolated, scaled (GroundMotion)
//   2. the reference structure: one Newmark step with a_g(t_k), F = 0
//   3. the actuator displacements y_i(t_k) + n(k) (one noise draw on both channels, Simulink's
//      Band-Limited White Noise with seed 123 by default)
//   4. actuator -> frame: the model's estimate (x, theta) from the measured displacements (coupler.hpp)
//   5. the physical frame's feedback force from (x, theta) and its two derivative blocks
//   6. the numerical substructure: one Newmark step with a_g(t_k) and that force, same sample
//   7. frame -> actuator: the targets from the numerical substructure's interface (x_N, theta_N)
//   8. the controller's commands
//   9. the command voltages (optionally through the DAQ's D/A: quantiser and saturation)
//  10. log row k; the plant holds the commands over [t_k, t_k + dt]
// Units are SI in the rows (m, rad, N, N m; the voltages in V); the benchmark's mm are the model's,
// inside the identified plant and RoDeAC.  Construction validates (throws Error); run() is noexcept and
// allocation-free (the caller provides the rows) and returns the RunSummary of every loop.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/converters.hpp"
#include "servohydraulics/coupler.hpp"
#include "servohydraulics/ground_motion.hpp"
#include "servohydraulics/marths/structure.hpp"
#include "servohydraulics/multi_actuator.hpp"
#include "servohydraulics/record.hpp"

namespace servohydraulics::marths {

//! A command channel's displacement -> voltage conversion (S1_Input_Data.m): the actuator's controller reads
//! d = correction (gain v + offset) [mm], so the command u [mm] is v = u / (correction gain) - offset / gain [V].
struct CommandVoltage {
  double gain = 7.4921;       //!< v2d_gain [mm/V]
  double offset = 0.0092;     //!< v2d_const [mm]
  double correction = 1.053;  //!< correction_gain [-]
  void validate() const;
  double volts(double u_mm) const noexcept { return u_mm / (correction * gain) - offset / gain; }
  double millimetres(double v) const noexcept { return (v + offset / gain) * correction * gain; }
};

struct MarthsLoopConfig {
  double dt = 1.0 / 1024.0;  //!< [s]: fs = 1024 Hz; the plant's dt must equal it
  double noise_power = 1.5e-7;  //!< Cov of the Band-Limited White Noise blocks [mm^2 s] (S1: rms_noise_DT)
  double sensor_unit = 1e-3;    //!< the unit of the sensors and commands of the benchmark's model [m] (mm)
  bool independent_noise = false;  //!< false: one draw for both channels, as the model (same seed in both blocks)
  std::uint64_t seed = 123;        //!< the noise seed (S1_Input_Data.m: rng(123) on the nominal trial)
  NoiseGenerator generator = NoiseGenerator::SimulinkRandomNumber;
  std::array<CommandVoltage, 2> voltage{CommandVoltage{7.4921, 0.0092, 1.053}, CommandVoltage{7.3907, -0.0059, 1.055}};
  //! The DAQ blocks the scripts define but the model leaves unconnected (off: the model): the D/A on the command
  //! voltage, a quantiser of 2^-18 V and a saturation at +-3.8 V; the plant then gets the converted command.
  bool daq_quantizer = false;
  bool daq_saturation = false;
  double daq_quantum = 1.0 / 262144.0;  //!< [V] (quantize_int = 1/2^18)
  double daq_limit = 3.8;               //!< [V] (sat_limit)
  //! false: the model's estimate of (x, theta) (s, not asin(s), in the cosine); true: the exact inverse.
  bool exact_kinematics = false;
  void validate() const;
  double noise_sigma() const;  //!< sqrt(noise_power / dt) sensor_unit [m]
};

//! Every channel of one maRTHS sample (row k: the signals at t_k, before the commands are applied).
struct MarthsOutput {
  double time = 0.0;                 //!< t_k [s]
  double ground_acceleration = 0.0;  //!< [m/s^2], scaled
  double target_1 = 0.0, target_2 = 0.0;              //!< xa_i,t [m]
  double measured_1 = 0.0, measured_2 = 0.0;          //!< xa_i,m [m]
  double displacement_1 = 0.0, displacement_2 = 0.0;  //!< y_i without noise [m]
  double command_1 = 0.0, command_2 = 0.0;            //!< u_i [m]
  double voltage_1 = 0.0, voltage_2 = 0.0;            //!< command voltages [V]
  double x_estimate = 0.0, theta_estimate = 0.0;      //!< xm_hat [m], rm_hat [rad]
  double x_numerical = 0.0, theta_numerical = 0.0;    //!< xNum = U(27) [m], rNum = -U(21) [rad]
  double x_reference = 0.0, theta_reference = 0.0;    //!< xRef, rRef
  double x_story2_numerical = 0.0, theta_story2_numerical = 0.0;  //!< U(26) [m], U(22) [rad]
  double x_story3_numerical = 0.0, theta_story3_numerical = 0.0;  //!< U(13), U(3)
  double x_story2_reference = 0.0, theta_story2_reference = 0.0;
  double x_story3_reference = 0.0, theta_story3_reference = 0.0;
  double feedback_force = 0.0;      //!< F(27) = f1 [N]
  double feedback_moment = 0.0;     //!< F(21) = -f2 [N m]
  double feedback_moment_b = 0.0;   //!< F(29) = -f3 [N m]
};

inline constexpr ChannelInfoOf<MarthsOutput> kMarthsChannels[] = {
    {"time", "s", "time of the sample t_k", &MarthsOutput::time},
    {"ground_acceleration", "m/s^2", "ground acceleration a_g(t_k), scaled", &MarthsOutput::ground_acceleration},
    {"target_1", "m", "actuator 1's target xa1_t", &MarthsOutput::target_1},
    {"target_2", "m", "actuator 2's target xa2_t", &MarthsOutput::target_2},
    {"measured_1", "m", "actuator 1's measured displacement xa1m (with noise)", &MarthsOutput::measured_1},
    {"measured_2", "m", "actuator 2's measured displacement xa2m (with noise)", &MarthsOutput::measured_2},
    {"displacement_1", "m", "actuator 1's displacement without noise", &MarthsOutput::displacement_1},
    {"displacement_2", "m", "actuator 2's displacement without noise", &MarthsOutput::displacement_2},
    {"command_1", "m", "actuator 1's command u1", &MarthsOutput::command_1},
    {"command_2", "m", "actuator 2's command u2", &MarthsOutput::command_2},
    {"voltage_1", "V", "actuator 1's command voltage", &MarthsOutput::voltage_1},
    {"voltage_2", "V", "actuator 2's command voltage", &MarthsOutput::voltage_2},
    {"x_estimate", "m", "interface translation from the measured displacements (xm_hat)", &MarthsOutput::x_estimate},
    {"theta_estimate", "rad", "interface rotation from the measured displacements (rm_hat)",
     &MarthsOutput::theta_estimate},
    {"x_numerical", "m", "numerical substructure's interface translation U(27) (xNum)", &MarthsOutput::x_numerical},
    {"theta_numerical", "rad", "numerical substructure's interface rotation -U(21) (rNum)",
     &MarthsOutput::theta_numerical},
    {"x_reference", "m", "reference structure's U(27) (xRef)", &MarthsOutput::x_reference},
    {"theta_reference", "rad", "reference structure's -U(21) (rRef)", &MarthsOutput::theta_reference},
    {"x_story2_numerical", "m", "numerical U(26), 2nd story", &MarthsOutput::x_story2_numerical},
    {"theta_story2_numerical", "rad", "numerical U(22), 2nd story", &MarthsOutput::theta_story2_numerical},
    {"x_story3_numerical", "m", "numerical U(13), 3rd story", &MarthsOutput::x_story3_numerical},
    {"theta_story3_numerical", "rad", "numerical U(3), 3rd story", &MarthsOutput::theta_story3_numerical},
    {"x_story2_reference", "m", "reference U(26), 2nd story", &MarthsOutput::x_story2_reference},
    {"theta_story2_reference", "rad", "reference U(22), 2nd story", &MarthsOutput::theta_story2_reference},
    {"x_story3_reference", "m", "reference U(13), 3rd story", &MarthsOutput::x_story3_reference},
    {"theta_story3_reference", "rad", "reference U(3), 3rd story", &MarthsOutput::theta_story3_reference},
    {"feedback_force", "N", "physical frame's force on DOF 27 (F(27) = f1)", &MarthsOutput::feedback_force},
    {"feedback_moment", "N m", "physical frame's moment on DOF 21 (F(21) = -f2)", &MarthsOutput::feedback_moment},
    {"feedback_moment_b", "N m", "physical frame's moment on DOF 29 (F(29) = -f3)", &MarthsOutput::feedback_moment_b},
};
static_assert(sizeof(MarthsOutput) == sizeof(kMarthsChannels) / sizeof(kMarthsChannels[0]) * sizeof(double),
              "every MarthsOutput member is a channel of kMarthsChannels");

class MarthsLoop {
 public:
  //! References are kept: the plant and the controller must outlive the loop.  Two actuators (the benchmark's
  //! coupler); plant.dt() must equal config.dt.
  MarthsLoop(MultiActuatorSystem& plant, MultiTrackingController& controller, const MarthsStructures& structures,
             const MarthsLoopConfig& config = {}, const Coupler& coupler = Coupler::marths());
  void reset() noexcept;
  //! n samples t_k = k dt from rest; ag already scaled.  rows (n) and step_seconds (n: each sample's wall time
  //! [s]) may be nullptr.  The summary: rows, peak_force = max |F(27)| [N], peak_displacement = max |y_i| [m],
  //! peak_velocity = max |y_i'| (backward difference) [m/s], the plant's work counts; at a failure, status (the
  //! plant's, NonFinite when the loop's own signals, the structures or the controller failed) and
  //! failure_time = status.t = t_k.
  RunSummary run(const GroundMotion& ag, std::size_t n, MarthsOutput* rows, double* step_seconds = nullptr) noexcept;

  const MarthsLoopConfig& config() const noexcept { return cfg_; }
  const MultiActuatorSystem& plant() const noexcept { return plant_; }
  const MultiTrackingController& controller() const noexcept { return ctrl_; }
  const NewmarkStructure& reference() const noexcept { return ref_; }
  const NewmarkStructure& numerical() const noexcept { return num_; }
  const Coupler& coupler() const noexcept { return coupler_; }

 private:
  MultiActuatorSystem& plant_;
  MultiTrackingController& ctrl_;
  MarthsLoopConfig cfg_;
  Coupler coupler_;
  MarthsDofs dofs_;
  NewmarkStructure ref_, num_;
  FrameFeedback frame_;
  GaussianSequence w1_, w2_;
  Converter da_;
  Eigen::VectorXd F_;
  double sigma_ = 0.0;
};

}  // namespace servohydraulics::marths
