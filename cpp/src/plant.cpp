// The plant stepped at the controller rate: the zero-order hold of the command,
// the divergence guard and the lifecycle, over one of the integrators
// (detail/dopri5_integrator, cvode_integrator, rk4_integrator, arkode_integrator)
// held in a std::variant.
#include "servohydraulics/plant.hpp"

#include <cmath>
#include <utility>
#include <variant>

#include "detail/arkode_integrator.hpp"
#include "detail/cvode_integrator.hpp"
#include "detail/dopri5_integrator.hpp"
#include "detail/rk4_integrator.hpp"

namespace servohydraulics {

namespace {
// The divergence guard: a state beyond these is a failed run, not a result.
constexpr double kMaxDisplacement = 100.0;  // [m]
constexpr double kMaxPressureRatio = 100.0; // [p_s]

using Integrator = std::variant<detail::Dopri5Integrator, detail::CvodeIntegrator, detail::Rk4Integrator,
                                detail::ArkodeIntegrator>;

SolverOptions checked(const SolverOptions& o, double dt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
  o.validate();
  return o;
}

// Built in place (the SUNDIALS integrators are pinned: SUNDIALS holds their address).
Integrator make_integrator(const Dynamics& dyn, double dt, const SolverOptions& opt) {
  using M = SolverOptions::Method;
  const State y0 = dyn.equilibrium(0.0);
  switch (opt.method) {
    case M::CvodeBdf: return Integrator(std::in_place_type<detail::CvodeIntegrator>, dyn, dt, opt, y0);
    case M::Rk4: return Integrator(std::in_place_type<detail::Rk4Integrator>, dyn, dt, opt);
    case M::ArkodeErk:
    case M::ArkodeDirk:
      return Integrator(std::in_place_type<detail::ArkodeIntegrator>, dyn, dt, opt, y0, opt.method == M::ArkodeDirk);
    case M::Dopri5: break;
  }
  return Integrator(std::in_place_type<detail::Dopri5Integrator>, dyn, dt, opt, y0);
}
}  // namespace

struct Plant::Impl {
  Dynamics dyn;
  SolverOptions opt;
  double dt;
  double t = 0.0;
  double t0 = 0.0;  // time of the last reset [s]
  long k = 0;       // samples since then: sample times are t0 + k dt, never an accumulated sum
  State y{};
  Dynamics::Input input{};
  double prev_u = 0.0;
  bool have_prev_u = false;
  bool failed = false;
  Integrator integ;

  Impl(const Rig& rig, ControlMode mode, double dt_, const SolverOptions& o)
      : dyn(rig, mode), opt(checked(o, dt_)), dt(dt_), integ(make_integrator(dyn, dt, opt)) {
    if (auto* rk4 = std::get_if<detail::Rk4Integrator>(&integ)) opt.rk4_substeps = rk4->substeps();
  }

  bool state_ok() const noexcept {
    for (double v : y)
      if (!std::isfinite(v)) return false;
    if (std::fabs(y[kX]) > kMaxDisplacement) return false;
    if (std::fabs(y[kP]) > kMaxPressureRatio * dyn.rig().p_s) return false;
    return true;
  }
};

Plant::Plant(const Rig& rig, ControlMode mode, double dt, const SolverOptions& options)
    : impl_(std::make_unique<Impl>(rig, mode, dt, options)) {
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
  m.t0 = t0;
  m.k = 0;
  m.input = {};
  m.have_prev_u = false;
  m.failed = false;
  std::visit([&](auto& integ) { integ.reset(m.y, m.t); }, m.integ);
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
  // Zero-order hold: the command is held over the sample, its rate is the last increment / dt.
  m.input.u = command;
  m.input.u_rate = m.have_prev_u ? (command - m.prev_u) / m.dt : 0.0;
  m.prev_u = command;
  m.have_prev_u = true;

  const double t_next = m.t0 + static_cast<double>(m.k + 1) * m.dt;
  Status st = std::visit([&](auto& integ) { return integ.advance(m.dyn, m.input, m.y, m.t, t_next); }, m.integ);
  if (st.ok() && !m.state_ok()) {
    st.code = Status::NonFinite;
  }
  if (st.ok()) ++m.k;
  else m.failed = true;
  observe(out);
  return st;
}

void Plant::observe(Output& out) const noexcept {
  out.time = impl_->t;
  impl_->dyn.outputs(impl_->y.data(), impl_->input, out);
}

double Plant::time() const noexcept { return impl_->t; }
double Plant::dt() const noexcept { return impl_->dt; }
const State& Plant::state() const noexcept { return impl_->y; }
const Dynamics& Plant::dynamics() const noexcept { return impl_->dyn; }
const SolverOptions& Plant::options() const noexcept { return impl_->opt; }
int Plant::rk4_substeps() const noexcept {
  const auto* rk4 = std::get_if<detail::Rk4Integrator>(&impl_->integ);
  return rk4 ? rk4->substeps() : 0;
}

long Plant::total_internal_steps() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_steps(); }, impl_->integ);
}
long Plant::total_rhs_evals() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_rhs_evals(); }, impl_->integ);
}
long Plant::total_restarts() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_restarts(); }, impl_->integ);
}

}  // namespace servohydraulics
