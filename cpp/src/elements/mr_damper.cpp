// MR damper, Spencer et al. (1997): y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1),
// z' = BW(x' - y', z), F = c1 y' + k1 (x - x0); alpha, c0, c1, beta, gamma by the field law
// (mr_damper_law: Spencer's linear law or the UTFSM thesis' law in the current or voltage u).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "hysteresis.hpp"
#include "servohydraulics/elements/mr_damper.hpp"

namespace servohydraulics {

namespace {
std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

constexpr StateInfo kMrStates[] = {
    {"mr_y", "m", "MR damper internal displacement y (Spencer et al. 1997; effects.mr_damper)"},
    {"mr_z", "m", "MR damper evolutionary variable z (Spencer et al. 1997; effects.mr_damper)"},
};
}

MrLawValues mr_damper_law(const Rig& r) noexcept {
  MrLawValues v;
  v.u = r.mr_input == MrInput::Current ? r.mr_current : r.mr_voltage;
  const double u = v.u;
  v.alpha = r.mr_alpha_a + r.mr_alpha_b * u;
  v.c0 = r.mr_c0_a + r.mr_c0_b * u;
  v.c1 = r.mr_c1_a + r.mr_c1_b * u;
  v.beta = r.mr_beta;
  v.gamma = r.mr_gamma;
  if (r.mr_law == MrLaw::Quiroz2022) {  // (Spencer's terms are left bit-identical)
    v.alpha += r.mr_alpha_c * u * u;
    const double decay = std::exp(-r.mr_bw_decay * u);
    v.beta *= decay;
    v.gamma *= decay;
  }
  return v;
}

void validate_mr_law(const Rig& r) {
  if (r.mr_input == MrInput::Voltage)
    require(r.mr_current == 0.0, "mr_current", r.mr_current,
            "must be 0 when mr_input = \"voltage\" (the law reads mr_voltage; set mr_input = \"current\")");
  else
    require(r.mr_voltage == 0.0, "mr_voltage", r.mr_voltage,
            "must be 0 when mr_input = \"current\" (the law reads mr_current; set mr_input = \"voltage\")");
  if (r.mr_law == MrLaw::Spencer) {
    const char* why = "must be 0 under mr_law = \"spencer\" (it is a term of mr_law = \"quiroz2022\")";
    require(r.mr_alpha_c == 0.0, "mr_alpha_c", r.mr_alpha_c, why);
    require(r.mr_bw_decay == 0.0, "mr_bw_decay", r.mr_bw_decay, why);
  }
  require(r.mr_law_min <= r.mr_law_max, "mr_law_min", r.mr_law_min,
          ("must be <= mr_law_max = " + num(r.mr_law_max)).c_str());
  const MrLawValues v = mr_damper_law(r);
  const std::string at = std::string(" at the field input u = ") + num(v.u) +
                         (r.mr_input == MrInput::Current ? " A" : " V") + " (mr_law = \"" +
                         name_of(kMrLawNames, r.mr_law) + "\")";
  require(std::isfinite(v.alpha) && v.alpha >= 0.0, "mr_alpha_c", r.mr_alpha_c,
          ("gives alpha = " + num(v.alpha) + " N/m" + at + ": alpha must be finite and >= 0").c_str());
  // c0, c1 > 0 follow from their keys' bounds (c0_a, c1_a > 0, slopes >= 0)
  require(std::isfinite(v.beta) && std::isfinite(v.gamma), "mr_bw_decay", r.mr_bw_decay,
          ("gives beta = " + num(v.beta) + ", gamma = " + num(v.gamma) + at +
           ": both must be finite")
              .c_str());
}

std::optional<MrDamper> MrDamper::from(const Rig& r, ControlMode) {
  if (!r.effects.mr_damper) return std::nullopt;
  const MrLawValues v = mr_damper_law(r);
  MrDamper m;
  m.alpha = v.alpha;
  m.c0 = v.c0;
  m.c1 = v.c1;
  m.beta = v.beta;
  m.gamma = v.gamma;
  m.k0 = r.mr_k0;
  m.k1 = r.mr_k1;
  m.x0 = r.mr_x0;
  m.A = r.mr_A;
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
  const detail::Hysteretic h = detail::hysteretic_rate(v - ydot, y[iz], A, gamma, beta, n);
  g.rate[iy] = ydot;
  g.rate[iz] = h.f;
  g.Fsp += c1 * ydot + k1 * (x - x0);
  if constexpr (W == 0) return;  // the values alone (rhs)
  dy[kX] = k0 / cs;
  dy[kV] = c0 / cs;
  dy[iy] = -k0 / cs;
  dy[iz] = alpha / cs;
  for (int j = 0; j < W; ++j) dz[j] = -h.df_dw * dy[j];
  dz[kV] += h.df_dw;
  dz[iz] += h.df_dz;
  for (int j = 0; j < W; ++j) g.dFsp[j] += c1 * dy[j];
  g.dFsp[kX] += k1;
}

SH_ELEMENT_EVAL_WIDTHS(MrDamper);

}  // namespace servohydraulics
