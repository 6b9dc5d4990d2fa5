// The tracking compensator of a hybrid simulation: the block between what the
// loop wants the actuator to do (the target) and the command it sends.  One
// interface for every loop of the project (EFT, RPsD, the RTHS benchmark) and
// for a user's own controller:
//
//   TrackingInput in;               // filled by the loop at t_k
//   in.desired = target; in.measured = x_meas; in.measured_force = f_meas; ...
//   double u = controller.command(in);   // hold u over [t_k, t_k + dt]
//
// What "desired" is depends on the loop's control mode: a displacement [m] in
// displacement control (RPsD: the solver's d_{k+1}; the RTHS benchmark: the
// numerical substructure's interface displacement y_n(1)), a force [N] in force
// control (EFT: the effective force P_eff = -m a_g).  The loop fills every field
// it has; a compensator reads what it needs.
//
// Implementations: the paper's amplitude compensation (AmplitudeLead, the RPsD
// default) and velocity feedback compensation (VelocityFeedbackTracking, the EFT
// default), and the RTHS benchmark's compensators (rths/tracking.hpp: the sample
// controller, polynomial extrapolation, ATS, model-based feedforward).
//
// Construct once (validates, throws Error); reset() and command() are noexcept
// and allocation-free.
#pragma once

#include "servohydraulics/compensators.hpp"

namespace servohydraulics {

//! What a tracking compensator reads at t_k.
struct TrackingInput {
  double desired = 0.0;               //!< target: displacement [m] (displacement control) or force [N] (force control)
  double desired_velocity = 0.0;      //!< rate of the target displacement (numerical substructure's interface) [m/s]
  double desired_acceleration = 0.0;  //!< its acceleration (relative) [m/s^2]
  double measured = 0.0;              //!< x_m, measured specimen displacement [m]
  double measured_force = 0.0;        //!< measured specimen force (load cell) [N]
  double measured_velocity = 0.0;     //!< measured actuator velocity [m/s]
  double measured_pressure = 0.0;     //!< measured load pressure p = p_1 - p_2 [Pa]
};

//! The interface: reset() to rest, command() once per sample.
class TrackingController {
 public:
  virtual ~TrackingController() = default;
  virtual void reset() noexcept = 0;
  //! The command to hold over [t_k, t_k + dt]: displacement [m] or force [N], the target's unit.
  virtual double command(const TrackingInput& in) noexcept = 0;
};

//! The paper's amplitude compensation of RPsD (Fig 1b): the phase lead
//! (T_d s + 1)/(alpha T_d s + 1) on the target displacement, u = H(desired)
//! (compensators.hpp PhaseLead; T_d = 68 ms, alpha = 0.1 by default; T = 0 passes through).
class AmplitudeLead final : public TrackingController {
 public:
  AmplitudeLead(double T, double alpha, double dt) : lead_(T, alpha, dt) {}
  void reset() noexcept override { lead_.reset(0.0); }
  double command(const TrackingInput& in) noexcept override { return lead_.step(in.desired); }
  const PhaseLead& lead() const noexcept { return lead_; }

 private:
  PhaseLead lead_;
};

//! The paper's velocity feedback compensation of EFT (Fig 1a, Eqs 9-10): the
//! force command plus the compensation du of the measured velocity, at the
//! force error desired - measured_force and the measured pressure:
//! u = desired + du (compensators.hpp VelocityFeedbackCompensator).
class VelocityFeedbackTracking final : public TrackingController {
 public:
  //! model: the controller's rig model; lead_T [s], alpha, dt [s] (Table I: 5 ms, 0.1, 0.5 ms).
  VelocityFeedbackTracking(const Rig& model, VelocityFeedbackCompensator::Kind kind, double lead_T, double alpha,
                           double dt)
      : vfc_(model, kind, lead_T, alpha, dt) {}
  void reset() noexcept override { vfc_.reset(); }
  double command(const TrackingInput& in) noexcept override {
    du_ = vfc_.step(in.measured_velocity, in.desired - in.measured_force, in.measured_pressure);
    return in.desired + du_;
  }
  const VelocityFeedbackCompensator& compensator() const noexcept { return vfc_; }
  double last_compensation() const noexcept { return du_; }  //!< du of the last command [N]

 private:
  VelocityFeedbackCompensator vfc_;
  double du_ = 0.0;
};

}  // namespace servohydraulics
