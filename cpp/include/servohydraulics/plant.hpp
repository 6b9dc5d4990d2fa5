// The servo-hydraulic plant: analog servo controller (Eq 1), servovalve (Eqs 2-3),
// actuator (Eq 4) and structure (Eq 5), integrated with SUNDIALS CVODE (or RK4)
// between the samples of the digital controller, whose output it holds
// (zero-order hold).
//
// This header is also the umbrella of the plant's concepts: including it gives
// state.hpp, output.hpp, channels.hpp, dynamics.hpp, solver_options.hpp and
// status.hpp, as before they were split.
#pragma once

#include <memory>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/output.hpp"
#include "servohydraulics/rig.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/state.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics {

//! The plant stepped at the controller rate.  Construct once (allocates), then
//! step(command) advances one sample of dt seconds: no allocation, no throw.
class Plant {
 public:
  Plant(const Rig& rig, ControlMode mode, double dt, const SolverOptions& options = {});
  ~Plant();
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;
  Plant(Plant&&) noexcept;
  Plant& operator=(Plant&&) noexcept;

  //! Restart at time t0 from the static equilibrium at displacement x0 (in
  //! Free mode: released from x0 at rest).  Allocates nothing.  The response
  //! does not depend on t0 (the integrators run in time since the reset); a
  //! non-finite t0 throws Error naming it.
  void reset(double x0 = 0.0, double t0 = 0.0);
  //! Restart from an explicit state (t0 as in reset).
  void reset_state(const State& y0, double t0 = 0.0);

  //! Hold command u for one sample [m in displacement, N in force/free mode]
  //! and integrate to the next sample time t0 + (k + 1) dt (t0 of the last
  //! reset, k samples since: the clock does not drift).  Output is the state
  //! at the end of the sample.
  Status step(double command, Output& out) noexcept;

  //! The outputs at the current time without stepping.
  void observe(Output& out) const noexcept;

  double time() const noexcept;
  double dt() const noexcept;
  const State& state() const noexcept;
  const Dynamics& dynamics() const noexcept;
  const SolverOptions& options() const noexcept;
  //! Rk4 substeps per sample in use (resolved if automatic); 0 for CVODE.
  int rk4_substeps() const noexcept;

  //! Totals since construction/reset.
  long total_internal_steps() const noexcept;
  long total_rhs_evals() const noexcept;
  long total_restarts() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

//! The automatic RK4 rule (SolverOptions::rk4_substeps = 0): the fewest substeps
//! per sample of dt [s] with h * rho(J) <= options.rk4_h_rho at the equilibrium
//! at x = 0, and with LuGre friction h sigma_0 v_ref / F_c <= rk4_h_rho
//! (v_ref = options.rk4_v_ref, or the no-load actuator speed if 0).  Throws Error
//! if more than 100000 would be needed (use CVODE).
int rk4_automatic_substeps(const Dynamics& dynamics, double dt, const SolverOptions& options);

}  // namespace servohydraulics
