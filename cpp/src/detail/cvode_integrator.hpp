// Internal: the plant's CVODE integrator (BDF, Newton, dense direct solver with
// the analytic Jacobian), as LLNL's examples/cvode/CXX_serial/cv_kpr.cpp does it,
// with every SUNDIALS object held by an RAII owner so that a constructor that
// throws part-way frees what it made (tests/cpp/test_integrators.cpp).
#pragma once

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.hpp>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <memory>
#include <type_traits>

#include "detail/ode_system.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

struct NVectorDeleter {
  void operator()(N_Vector v) const noexcept { N_VDestroy(v); }
};
struct SUNMatrixDeleter {
  void operator()(SUNMatrix m) const noexcept { SUNMatDestroy(m); }
};
struct SUNLinearSolverDeleter {
  void operator()(SUNLinearSolver s) const noexcept { SUNLinSolFree(s); }
};
struct CvodeMemDeleter {
  void operator()(void* mem) const noexcept { CVodeFree(&mem); }
};

//! CVODE over a system of the OdeSystem interface (ode_system.hpp): the single-actuator plant
//! (CvodeIntegrator) or the coupled multi-actuator rig.
template <class System>
class BasicCvodeIntegrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! Creates and configures CVODE for sys, then takes one priming step from
  //! y_prime (the plant passes its rest state); throws Error if a
  //! SUNDIALS call fails.  Call reset() before advancing.
  BasicCvodeIntegrator(const System& sys, double dt, const SolverOptions& options, const State& y_prime);
  // CVODE keeps a pointer to this object (its user data): neither copied nor moved.
  BasicCvodeIntegrator(const BasicCvodeIntegrator&) = delete;
  BasicCvodeIntegrator& operator=(const BasicCvodeIntegrator&) = delete;

  //! Restart at (y, t) with the held input zero; zeroes the counters.
  void reset(const State& y, double t) noexcept;
  //! Goes on from y at t as from a new start (the state was set from outside: the plant's
  //! re-integration to a located friction switch), its counters running on.
  void restart(const State&, double) noexcept { need_reinit_ = true; }
  //! Integrates from t to the stop time t_next with the input held, updating
  //! y and t (to where a failure happened).  Restarts (CVodeReInit) first if
  //! the input changed and the policy says so, or after a failure.
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;

  long total_steps() const noexcept;
  long total_rhs_evals() const noexcept;
  long total_restarts() const noexcept { return restarts_; }

 private:
  static int rhs(sunrealtype, N_Vector y, N_Vector ydot, void* self);
  static int jac(sunrealtype, N_Vector y, N_Vector, SUNMatrix J, void* self, N_Vector, N_Vector, N_Vector);
  void prime(const State& y_prime, double dt);
  void accumulate_counters() noexcept;

  int n_;  // active states (Sys::size): the vectors' and the matrix' length
  // Declared in creation order: destroyed in reverse, the context last.
  sundials::Context ctx_;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter> y_;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter> atol_;
  std::unique_ptr<std::remove_pointer_t<SUNMatrix>, SUNMatrixDeleter> J_;
  std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, SUNLinearSolverDeleter> LS_;
  std::unique_ptr<void, CvodeMemDeleter> mem_;

  SolverOptions::Restart restart_;
  const System* sys_;       // what the callbacks evaluate (set before every CVode call)
  Input in_{};              // the held input of the current sample
  bool need_reinit_ = true;
  long steps_done_ = 0, rhs_done_ = 0, restarts_ = 0;  // totals of past CVODE runs (ReInit resets its counters)
};

//! The single-actuator plant's CVODE integrator.
using CvodeIntegrator = BasicCvodeIntegrator<Dynamics>;

}  // namespace servohydraulics::detail
