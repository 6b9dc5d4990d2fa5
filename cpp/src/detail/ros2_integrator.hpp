// Internal: the plant's fixed-step linearly implicit integrator (Verwer's ROS2), for the runs
// that need a fixed cost and a residual smooth in the parameters on a rig that is stiff for RK4
// (an MR damper's or a LuGre bristle's fast states, a re-sized actuator's oil column).
#pragma once

#include <array>

#include "detail/ode_system.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

//! ROS2 (Verwer, Spee, Blom and Hundsdorfer 1999, SIAM J. Sci. Comput. 20(4)) over a system of the
//! OdeSystem interface, ros2_substeps equal substeps per sample.  Within a sample the held input
//! makes the system autonomous; each substep of size h solves two linear systems with
//! W = I - gamma h J, J the analytic Jacobian at the substep's start, gamma = 1 + 1/sqrt(2):
//!
//!     W k1 = f(y),   W k2 = f(y + h k1) - 2 k1,   y+ = y + h (3 k1 + k2) / 2
//!
//! Second order (for any J: a W-method) and L-stable (the stability function vanishes at
//! infinity): a stiff state is damped, never amplified, whatever h.  The Jacobian is refreshed
//! every substep (a regularised Coulomb law's slope changes by orders of magnitude within a
//! sample at a velocity reversal).  There is no error estimate: a caller that needs one compares with an
//! error-controlled run (the diagnosis' search_options).  No heap allocation: the matrices have
//! the system's fixed capacity.  A singular W (a pivot of 0) makes the state non-finite, which
//! the plant's guard reports (Status::NonFinite).
template <class System>
class BasicRos2Integrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;
  static constexpr int kCap = Sys::kCapacity;

  BasicRos2Integrator(const System& sys, double dt, const SolverOptions& options);

  void reset(const State& y0, double) noexcept;
  //! Goes on from y at t as from a new start (the state was set from outside: the plant's
  //! re-integration to a located friction switch), its counters running on.
  void restart(const State&, double) noexcept {}
  //! substeps() equal substeps from t to t_next (`substeps` > 0 replaces the configured count: the
  //! plant passes a share of it for each part of a sample split by a command delay).
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next,
                 int substeps = 0) noexcept;

  int substeps() const noexcept { return substeps_; }
  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return 0; }
  long total_flagged() const noexcept { return 0; }

  static constexpr double kGamma = 1.7071067811865475;  //!< 1 + 1/sqrt(2)

 private:
  int n_;
  int substeps_;
  // W = I - gamma h J in place of J (column-major n x n, leading dimension n), then its LU factors;
  // fixed capacity: no allocation.  A small hand-written LU: in a perf profile on the UTFSM rig
  // Eigen's dynamic-size one (and its triangular solves) took about a quarter of the run, more than
  // the right-hand sides; the wall-clock gain of the swap was within the shared machine's noise.
  std::array<double, static_cast<std::size_t>(kCap) * kCap> W_{};
  std::array<int, kCap> piv_{};
  State f_{}, k1_{}, tmp_{};
  long steps_done_ = 0, rhs_done_ = 0;
};

//! The single-actuator plant's linearly implicit fixed-step integrator.
using Ros2Integrator = BasicRos2Integrator<Dynamics>;

}  // namespace servohydraulics::detail
