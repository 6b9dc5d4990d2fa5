// Internal: the plant's fixed-step classical Runge-Kutta integrator (the
// real-time option), with its automatic substep rule (rk4_automatic_substeps,
// declared in plant.hpp).
#pragma once

#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

class Rk4Integrator {
 public:
  //! options.rk4_substeps per sample of dt [s], or the automatic rule if 0 (may throw Error).
  Rk4Integrator(const Dynamics& dyn, double dt, const SolverOptions& options);

  void reset(const State&, double) noexcept { steps_done_ = rhs_done_ = 0; }
  //! RK4 from t to t_next with the input held, in `substeps` equal substeps (0: the configured
  //! count; the plant passes a share of it for each part of a sample split by a command delay).
  Status advance(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t, double t_next,
                 int substeps = 0) noexcept;

  int substeps() const noexcept { return substeps_; }
  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return 0; }

 private:
  int substeps_;
  long steps_done_ = 0, rhs_done_ = 0;
};

}  // namespace servohydraulics::detail
