// The structure's friction laws: the static law g(v) tanh(v / v_stick) and LuGre, both at the
// Stribeck level g(v).
#include <cmath>

#include "../detail/math.hpp"
#include "servohydraulics/elements/friction.hpp"

namespace servohydraulics {

using detail::sgn;

StribeckLevel::Value StribeckLevel::at(double v) const noexcept {
  if (ratio == 1.0) return {F_c, 0.0};
  const double q = v / v_s, e = std::exp(-q * q);
  return {F_c * (1.0 + (ratio - 1.0) * e), F_c * (ratio - 1.0) * e * (-2.0 * q / v_s)};
}

std::optional<TanhFriction> TanhFriction::from(const Rig& r, ControlMode) {
  if (!acts(r) || LuGreFriction::acts(r) || r.v_stick == 0.0) return std::nullopt;
  return of(r);
}

std::optional<ExactCoulomb> ExactCoulomb::from(const Rig& r, ControlMode) {
  if (!TanhFriction::acts(r) || LuGreFriction::acts(r) || r.v_stick != 0.0) return std::nullopt;
  return ExactCoulomb{StribeckLevel::of(r)};
}

Sliding ExactCoulomb::mode(double v, double held) const noexcept {
  if (v > 0.0) return Sliding::Up;
  if (v < 0.0) return Sliding::Down;
  if (std::fabs(held) <= static_level()) return Sliding::Stuck;
  return held > 0.0 ? Sliding::Up : Sliding::Down;
}

LawForce ExactCoulomb::at(double v, Sliding s, double held) const noexcept {
  LawForce f;
  if (s == Sliding::Stuck) {
    f.F = held;  // the acceleration is 0: the dynamics zero its gradient (Dynamics::structure)
    return f;
  }
  const double sign = s == Sliding::Up ? 1.0 : -1.0;
  const StribeckLevel::Value gv = g.at(v);
  f.F = sign * gv.level;
  f.dF_dv = sign * gv.slope;
  return f;
}

LawForce TanhFriction::at(double v) const noexcept {
  const double t = std::tanh(v / v_stick);
  const StribeckLevel::Value gv = g.at(v);
  LawForce f;
  f.F = gv.level * t;
  f.dF_dv = gv.slope * t + gv.level * (1.0 - t * t) / v_stick;
  return f;
}

std::optional<LuGreFriction> LuGreFriction::from(const Rig& r, ControlMode) {
  if (!acts(r)) return std::nullopt;
  return LuGreFriction{StribeckLevel::of(r), r.sigma_0, r.sigma_1};
}

LawForce LuGreFriction::eval(const double* y, Algebra& a) const noexcept {
  const double v = y[kV], z = y[kZ];
  const StribeckLevel::Value s = g.at(v);
  const double gv = s.level, av = std::fabs(v);
  a.zdot = v - sigma_0 * av * z / gv;
  a.dzdot[kV] = 1.0 - sigma_0 * z * (sgn(v) * gv - av * s.slope) / (gv * gv);
  a.dzdot[kZ] = -sigma_0 * av / gv;
  LawForce f;
  f.F = sigma_0 * z + sigma_1 * a.zdot;
  f.dF_dv = sigma_1 * a.dzdot[kV];
  f.dF_dz = sigma_0 + sigma_1 * a.dzdot[kZ];
  return f;
}

}  // namespace servohydraulics
