// The structure's viscous damping, Eq (5): c v.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! F = c v (Rig::c; LuGre's sigma_2 v is this term).  Always part of the structure.
struct ViscousDamping {
  static constexpr const char* kName = "viscous_damping";
  double c = 0.0;

  static std::optional<ViscousDamping> from(const Rig& r, ControlMode) { return ViscousDamping{r.c}; }
  double force(double v) const noexcept { return c * v; }  //!< [N]
  double static_force(double) const noexcept { return kNoStaticForce; }
  double rate_bound(double) const noexcept { return 0.0; }
  LawForce eval(const double* y, Algebra&) const noexcept {
    LawForce f;
    f.F = force(y[kV]);
    f.dF_dv = c;
    return f;
  }
};

}  // namespace servohydraulics
