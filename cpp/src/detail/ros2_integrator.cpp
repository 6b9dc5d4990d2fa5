#include "detail/ros2_integrator.hpp"

#include <cmath>
#include <utility>

#include "detail/math.hpp"
#include "servohydraulics/multi_rig.hpp"

namespace servohydraulics::detail {

namespace {
// The matrix size m: an int, or std::integral_constant<int, M> for the single actuator's sizes
// (every ROS2 substep factors W, and the LU and its two solves are about half of a ROS2 run's
// instructions on the UTFSM rig: with m known at compile time their loops unroll).  The same
// operations on each element in the same order either way: the results are the same to the bit.
//
// In-place LU with partial pivoting of the m x m column-major a (leading dimension m): P a = L U,
// the unit lower L below the diagonal, U on and above it; piv[k] is the row swapped with row k at
// step k (the whole rows, LAPACK's getrf convention).
template <class Size>
void lu_factor(double* a, Size size, int* piv) noexcept {
  const int m = size;
  for (int k = 0; k < m; ++k) {
    int p = k;
    double best = std::fabs(a[k + k * m]);
    for (int i = k + 1; i < m; ++i) {
      const double v = std::fabs(a[i + k * m]);
      if (v > best) {
        best = v;
        p = i;
      }
    }
    piv[k] = p;
    if (p != k)
      for (int j = 0; j < m; ++j) std::swap(a[k + j * m], a[p + j * m]);
    const double inv = 1.0 / a[k + k * m];  // a pivot of 0 gives inf: the state turns non-finite
    for (int i = k + 1; i < m; ++i) a[i + k * m] *= inv;
    for (int j = k + 1; j < m; ++j) {
      const double akj = a[k + j * m];
      if (akj == 0.0) continue;
      for (int i = k + 1; i < m; ++i) a[i + j * m] -= a[i + k * m] * akj;
    }
  }
}

// b <- (L U)^-1 P b with the factors of lu_factor.
template <class Size>
void lu_solve(const double* a, Size size, const int* piv, double* b) noexcept {
  const int m = size;
  for (int k = 0; k < m; ++k)
    if (piv[k] != k) std::swap(b[k], b[piv[k]]);
  for (int j = 0; j < m; ++j) {
    const double bj = b[j];
    if (bj != 0.0)
      for (int i = j + 1; i < m; ++i) b[i] -= a[i + j * m] * bj;
  }
  for (int j = m - 1; j >= 0; --j) {
    b[j] /= a[j + j * m];
    const double bj = b[j];
    for (int i = 0; i < j; ++i) b[i] -= a[i + j * m] * bj;
  }
}

// f(std::integral_constant<int, m>) for the single actuator's sizes (kNumStates .. kMaxStates),
// f(m) otherwise (a multi-actuator rig).
template <class F>
void at_size(int m, F&& f) {
  with_constant<kNumStates, kMaxStates>(m, f, [&] { f(m); });
}
}  // namespace

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
