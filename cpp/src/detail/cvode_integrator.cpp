#include "detail/cvode_integrator.hpp"

#include <cstdlib>
#include <sstream>
#include <string>

#include "detail/sundials_check.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics::detail {

namespace {
constexpr const char* kSetup = "CVODE setup";
// CVODE prints its errors by default; the hot path must stay silent.  The
// status carries the flag instead.
void silent_error_handler(int, const char*, const char*, char*, void*) {}

std::string flag_name(int flag) {
  char* name = CVodeGetReturnFlagName(flag);  // malloc'ed by SUNDIALS
  std::string s = name ? name : "unknown";
  std::free(name);
  return s;
}
}  // namespace

template <class System>
BasicCvodeIntegrator<System>::BasicCvodeIntegrator(const System& sys, double dt, const SolverOptions& opt,
                                                   const State& y_prime)
    : n_(Sys::size(sys)), restart_(opt.restart), sys_(&sys) {
  // The vectors and the matrix have the active length (the base states and the switched-on elements').
  y_.reset(SH_PTR(N_VNew_Serial, n_, ctx_));
  atol_.reset(SH_PTR(N_VNew_Serial, n_, ctx_));
  Sys::tolerances(sys, opt, N_VGetArrayPointer(atol_.get()));
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = 0.0;
  mem_.reset(SH_PTR(CVodeCreate, CV_BDF, ctx_));
  void* cv = mem_.get();
  SH_FLAG(CVodeInit, cv, &BasicCvodeIntegrator::rhs, 0.0, y_.get());
  SH_FLAG(CVodeSetUserData, cv, this);
  SH_FLAG(CVodeSetErrHandlerFn, cv, silent_error_handler, nullptr);
  SH_FLAG(CVodeSVtolerances, cv, opt.rtol, atol_.get());
  J_.reset(SH_PTR(SUNDenseMatrix, n_, n_, ctx_));
  LS_.reset(SH_PTR(SUNLinSol_Dense, y_.get(), J_.get(), ctx_));
  SH_FLAG(CVodeSetLinearSolver, cv, LS_.get(), J_.get());
  SH_FLAG(CVodeSetJacFn, cv, &BasicCvodeIntegrator::jac);
  SH_FLAG(CVodeSetMaxNumSteps, cv, opt.max_steps_per_sample);
  SH_FLAG(CVodeSetMaxOrd, cv, opt.max_order);
  // A held command that jumps (a step input) makes the right-hand side
  // discontinuous at the sample start; with Restart::Never the BDF history
  // straddles it and CVODE's default of 7 error-test failures is not enough
  // to cut h down to the jump (CV_ERR_FAILURE; tests/cpp/test_status.cpp).
  SH_FLAG(CVodeSetMaxErrTestFails, cv, 20);
  SH_FLAG(CVodeSetMaxHnilWarns, cv, -1);
  if (opt.max_internal_step > 0.0) SH_FLAG(CVodeSetMaxStep, cv, opt.max_internal_step);
  prime(y_prime, dt);
}

// CVODE allocates the linear solver's saved Jacobian (cvLsInitialize, a
// SUNMatClone) in its first CVode() call, not in CVodeInit: take one
// throw-away internal step here, at construction, so that advance() never
// allocates (tests/cpp/test_allocations.cpp).  The caller resets afterwards
// (CVodeReInit keeps that memory).
template <class System>
void BasicCvodeIntegrator<System>::prime(const State& y_prime, double dt) {
  in_ = {};
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y_prime[i];
  SH_FLAG(CVodeReInit, mem_.get(), 0.0, y_.get());
  SH_FLAG(CVodeSetStopTime, mem_.get(), dt);
  sunrealtype tret = 0.0;
  const int flag = inject_setup_fault() ? -1 : CVode(mem_.get(), dt, y_.get(), &tret, CV_ONE_STEP);
  if (flag < 0) {
    std::ostringstream s;
    s << kSetup << ": the priming step (one internal step from " << Sys::kPrimeState << ", "
      << "t = 0 towards dt = " << dt << " s) failed at t = " << tret << " s: CVode returned flag " << flag << " ("
      << flag_name(flag) << "); the rig's equilibrium or right-hand side is not finite there, or it is too stiff";
    throw Error(s.str());
  }
}

template <class System>
int BasicCvodeIntegrator<System>::rhs(sunrealtype, N_Vector yv, N_Vector ydot, void* user) {
  auto* self = static_cast<BasicCvodeIntegrator*>(user);
  Sys::rhs(*self->sys_, N_VGetArrayPointer(yv), self->in_, N_VGetArrayPointer(ydot));
  return 0;
}

// SUNDIALS' dense matrix is column-major with n rows (SM_ELEMENT_D(J, i, j) = data[j n + i]).
template <class System>
int BasicCvodeIntegrator<System>::jac(sunrealtype, N_Vector yv, N_Vector, SUNMatrix Jm, void* user, N_Vector,
                                      N_Vector, N_Vector) {
  auto* self = static_cast<BasicCvodeIntegrator*>(user);
  Sys::jacobian(*self->sys_, N_VGetArrayPointer(yv), self->in_, SM_DATA_D(Jm));
  return 0;
}

template <class System>
void BasicCvodeIntegrator<System>::reset(const State& y, double t) noexcept {
  steps_done_ = rhs_done_ = restarts_ = 0;
  in_ = {};
  // CVodeReInit also zeroes the counters of the current run, so that the totals restart.
  for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y[i];
  CVodeReInit(mem_.get(), t, y_.get());
  need_reinit_ = false;
}

template <class System>
void BasicCvodeIntegrator<System>::accumulate_counters() noexcept {
  long ns = 0, nf = 0;
  CVodeGetNumSteps(mem_.get(), &ns);
  CVodeGetNumRhsEvals(mem_.get(), &nf);
  steps_done_ += ns;
  rhs_done_ += nf;
}

template <class System>
Status BasicCvodeIntegrator<System>::advance(const System& sys, const Input& in, State& y, double& t,
                                             double t_next) noexcept {
  // A ZOH jump (the held command or its rate changed) is a discontinuity of the
  // right-hand side at the sample start: restart the BDF history there.
  const bool changed = Sys::changed(in, in_);
  if (changed && restart_ == SolverOptions::Restart::OnInputChange) need_reinit_ = true;
  sys_ = &sys;
  in_ = in;
  void* cv = mem_.get();
  Status st;
  if (need_reinit_) {
    accumulate_counters();
    for (int i = 0; i < n_; ++i) NV_Ith_S(y_.get(), i) = y[i];
    CVodeReInit(cv, t, y_.get());
    need_reinit_ = false;
    st.restarted = true;
    ++restarts_;
  }
  long ns0 = 0, nf0 = 0;
  CVodeGetNumSteps(cv, &ns0);
  CVodeGetNumRhsEvals(cv, &nf0);
  CVodeSetStopTime(cv, t_next);  // end exactly on the controller sample, never straddle it
  sunrealtype tret = t;
  const int flag = CVode(cv, t_next, y_.get(), &tret, CV_NORMAL);
  long ns1 = 0, nf1 = 0;
  CVodeGetNumSteps(cv, &ns1);
  CVodeGetNumRhsEvals(cv, &nf1);
  st.internal_steps = static_cast<int>(ns1 - ns0);
  st.rhs_evals = static_cast<int>(nf1 - nf0);
  for (int i = 0; i < n_; ++i) y[i] = NV_Ith_S(y_.get(), i);
  t = tret;
  if (flag < 0) {
    st.code = flag == CV_TOO_MUCH_WORK ? Status::TooMuchWork : Status::SolverFailure;
    st.cvode_flag = flag;
    need_reinit_ = true;
  }
  st.t = t;
  return st;
}

template <class System>
long BasicCvodeIntegrator<System>::total_steps() const noexcept {
  long ns = 0;
  CVodeGetNumSteps(mem_.get(), &ns);
  return steps_done_ + ns;
}
template <class System>
long BasicCvodeIntegrator<System>::total_rhs_evals() const noexcept {
  long nf = 0;
  CVodeGetNumRhsEvals(mem_.get(), &nf);
  return rhs_done_ + nf;
}

template class BasicCvodeIntegrator<Dynamics>;
template class BasicCvodeIntegrator<MultiRig>;

}  // namespace servohydraulics::detail
