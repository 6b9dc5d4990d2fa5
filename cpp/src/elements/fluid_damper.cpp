// Nonlinear viscous fluid damper with a Maxwell (series) stiffness: the dashpot's displacement u
// is the state, the series spring carries F = k_d (x - u), the dashpot F = c |u'|^alpha sign(u').
#include <algorithm>
#include <cmath>

#include "servohydraulics/elements/fluid_damper.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
constexpr StateInfo kFluidDamperStates[] = {
    {"fd_u", "m", "fluid damper's dashpot displacement u (effects.fluid_damper)"}};
}

std::optional<FluidDamper> FluidDamper::from(const Rig& r, ControlMode) {
  if (!r.effects.fluid_damper) return std::nullopt;
  require(r.fd_alpha <= 1.0, "fd_alpha", r.fd_alpha,
          "must be in (0, 1] (a fluid damper's velocity exponent; above 1 the dashpot rate has an infinite "
          "slope at zero force)");
  return FluidDamper{r.fd_c, r.fd_alpha, r.fd_k};
}

const StateInfo* FluidDamper::states() noexcept { return kFluidDamperStates; }

double FluidDamper::rate_bound(double v_ref) const noexcept {
  return k * std::pow(v_ref, 1.0 - alpha) / (alpha * c);
}

template <int W>
void FluidDamper::eval(const double* y, int iu, Algebra& g) const noexcept {
  const double F = k * (y[kX] - y[iu]);
  double rate, slope;  // u' and du'/dF
  if (alpha == 1.0) {
    rate = F / c;
    slope = 1.0 / c;
  } else {
    const double q = std::fabs(F) / c;
    slope = std::pow(q, 1.0 / alpha - 1.0) / (alpha * c);
    rate = std::copysign(q * slope * alpha * c, F);  // (|F| / c)^(1/alpha), signed
  }
  double* dr = g.drate[iu];
  std::fill(dr, dr + W, 0.0);
  g.rate[iu] = rate;
  g.Fsp += F;
  if constexpr (W == 0) return;  // the values alone (rhs)
  dr[kX] = slope * k;
  dr[iu] = -slope * k;
  g.dFsp[kX] += k;
  g.dFsp[iu] -= k;
}

SH_ELEMENT_EVAL_WIDTHS(FluidDamper);

}  // namespace servohydraulics
