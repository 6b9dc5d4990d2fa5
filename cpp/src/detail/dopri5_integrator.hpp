// Internal: the plant's default integrator, the Dormand-Prince 5(4) embedded
// Runge-Kutta pair with error control inside each controller sample (the
// sample is the maximum step; first-same-as-last within a sample and across
// samples while the held input and the state are unchanged), and an automatic
// switch to CVODE for a sample where the pair turns stiff.
#pragma once

#include <memory>

#include "detail/cvode_integrator.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

class Dopri5Integrator {
 public:
  //! Creates the CVODE fallback (if options.stiff_fallback) primed from y_prime; may throw Error.
  Dopri5Integrator(const Dynamics& dyn, double dt, const SolverOptions& options, const State& y_prime);

  void reset(const State& y, double t) noexcept;
  //! Integrates from t to t_next with the input held.  Stiffness (more than stiff_steps steps in the
  //! sample, a step below 1e-12 of the sample, or a non-finite stage) redoes the sample from its start
  //! with CVODE (Status::stiff) and stays on CVODE for kImplicitHold samples; without the fallback it
  //! returns Status::Stiff.  More than max_steps_per_sample steps: TooMuchWork.
  Status advance(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t, double t_next) noexcept;

  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return restarts_; }
  long total_stiff_samples() const noexcept { return stiff_samples_; }

  //! Samples that stay on CVODE after a stiff one before the pair is tried again.
  static constexpr int kImplicitHold = 16;

 private:
  enum class Outcome { Done, Stiff, TooMuchWork };
  Outcome explicit_sample(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t, double t_next,
                          Status& st) noexcept;
  //! One trial step of size h from (y, k1): the 5th-order solution in y5, its slope in k7, and the
  //! weighted RMS norm of the embedded error estimate (returned).
  double trial_step(const Dynamics& dyn, const Dynamics::Input& in, const State& y, double h, State& y5) noexcept;
  Status implicit_sample(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t,
                         double t_next) noexcept;

  int n_;
  double rtol_;
  double atol_[kMaxStates];
  long max_steps_;
  int stiff_steps_;
  double dt_;
  std::unique_ptr<CvodeIntegrator> implicit_;  // the stiff fallback, or null
  State k_[7];         // the stages; k_[0] is the slope at the current state
  bool fsal_ = false;  // k_[0] is f(y, in) of the state and input the next sample starts from
  Dynamics::Input fsal_in_{};
  double h_;           // the step the controller proposes next [s]
  int hold_ = 0;       // samples left on CVODE
  long steps_done_ = 0, rhs_done_ = 0, restarts_ = 0, stiff_samples_ = 0;
};

}  // namespace servohydraulics::detail
