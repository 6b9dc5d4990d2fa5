// The structure's spring, Eq (5), with the softening of the paper's rig: stiffness k, and k_2
// beyond +-x_contact where one spring pair loses contact (effects.spring_softening).
#pragma once

#include <cmath>
#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! f_s(x) = k x for |x| <= x_contact, sign(x) (k x_contact + k_2 (|x| - x_contact)) beyond (with
//! softening; k x throughout without).  Always part of the structure.
struct Spring {
  static constexpr const char* kName = "spring";
  double k = 0.0, k_2 = 0.0, x_contact = 0.0;
  bool softening = false;

  static std::optional<Spring> from(const Rig& r, ControlMode) {
    return Spring{r.k, r.k_2, r.x_contact, r.effects.spring_softening};
  }
  double force(double x) const noexcept {  //!< f_s(x) [N]
    if (!softening || std::fabs(x) <= x_contact) return k * x;
    return std::copysign(k * x_contact + k_2 * (std::fabs(x) - x_contact), x);
  }
  double stiffness(double x) const noexcept {  //!< df_s/dx [N/m]
    if (!softening || std::fabs(x) <= x_contact) return k;
    return k_2;
  }
  double static_force(double x) const noexcept { return force(x); }
  double rate_bound(double) const noexcept { return 0.0; }
  LawForce eval(const double* y, Algebra&) const noexcept {
    LawForce f;
    f.F = force(y[kX]);
    f.dF_dx = stiffness(y[kX]);
    return f;
  }
};

}  // namespace servohydraulics
