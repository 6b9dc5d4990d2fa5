#include "servohydraulics/coupler.hpp"

#include <cmath>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

Coupler::Coupler(std::size_t n, const double* d, const double* alpha) : n_(n) {
  require(n >= 1 && n <= kMaxActuators, "coupler.actuators", static_cast<double>(n),
          "must be 1 to 8 actuators");
  for (std::size_t i = 0; i < n; ++i) {
    const std::string arm = "coupler.d[" + std::to_string(i) + "]";
    const std::string ang = "coupler.alpha[" + std::to_string(i) + "]";
    require(std::isfinite(d[i]) && d[i] > 0.0 && d[i] < 1e3, arm.c_str(), d[i], "must be finite, > 0 and < 1000 m");
    require(std::isfinite(alpha[i]) && std::fabs(alpha[i]) < kPi / 2, ang.c_str(), alpha[i],
            "must be finite with |alpha| < pi/2 rad");
    d_[i] = d[i];
    alpha_[i] = alpha[i];
  }
}

Coupler Coupler::marths() {
  // fcn_coupler_geometry.m: (xv, yv) = (0.2667, -/+0.127) m, alpha = -/+25.4633 deg.
  const double d = std::sqrt(0.2667 * 0.2667 + 0.127 * 0.127);
  const double a = 25.4633 * kPi / 180.0;
  const double ds[2] = {d, d};
  const double as[2] = {-a, a};
  return Coupler(2, ds, as);
}

void Coupler::strokes(double x, double theta, double* s) const noexcept {
  for (std::size_t i = 0; i < n_; ++i) s[i] = x + d_[i] * (std::cos(theta + alpha_[i]) - std::cos(alpha_[i]));
}

double Coupler::dstroke_dtheta(std::size_t i, double theta) const noexcept {
  return -d_[i] * std::sin(theta + alpha_[i]);
}

double Coupler::d2stroke_dtheta2(std::size_t i, double theta) const noexcept {
  return -d_[i] * std::cos(theta + alpha_[i]);
}

double Coupler::d3stroke_dtheta3(std::size_t i, double theta) const noexcept {
  return d_[i] * std::sin(theta + alpha_[i]);
}

void Coupler::node_load(double theta, const double* F, double* Fx, double* M) const noexcept {
  double fx = 0.0, m = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    fx += F[i];
    m += dstroke_dtheta(i, theta) * F[i];
  }
  *Fx = fx;
  *M = m;
}

bool Coupler::node_from_strokes(const double* s, double* x, double* theta) const noexcept {
  if (n_ < 2) return false;
  // s_0 - s_1 = d_0 (cos(th + a_0) - cos a_0) - d_1 (cos(th + a_1) - cos a_1) =: g(th); Newton from the
  // benchmark's estimate, then x from actuator 0.
  const double target = s[0] - s[1];
  auto g = [&](double th) {
    return d_[0] * (std::cos(th + alpha_[0]) - std::cos(alpha_[0])) -
           d_[1] * (std::cos(th + alpha_[1]) - std::cos(alpha_[1]));
  };
  auto dg = [&](double th) { return dstroke_dtheta(0, th) - dstroke_dtheta(1, th); };
  double th = 0.0;
  if (n_ == 2) {
    double bx = 0.0;
    benchmark_estimate(s, &bx, &th);
    if (!std::isfinite(th) || std::fabs(th) >= kPi / 2) th = 0.0;
  }
  for (int it = 0; it < 60; ++it) {
    const double slope = dg(th);
    if (!(std::fabs(slope) > 0.0)) return false;
    const double step = (g(th) - target) / slope;
    th -= step;
    if (!std::isfinite(th) || std::fabs(th) >= kPi / 2) return false;
    if (std::fabs(step) <= 1e-15 * (1.0 + std::fabs(th))) break;
  }
  if (std::fabs(g(th) - target) > 1e-12 * (d_[0] + d_[1])) return false;
  *theta = th;
  *x = s[0] - d_[0] * (std::cos(th + alpha_[0]) - std::cos(alpha_[0]));
  return true;
}

void Coupler::benchmark_estimate(const double* s, double* x, double* theta) const noexcept {
  const double r = (s[0] - s[1]) / (2.0 * d_[1] * std::sin(alpha_[1]));
  *theta = r >= 1.0 ? kPi / 2 : (r <= -1.0 ? -kPi / 2 : std::asin(r));
  *x = s[0] - d_[0] * (std::cos(alpha_[0] + r) - std::cos(alpha_[0]));
}

}  // namespace servohydraulics
