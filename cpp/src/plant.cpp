// Integration of the plant between controller samples with SUNDIALS CVODE
// (BDF, Newton, dense direct solver with the analytic Jacobian) or fixed-step RK4.
#include "servohydraulics/plant.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

namespace servohydraulics {

const char* Status::message() const noexcept {
  switch (code) {
    case Ok: return "ok";
    case SolverFailure: return "CVODE failed (see cvode_flag)";
    case TooMuchWork: return "overrun: more CVODE internal steps than max_steps_per_sample in one sample";
    case NonFinite: return "the state became NaN or infinite (the run diverged)";
    case NotReady: return "step() called after a failure without reset()";
  }
  return "?";
}

void SolverOptions::validate() const {
  require(std::isfinite(rtol) && rtol > 0.0 && rtol < 1.0, "rtol", rtol, "must be in (0, 1)");
  for (double s : atol_scale) require(std::isfinite(s) && s > 0.0, "atol_scale", s, "must be finite and > 0");
  require(max_order >= 1 && max_order <= 5, "max_order", max_order, "BDF order must be 1..5");
  require(max_steps_per_sample >= 1, "max_steps_per_sample", static_cast<double>(max_steps_per_sample), "must be >= 1");
  require(std::isfinite(max_internal_step) && max_internal_step >= 0.0, "max_internal_step", max_internal_step,
          "must be finite and >= 0 (0 = no limit)");
  require(rk4_substeps >= 0, "rk4_substeps", rk4_substeps, "must be >= 1, or 0 for automatic");
  require(std::isfinite(rk4_h_rho) && rk4_h_rho > 0.0 && rk4_h_rho <= 2.5, "rk4_h_rho", rk4_h_rho,
          "must be in (0, 2.5] (RK4 is unstable past |h lambda| ~ 2.8)");
}

namespace {
// The divergence guard: a state beyond these is a failed run, not a result.
constexpr double kMaxDisplacement = 100.0;  // [m]
constexpr double kMaxPressureRatio = 100.0; // [p_s]

int check_flag(int flag, const char* call) {
  if (flag < 0) throw Error(std::string("SUNDIALS setup call ") + call + " failed with flag " + std::to_string(flag));
  return flag;
}
void* check_ptr(void* p, const char* call) {
  if (p == nullptr) throw Error(std::string("SUNDIALS setup call ") + call + " returned NULL");
  return p;
}
// CVODE prints its errors by default; the hot path must stay silent.  The
// status carries the flag instead.
void silent_error_handler(int, const char*, const char*, char*, void*) {}
}  // namespace

struct Plant::Impl {
  Dynamics dyn;
  SolverOptions opt;
  double dt;
  double t = 0.0;
  State y{};
  Dynamics::Input input{};
  double prev_u = 0.0;
  bool have_prev_u = false;
  bool failed = false;
  bool need_reinit = true;
  long steps_done = 0, rhs_done = 0, restarts = 0;  // totals of past CVODE instances (ReInit resets counters)

  // CVODE objects (only for CvodeBdf).
  SUNContext ctx = nullptr;
  void* cvode = nullptr;
  N_Vector nv = nullptr;
  N_Vector atol = nullptr;
  SUNMatrix J = nullptr;
  SUNLinearSolver LS = nullptr;

  Impl(const Rig& rig, ControlMode mode, double dt_, const SolverOptions& o) : dyn(rig, mode), opt(o), dt(dt_) {
    require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
    opt.validate();
    if (opt.method == SolverOptions::Method::CvodeBdf) setup_cvode();
    else if (opt.rk4_substeps == 0) opt.rk4_substeps = automatic_substeps();
  }
  ~Impl() { free_cvode(); }

  void setup_cvode() {
    check_flag(SUNContext_Create(nullptr, &ctx), "SUNContext_Create");
    nv = static_cast<N_Vector>(check_ptr(N_VNew_Serial(kNumStates, ctx), "N_VNew_Serial"));
    atol = static_cast<N_Vector>(check_ptr(N_VNew_Serial(kNumStates, ctx), "N_VNew_Serial"));
    for (int i = 0; i < kNumStates; ++i) NV_Ith_S(atol, i) = opt.rtol * opt.atol_scale[i];
    for (int i = 0; i < kNumStates; ++i) NV_Ith_S(nv, i) = y[i];
    cvode = check_ptr(CVodeCreate(CV_BDF, ctx), "CVodeCreate");
    check_flag(CVodeInit(cvode, &Impl::cv_rhs, t, nv), "CVodeInit");
    check_flag(CVodeSetUserData(cvode, this), "CVodeSetUserData");
    check_flag(CVodeSetErrHandlerFn(cvode, silent_error_handler, nullptr), "CVodeSetErrHandlerFn");
    check_flag(CVodeSVtolerances(cvode, opt.rtol, atol), "CVodeSVtolerances");
    J = static_cast<SUNMatrix>(check_ptr(SUNDenseMatrix(kNumStates, kNumStates, ctx), "SUNDenseMatrix"));
    LS = static_cast<SUNLinearSolver>(check_ptr(SUNLinSol_Dense(nv, J, ctx), "SUNLinSol_Dense"));
    check_flag(CVodeSetLinearSolver(cvode, LS, J), "CVodeSetLinearSolver");
    check_flag(CVodeSetJacFn(cvode, &Impl::cv_jac), "CVodeSetJacFn");
    check_flag(CVodeSetMaxNumSteps(cvode, opt.max_steps_per_sample), "CVodeSetMaxNumSteps");
    check_flag(CVodeSetMaxOrd(cvode, opt.max_order), "CVodeSetMaxOrd");
    // A held command that jumps (a step input) makes the right-hand side
    // discontinuous at the sample start; with Restart::Never the BDF history
    // straddles it and CVODE's default of 7 error-test failures is not enough
    // to cut h down to the jump (CV_ERR_FAILURE; tests/cpp/test_status.cpp).
    check_flag(CVodeSetMaxErrTestFails(cvode, 20), "CVodeSetMaxErrTestFails");
    check_flag(CVodeSetMaxHnilWarns(cvode, -1), "CVodeSetMaxHnilWarns");
    if (opt.max_internal_step > 0.0) check_flag(CVodeSetMaxStep(cvode, opt.max_internal_step), "CVodeSetMaxStep");
  }
  // CVODE allocates the linear solver's saved Jacobian (cvLsInitialize, a
  // SUNMatClone) in its first CVode() call, not in CVodeInit: take one
  // throw-away internal step here, at construction, so that step() never
  // allocates (tests/cpp/test_allocations.cpp).  The caller resets afterwards
  // (CVodeReInit keeps that memory).
  void prime() {
    y = dyn.equilibrium(0.0);
    for (int i = 0; i < kNumStates; ++i) NV_Ith_S(nv, i) = y[i];
    check_flag(CVodeReInit(cvode, 0.0, nv), "CVodeReInit");
    check_flag(CVodeSetStopTime(cvode, dt), "CVodeSetStopTime");
    sunrealtype tret = 0.0;
    check_flag(CVode(cvode, dt, nv, &tret, CV_ONE_STEP), "CVode (priming step)");
  }
  // Fewest RK4 substeps that keep h * rho(J) within the bound at the equilibrium,
  // where the regularised friction is steepest (the slope of tanh peaks at v = 0).
  int automatic_substeps() const {
    const State y0 = dyn.equilibrium(0.0);
    Jacobian J;
    dyn.jacobian(y0.data(), {}, J);
    Eigen::Matrix<double, kNumStates, kNumStates> A;
    for (int i = 0; i < kNumStates; ++i)
      for (int j = 0; j < kNumStates; ++j) A(i, j) = J[i][j];
    double rho = A.eigenvalues().cwiseAbs().maxCoeff();
    // LuGre: the bristle rate sigma_0 |v| / g(v) is 0 at rest and grows with the sliding speed.  Bound
    // |v| by the no-load actuator speed K_v g(x_v_max) / A (1 m/s in free mode, no actuator).
    if (dyn.lugre()) {
      const Rig& r = dyn.rig();
      const double v_ref = dyn.mode() == ControlMode::Free ? 1.0 : r.K_v * dyn.flow_gain(std::min(r.x_v_max, 1.0)) / r.A;
      rho = std::max(rho, r.sigma_0 * v_ref / r.F_c);
    }
    const double n = std::ceil(dt * rho / opt.rk4_h_rho);
    require(std::isfinite(n) && n <= 100000.0, "rk4_substeps (automatic)", n,
            "the plant is too stiff for a fixed-step integrator at this dt: use CVODE");
    return std::max(1, static_cast<int>(n));
  }
  void free_cvode() {
    if (cvode) CVodeFree(&cvode);
    if (LS) SUNLinSolFree(LS);
    if (J) SUNMatDestroy(J);
    if (nv) N_VDestroy(nv);
    if (atol) N_VDestroy(atol);
    if (ctx) SUNContext_Free(&ctx);
    cvode = nullptr; LS = nullptr; J = nullptr; nv = nullptr; atol = nullptr; ctx = nullptr;
  }

  static int cv_rhs(sunrealtype, N_Vector yv, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    self->dyn.rhs(N_VGetArrayPointer(yv), self->input, N_VGetArrayPointer(ydot));
    return 0;
  }
  static int cv_jac(sunrealtype, N_Vector yv, N_Vector, SUNMatrix Jm, void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    Jacobian Jl;
    self->dyn.jacobian(N_VGetArrayPointer(yv), self->input, Jl);
    for (int i = 0; i < kNumStates; ++i)
      for (int j = 0; j < kNumStates; ++j) SM_ELEMENT_D(Jm, i, j) = Jl[i][j];
    return 0;
  }

  void accumulate_counters() noexcept {
    long ns = 0, nf = 0;
    CVodeGetNumSteps(cvode, &ns);
    CVodeGetNumRhsEvals(cvode, &nf);
    steps_done += ns;
    rhs_done += nf;
  }

  bool state_ok() const noexcept {
    for (double v : y)
      if (!std::isfinite(v)) return false;
    if (std::fabs(y[kX]) > kMaxDisplacement) return false;
    if (std::fabs(y[kP]) > kMaxPressureRatio * dyn.rig().p_s) return false;
    return true;
  }

  Status step_cvode(double t_next) noexcept {
    Status st;
    if (need_reinit) {
      accumulate_counters();
      for (int i = 0; i < kNumStates; ++i) NV_Ith_S(nv, i) = y[i];
      CVodeReInit(cvode, t, nv);
      need_reinit = false;
      st.restarted = true;
      ++restarts;
    }
    long ns0 = 0, nf0 = 0;
    CVodeGetNumSteps(cvode, &ns0);
    CVodeGetNumRhsEvals(cvode, &nf0);
    CVodeSetStopTime(cvode, t_next);
    sunrealtype tret = t;
    const int flag = CVode(cvode, t_next, nv, &tret, CV_NORMAL);
    long ns1 = 0, nf1 = 0;
    CVodeGetNumSteps(cvode, &ns1);
    CVodeGetNumRhsEvals(cvode, &nf1);
    st.internal_steps = static_cast<int>(ns1 - ns0);
    st.rhs_evals = static_cast<int>(nf1 - nf0);
    for (int i = 0; i < kNumStates; ++i) y[i] = NV_Ith_S(nv, i);
    t = tret;
    if (flag < 0) {
      st.code = flag == CV_TOO_MUCH_WORK ? Status::TooMuchWork : Status::SolverFailure;
      st.cvode_flag = flag;
      need_reinit = true;
    }
    st.t = t;
    return st;
  }

  Status step_rk4(double t_next) noexcept {
    Status st;
    const int n = opt.rk4_substeps;
    const double h = (t_next - t) / n;
    double k1[kNumStates], k2[kNumStates], k3[kNumStates], k4[kNumStates], tmp[kNumStates];
    for (int s = 0; s < n; ++s) {
      dyn.rhs(y.data(), input, k1);
      for (int i = 0; i < kNumStates; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
      dyn.rhs(tmp, input, k2);
      for (int i = 0; i < kNumStates; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
      dyn.rhs(tmp, input, k3);
      for (int i = 0; i < kNumStates; ++i) tmp[i] = y[i] + h * k3[i];
      dyn.rhs(tmp, input, k4);
      for (int i = 0; i < kNumStates; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    t = t_next;
    st.internal_steps = n;
    st.rhs_evals = 4 * n;
    steps_done += n;
    rhs_done += 4 * n;
    st.t = t;
    return st;
  }
};

Plant::Plant(const Rig& rig, ControlMode mode, double dt, const SolverOptions& options)
    : impl_(std::make_unique<Impl>(rig, mode, dt, options)) {
  if (impl_->cvode) impl_->prime();
  reset(0.0, 0.0);
}
Plant::~Plant() = default;
Plant::Plant(Plant&&) noexcept = default;
Plant& Plant::operator=(Plant&&) noexcept = default;

void Plant::reset(double x0, double t0) noexcept { reset_state(impl_->dyn.equilibrium(x0), t0); }

void Plant::reset_state(const State& y0, double t0) noexcept {
  Impl& m = *impl_;
  m.y = y0;
  m.t = t0;
  m.input = {};
  m.have_prev_u = false;
  m.failed = false;
  m.need_reinit = true;
  m.steps_done = 0;
  m.rhs_done = 0;
  m.restarts = 0;
  if (m.cvode) {
    // Zero the counters of the current instance so that the totals restart.
    for (int i = 0; i < kNumStates; ++i) NV_Ith_S(m.nv, i) = m.y[i];
    CVodeReInit(m.cvode, m.t, m.nv);
    m.need_reinit = false;
  }
}

Status Plant::step(double command, Output& out) noexcept {
  Impl& m = *impl_;
  if (m.failed) {
    Status st;
    st.code = Status::NotReady;
    st.t = m.t;
    observe(out);
    return st;
  }
  if (!std::isfinite(command)) {
    Status st;
    st.code = Status::NonFinite;
    st.t = m.t;
    m.failed = true;
    observe(out);
    return st;
  }
  const Dynamics::Input previous = m.input;
  m.input.u = command;
  m.input.u_rate = m.have_prev_u ? (command - m.prev_u) / m.dt : 0.0;
  m.prev_u = command;
  m.have_prev_u = true;
  const bool changed = m.input.u != previous.u || m.input.u_rate != previous.u_rate;
  if (changed && m.opt.restart == SolverOptions::Restart::OnInputChange) m.need_reinit = true;

  const double t_next = m.t + m.dt;
  Status st = m.opt.method == SolverOptions::Method::CvodeBdf ? m.step_cvode(t_next) : m.step_rk4(t_next);
  if (st.ok() && !m.state_ok()) {
    st.code = Status::NonFinite;
  }
  if (!st.ok()) m.failed = true;
  observe(out);
  return st;
}

void Plant::observe(Output& out) const noexcept {
  out.t = impl_->t;
  impl_->dyn.outputs(impl_->y.data(), impl_->input, out);
}

double Plant::time() const noexcept { return impl_->t; }
double Plant::dt() const noexcept { return impl_->dt; }
const State& Plant::state() const noexcept { return impl_->y; }
const Dynamics& Plant::dynamics() const noexcept { return impl_->dyn; }
const SolverOptions& Plant::options() const noexcept { return impl_->opt; }
int Plant::rk4_substeps() const noexcept {
  return impl_->opt.method == SolverOptions::Method::Rk4 ? impl_->opt.rk4_substeps : 0;
}

long Plant::total_internal_steps() const noexcept {
  long ns = 0;
  if (impl_->cvode) CVodeGetNumSteps(impl_->cvode, &ns);
  return impl_->steps_done + ns;
}
long Plant::total_rhs_evals() const noexcept {
  long nf = 0;
  if (impl_->cvode) CVodeGetNumRhsEvals(impl_->cvode, &nf);
  return impl_->rhs_done + nf;
}
long Plant::total_restarts() const noexcept { return impl_->restarts; }

}  // namespace servohydraulics
