// The Bouc-Wen evolution law, shared by the Bouc-Wen specimen and the MR damper.
#pragma once

#include <cmath>

#include "../detail/math.hpp"

namespace servohydraulics::detail {

// The Bouc-Wen evolution law (Wen 1976) and its partial derivatives:
//   z' = A w - b |w| |z|^(n-1) z - g w |z|^n,  w the deformation rate.
// Spencer et al. (1997) write the same law with their gamma on the |w| term and
// their beta on the w term: call it with (A, gamma_S, beta_S).
struct Hysteretic {
  double f = 0.0, df_dw = 0.0, df_dz = 0.0;
};
inline Hysteretic hysteretic_rate(double w, double z, double A, double b, double g, double n) noexcept {
  const double az = std::fabs(z);
  // |z|^(n-1); pow(|z|, 1) is |z| exactly (the common n = 2 without the library call)
  const double p = n == 1.0 ? 1.0 : (n == 2.0 ? az : std::pow(az, n - 1.0));
  const double zn = p * az;                                   // |z|^n
  Hysteretic h;
  h.f = A * w - b * std::fabs(w) * p * z - g * w * zn;
  h.df_dw = A - b * sgn(w) * p * z - g * zn;
  h.df_dz = -n * p * (b * std::fabs(w) + g * w * sgn(z));
  return h;
}

// Upper estimate of |dz'/dz| <= n (b + g) |z|^(n-1) |w| with |z| below its ultimate (A / (b + g))^(1/n).
inline double hysteretic_bound(double A, double bg, double n, double v_ref) noexcept {
  if (bg <= 0.0) return 0.0;
  return n * bg * std::pow(A / bg, (n - 1.0) / n) * v_ref;
}

}  // namespace servohydraulics::detail
