// Internal: the plant's fixed-step classical Runge-Kutta integrator (the
// real-time option), with its automatic substep rule (rk4_automatic_substeps,
// declared in plant.hpp) and an embedded error estimate that flags a sample.
#pragma once

#include "detail/ode_system.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

//! RK4 over a system of the OdeSystem interface (ode_system.hpp): the single-actuator plant
//! (Rk4Integrator) or the coupled multi-actuator rig.
template <class System>
class BasicRk4Integrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! options.rk4_substeps per sample of dt [s], or the automatic rule if 0 (may throw Error).
  BasicRk4Integrator(const System& sys, double dt, const SolverOptions& options);

  void reset(const State& y0, double) noexcept;
  //! The classical RK4 over substeps() equal substeps, and the estimate of its error: the classical
  //! stages with k5 = f(y_next) (the next substep's k1; one extra evaluation per sample) give the
  //! 3rd-order companion b^ = (1/6, 1/3, 1/3, 0, 1/6), so e = h (k4 - k5) / 6 per substep, summed in
  //! absolute value over the sample and measured in the weighted RMS norm of (rk4_flag_rtol, atol)
  //! relative to each state's running peak |y| since the last reset: the accuracy asked of a run is
  //! relative to its signals' peak, so a sample near a zero crossing is not judged against its own
  //! small |y| (which flagged accurate runs).
  //! Above 1: Status::inaccurate, and the sample is redone with twice the substeps up to
  //! rk4_max_refinements times (the flag stays: a local estimate does not bound the error carried on).
  //! `substeps` > 0 replaces the configured count (the plant passes a share of it for each part of a
  //! sample split by a command delay).
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next,
                 int substeps = 0) noexcept;

  int substeps() const noexcept { return substeps_; }
  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return 0; }
  long total_flagged() const noexcept { return flagged_; }

 private:
  //! n substeps of size h from y (updated); returns the weighted norm of the error estimate.
  double sweep(const System& sys, const Input& in, State& y, int n, double h) const noexcept;
  void track_peak(const State& y) noexcept;

  int n_;
  int substeps_;
  int max_refinements_;
  double rtol_;
  double atol_[Sys::kCapacity];
  double peak_[Sys::kCapacity] = {};  //!< max |y_i| over the samples since the last reset
  long steps_done_ = 0, rhs_done_ = 0, flagged_ = 0;
};

//! The single-actuator plant's fixed-step integrator.
using Rk4Integrator = BasicRk4Integrator<Dynamics>;

}  // namespace servohydraulics::detail
