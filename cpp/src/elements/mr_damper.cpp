// MR damper, Spencer et al. (1997): y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1),
// z' = BW(x' - y', z), F = c1 y' + k1 (x - x0).
#include <algorithm>

#include "hysteresis.hpp"
#include "servohydraulics/elements/mr_damper.hpp"

namespace servohydraulics {

namespace {
constexpr StateInfo kMrStates[] = {
    {"mr_y", "m", "MR damper internal displacement y (Spencer et al. 1997; effects.mr_damper)"},
    {"mr_z", "m", "MR damper evolutionary variable z (Spencer et al. 1997; effects.mr_damper)"},
};
}

std::optional<MrDamper> MrDamper::from(const Rig& r, ControlMode) {
  if (!r.effects.mr_damper) return std::nullopt;
  const double u = r.mr_voltage;
  MrDamper m;
  m.alpha = r.mr_alpha_a + r.mr_alpha_b * u;
  m.c0 = r.mr_c0_a + r.mr_c0_b * u;
  m.c1 = r.mr_c1_a + r.mr_c1_b * u;
  m.k0 = r.mr_k0;
  m.k1 = r.mr_k1;
  m.x0 = r.mr_x0;
  m.A = r.mr_A;
  m.beta = r.mr_beta;
  m.gamma = r.mr_gamma;
  m.n = r.mr_n;
  return m;
}

const StateInfo* MrDamper::states() noexcept { return kMrStates; }

void MrDamper::rest(const RestPoint& p, double* z) const noexcept {
  z[0] = p.x;
  z[1] = 0.0;
}

double MrDamper::rate_bound(double v_ref) const noexcept {
  const double cs = c0 + c1;
  return detail::hysteretic_bound(A, beta + gamma, n, v_ref) + (A * alpha + k0) / cs;
}

template <int W>
void MrDamper::eval(const double* y, int iy, Algebra& g) const noexcept {
  const int iz = iy + 1;
  const double x = y[kX], v = y[kV];
  const double cs = c0 + c1;
  double* dy = g.drate[iy];
  double* dz = g.drate[iz];
  std::fill(dy, dy + W, 0.0);
  const double ydot = (alpha * y[iz] + c0 * v + k0 * (x - y[iy])) / cs;
  dy[kX] = k0 / cs;
  dy[kV] = c0 / cs;
  dy[iy] = -k0 / cs;
  dy[iz] = alpha / cs;
  const detail::Hysteretic h = detail::hysteretic_rate(v - ydot, y[iz], A, gamma, beta, n);
  g.rate[iy] = ydot;
  g.rate[iz] = h.f;
  for (int j = 0; j < W; ++j) dz[j] = -h.df_dw * dy[j];
  dz[kV] += h.df_dw;
  dz[iz] += h.df_dz;
  g.Fsp += c1 * ydot + k1 * (x - x0);
  for (int j = 0; j < W; ++j) g.dFsp[j] += c1 * dy[j];
  g.dFsp[kX] += k1;
}

SH_ELEMENT_EVAL_WIDTHS(MrDamper);

}  // namespace servohydraulics
