// The paper's two real-time test methods as closed loops stepped at the
// controller rate (Zhao et al. 2003, Figs 1 and 7).  Each object owns the plant,
// the controller-side blocks and (RPsD) the online solver.  Construct once
// (validates, throws Error, allocates); reset() and step() are noexcept and
// allocation-free, step() returns the plant's Status.
//
// Row convention (as record.hpp): step() fills row k with the sensors at t_k,
// then the controller computes from them the command it holds over
// [t_k, t_k + dt], then the plant advances to t_{k+1}.
//
// Symbols of the phase-lead time constants: Table I and the text of the paper
// swap T_d and T_ld.  We follow the text: T_d = 68 ms is the amplitude
// compensation (on the displacement command), T_ld = 11.2 ms the delay
// compensation (on the restoring force).  The EFT lead is Table I's T_d-hat = 5 ms.
#pragma once

#include <cstddef>

#include "servohydraulics/compensators.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/record.hpp"
#include "servohydraulics/solvers.hpp"

namespace servohydraulics {

// ---------------------------------------------------------------------------
// Effective force testing (force control, Fig 1a)
// ---------------------------------------------------------------------------

struct EftConfig {
  double dt = 5e-4;        //!< controller sample time [s] (2 kHz DSP)
  double mass = 0.0;       //!< m in P_eff = -m a_g [kg]; 0 = the rig's structural mass
  VelocityFeedbackCompensator::Kind compensation = VelocityFeedbackCompensator::Kind::Linear;
  double lead_T = 5e-3;    //!< phase lead on the compensation [s] (Table I T_d-hat = 5 ms); 0 = none
  double alpha = 0.1;      //!< phase-lead constant (Table I)
  int compute_delay = 0;   //!< samples of compute delay on the command (0 or 1 usually)
  SolverOptions plant_options;
  void validate() const;
};

//! Every channel of one EFT sample.
struct EftOutput {
  Output plant;                      //!< sensors at t_k (force = load cell) [SI]
  double ground_acceleration = 0.0;  //!< a_g(t_k) [m/s^2]
  double effective_force = 0.0;      //!< P_eff = -m a_g [N]
  double compensation = 0.0;         //!< velocity feedback compensation du [N]
  double compensation_opening = 0.0; //!< nonlinear compensator: total spool opening x_t [-]
  double command = 0.0;              //!< force command sent to the servo controller [N]
};

class EffectiveForceTest {
 public:
  //! rig: the plant; model: the controller's model of the rig for the compensator
  //! (nullptr = the same rig, i.e. perfect knowledge).
  EffectiveForceTest(const Rig& rig, const EftConfig& config, const Rig* model = nullptr);

  void reset() noexcept;  //!< at rest at t = 0
  Status step(double ground_acceleration, EftOutput& out) noexcept;

  const Plant& plant() const noexcept { return plant_; }
  const EftConfig& config() const noexcept { return cfg_; }
  const VelocityFeedbackCompensator& compensator() const noexcept { return vfc_; }

 private:
  EftConfig cfg_;
  Plant plant_;
  VelocityFeedbackCompensator vfc_;
  SampleDelay delay_;
  double mass_;
  Output last_;
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
enum class SolverKind { CentralDifference, ExplicitNewmark };
enum class ForceMeasurement {
  LoadCell,          //!< the plant's load cell between piston and structure
  ActuatorPressure,  //!< p A, the force on the piston (includes the piston's inertia: the paper's "pA")
};

struct RpsdConfig {
  double dt = 5e-4;                    //!< controller sample time [s]
  ModelSDOF model;                     //!< m_m, c_m of Eq (15) (Table I)
  double k_m = 0.0;                    //!< stiffness for options (a), (b) [N/m]; 0 = the rig's k
  SolverKind solver = SolverKind::CentralDifference;
  RestoringForce restoring_force = RestoringForce::MeasuredDisplacement;
  ForceMeasurement force_measurement = ForceMeasurement::LoadCell;
  double amplitude_T = 68e-3;          //!< amplitude compensation T_d on the command [s] (text; Table I calls it T_ld); 0 = none
  double delay_T = 11.2e-3;            //!< delay compensation T_ld on the restoring force [s] (text; Table I: T_d); 0 = none
  double alpha = 0.1;                  //!< phase-lead constant of both networks
  double physical_mass_fraction = 1.0; //!< substructuring: the plant's structural mass = fraction * m_m (2 % = 140 kg)
  double subtract_mass = -1.0;         //!< (d): mass times measured acceleration removed [kg]; < 0 = the physical mass behind the force measurement
  double subtract_damping = -1.0;      //!< (d): damping times measured velocity removed [N s/m]; < 0 = the rig's c
  int compute_delay = 0;               //!< samples of compute delay on the command
  SolverOptions plant_options;
  void validate() const;
};

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

class RealTimePseudoDynamicTest {
 public:
  //! rig: the physical test (its m is replaced by physical_mass_fraction * m_m).
  RealTimePseudoDynamicTest(const Rig& rig, const RpsdConfig& config);

  void reset() noexcept;
  //! ground_acceleration [m/s^2], external_force into the solver [N], restoring_force_error added to f [N].
  Status step(double ground_acceleration, double external_force, double restoring_force_error,
              RpsdOutput& out) noexcept;

  const Plant& plant() const noexcept { return plant_; }
  const RpsdConfig& config() const noexcept { return cfg_; }
  const SolverState& solver_state() const noexcept;
  double k_m() const noexcept { return k_m_; }
  double subtract_mass() const noexcept { return m_sub_; }
  double subtract_damping() const noexcept { return c_sub_; }

 private:
  static Rig physical_rig(const Rig& rig, const RpsdConfig& cfg);
  RpsdConfig cfg_;
  Plant plant_;
  CentralDifference cd_;
  ExplicitNewmark nm_;
  PhaseLead amplitude_, delay_comp_;
  SampleDelay delay_;
  double k_m_, m_sub_, c_sub_, A_;
  Output last_;
};

// ---------------------------------------------------------------------------
// Whole-record runners: n samples, rows written to a caller-provided buffer of
// n rows (no allocation, no throw); stop at the first failed sample (its row is
// written; summary.rows counts the rows written).
// ---------------------------------------------------------------------------

RunSummary run_eft(EffectiveForceTest& test, const double* ground_acceleration, std::size_t n,
                   EftOutput* rows) noexcept;
//! external_force and restoring_force_error may be nullptr (zero).
RunSummary run_rpsd(RealTimePseudoDynamicTest& test, const double* ground_acceleration,
                    const double* external_force, const double* restoring_force_error, std::size_t n,
                    RpsdOutput* rows) noexcept;

}  // namespace servohydraulics
