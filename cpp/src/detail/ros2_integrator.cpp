#include "detail/ros2_integrator.hpp"

#include "servohydraulics/multi_rig.hpp"

namespace servohydraulics::detail {

template <class System>
BasicRos2Integrator<System>::BasicRos2Integrator(const System& sys, double, const SolverOptions& opt)
    : n_(Sys::size(sys)),
      substeps_(opt.ros2_substeps),
      J_(n_, n_),
      W_(n_, n_),
      lu_(n_),
      f_(n_),
      k1_(n_),
      k2_(n_) {}

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
  const int m = n_;
  for (int s = 0; s < n; ++s) {
    Sys::jacobian(sys, y.data(), in, J_.data());  // column-major m x m, the layout of J_
    W_.noalias() = -kGamma * h * J_;
    W_.diagonal().array() += 1.0;
    lu_.compute(W_);
    Sys::rhs(sys, y.data(), in, f_.data());
    k1_.noalias() = lu_.solve(f_);
    for (int i = 0; i < m; ++i) tmp_[i] = y[i] + h * k1_[i];
    Sys::rhs(sys, tmp_.data(), in, f_.data());
    f_.noalias() -= 2.0 * k1_;
    k2_.noalias() = lu_.solve(f_);
    for (int i = 0; i < m; ++i) y[i] += 0.5 * h * (3.0 * k1_[i] + k2_[i]);
  }
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
