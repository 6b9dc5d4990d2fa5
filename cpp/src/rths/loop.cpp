#include "servohydraulics/rths/loop.hpp"

#include <chrono>
#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics::rths {

void RthsLoopConfig::validate() const {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0");
  displacement_noise.validate();
  force_noise.validate();
}

RthsLoop::RthsLoop(ExperimentalSubstructure& experimental, NumericalSubstructure& numerical,
                   TrackingController& controller, const RthsLoopConfig& config)
    : exp_(experimental), num_(numerical), ctrl_(controller), cfg_(config), dx_(config.dt), dv_(config.dt) {
  cfg_.validate();
  require(std::fabs(exp_.dt() - cfg_.dt) <= 1e-12 * cfg_.dt, "experimental.dt", exp_.dt(), "the loop's dt");
  require(std::fabs(num_.sample_time() - cfg_.dt) <= 1e-12 * cfg_.dt, "numerical.h", num_.sample_time(),
          "the loop's dt");
  require(num_.interface_dof() >= 0 && num_.interface_dof() < num_.dof_count(), "numerical.interface_dof",
          static_cast<double>(num_.interface_dof()), "one of the numerical substructure's DOFs");
  reset();
}

void RthsLoop::reset() noexcept {
  exp_.reset();
  num_.reset();
  ctrl_.reset();
  wx_.reset(cfg_.seed, cfg_.generator);
  wf_.reset(cfg_.seed ^ 0x9E3779B97F4A7C15ull, cfg_.generator);
  dx_.reset();
  dv_.reset();
  delay_.reset();
}

RunSummary RthsLoop::run(const GroundMotion& ag, std::size_t n, RthsOutput* rows, double* numerical,
                         double* step_seconds) noexcept {
  using clock = std::chrono::steady_clock;
  RunSummary sum;
  const double h = cfg_.dt;
  const SpecimenModel sp = exp_.specimen();
  const Eigen::Index nd = num_.dof_count(), dof = num_.interface_dof();
  for (std::size_t k = 0; k < n; ++k) {
    const auto t0 = step_seconds ? clock::now() : clock::time_point{};
    const double t = static_cast<double>(k) * h;
    const double x = exp_.displacement(), y1 = num_.dof_displacement(dof);
    const double w = wx_.next();
    const double wf = cfg_.independent_noise ? wf_.next() : w;
    const double xm = cfg_.displacement_noise(x, w);
    const double v = dx_(x), a = dv_(v);
    const double fm = cfg_.force_noise(sp.k * x + sp.c * v + sp.m * a, wf);
    const double fin = delay_(fm);
    const double ag0 = ag(t);
    TrackingInput in{y1, num_.interface_velocity(), num_.interface_acceleration(ag0, fin), xm, fm};
    in.measured_velocity = v;  // the backward difference of the specimen displacement
    const double u = ctrl_.command(in);
    const double f = exp_.actuator_force();
    if (rows) rows[k] = RthsOutput{t, ag0, xm, x, f, u, fin};
    if (numerical)
      for (Eigen::Index i = 0; i < nd; ++i) numerical[k * nd + i] = num_.dof_displacement(i);
    sum.rows = k + 1;
    sum.peaks(f, x, exp_.velocity());
    const Status st = exp_.step(u);
    num_.step(ag0, ag(t + 0.5 * h), ag(t + h), fin);
    if (step_seconds) step_seconds[k] = std::chrono::duration<double>(clock::now() - t0).count();
    sum.internal_steps += st.internal_steps;
    sum.rhs_evals += st.rhs_evals;
    sum.restarts += st.restarted ? 1 : 0;
    if (!sum.count(st, t) || !std::isfinite(xm) || !std::isfinite(u) || !num_.healthy()) {
      if (st.ok()) {  // the loop's own signals or the numerical part
        sum.status = st;
        sum.status.code = Status::NonFinite;
        sum.failure_time = t;
      }
      sum.status.t = t;  // the loop's sample time, not the substructure's clock
      break;
    }
  }
  return sum;
}

}  // namespace servohydraulics::rths
