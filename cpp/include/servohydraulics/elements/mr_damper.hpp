// MR damper, Spencer, Dyke, Sain, Carlson (1997), in parallel with the structure.  States mr_y, mr_z.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! The MR damper's field-dependent parameters at the rig's field input u (rig.mr_input: mr_voltage
//! [V] or mr_current [A]) by its law (rig.mr_law): the one home of the law.
//!   spencer (Spencer et al. 1997):  alpha = alpha_a + alpha_b u, c0 = c0_a + c0_b u,
//!                                   c1 = c1_a + c1_b u, beta, gamma constant;
//!   quiroz2022 (Quiroz 2022, UTFSM): alpha = alpha_a + alpha_b u + alpha_c u^2, c0 and c1 as above,
//!                                   beta = mr_beta exp(-d u), gamma = mr_gamma exp(-d u), d = mr_bw_decay.
struct MrLawValues {
  double u = 0.0;  //!< the field input [V or A]
  double alpha = 0.0, c0 = 0.0, c1 = 0.0, beta = 0.0, gamma = 0.0;
};
MrLawValues mr_damper_law(const Rig& rig) noexcept;
//! Throws Error naming the field: the field input the law does not read is not 0, a quiroz2022 key is
//! not 0 under spencer, mr_law_min > mr_law_max, or the law gives alpha < 0 or beta, gamma not
//! finite at the rig's u.  (Rig::validate calls it.)
void validate_mr_law(const Rig& rig);

//! F = c1 y' + k1 (x - x0),  y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1),
//! z' = BW(x' - y', z) with Spencer's (A, gamma, beta, n)  (effects.mr_damper).
struct MrDamper {
  static constexpr const char* kName = "mr_damper";
  static constexpr Port kPort = Port::Structure;
  static constexpr int kCapacity = 2;
  double alpha = 0.0, c0 = 0.0, c1 = 0.0, beta = 0.0, gamma = 0.0;  //!< at the run's field input (mr_damper_law)
  double k0 = 0.0, k1 = 0.0, x0 = 0.0, A = 0.0, n = 1.0;

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
