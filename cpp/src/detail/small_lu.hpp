// Internal: the small dense LU of the linearly implicit integrators (ROS2's fixed substeps and the
// dopri5 pair's error-controlled Rosenbrock method for stiff samples), no allocation, sizes unrolled.
#pragma once

#include <cmath>
#include <utility>

#include "detail/math.hpp"
#include "servohydraulics/state.hpp"

namespace servohydraulics::detail {

// The matrix size m: an int, or std::integral_constant<int, M> for the single actuator's sizes
// (every ROS2 substep factors W, and the LU and its two solves are about half of a ROS2 run's
// instructions on the UTFSM rig: with m known at compile time their loops unroll).  The same
// operations on each element in the same order either way: the results are the same to the bit.
//
// In-place LU with partial pivoting of the m x m column-major a (leading dimension m): P a = L U,
// the unit lower L below the diagonal, U on and above it; piv[k] is the row swapped with row k at
// step k (the whole rows, LAPACK's getrf convention).
template <class Size>
inline void lu_factor(double* a, Size size, int* piv) noexcept {
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
inline void lu_solve(const double* a, Size size, const int* piv, double* b) noexcept {
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
inline void at_size(int m, F&& f) {
  with_constant<kNumStates, kMaxStates>(m, f, [&] { f(m); });
}

}  // namespace servohydraulics::detail
