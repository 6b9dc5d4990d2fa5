#include "servohydraulics/compensators.hpp"

#include <algorithm>
#include <cmath>

namespace servohydraulics {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

PhaseLead::PhaseLead(double T, double alpha, double dt, double prewarp) : T_(T), alpha_(alpha) {
  require(std::isfinite(T) && T >= 0.0, "T", T, "phase-lead time constant must be finite and >= 0 [s]");
  require(std::isfinite(alpha) && alpha > 0.0 && alpha <= 1.0, "alpha", alpha, "phase-lead constant must be in (0, 1]");
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
  require(std::isfinite(prewarp), "prewarp", prewarp, "prewarping frequency must be finite [rad/s]");
  if (T == 0.0 || alpha == 1.0) {  // identity
    b0_ = 1.0, b1_ = 0.0, a1_ = 0.0, wp_ = 0.0;
    return;
  }
  const double nyquist = kPi / dt;
  double c;
  if (prewarp < 0.0) {
    wp_ = 0.0;
    c = 2.0 / dt;
  } else {
    if (prewarp > 0.0)
      require(prewarp < 0.9 * nyquist, "prewarp", prewarp, "must be below 0.9 pi/dt (Nyquist) [rad/s]");
    wp_ = prewarp > 0.0 ? prewarp : std::min(1.0 / (T * std::sqrt(alpha)), 0.9 * nyquist);
    c = wp_ / std::tan(0.5 * wp_ * dt);
  }
  // H(z) = ((T c + 1) z + (1 - T c)) / ((alpha T c + 1) z + (1 - alpha T c))
  const double den = alpha * T * c + 1.0;
  b0_ = (T * c + 1.0) / den;
  b1_ = (1.0 - T * c) / den;
  a1_ = (1.0 - alpha * T * c) / den;
}

void PhaseLead::reset(double u0) noexcept {
  u1_ = u0;
  y1_ = u0;  // DC gain 1: (b0 + b1) / (1 + a1) = 1
}

double PhaseLead::step(double u) noexcept {
  const double y = b0_ * u + b1_ * u1_ - a1_ * y1_;
  u1_ = u;
  y1_ = y;
  return y;
}

void PhaseLead::filter(const double* u, double* y, std::size_t n) noexcept {
  for (std::size_t k = 0; k < n; ++k) y[k] = step(u[k]);
}

SampleDelay::SampleDelay(int samples) {
  require(samples >= 0 && samples <= 1000000, "delay samples", samples, "must be in [0, 1e6]");
  buf_.assign(static_cast<std::size_t>(samples), 0.0);
}

void SampleDelay::reset(double u0) noexcept {
  std::fill(buf_.begin(), buf_.end(), u0);
  head_ = 0;
}

double SampleDelay::step(double u) noexcept {
  if (buf_.empty()) return u;
  const double y = buf_[head_];
  buf_[head_] = u;
  head_ = head_ + 1 == buf_.size() ? 0 : head_ + 1;
  return y;
}

VelocityFeedbackCompensator::VelocityFeedbackCompensator(const Rig& model, Kind kind, double lead_T, double alpha,
                                                         double dt)
    : model_(model, ControlMode::Force), kind_(kind), lead_(lead_T, alpha, dt) {
  const Rig& r = model_.rig();
  A_ = r.A;
  K_v_ = r.K_v;
  Kx_ = r.K_s * r.C_F_force * r.G_p;
  Kf_ = K_v_ * Kx_;
  x_v_max_ = r.x_v_max;
  require(Kf_ > 0.0, "K_v K_s C_F G_p", Kf_, "the forward path gain of the compensator model must be > 0");
}

void VelocityFeedbackCompensator::reset() noexcept {
  lead_.reset(0.0);
  x_total_ = 0.0;
}

double VelocityFeedbackCompensator::step(double velocity, double force_error, double pressure) noexcept {
  if (kind_ == Kind::None) return 0.0;
  const double v = lead_.step(velocity);  // velocity advanced by the valve delay
  if (kind_ == Kind::Linear) return A_ * v / Kf_;
  // Nonlinear: the total opening that delivers the linear design's flow.
  const double x_e = Kx_ * force_error;                  // force-error opening [-]
  const double Q_d = K_v_ * x_e + A_ * v;                // desired valve flow [m^3/s]
  const double dir = Q_d >= 0.0 ? 1.0 : -1.0;            // sgn of the opening that delivers Q_d
  const double R = std::max(model_.pressure_factor(dir, pressure), 1e-3);  // sqrt(1 - sgn p/p_s)
  const double q = Q_d / (K_v_ * R);                     // normalised flow g(x_t)
  double x_t = model_.rig().effects.flow_nonlinearity ? model_.rig().flow_curve.inverse(q) : q;
  x_t = std::clamp(x_t, -x_v_max_, x_v_max_);
  x_total_ = x_t;
  return (x_t - x_e) / Kx_;
}

}  // namespace servohydraulics
