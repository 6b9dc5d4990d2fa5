// The structure's friction laws, Eq (5): the static law g(v) tanh(v / v_stick), LuGre
// (Canudas de Wit et al. 1995) with the bristle deflection z, the base state kZ, or the exact
// Coulomb law (v_stick = 0: stick and slip, ExactCoulomb).  All slide at the level g(v) with the
// Stribeck peak.  At most one is on (effects.coulomb_friction; effects.lugre_friction chooses
// LuGre, v_stick = 0 the exact law).
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! The sliding level g(v) = F_c (1 + (F_s / F_c - 1) exp(-(v / v_s)^2)) and its slope.
struct StribeckLevel {
  double F_c = 0.0, ratio = 1.0, v_s = 1.0;  //!< Rig::F_c, stribeck_ratio, v_s
  static StribeckLevel of(const Rig& r) noexcept { return {r.F_c, r.stribeck_ratio, r.v_s}; }
  struct Value {
    double level, slope;  //!< g(v) [N] and g'(v) [N s/m]
  };
  Value at(double v) const noexcept;  //!< both, with one exp
};

//! The static law F = g(v) tanh(v / v_stick) (effects.coulomb_friction without lugre_friction).
struct TanhFriction {
  static constexpr const char* kName = "coulomb_friction";
  StribeckLevel g;
  double v_stick = 1.0;

  static std::optional<TanhFriction> from(const Rig& r, ControlMode);  //!< on with v_stick > 0
  static TanhFriction of(const Rig& r) noexcept { return {StribeckLevel::of(r), r.v_stick}; }  //!< whichever is on
  //! The Coulomb switch is on with a force (either law acts).
  static bool acts(const Rig& r) noexcept { return r.effects.coulomb_friction && r.F_c != 0.0; }
  //! The force F [N] and its slope dF/dv [N s/m] at v (the other derivatives 0).
  LawForce at(double v) const noexcept;
  double static_force(double) const noexcept { return kNoStaticForce; }
  double rate_bound(double) const noexcept { return 0.0; }
  LawForce eval(const double* y, Algebra&) const noexcept { return at(y[kV]); }
};

//! The sliding state of the exact Coulomb law over a stretch of integration, which the plant holds
//! (Plant: a mode, not an ODE state).  Auto reads it from the state: v > 0 Up, v < 0 Down, and at
//! v = 0 Stuck while the other forces stay within the static level g(0), else the way they push.
enum class Sliding : signed char { Auto = 0, Up = 1, Down = -1, Stuck = 2 };

//! The exact Coulomb law, the limit v_stick -> 0 of TanhFriction (effects.coulomb_friction with
//! v_stick = 0, without lugre_friction; Karnopp 1985, with the switch located in time).  Sliding
//! (Up, Down) it is the level g(v) against the motion, a smooth function of v with no stiff
//! slope; stuck it holds v = 0 with whatever force the others leave (|F| <= g(0)).  The plant
//! integrates each stretch in one mode and locates where it ends (Plant::Impl::advance_sliding): v
//! crossing 0 while sliding, or the held force reaching g(0) while stuck.  Dynamics applies it
//! after the other forces (Dynamics::structure), since stuck it is their sum.
struct ExactCoulomb {
  StribeckLevel g;

  static std::optional<ExactCoulomb> from(const Rig& r, ControlMode);
  //! The static level g(0) = F_s [N]: the most the stuck law holds.
  double static_level() const noexcept { return g.at(0.0).level; }
  //! The mode at velocity v with the other forces' sum `held` [N] (Sliding::Auto's rule).
  Sliding mode(double v, double held) const noexcept;
  //! The force [N] and dF/dv in mode s (not Auto) at v with the other forces' sum `held`.
  LawForce at(double v, Sliding s, double held) const noexcept;
  //! The force as a function of v alone: sliding g(v) sgn(v), 0 at v = 0 (where it is whatever is held).
  LawForce sliding_at(double v) const noexcept {
    return v == 0.0 ? LawForce{} : at(v, v > 0.0 ? Sliding::Up : Sliding::Down, 0.0);
  }
};

//! LuGre: z' = v - sigma_0 |v| z / g(v), F = sigma_0 z + sigma_1 z' (its sigma_2 v is the
//! viscous damping); z is the base state kZ, whose rate it writes into Algebra::zdot
//! (effects.coulomb_friction and lugre_friction with F_c > 0).
struct LuGreFriction {
  static constexpr const char* kName = "lugre_friction";
  StribeckLevel g;
  double sigma_0 = 0.0, sigma_1 = 0.0;

  static std::optional<LuGreFriction> from(const Rig& r, ControlMode);
  static bool acts(const Rig& r) noexcept {
    return r.effects.coulomb_friction && r.effects.lugre_friction && r.F_c > 0.0;
  }
  double static_force(double) const noexcept { return kNoStaticForce; }  // z = 0 at rest
  //! |dz'/dz| <= sigma_0 v_ref / g(v) <= sigma_0 v_ref / F_c when sliding at v_ref [1/s].
  double rate_bound(double v_ref) const noexcept { return sigma_0 * v_ref / g.F_c; }
  LawForce eval(const double* y, Algebra& a) const noexcept;
};

}  // namespace servohydraulics
