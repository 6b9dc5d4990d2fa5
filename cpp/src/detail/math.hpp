// Small numerical helpers shared by the plant's equations and its elements (one home each).
#pragma once

#include <cmath>
#include <type_traits>
#include <utility>

namespace servohydraulics::detail {

constexpr double kPi = 3.14159265358979323846;
// Width of the C1 polynomial patch of the signed square root near 0 (Eq 3).
constexpr double kSqrtEps = 1e-3;

// f(std::integral_constant<int, n>) where Lo <= n <= Hi, otherwise(): a size known at run time made a
// compile-time constant, so that the loops over it unroll (Dynamics' gradient width, ROS2's LU).
template <int Lo, int Hi, class F, class G>
decltype(auto) with_constant(int n, F&& f, G&& otherwise) {
  if constexpr (Lo > Hi) {
    return otherwise();
  } else {
    if (n == Lo) return f(std::integral_constant<int, Lo>{});
    return with_constant<Lo + 1, Hi>(n, std::forward<F>(f), std::forward<G>(otherwise));
  }
}

inline double sgn(double v) noexcept { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// Signed square root sign(r) sqrt(|r|), replaced by a C1 odd cubic for |r| < eps
// so that the Jacobian stays finite when the load pressure reaches p_s.  Past
// p_s the flow reverses through the open port, which bounds p by the supply.
inline double ssqrt(double r) noexcept {
  const double a = std::fabs(r);
  if (a >= kSqrtEps) return std::copysign(std::sqrt(a), r);
  const double se = std::sqrt(kSqrtEps);
  return 1.25 * r / se - 0.25 * r * r * r / (kSqrtEps * kSqrtEps * se);
}
inline double ssqrt_slope(double r) noexcept {
  const double a = std::fabs(r);
  if (a >= kSqrtEps) return 0.5 / std::sqrt(a);
  const double se = std::sqrt(kSqrtEps);
  return 1.25 / se - 0.75 * r * r / (kSqrtEps * kSqrtEps * se);
}

}  // namespace servohydraulics::detail
