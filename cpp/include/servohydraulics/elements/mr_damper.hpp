// MR damper, Spencer, Dyke, Sain, Carlson (1997), in parallel with the structure.  States mr_y, mr_z.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! F = c1 y' + k1 (x - x0),  y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1),
//! z' = BW(x' - y', z) with Spencer's (A, gamma, beta, n)  (effects.mr_damper).
struct MrDamper {
  static constexpr const char* kName = "mr_damper";
  static constexpr Port kPort = Port::Structure;
  static constexpr int kCapacity = 2;
  double alpha = 0.0, c0 = 0.0, c1 = 0.0;  //!< at the run's voltage
  double k0 = 0.0, k1 = 0.0, x0 = 0.0, A = 0.0, beta = 0.0, gamma = 0.0, n = 1.0;

  static std::optional<MrDamper> from(const Rig& rig, ControlMode mode);
  int count() const noexcept { return 2; }
  static const StateInfo* states() noexcept;
  double scale(int k) const noexcept { return k == 0 ? 1e-3 : 1e-6; }  // y as x [m]; z [m]
  void rest(const RestPoint& p, double* z) const noexcept;  //!< y = x, z = 0
  double static_force(double x) const noexcept { return k1 * (x - x0); }  //!< at rest: the accumulator
  double rate_bound(double v_ref) const noexcept;
  template <int W>
  void eval(const double* y, int offset, Algebra& g) const noexcept;
  //! Its rows of J = df/dy and B = df/du (J and B zero on entry) from the evaluation g.
  void jacobian(const Algebra& g, int offset, int n, int ku, Jacobian& J, State* B) const noexcept {
    copy_rows(g, offset, count(), n, ku, J, B);
  }
};

}  // namespace servohydraulics
