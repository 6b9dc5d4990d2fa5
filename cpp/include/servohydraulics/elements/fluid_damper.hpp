// A nonlinear viscous fluid damper, F = c |u'|^alpha sign(u'), in series with a Maxwell
// stiffness k_d, in parallel with the structure.  One state: the dashpot's displacement u.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! F = k_d (x - u) = c |u'|^alpha sign(u'), so u' = sign(F) (|F| / c)^(1/alpha)  (effects.fluid_damper).
//! 0 < alpha <= 1 keeps u' continuously differentiable in F (its slope is 0 at F = 0 for alpha < 1).
struct FluidDamper {
  static constexpr const char* kName = "fluid_damper";
  static constexpr Port kPort = Port::Structure;
  static constexpr int kCapacity = 1;
  double c = 0.0, alpha = 1.0, k = 0.0;

  static std::optional<FluidDamper> from(const Rig& rig, ControlMode mode);
  int count() const noexcept { return 1; }
  static const StateInfo* states() noexcept;
  double scale(int) const noexcept { return 1e-3; }  // [m], as x
  void rest(const RestPoint& p, double* z) const noexcept { z[0] = p.x; }  // no force at rest
  double static_force(double) const noexcept { return 0.0; }
  //! |du'/du| = k_d (|F| / c)^(1/alpha - 1) / (alpha c) with |F| <= c v_ref^alpha [1/s].
  double rate_bound(double v_ref) const noexcept;
  template <int W>
  void eval(const double* y, int offset, Algebra& g) const noexcept;
  //! Its rows of J = df/dy and B = df/du (J and B zero on entry) from the evaluation g.
  void jacobian(const Algebra& g, int offset, int n, int ku, Jacobian& J, State* B) const noexcept {
    copy_rows(g, offset, count(), n, ku, J, B);
  }
};

}  // namespace servohydraulics
