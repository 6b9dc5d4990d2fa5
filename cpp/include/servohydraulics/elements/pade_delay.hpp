// The loop's analog transport delay on the valve drive, as an (N, N) Pade approximant.
#pragma once

#include <optional>

#include "servohydraulics/elements/element.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! The Pade loop delay's realisation: dq/dt = (A' q + e_N w) / tau, out = C' q + d w, with
//! A' a companion matrix whose last row is -a[0..N-1] (a monic denominator in s tau)
//! (effects.loop_delay; inactive in free mode).
struct PadeDelay {
  static constexpr const char* kName = "loop_delay";
  static constexpr Port kPort = Port::Drive;
  static constexpr int kCapacity = kMaxPadeOrder;
  int order = 0;
  double tau = 0.0;
  double a[kMaxPadeOrder] = {};  //!< denominator coefficients over the leading one
  double c[kMaxPadeOrder] = {};  //!< output row C'
  double a_tau[kMaxPadeOrder] = {};  //!< a[k] / tau: the last state's constant gradient on the chain
  double d = 0.0;                //!< feedthrough (-1)^N
  double K_s = 0.0;              //!< the valve gain (the rest state holds the spool)
  double full_drive = 0.0;       //!< the drive that opens the valve fully, x_v_max / K_s [V]

  static std::optional<PadeDelay> from(const Rig& rig, ControlMode mode);
  int count() const noexcept { return order; }
  static const StateInfo* states() noexcept;
  double scale(int k) const noexcept;
  void rest(const RestPoint& p, double* z) const noexcept;  //!< q_1 = w / a_0 holds the drive w = spool / K_s
  double static_force(double) const noexcept { return 0.0; }
  double rate_bound(double) const noexcept { return 0.0; }  // linear: the spectral radius sees it
  template <int W>
  void eval(const double* y, int offset, Algebra& g) const noexcept;
  //! Its rows of J and B (zero on entry): the chain's constant 1 / tau, and the last state's row
  //! from the evaluation g (the only one eval fills).
  void jacobian(const Algebra& g, int offset, int n, int ku, Jacobian& J, State* B) const noexcept;
};

//! Coefficients of the (N, N) Pade approximant of exp(-s tau) in s tau, lowest power first:
//! den[k] = (2N-k)! N! / ((2N)! k! (N-k)!), num[k] = (-1)^k den[k].  1 <= N <= kMaxPadeOrder.
void pade_coefficients(int order, double* num, double* den) noexcept;

}  // namespace servohydraulics
