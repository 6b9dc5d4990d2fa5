#include "detail/rk4_integrator.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "servohydraulics/error.hpp"
#include "servohydraulics/plant.hpp"

namespace servohydraulics {

namespace {
// The operating envelope the loop reaches: load pressures and spool openings as fractions of p_s
// and x_v_max.
constexpr double kPressureFractions[] = {-0.9, -0.5, 0.0, 0.5, 0.9};
constexpr double kSpoolFractions[] = {-1.0, -0.5, 0.0, 0.5, 1.0};

double spectral_radius(const Dynamics& dyn, const State& y) {
  Jacobian J;
  dyn.jacobian(y.data(), {}, J);
  const int n = dyn.num_states();
  // Sized at run time within a fixed maximum: no heap allocation.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStates, kMaxStates> A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = J[i][j];
  const double rho = A.eigenvalues().cwiseAbs().maxCoeff();
  return std::isfinite(rho) ? rho : 0.0;
}

// The largest spectral radius over the operating states the loop reaches: the equilibrium at x = 0
// (where the regularised friction is steepest: the slope of tanh peaks at v = 0), and with the load
// pressure at 0, +-0.5 p_s and +-0.9 p_s combined with the spool shut, half open and at its stops
// (the square-root term of Eq 3 and the flow gain change the pressure and loop rates there).
double loop_spectral_radius(const Dynamics& dyn) {
  const State y0 = dyn.equilibrium(0.0);
  double rho = spectral_radius(dyn, y0);
  if (dyn.mode() == ControlMode::Free) return rho;
  const Rig& r = dyn.rig();
  for (double pf : kPressureFractions)
    for (double sf : kSpoolFractions) {
      State y = y0;
      y[kP] = pf * r.p_s;
      if (r.effects.servovalve_dynamics) y[kXv] = sf * r.x_v_max;
      rho = std::max(rho, spectral_radius(dyn, y));
    }
  return rho;
}

// The laws' and the elements' states (LuGre's bristle, hysteretic specimens, dashpots) stiffen with the
// sliding speed (Dynamics::rate_bound): bound |v| by v_ref, given, or the no-load actuator speed (1 m/s
// in free mode, no actuator).
double sliding_rate_bound(const Dynamics& dyn, const SolverOptions& opt) {
  const double v_ref =
      opt.rk4_v_ref > 0.0 ? opt.rk4_v_ref : (dyn.mode() == ControlMode::Free ? 1.0 : dyn.no_load_speed());
  return dyn.rate_bound(v_ref);
}

// The fewest substeps with h rho <= rk4_h_rho.
int substeps_for(double rho, double dt, const SolverOptions& opt) {
  const double n = std::ceil(dt * rho / opt.rk4_h_rho);
  require(std::isfinite(n) && n <= SolverOptions::kMaxSubsteps, "rk4_substeps (automatic)", n,
          "exceeds the cap of 100000 per sample: the plant is too stiff for a fixed-step integrator at this dt; "
          "use the default (dopri5) or CVODE");
  return std::max(1, static_cast<int>(n));
}
}  // namespace

int rk4_automatic_substeps(const Dynamics& dyn, double dt, const SolverOptions& opt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
  opt.validate();
  double rho = loop_spectral_radius(dyn);
  rho = std::max(rho, sliding_rate_bound(dyn, opt));
  return substeps_for(rho, dt, opt);
}

// The coupled rig: the same envelope, every actuator at once, and every actuator's sliding bound.
int rk4_automatic_substeps(const MultiRig& rig, double dt, const SolverOptions& opt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "the loop's sample time must be finite and > 0 [s]");
  opt.validate();
  const int n = rig.num_states();
  Eigen::MatrixXd A(n, n);  // column-major: element (r, c) at r + c n
  auto radius = [&](const MultiRig::State& y) {
    rig.jacobian(y.data(), MultiRig::Input{}, A.data(), 1, n);
    const double rho = A.eigenvalues().cwiseAbs().maxCoeff();
    return std::isfinite(rho) ? rho : 0.0;
  };
  const MultiRig::State y0 = rig.rest();
  double rho = radius(y0);
  for (double pf : kPressureFractions)
    for (double sf : kSpoolFractions) {
      MultiRig::State y = y0;
      for (int i = 0; i < rig.actuators(); ++i) {
        const Rig& r = rig.actuator(i).rig();
        y[static_cast<std::size_t>(rig.index(i, kP))] = pf * r.p_s;
        if (r.effects.servovalve_dynamics) y[static_cast<std::size_t>(rig.index(i, kXv))] = sf * r.x_v_max;
      }
      rho = std::max(rho, radius(y));
    }
  for (int i = 0; i < rig.actuators(); ++i) rho = std::max(rho, sliding_rate_bound(rig.actuator(i), opt));
  return substeps_for(rho, dt, opt);
}

namespace detail {

template <class System>
BasicRk4Integrator<System>::BasicRk4Integrator(const System& sys, double dt, const SolverOptions& opt)
    : n_(Sys::size(sys)),
      substeps_(opt.rk4_substeps > 0 ? opt.rk4_substeps : Sys::rk4_substeps(sys, dt, opt)),
      max_refinements_(opt.rk4_max_refinements),
      rtol_(opt.rk4_flag_rtol) {
  SolverOptions flag = opt;
  flag.rtol = opt.rk4_flag_rtol;
  Sys::tolerances(sys, flag, atol_);
}

template <class System>
double BasicRk4Integrator<System>::sweep(const System& sys, const Input& in, State& y, int n, double h) const
    noexcept {
  State k1, k2, k3, k4, tmp, err{};
  const int m = n_;
  Sys::rhs(sys, y.data(), in, k1.data());
  for (int s = 0; s < n; ++s) {
    for (int i = 0; i < m; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
    Sys::rhs(sys, tmp.data(), in, k2.data());
    for (int i = 0; i < m; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
    Sys::rhs(sys, tmp.data(), in, k3.data());
    for (int i = 0; i < m; ++i) tmp[i] = y[i] + h * k3[i];
    Sys::rhs(sys, tmp.data(), in, k4.data());
    for (int i = 0; i < m; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    Sys::rhs(sys, y.data(), in, k1.data());  // k5 of this substep, k1 of the next
    for (int i = 0; i < m; ++i) err[i] += std::fabs(h / 6.0 * (k4[i] - k1[i]));
  }
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double q = err[i] / (atol_[i] + rtol_ * std::max(peak_[i], std::fabs(y[i])));
    sum += q * q;
  }
  return std::sqrt(sum / m);  // NaN if the state blew up: flagged, and the plant's guard fails the sample
}

template <class System>
void BasicRk4Integrator<System>::reset(const State& y0, double) noexcept {
  steps_done_ = rhs_done_ = flagged_ = 0;
  for (int i = 0; i < n_; ++i) peak_[i] = 0.0;
  track_peak(y0);
}

template <class System>
void BasicRk4Integrator<System>::track_peak(const State& y) noexcept {
  for (int i = 0; i < n_; ++i) peak_[i] = std::max(peak_[i], std::fabs(y[i]));
}

template <class System>
Status BasicRk4Integrator<System>::advance(const System& sys, const Input& in, State& y, double& t,
                                           double t_next, int substeps) noexcept {
  Status st;
  const State y0 = y;
  int n = substeps > 0 ? substeps : substeps_;
  track_peak(y0);
  for (int r = 0;; ++r) {
    st.error_estimate = sweep(sys, in, y, n, (t_next - t) / n);
    st.internal_steps += n;
    st.rhs_evals += 4 * n + 1;
    // Flagged if the configured substeps missed the tolerance, refined or not: the local estimate
    // does not bound the error carried into later samples, so a refined sample still says so.
    if (r == 0) st.inaccurate = !(st.error_estimate <= 1.0);
    if (st.error_estimate <= 1.0 || r >= max_refinements_ || 2L * n > SolverOptions::kMaxSubsteps) break;
    y = y0;
    n *= 2;
  }
  if (st.inaccurate) ++flagged_;
  track_peak(y);
  t = t_next;
  steps_done_ += st.internal_steps;
  rhs_done_ += st.rhs_evals;
  st.t = t;
  return st;
}

template class BasicRk4Integrator<Dynamics>;
template class BasicRk4Integrator<MultiRig>;

}  // namespace detail
}  // namespace servohydraulics
