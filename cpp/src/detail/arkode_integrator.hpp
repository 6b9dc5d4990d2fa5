// Internal: the plant's ARKODE integrators (ARKStep), the references the
// default Dormand-Prince pair is tested against: an explicit table
// (ARKODE_DORMAND_PRINCE_7_4_5) or an implicit DIRK table (ARKODE_SDIRK_5_3_4,
// Newton with the dense direct solver and the analytic Jacobian).  Every
// SUNDIALS object is held by an RAII owner and every setup call goes through
// check_flag/check_ptr (sundials_check.hpp), as in cvode_integrator.
#pragma once

#include <arkode/arkode_arkstep.h>

#include <memory>

#include "detail/cvode_integrator.hpp"  // the N_Vector, SUNMatrix and SUNLinearSolver owners

namespace servohydraulics::detail {

struct ArkodeMemDeleter {
  void operator()(void* mem) const noexcept { ARKStepFree(&mem); }
};

class ArkodeIntegrator {
 public:
  //! Creates and configures ARKStep for dyn (implicit: the DIRK table, else the explicit one), then
  //! takes one priming step from y_prime so that advance() never allocates; throws Error if a SUNDIALS
  //! call fails.  Call reset() before advancing.
  ArkodeIntegrator(const Dynamics& dyn, double dt, const SolverOptions& options, const State& y_prime,
                   bool implicit);
  // ARKODE keeps a pointer to this object (its user data): neither copied nor moved.
  ArkodeIntegrator(const ArkodeIntegrator&) = delete;
  ArkodeIntegrator& operator=(const ArkodeIntegrator&) = delete;

  void reset(const State& y, double t) noexcept;
  //! Goes on from y at t as from a new start (the state was set from outside: the plant's
  //! re-integration to a located friction switch), its counters running on.
  void restart(const State&, double) noexcept { need_reset_ = true; }
  //! Integrates from t to the stop time t_next with the input held; restarts the one-step method
  //! (ARKStepReset, with the last step size as the first) where the input changed.
  Status advance(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t, double t_next) noexcept;

  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return restarts_; }

 private:
  static int rhs(sunrealtype, N_Vector y, N_Vector ydot, void* self);
  static int jac(sunrealtype, N_Vector y, N_Vector, SUNMatrix J, void* self, N_Vector, N_Vector, N_Vector);
  void prime(const State& y_prime, double dt);
  void counters(long& steps, long& rhs) const noexcept;

  int n_;
  double dt_;
  // Declared in creation order: destroyed in reverse, the context last.
  sundials::Context ctx_;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter> y_;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter> atol_;
  std::unique_ptr<std::remove_pointer_t<SUNMatrix>, SUNMatrixDeleter> J_;  // made after mem_, freed after it
  std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, SUNLinearSolverDeleter> LS_;
  std::unique_ptr<void, ArkodeMemDeleter> mem_;

  const Dynamics* dyn_;
  Dynamics::Input in_{};
  bool need_reset_ = true;
  long steps_done_ = 0, rhs_done_ = 0, restarts_ = 0;
};

}  // namespace servohydraulics::detail
