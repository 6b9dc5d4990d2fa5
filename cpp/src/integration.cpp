#include "servohydraulics/integration.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

void ModelSDOF::validate() const {
  require(std::isfinite(m_m) && m_m > 0.0, "m_m", m_m, "modelled mass must be finite and > 0 [kg]");
  require(std::isfinite(c_m) && c_m >= 0.0, "c_m", c_m, "modelled damping must be finite and >= 0 [N s/m]");
}

CentralDifference::CentralDifference(const ModelSDOF& model, double dt) : mdl_(model), dt_(dt) {
  mdl_.validate();
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "integration time step must be finite and > 0 [s]");
}

void CentralDifference::reset(double d0) noexcept {
  d_prev_ = d0;
  started_ = false;
  s_ = IntegratorState{};
  s_.displacement = d0;
  s_.next_displacement = d0;
}

double CentralDifference::step(double load, double f) noexcept {
  const double m = mdl_.m_m / (dt_ * dt_), c = mdl_.c_m / (2.0 * dt_);
  if (started_) {  // advance k-1 -> k: the previous target is the current displacement
    d_prev_ = s_.displacement;
    s_.displacement = s_.next_displacement;
  }
  const double d = s_.displacement;
  if (!started_) {  // textbook starter from rest: d_{-1} = d_0 + dt^2/2 a_0, a_0 from Eq (15)
    d_prev_ = d + 0.5 * dt_ * dt_ * (load - f) / mdl_.m_m;
    started_ = true;
  }
  const double dn = (load - f + 2.0 * m * d - (m - c) * d_prev_) / (m + c);
  s_.velocity = (dn - d_prev_) / (2.0 * dt_);
  s_.acceleration = (dn - 2.0 * d + d_prev_) / (dt_ * dt_);
  s_.next_displacement = dn;
  return dn;
}

ExplicitNewmark::ExplicitNewmark(const ModelSDOF& model, double dt, double gamma)
    : mdl_(model), dt_(dt), gamma_(gamma) {
  mdl_.validate();
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "integration time step must be finite and > 0 [s]");
  require(std::isfinite(gamma) && gamma >= 0.5 && gamma <= 1.0, "gamma", gamma, "must be in [0.5, 1]");
}

void ExplicitNewmark::reset(double d0) noexcept {
  first_ = true;
  s_ = IntegratorState{};
  s_.displacement = d0;
  s_.next_displacement = d0;
}

double ExplicitNewmark::step(double load, double f) noexcept {
  const double m = mdl_.m_m, c = mdl_.c_m, h = dt_, g = gamma_;
  if (!first_) s_.displacement = s_.next_displacement;  // d_k = the previous predictor
  double a, v;
  if (first_) {
    v = s_.velocity;  // at rest
    a = (load - f - c * v) / m;
    first_ = false;
  } else {
    const double vp = s_.velocity + (1.0 - g) * h * s_.acceleration;
    a = (load - f - c * vp) / (m + g * h * c);
    v = vp + g * h * a;
  }
  s_.acceleration = a;
  s_.velocity = v;
  s_.next_displacement = s_.displacement + h * v + 0.5 * h * h * a;
  return s_.next_displacement;
}

}  // namespace servohydraulics
