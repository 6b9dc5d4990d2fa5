#include "servohydraulics/tracking.hpp"

#include <algorithm>
#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
void require_dt(double dt) { require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0"); }

TustinFirstOrder make_pi(const PiGains& g, double dt) { return TustinFirstOrder(g.Kp, g.Ki, 1.0, 0.0, dt); }

TustinFirstOrder low_pass(double hz, double dt) {
  return TustinFirstOrder(0.0, 1.0, 1.0 / (2.0 * 3.14159265358979323846 * hz), 1.0, dt);
}
}  // namespace

TustinFirstOrder::TustinFirstOrder(double b1, double b0, double a1, double a0, double h) {
  require_dt(h);
  const double c = 2.0 / h, D = a1 * c + a0;
  require(std::isfinite(D) && D != 0.0, "a1 2/h + a0", D, "finite and nonzero");
  n0_ = (b1 * c + b0) / D;
  n1_ = (b0 - b1 * c) / D;
  d1_ = (a0 - a1 * c) / D;
}

void ControllerConverters::validate() const {
  ad.validate();
  da.validate();
}

void PiGains::validate() const {
  require(std::isfinite(Kp), "pi.Kp", Kp, "finite");
  require(std::isfinite(Ki), "pi.Ki", Ki, "finite");
}

// ----------------------------------------------------------------------- sample controller

void SampleControllerConfig::validate() const {
  require_dt(dt);
  pi.validate();
  require(std::isfinite(lead_b1) && std::isfinite(lead_b0), "lead_b1", lead_b1, "finite (and lead_b0)");
  require(std::isfinite(lead_a0) && lead_a0 > 0.0, "lead_a0", lead_a0, "finite and > 0 (a stable lead)");
  converters.validate();
}

SampleController::SampleController(const SampleControllerConfig& config) : cfg_(config) {
  cfg_.validate();
  lead_ = TustinFirstOrder(cfg_.lead_b1, cfg_.lead_b0, 1.0, cfg_.lead_a0, cfg_.dt);
  pi_ = make_pi(cfg_.pi, cfg_.dt);
}

void SampleController::reset() noexcept {
  lead_.reset();
  pi_.reset();
}

double SampleController::command(const TrackingInput& in) noexcept {
  const ControllerConverters& cv = cfg_.converters;
  const double r = cv.ad(in.desired);
  const double yp = cv.da(lead_(r));
  const double e = cv.ad(yp - in.measured);
  return cv.da(pi_(e));
}

// ----------------------------------------------------------------------- polynomial extrapolation

void PolynomialConfig::validate() const {
  require_dt(dt);
  require(std::isfinite(tau) && tau >= 0.0, "tau", tau, "finite and >= 0");
  require(order >= 1 && order <= 5, "order", order, "1..5");
  require(stride >= 1 && stride <= 4096, "stride", stride, "1..4096");
  require(std::isfinite(static_gain) && static_gain > 0.0, "static_gain", static_gain, "finite and > 0");
  pi.validate();
  converters.validate();
}

PolynomialExtrapolation::PolynomialExtrapolation(const PolynomialConfig& config) : cfg_(config) {
  cfg_.validate();
  const int n = cfg_.order;
  const double D = cfg_.stride * cfg_.dt;
  w_.assign(n + 1, 1.0);
  for (int i = 0; i <= n; ++i)  // Lagrange basis at t_k + tau of the nodes t_k - j D
    for (int j = 0; j <= n; ++j)
      if (j != i) w_[i] *= (cfg_.tau + j * D) / ((j - i) * D);
  hist_.assign(static_cast<std::size_t>(n * cfg_.stride + 1), 0.0);
  pi_ = make_pi(cfg_.pi, cfg_.dt);
  reset();
}

void PolynomialExtrapolation::reset() noexcept {
  std::fill(hist_.begin(), hist_.end(), 0.0);
  head_ = 0;
  pi_.reset();
}

double PolynomialExtrapolation::command(const TrackingInput& in) noexcept {
  const ControllerConverters& cv = cfg_.converters;
  const double r = cv.ad(in.desired);
  const std::size_t L = hist_.size();
  head_ = (head_ + 1) % L;
  hist_[head_] = r;
  double pred = 0.0;
  for (std::size_t i = 0; i < w_.size(); ++i)
    pred += w_[i] * hist_[(head_ + L - i * static_cast<std::size_t>(cfg_.stride)) % L];
  const double e = cv.ad(r - in.measured);
  return cv.da(pred / cfg_.static_gain + pi_(e));
}

// ----------------------------------------------------------------------- adaptive time series

void AtsConfig::validate() const {
  require_dt(dt);
  for (int i = 0; i < 3; ++i) {
    require(std::isfinite(lower[i]) && std::isfinite(upper[i]) && lower[i] <= upper[i], "ats.lower",
            lower[i], "finite and <= upper");
    require(initial[i] >= lower[i] && initial[i] <= upper[i], "ats.initial", initial[i], "within [lower, upper]");
  }
  require(std::isfinite(window) && window > dt, "window", window, "finite and > dt");
  require(std::isfinite(filter_hz) && filter_hz > 0.0 && filter_hz < 0.5 / dt, "filter_hz", filter_hz,
          "in (0, Nyquist)");
  require(update_every >= 1, "update_every", update_every, ">= 1");
  require(std::isfinite(min_amplitude) && min_amplitude >= 0.0, "min_amplitude", min_amplitude, "finite and >= 0");
  pi.validate();
  converters.validate();
}

AdaptiveTimeSeries::AdaptiveTimeSeries(const AtsConfig& config) : cfg_(config) {
  cfg_.validate();
  pi_ = make_pi(cfg_.pi, cfg_.dt);
  lpu1_ = lpu2_ = lpx1_ = lpx2_ = low_pass(cfg_.filter_hz, cfg_.dt);
  lambda_ = std::exp(-cfg_.dt / cfg_.window);
  reset();
}

void AdaptiveTimeSeries::reset() noexcept {
  a_ = cfg_.initial;
  pi_.reset();
  for (TustinFirstOrder* f : {&lpu1_, &lpu2_, &lpx1_, &lpx2_}) f->reset();
  R_.setZero();
  r_.setZero();
  xf_[0] = xf_[1] = xf_[2] = uf_[0] = uf_[1] = 0.0;
  energy_ = weight_ = 0.0;
  k_ = 0;
}

void AdaptiveTimeSeries::learn(double u, double xm) noexcept {
  xf_[2] = xf_[1];
  xf_[1] = xf_[0];
  xf_[0] = lpx2_(lpx1_(xm));
  uf_[1] = uf_[0];
  uf_[0] = lpu2_(lpu1_(u));
  ++k_;
  if (k_ < 3) return;
  const double h = cfg_.dt;
  // Regress at t_{k-1}: central differences; columns scaled to similar magnitudes.
  const Eigen::Vector3d phi(xf_[1], 1e-2 * (xf_[0] - xf_[2]) / (2.0 * h),
                            1e-4 * (xf_[0] - 2.0 * xf_[1] + xf_[2]) / (h * h));
  R_ = lambda_ * R_ + phi * phi.transpose();
  r_ = lambda_ * r_ + phi * uf_[1];
  energy_ = lambda_ * energy_ + xf_[1] * xf_[1];
  weight_ = lambda_ * weight_ + 1.0;
  if (k_ % cfg_.update_every != 0 || std::sqrt(energy_ / weight_) < cfg_.min_amplitude) return;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(R_);
  if (ldlt.info() != Eigen::Success) return;
  const Eigen::Vector3d s = ldlt.solve(r_);
  if (!s.allFinite()) return;
  const double scale[3] = {1.0, 1e-2, 1e-4};
  for (int i = 0; i < 3; ++i) a_[i] = std::clamp(s[i] * scale[i], cfg_.lower[i], cfg_.upper[i]);
}

double AdaptiveTimeSeries::command(const TrackingInput& in) noexcept {
  const ControllerConverters& cv = cfg_.converters;
  const double r = cv.ad(in.desired);
  const double ff = a_[0] * r + a_[1] * in.desired_velocity + a_[2] * in.desired_acceleration;
  const double e = cv.ad(r - in.measured);
  const double u = cv.da(ff + pi_(e));
  learn(u, in.measured);
  return u;
}

// ----------------------------------------------------------------------- model-based

void ModelBasedConfig::validate() const {
  require_dt(dt);
  for (double c : coefficients) require(std::isfinite(c), "coefficients", c, "finite");
  pi.validate();
  converters.validate();
}

ModelBasedConfig ModelBasedConfig::from_denominator(const std::array<double, 6>& A, double b0, int order) {
  require(order >= 0 && order <= 3, "order", order, "0..3");
  require(std::isfinite(b0) && b0 != 0.0, "b0", b0, "finite and nonzero");
  ModelBasedConfig c;
  for (int i = 0; i <= 3; ++i) c.coefficients[i] = i <= order ? A[5 - i] / b0 : 0.0;
  return c;
}

ModelBasedCompensator::ModelBasedCompensator(const ModelBasedConfig& config) : cfg_(config) {
  cfg_.validate();
  pi_ = make_pi(cfg_.pi, cfg_.dt);
}

void ModelBasedCompensator::reset() noexcept {
  pi_.reset();
  a_prev_ = 0.0;
  first_ = true;
}

double ModelBasedCompensator::command(const TrackingInput& in) noexcept {
  const ControllerConverters& cv = cfg_.converters;
  const double r = cv.ad(in.desired);
  const double jerk = first_ ? 0.0 : (in.desired_acceleration - a_prev_) / cfg_.dt;
  first_ = false;
  a_prev_ = in.desired_acceleration;
  const auto& c = cfg_.coefficients;
  const double ff = c[0] * r + c[1] * in.desired_velocity + c[2] * in.desired_acceleration + c[3] * jerk;
  const double e = cv.ad(r - in.measured);
  return cv.da(ff + pi_(e));
}

}  // namespace servohydraulics
