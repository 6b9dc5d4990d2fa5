// Bouc-Wen hysteretic specimen (Wen 1976): F_bw = k z, z' = BW(v, z).
#include <algorithm>

#include "hysteresis.hpp"
#include "servohydraulics/elements/bouc_wen.hpp"

namespace servohydraulics {

namespace {
constexpr StateInfo kBoucWenStates[] = {
    {"bw_z", "m", "Bouc-Wen hysteretic displacement z (effects.bouc_wen_hysteresis)"}};
}

std::optional<BoucWen> BoucWen::from(const Rig& r, ControlMode) {
  if (!r.effects.bouc_wen_hysteresis) return std::nullopt;
  return BoucWen{r.bw_k, r.bw_A, r.bw_beta, r.bw_gamma, r.bw_n};
}

const StateInfo* BoucWen::states() noexcept { return kBoucWenStates; }

double BoucWen::rate_bound(double v_ref) const noexcept { return detail::hysteretic_bound(A, beta + gamma, n, v_ref); }

template <int W>
void BoucWen::eval(const double* y, int iz, Algebra& g) const noexcept {
  double* dr = g.drate[iz];
  std::fill(dr, dr + W, 0.0);
  const detail::Hysteretic h = detail::hysteretic_rate(y[kV], y[iz], A, beta, gamma, n);
  g.rate[iz] = h.f;
  g.Fsp += k * y[iz];
  if constexpr (W == 0) return;  // the values alone (rhs)
  dr[kV] = h.df_dw;
  dr[iz] = h.df_dz;
  g.dFsp[iz] += k;
}

SH_ELEMENT_EVAL_WIDTHS(BoucWen);

}  // namespace servohydraulics
