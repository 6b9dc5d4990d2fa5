// The Pade loop delay on the valve drive w: q' = (A' q + e_N w) / tau, w_delayed = C' q + d w.
#include <algorithm>
#include <cmath>

#include "servohydraulics/elements/pade_delay.hpp"

namespace servohydraulics {

namespace {
constexpr StateInfo kPadeStates[kMaxPadeOrder] = {
    {"delay_1", "V", "Pade loop-delay state 1 (effects.loop_delay)"},
    {"delay_2", "V", "Pade loop-delay state 2"},
    {"delay_3", "V", "Pade loop-delay state 3"},
    {"delay_4", "V", "Pade loop-delay state 4"},
    {"delay_5", "V", "Pade loop-delay state 5"},
    {"delay_6", "V", "Pade loop-delay state 6"},
};

double factorial(int k) noexcept {
  double f = 1.0;
  for (int i = 2; i <= k; ++i) f *= i;
  return f;
}
}  // namespace

void pade_coefficients(int N, double* num, double* den) noexcept {
  for (int k = 0; k <= N; ++k) {
    den[k] = factorial(2 * N - k) * factorial(N) / (factorial(2 * N) * factorial(k) * factorial(N - k));
    num[k] = (k % 2 ? -1.0 : 1.0) * den[k];
  }
}

std::optional<PadeDelay> PadeDelay::from(const Rig& r, ControlMode mode) {
  if (mode == ControlMode::Free || !r.effects.loop_delay) return std::nullopt;
  const int N = static_cast<int>(r.loop_delay_order);
  double num[kMaxPadeOrder + 1], den[kMaxPadeOrder + 1];
  pade_coefficients(N, num, den);
  PadeDelay P;
  P.order = N;
  P.tau = r.loop_delay;
  P.d = num[N] / den[N];
  for (int k = 0; k < N; ++k) {
    P.a[k] = den[k] / den[N];
    P.c[k] = (num[k] - P.d * den[k]) / den[N];
    P.a_tau[k] = P.a[k] / P.tau;
  }
  P.K_s = r.K_s;
  P.full_drive = r.x_v_max / r.K_s;
  return P;
}

const StateInfo* PadeDelay::states() noexcept { return kPadeStates; }

// Pade state q_k [V]: the full-scale drive (the one that opens the valve fully) over the largest
// coefficient through which q_k acts (the denominator a_k on the chain, the output row c_k on the
// drive), so that its tolerance weighs the drive error it makes, as the valve states' tolerances do.
double PadeDelay::scale(int k) const noexcept {
  return full_drive / std::max({1.0, std::fabs(a[k]), std::fabs(c[k])});
}

void PadeDelay::rest(const RestPoint& p, double* z) const noexcept {
  for (int k = 0; k < order; ++k) z[k] = 0.0;
  z[0] = p.spool / (K_s * a[0]);
}

// The sums run in locals and the last row is built in a local array: y, g's rows and this element
// could alias as far as the compiler knows, which made it store and reload every term and check
// the row's loop for overlap at run time (+50 instructions a call, +6 % on a step with order 3).
template <int W>
void PadeDelay::eval(const double* y, int i0, Algebra& g) const noexcept {
  const int N = order;
  const double* q = y + i0;
  double vdrive = d * g.drive, last = g.drive;
  for (int j = 0; j < W; ++j) g.dvdrive[j] = d * g.ddrive[j];
  for (int k = 0; k < N; ++k) {
    vdrive += c[k] * q[k];
    if constexpr (W > 0) g.dvdrive[i0 + k] += c[k];
    last -= a[k] * q[k];
  }
  g.vdrive = vdrive;
  // The chain q_k' = q_(k+1) / tau (its constant gradient rows are written by jacobian()), and
  // the last state's rate and row.
  for (int k = 0; k + 1 < N; ++k) g.rate[i0 + k] = q[k + 1] / tau;
  g.rate[i0 + N - 1] = last / tau;
  if constexpr (W == 0) return;  // the values alone (rhs)
  double row[kGradientCapacity];
  for (int j = 0; j < W; ++j) row[j] = g.ddrive[j] / tau;
  for (int k = 0; k < N; ++k) row[i0 + k] -= a_tau[k];
  std::copy(row, row + W, g.drate[i0 + N - 1]);
}

void PadeDelay::jacobian(const Algebra& g, int i0, int n, int ku, Jacobian& J, State* B) const noexcept {
  for (int k = 0; k + 1 < order; ++k) J[i0 + k][i0 + k + 1] = 1.0 / tau;
  copy_rows(g, i0 + order - 1, 1, n, ku, J, B);
}

SH_ELEMENT_EVAL_WIDTHS(PadeDelay);

}  // namespace servohydraulics
