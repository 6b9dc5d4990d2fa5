#include "servohydraulics/rths/benchmark_plant.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"
#include "servohydraulics/rths/converters.hpp"

namespace servohydraulics::rths {

void BenchmarkPlantParameters::validate() const {
  require(std::isfinite(a1_beta0) && a1_beta0 > 0.0, "a1_beta0", a1_beta0, "finite and > 0");
  require(std::isfinite(a2) && a2 >= 0.0, "a2", a2, "finite and >= 0");
  require(std::isfinite(a3), "a3", a3, "finite");  // a3 < 0 occurs in the official draws: kept
  require(std::isfinite(beta1), "beta1", beta1, "finite");
  require(std::isfinite(beta2), "beta2", beta2, "finite");
  require(std::isfinite(m_e) && m_e > 0.0, "m_e", m_e, "finite and > 0");
  require(std::isfinite(k_e) && k_e > 0.0, "k_e", k_e, "finite and > 0");
  require(std::isfinite(zeta_e) && zeta_e >= 0.0, "zeta_e", zeta_e, "finite and >= 0");
  require(std::isfinite(gain) && gain > 0.0, "gain", gain, "finite and > 0");
}

double BenchmarkPlantParameters::c_e() const noexcept {
  return 2.0 * zeta_e * m_e * std::sqrt(k_e / m_e);  // F1 L69, in the code's form
}

std::array<double, 6> BenchmarkPlantParameters::denominator() const noexcept {
  const double ce = c_e(), me = m_e, ke = k_e;
  const double kk = ke + ce * a3 + a2, cc = ce + me * a3;
  const double A0 = ke * a3 * beta2 + a1_beta0;
  const double A1 = ke * a3 * beta1 + kk * beta2;
  const double A2 = ke * a3 + kk * beta1 + cc * beta2;
  const double A3 = kk + cc * beta1 + me * beta2;
  const double A4 = ce + me * a3 + me * beta1;
  return {me, A4, A3, A2, A1, A0};
}

BenchmarkPlantParameters BenchmarkPlantUncertainty::draw(const BenchmarkPlantParameters& nominal,
                                                         std::uint64_t seed) const {
  GaussianSequence z(seed);
  BenchmarkPlantParameters p = nominal;
  p.k_e = nominal.k_e + k_e * z.next();
  p.beta1 = nominal.beta1 + beta1 * z.next();
  p.beta2 = nominal.beta2 + beta2 * z.next();
  p.a3 = nominal.a3 + a3 * z.next();
  p.validate();
  return p;
}

BenchmarkPlant::BenchmarkPlant(const BenchmarkPlantParameters& parameters, double dt) : par_(parameters), dt_(dt) {
  par_.validate();
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0");
  c_e_ = par_.c_e();
}

// x' seen by the CSI: the state, or the Derivative block's difference quotient
// from the last major step (since = time since it; 0 = the major step itself).
double BenchmarkPlant::csi_rate(const std::array<double, 5>& p, double since) const noexcept {
  if (!par_.csi_derivative_block) return p[4];
  return since > 0.0 ? (p[3] - x_major_) / since : d_major_;
}

void BenchmarkPlant::rhs(const std::array<double, 5>& p, double u, double rate, std::array<double, 5>& dp) const noexcept {
  dp[0] = p[1];
  dp[1] = -par_.beta1 * p[1] - par_.beta2 * p[0] + par_.a1_beta0 * (par_.gain * u - p[3]);
  dp[2] = -par_.a3 * p[2] + p[0] - par_.a2 * rate;
  dp[3] = p[4];
  dp[4] = (p[2] - c_e_ * p[4] - par_.k_e * p[3]) / par_.m_e;
}

Status BenchmarkPlant::step(double command) noexcept {
  std::array<double, 5> k1, k2, k3, k4, t;
  const double h = dt_;
  x_major_ = p_[3];
  d_major_ = first_ ? 0.0 : (p_[3] - x_prev_) / h;
  first_ = false;
  x_prev_ = p_[3];
  rhs(p_, command, csi_rate(p_, 0.0), k1);
  for (int i = 0; i < 5; ++i) t[i] = p_[i] + 0.5 * h * k1[i];
  rhs(t, command, csi_rate(t, 0.5 * h), k2);
  for (int i = 0; i < 5; ++i) t[i] = p_[i] + 0.5 * h * k2[i];
  rhs(t, command, csi_rate(t, 0.5 * h), k3);
  for (int i = 0; i < 5; ++i) t[i] = p_[i] + h * k3[i];
  rhs(t, command, csi_rate(t, h), k4);
  bool finite = true;
  for (int i = 0; i < 5; ++i) {
    p_[i] += (h / 6.0) * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    finite = finite && std::isfinite(p_[i]);
  }
  Status st;
  if (!finite) st.code = Status::NonFinite;
  return st;
}

ServoHydraulicSubstructure::ServoHydraulicSubstructure(const Rig& rig, double dt, const SolverOptions& options)
    : plant_(rig, ControlMode::Displacement, dt, options), specimen_{rig.m, rig.c, rig.k} {
  reset();
}

void ServoHydraulicSubstructure::reset() noexcept {
  plant_.reset(0.0, 0.0);
  plant_.observe(out_);
}

Status ServoHydraulicSubstructure::step(double command) noexcept { return plant_.step(command, out_); }

}  // namespace servohydraulics::rths
