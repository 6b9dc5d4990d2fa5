#include "detail/rk4_integrator.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "servohydraulics/error.hpp"
#include "servohydraulics/plant.hpp"

namespace servohydraulics {

// Fewest RK4 substeps that keep h * rho(J) within the bound at the equilibrium,
// where the regularised friction is steepest (the slope of tanh peaks at v = 0).
int rk4_automatic_substeps(const Dynamics& dyn, double dt, const SolverOptions& opt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
  opt.validate();
  const State y0 = dyn.equilibrium(0.0);
  Jacobian J;
  dyn.jacobian(y0.data(), {}, J);
  const int ns = dyn.num_states();
  Eigen::MatrixXd A(ns, ns);
  for (int i = 0; i < ns; ++i)
    for (int j = 0; j < ns; ++j) A(i, j) = J[i][j];
  double rho = A.eigenvalues().cwiseAbs().maxCoeff();
  // LuGre: the bristle rate sigma_0 |v| / g(v) is 0 at rest and grows with the sliding speed.  Bound
  // |v| by v_ref: given, or the no-load actuator speed K_v g(x_v_max) / A (1 m/s in free mode, no actuator).
  if (dyn.lugre()) {
    const Rig& r = dyn.rig();
    const double v_no_load =
        dyn.mode() == ControlMode::Free ? 1.0 : r.K_v * dyn.flow_gain(std::min(r.x_v_max, 1.0)) / r.A;
    const double v_ref = opt.rk4_v_ref > 0.0 ? opt.rk4_v_ref : v_no_load;
    rho = std::max(rho, r.sigma_0 * v_ref / r.F_c);
  }
  // Hysteretic specimens (Bouc-Wen, MR damper): their z' stiffens with the sliding speed, bounded alike.
  const StateLayout& L = dyn.layout();
  if (L.bw_z >= 0 || L.mr_y >= 0) {
    const Rig& r = dyn.rig();
    const double v_no_load =
        dyn.mode() == ControlMode::Free ? 1.0 : r.K_v * dyn.flow_gain(std::min(r.x_v_max, 1.0)) / r.A;
    rho = std::max(rho, dyn.hysteretic_rate_bound(opt.rk4_v_ref > 0.0 ? opt.rk4_v_ref : v_no_load));
  }
  const double n = std::ceil(dt * rho / opt.rk4_h_rho);
  require(std::isfinite(n) && n <= 100000.0, "rk4_substeps (automatic)", n,
          "the plant is too stiff for a fixed-step integrator at this dt: use CVODE");
  return std::max(1, static_cast<int>(n));
}

namespace detail {

Rk4Integrator::Rk4Integrator(const Dynamics& dyn, double dt, const SolverOptions& opt)
    : substeps_(opt.rk4_substeps > 0 ? opt.rk4_substeps : rk4_automatic_substeps(dyn, dt, opt)) {}

Status Rk4Integrator::advance(const Dynamics& dyn, const Dynamics::Input& in, State& y, double& t,
                              double t_next, int substeps) noexcept {
  Status st;
  const int n = substeps > 0 ? substeps : substeps_;
  const int ns = dyn.num_states();
  const double h = (t_next - t) / n;
  double k1[kMaxStates], k2[kMaxStates], k3[kMaxStates], k4[kMaxStates], tmp[kMaxStates] = {};
  for (int s = 0; s < n; ++s) {
    dyn.rhs(y.data(), in, k1);
    for (int i = 0; i < ns; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
    dyn.rhs(tmp, in, k2);
    for (int i = 0; i < ns; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
    dyn.rhs(tmp, in, k3);
    for (int i = 0; i < ns; ++i) tmp[i] = y[i] + h * k3[i];
    dyn.rhs(tmp, in, k4);
    for (int i = 0; i < ns; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  t = t_next;
  st.internal_steps = n;
  st.rhs_evals = 4 * n;
  steps_done_ += n;
  rhs_done_ += 4 * n;
  st.t = t;
  return st;
}

}  // namespace detail
}  // namespace servohydraulics
