#include "detail/ros2_integrator.hpp"

#include <cmath>
#include <utility>

#include "detail/small_lu.hpp"
#include "servohydraulics/multi_rig.hpp"

namespace servohydraulics::detail {


template <class System>
BasicRos2Integrator<System>::BasicRos2Integrator(const System& sys, double, const SolverOptions& opt)
    : n_(Sys::size(sys)), substeps_(opt.ros2_substeps) {}

template <class System>
void BasicRos2Integrator<System>::reset(const State&, double) noexcept {
  steps_done_ = rhs_done_ = 0;
}

template <class System>
Status BasicRos2Integrator<System>::advance(const System& sys, const Input& in, State& y, double& t,
                                            double t_next, int substeps) noexcept {
  Status st;
  const int n = substeps > 0 ? substeps : substeps_;
  const double h = (t_next - t) / n;
  double* W = W_.data();
  at_size(n_, [&](auto size) {
    const int m = size;
    for (int s = 0; s < n; ++s) {
      Sys::jacobian_rhs(sys, y.data(), in, W, f_.data());  // J column-major m x m, and f(y)
      for (int i = 0; i < m * m; ++i) W[i] *= -kGamma * h;
      for (int i = 0; i < m; ++i) W[i + i * m] += 1.0;
      lu_factor(W, size, piv_.data());
      for (int i = 0; i < m; ++i) k1_[i] = f_[i];
      lu_solve(W, size, piv_.data(), k1_.data());  // W k1 = f(y)
      for (int i = 0; i < m; ++i) tmp_[i] = y[i] + h * k1_[i];
      Sys::rhs(sys, tmp_.data(), in, f_.data());
      for (int i = 0; i < m; ++i) f_[i] -= 2.0 * k1_[i];
      lu_solve(W, size, piv_.data(), f_.data());  // W k2 = f(y + h k1) - 2 k1
      for (int i = 0; i < m; ++i) y[i] += 0.5 * h * (3.0 * k1_[i] + f_[i]);
    }
  });
  st.internal_steps = n;
  st.rhs_evals = 2 * n;
  t = t_next;
  steps_done_ += n;
  rhs_done_ += 2 * n;
  st.t = t;
  return st;
}

template class BasicRos2Integrator<Dynamics>;
template class BasicRos2Integrator<MultiRig>;

}  // namespace servohydraulics::detail
