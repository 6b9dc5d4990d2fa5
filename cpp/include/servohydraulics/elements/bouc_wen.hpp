// Bouc-Wen hysteretic specimen (Wen 1976), in parallel with the structure.  One state, bw_z.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! F_bw = k z,  z' = A v - beta |v| |z|^(n-1) z - gamma v |z|^n  (effects.bouc_wen_hysteresis).
struct BoucWen {
  static constexpr const char* kName = "bouc_wen_hysteresis";  //!< its switch in Effects
  static constexpr Port kPort = Port::Structure;
  static constexpr int kCapacity = 1;  //!< most states it appends
  double k = 0.0, A = 0.0, beta = 0.0, gamma = 0.0, n = 1.0;

  static std::optional<BoucWen> from(const Rig& rig, ControlMode mode);
  int count() const noexcept { return 1; }
  static const StateInfo* states() noexcept;
  double scale(int) const noexcept { return 1e-6; }  // [m], as the LuGre bristle
  void rest(const RestPoint&, double* z) const noexcept { z[0] = 0.0; }
  double static_force(double) const noexcept { return 0.0; }
  double rate_bound(double v_ref) const noexcept;  //!< |dz'/dz| bound when sliding at v_ref [1/s]
  template <int W>
  void eval(const double* y, int offset, Algebra& g) const noexcept;
  //! Its rows of J = df/dy and B = df/du (J and B zero on entry) from the evaluation g.
  void jacobian(const Algebra& g, int offset, int n, int ku, Jacobian& J, State* B) const noexcept {
    copy_rows(g, offset, count(), n, ku, J, B);
  }
};

}  // namespace servohydraulics
