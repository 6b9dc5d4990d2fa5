// Internal: the plant's fixed-step classical Runge-Kutta integrator (the
// real-time option), with its automatic substep rule (rk4_automatic_substeps,
// declared in plant.hpp) and a companion run at twice the substeps that flags
// the samples where the result departs from it.
#pragma once

#include "detail/ode_system.hpp"
#include "detail/output_gap.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

//! RK4 over a system of the OdeSystem interface (ode_system.hpp): the single-actuator plant
//! (Rk4Integrator) or the coupled multi-actuator rig (the check compares OdeSystem::checked_values:
//! the displacement and load-cell force of the plant, every actuator's stroke and force of the rig).
template <class System>
class BasicRk4Integrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! options.rk4_substeps per sample of dt [s], or the automatic rule if 0 (may throw Error).
  BasicRk4Integrator(const System& sys, double dt, const SolverOptions& options);

  void reset(const State& y0, double) noexcept;
  //! Goes on from y at t as from a new start (the state was set from outside: the plant's
  //! re-integration to a located friction switch), its counters running on.
  void restart(const State& y, double) noexcept { companion_ = y; }
  //! The classical RK4 over substeps() equal substeps (`substeps` > 0 replaces the configured
  //! count: the plant passes a share of it for each part of a sample split by a command delay),
  //! twice as many after each refinement.
  //! The check (rk4_flag_rtol > 0): a companion state, equal to the result at the reset, is
  //! integrated by the same RK4 at twice the substeps, so its error is about 1/16 of the result's
  //! (RK4's global error is O(h^4)) and their gap is the result's own error on x and F, as the
  //! loop carries it from sample to sample.  Where the result's displacement or load-cell force
  //! departs from the companion's by more than rk4_flag_rtol of the run's peak so far (OutputGap),
  //! the sample is flagged (Status::inaccurate; Status::error_estimate is the gap over
  //! rk4_flag_rtol).  With rk4_max_refinements > 0 a flagged sample ends on the companion's state
  //! (the more accurate run) and the run goes on at twice the substeps, the companion too, at most
  //! that many times (the flagged sample stays flagged).
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next,
                 int substeps = 0) noexcept;

  int substeps() const noexcept { return substeps_; }
  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return 0; }
  long total_flagged() const noexcept { return flagged_; }

 private:
  //! n classical RK4 substeps of size h from y (updated, its first m states); 4 n evaluations of
  //! the right-hand side.
  static void sweep(const System& sys, const Input& in, State& y, int n, int m, double h) noexcept;

  int n_;
  int substeps_;
  int max_refinements_;
  double flag_rtol_;         //!< 0: no companion, no flag
  int refined_ = 0;          //!< refinements since the reset: the substeps are 2^refined_ x the configured ones
  State companion_{};        //!< the companion's state at the current time
  OutputGap<System> gap_;    //!< the run's peaks and the gap between the result and the companion
  long steps_done_ = 0, rhs_done_ = 0, flagged_ = 0;
};

//! The single-actuator plant's fixed-step integrator.
using Rk4Integrator = BasicRk4Integrator<Dynamics>;

}  // namespace servohydraulics::detail
