#include "detail/arkode_integrator.hpp"

#include <algorithm>

#include "detail/sundials_check.hpp"

namespace servohydraulics::detail {

namespace {
constexpr const char* kSetup = "ARKODE setup";
void silent_error_handler(int, const char*, const char*, char*, void*) {}
}  // namespace

ArkodeIntegrator::ArkodeIntegrator(const Dynamics& dyn, double dt, const SolverOptions& opt, const State& y_prime,
                                   bool implicit)
    : n_(dyn.num_states()), dt_(dt), dyn_(&dyn) {
  y_.reset(SH_PTR(N_VNew_Serial, n_, ctx_));
  atol_.reset(SH_PTR(N_VNew_Serial, n_, ctx_));
  absolute_tolerances(dyn, opt, N_VGetArrayPointer(atol_.get()));
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y_prime[i];
  ARKRhsFn fe = implicit ? nullptr : &ArkodeIntegrator::rhs;
  ARKRhsFn fi = implicit ? &ArkodeIntegrator::rhs : nullptr;
  mem_.reset(SH_PTR(ARKStepCreate, fe, fi, 0.0, y_.get(), ctx_));
  void* ark = mem_.get();
  SH_FLAG(ARKStepSetUserData, ark, this);
  SH_FLAG(ARKStepSetErrHandlerFn, ark, silent_error_handler, nullptr);
  SH_FLAG(ARKStepSVtolerances, ark, opt.rtol, atol_.get());
  if (implicit) {
    SH_FLAG(ARKStepSetTableNum, ark, ARKODE_SDIRK_5_3_4, ARKODE_ERK_NONE);
    J_.reset(SH_PTR(SUNDenseMatrix, n_, n_, ctx_));
    LS_.reset(SH_PTR(SUNLinSol_Dense, y_.get(), J_.get(), ctx_));
    SH_FLAG(ARKStepSetLinearSolver, ark, LS_.get(), J_.get());
    SH_FLAG(ARKStepSetJacFn, ark, &ArkodeIntegrator::jac);
  } else {
    SH_FLAG(ARKStepSetTableNum, ark, ARKODE_DIRK_NONE, ARKODE_DORMAND_PRINCE_7_4_5);
  }
  SH_FLAG(ARKStepSetMaxNumSteps, ark, opt.max_steps_per_sample);
  SH_FLAG(ARKStepSetMaxErrTestFails, ark, 20);
  SH_FLAG(ARKStepSetMaxHnilWarns, ark, -1);
  SH_FLAG(ARKStepSetMaxStep, ark, opt.max_internal_step > 0.0 ? std::min(opt.max_internal_step, dt) : dt);
  prime(y_prime, dt);
}

// As CvodeIntegrator::prime: ARKODE allocates some workspace in its first step; take it here.
void ArkodeIntegrator::prime(const State& y_prime, double dt) {
  in_ = {};
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y_prime[i];
  SH_FLAG(ARKStepReset, mem_.get(), 0.0, y_.get());
  SH_FLAG(ARKStepSetStopTime, mem_.get(), dt);
  sunrealtype tret = 0.0;
  SH_FLAG(ARKStepEvolve, mem_.get(), dt, y_.get(), &tret, ARK_ONE_STEP);
}

int ArkodeIntegrator::rhs(sunrealtype, N_Vector yv, N_Vector ydot, void* user) {
  auto* self = static_cast<ArkodeIntegrator*>(user);
  self->dyn_->rhs(N_VGetArrayPointer(yv), self->in_, N_VGetArrayPointer(ydot));
  return 0;
}

int ArkodeIntegrator::jac(sunrealtype, N_Vector yv, N_Vector, SUNMatrix Jm, void* user, N_Vector, N_Vector,
                          N_Vector) {
  auto* self = static_cast<ArkodeIntegrator*>(user);
  Jacobian Jl;
  self->dyn_->jacobian(N_VGetArrayPointer(yv), self->in_, Jl);
  for (int i = 0; i < self->n_; ++i)
    for (int j = 0; j < self->n_; ++j) SM_ELEMENT_D(Jm, i, j) = Jl[i][j];
  return 0;
}

void ArkodeIntegrator::counters(long& steps, long& rhs) const noexcept {
  long nfe = 0, nfi = 0;
  steps = 0;
  ARKStepGetNumSteps(mem_.get(), &steps);
  ARKStepGetNumRhsEvals(mem_.get(), &nfe, &nfi);
  rhs = nfe + nfi;
}

void ArkodeIntegrator::reset(const State& y, double t) noexcept {
  steps_done_ = rhs_done_ = restarts_ = 0;
  in_ = {};
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y[i];
  ARKStepSetInitStep(mem_.get(), 0.0);  // estimate the first step
  ARKStepReset(mem_.get(), t, y_.get());
  need_reset_ = false;
}

Status ArkodeIntegrator::advance(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t,
                                 double t_next) noexcept {
  if (OdeSystem<Dynamics>::changed(in, in_)) need_reset_ = true;  // a ZOH jump (or a friction switch): restart there
  dyn_ = &dyn;
  in_ = in;
  void* ark = mem_.get();
  Status st;
  long ns0 = 0, nf0 = 0, ns1 = 0, nf1 = 0;
  if (need_reset_) {
    sunrealtype h = 0.0;
    ARKStepGetLastStep(ark, &h);
    for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y[i];
    ARKStepSetInitStep(ark, h > 0.0 ? std::min(h, dt_) : 0.0);
    ARKStepReset(ark, t, y_.get());  // zeroes nothing: counters run on
    need_reset_ = false;
    st.restarted = true;
    ++restarts_;
  }
  counters(ns0, nf0);
  ARKStepSetStopTime(ark, t_next);
  sunrealtype tret = t;
  const int flag = ARKStepEvolve(ark, t_next, y_.get(), &tret, ARK_NORMAL);
  counters(ns1, nf1);
  st.internal_steps = static_cast<int>(ns1 - ns0);
  st.rhs_evals = static_cast<int>(nf1 - nf0);
  steps_done_ += st.internal_steps;
  rhs_done_ += st.rhs_evals;
  for (int i = 0; i < n_; ++i) y[i] = NV_Ith_S(y_.get(), i);
  t = tret;
  if (flag < 0) {
    st.code = flag == ARK_TOO_MUCH_WORK ? Status::TooMuchWork : Status::SolverFailure;
    st.cvode_flag = flag;
    need_reset_ = true;
  }
  st.t = t;
  return st;
}

}  // namespace servohydraulics::detail
