// Right-hand side, analytic Jacobian and outputs of the plant, Eqs (1)-(5).
#include <algorithm>
#include <cmath>

#include "servohydraulics/dynamics.hpp"

namespace servohydraulics {

namespace {
constexpr double kPi = 3.14159265358979323846;
// Width of the C1 polynomial patch of the signed square root near 0 (Eq 3).
constexpr double kSqrtEps = 1e-3;

// Signed square root sign(r) sqrt(|r|), replaced by a C1 odd cubic for |r| < eps
// so that the Jacobian stays finite when the load pressure reaches p_s.  Past
// p_s the flow reverses through the open port, which bounds p by the supply.
double ssqrt(double r) noexcept {
  const double a = std::fabs(r);
  if (a >= kSqrtEps) return std::copysign(std::sqrt(a), r);
  const double se = std::sqrt(kSqrtEps);
  return 1.25 * r / se - 0.25 * r * r * r / (kSqrtEps * kSqrtEps * se);
}
double ssqrt_slope(double r) noexcept {
  const double a = std::fabs(r);
  if (a >= kSqrtEps) return 0.5 / std::sqrt(a);
  const double se = std::sqrt(kSqrtEps);
  return 1.25 / se - 0.75 * r * r / (kSqrtEps * kSqrtEps * se);
}
double sgn(double v) noexcept { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// The Bouc-Wen evolution law (Wen 1976) and its partial derivatives:
//   z' = A w - b |w| |z|^(n-1) z - g w |z|^n,  w the deformation rate.
// Spencer et al. (1997) write the same law with their gamma on the |w| term and
// their beta on the w term: call it with (A, gamma_S, beta_S).
struct Hysteretic {
  double f = 0.0, df_dw = 0.0, df_dz = 0.0;
};
Hysteretic hysteretic_rate(double w, double z, double A, double b, double g, double n) noexcept {
  const double az = std::fabs(z);
  const double p = n == 1.0 ? 1.0 : std::pow(az, n - 1.0);  // |z|^(n-1)
  const double zn = p * az;                                   // |z|^n
  Hysteretic h;
  h.f = A * w - b * std::fabs(w) * p * z - g * w * zn;
  h.df_dw = A - b * sgn(w) * p * z - g * zn;
  h.df_dz = -n * p * (b * std::fabs(w) + g * w * sgn(z));
  return h;
}

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

Dynamics::Dynamics(const Rig& rig, ControlMode mode) : rig_(rig), mode_(mode) {
  rig_.validate();
  if (mode == ControlMode::Force && rig_.G_d != 0.0)
    require(false, "G_d", rig_.G_d, "derivative gain in force control is not modelled; set G_d = 0");
  const bool actuator = mode != ControlMode::Free;
  mp_ = (actuator && rig_.effects.piston_mass) ? rig_.m_p : 0.0;
  M_ = rig_.m + mp_;
  CF_ = mode == ControlMode::Force ? rig_.C_F_force : rig_.C_F_disp;
  wv_ = 2.0 * kPi * rig_.f_v;
  lugre_ = rig_.effects.coulomb_friction && rig_.effects.lugre_friction && rig_.F_c > 0.0;
  // Appended states, in a fixed order: Bouc-Wen z, MR damper (y, z), Pade loop delay.
  int n = kNumStates;
  if (rig_.effects.bouc_wen_hysteresis) layout_.bw_z = n++;
  if (rig_.effects.mr_damper) {
    layout_.mr_y = n;
    n += 2;
    const double u = rig_.mr_voltage;
    mr_alpha_ = rig_.mr_alpha_a + rig_.mr_alpha_b * u;
    mr_c0_ = rig_.mr_c0_a + rig_.mr_c0_b * u;
    mr_c1_ = rig_.mr_c1_a + rig_.mr_c1_b * u;
  }
  if (actuator && rig_.effects.loop_delay) {
    const int N = static_cast<int>(rig_.loop_delay_order);
    layout_.pade = n;
    layout_.pade_order = N;
    n += N;
    double num[kMaxPadeOrder + 1], den[kMaxPadeOrder + 1];
    pade_coefficients(N, num, den);
    pade_.order = N;
    pade_.tau = rig_.loop_delay;
    pade_.d = num[N] / den[N];
    for (int k = 0; k < N; ++k) {
      pade_.a[k] = den[k] / den[N];
      pade_.c[k] = (num[k] - pade_.d * den[k]) / den[N];
    }
  }
  layout_.num_states = n;
  ku_ = n;
  ng_ = n + 1;
}

const StateInfo& Dynamics::state_info(int i) const noexcept {
  const StateLayout& L = layout_;
  if (i == L.bw_z) return kBoucWenState;
  if (L.mr_y >= 0 && (i == L.mr_y || i == L.mr_y + 1)) return kMrStates[i - L.mr_y];
  if (L.pade >= 0 && i >= L.pade && i < L.pade + L.pade_order) return kPadeStates[i - L.pade];
  return kStates[i >= 0 && i < kNumStates ? i : 0];
}

double Dynamics::state_scale(int i) const noexcept {
  const StateLayout& L = layout_;
  if (i == L.bw_z) return 1e-6;                  // [m], as the LuGre bristle
  if (i == L.mr_y) return 1e-3;                  // [m], as x
  if (L.mr_y >= 0 && i == L.mr_y + 1) return 1e-6;  // [m]
  if (L.pade >= 0 && i >= L.pade && i < L.pade + L.pade_order) {
    // Pade state q_k [V]: the full-scale drive (the one that opens the valve fully)
    // over the largest coefficient through which q_k acts (the denominator a_k on the
    // chain, the output row c_k on the drive), so that its tolerance weighs the drive
    // error it makes, as the valve states' tolerances do.
    const int k = i - L.pade;
    const double drive = rig_.x_v_max / rig_.K_s;
    return drive / std::max({1.0, std::fabs(pade_.a[k]), std::fabs(pade_.c[k])});
  }
  return 1e-3;
}

double Dynamics::static_force(double x) const noexcept {
  const double f = spring_force(x);
  return layout_.mr_y >= 0 ? f + rig_.mr_k1 * (x - rig_.mr_x0) : f;  // at rest y = x, z = 0: F_mr = k1 (x - x0)
}

double Dynamics::hysteretic_rate_bound(double v_ref) const noexcept {
  // |dz'/dz| <= n (beta + gamma) |z|^(n-1) |w|, with |z| below its ultimate (A / (beta + gamma))^(1/n).
  auto bound = [v_ref](double A, double bg, double n) {
    if (bg <= 0.0) return 0.0;
    return n * bg * std::pow(A / bg, (n - 1.0) / n) * v_ref;
  };
  const Rig& r = rig_;
  double rho = 0.0;
  if (layout_.bw_z >= 0) rho = std::max(rho, bound(r.bw_A, r.bw_beta + r.bw_gamma, r.bw_n));
  if (layout_.mr_y >= 0) {
    const double cs = mr_c0_ + mr_c1_;
    rho = std::max(rho, bound(r.mr_A, r.mr_beta + r.mr_gamma, r.mr_n) + (r.mr_A * mr_alpha_ + r.mr_k0) / cs);
  }
  return rho;
}

double Dynamics::spring_force(double x) const noexcept {
  const double xc = rig_.x_contact;
  if (!rig_.effects.spring_softening || std::fabs(x) <= xc) return rig_.k * x;
  return std::copysign(rig_.k * xc + rig_.k_2 * (std::fabs(x) - xc), x);
}
double Dynamics::spring_stiffness(double x) const noexcept {
  if (!rig_.effects.spring_softening || std::fabs(x) <= rig_.x_contact) return rig_.k;
  return rig_.k_2;
}
double Dynamics::friction_level(double v) const noexcept {
  if (rig_.stribeck_ratio == 1.0) return rig_.F_c;
  const double q = v / rig_.v_s;
  return rig_.F_c * (1.0 + (rig_.stribeck_ratio - 1.0) * std::exp(-q * q));
}
double Dynamics::friction_level_slope(double v) const noexcept {
  if (rig_.stribeck_ratio == 1.0) return 0.0;
  const double q = v / rig_.v_s;
  return rig_.F_c * (rig_.stribeck_ratio - 1.0) * std::exp(-q * q) * (-2.0 * q / rig_.v_s);
}
double Dynamics::friction_force(double v) const noexcept {
  if (!rig_.effects.coulomb_friction || rig_.F_c == 0.0) return 0.0;
  return friction_level(v) * std::tanh(v / rig_.v_stick);
}
double Dynamics::friction_slope(double v) const noexcept {
  if (!rig_.effects.coulomb_friction || rig_.F_c == 0.0) return 0.0;
  const double t = std::tanh(v / rig_.v_stick);
  return friction_level_slope(v) * t + friction_level(v) * (1.0 - t * t) / rig_.v_stick;
}
double Dynamics::flow_gain(double s) const noexcept {
  return rig_.effects.flow_nonlinearity ? rig_.flow_curve.eval(s) : s;
}
double Dynamics::flow_gain_slope(double s) const noexcept {
  return rig_.effects.flow_nonlinearity ? rig_.flow_curve.slope(s) : 1.0;
}
double Dynamics::pressure_factor(double s, double p) const noexcept {
  if (!rig_.effects.load_pressure) return 1.0;
  return ssqrt(1.0 - sgn(s) * p / rig_.p_s);
}
double Dynamics::pressure_factor_dp(double s, double p) const noexcept {
  if (!rig_.effects.load_pressure) return 0.0;
  return -sgn(s) / rig_.p_s * ssqrt_slope(1.0 - sgn(s) * p / rig_.p_s);
}

// Gradients have the active states' columns 0..n-1 and one more, index ku_ = n, for the
// derivative by the command u (n = num_states(): the width stays the paper plant's 7 when no
// element is appended).  Arrays are sized for the capacity; evaluate<W> runs over W = n + 1.
constexpr int kCap = kMaxStates + 1;

struct Dynamics::Algebra {
  double a = 0, da[kCap];          // acceleration and its gradient
  double F = 0, dF[kCap];          // load-cell force
  double drive = 0, ddrive[kCap];  // valve drive after saturation
  double s = 0, ds[kCap];          // metering opening after saturation
  double Q = 0, dQ[kCap];          // valve flow
  double pdot = 0, dpdot[kCap];
  double xvdd = 0, dxvdd[kCap];
  double zdot = 0, dzdot[kCap];    // LuGre bristle rate
  double Fsp = 0, dFsp[kCap];      // specimen force (Bouc-Wen + MR damper)
  double bw_zdot = 0, dbw_zdot[kCap];  // Bouc-Wen rate
  double mr_ydot = 0, dmr_ydot[kCap];  // MR damper y' and z'
  double mr_zdot = 0, dmr_zdot[kCap];
  double vdrive = 0, dvdrive[kCap];    // the drive as the valve sees it (after the Pade loop delay)
  double qdot = 0, dqdot[kCap];        // the last Pade state's rate
  bool drive_sat = false, spool_sat = false;
  // Zeroes the first W entries of the gradients of the paper plant (and of the specimen force,
  // read by outputs()); the appended elements zero theirs when on.
  template <int W>
  void zero() noexcept {
    for (int j = 0; j < W; ++j) {
      da[j] = dF[j] = ddrive[j] = ds[j] = dQ[j] = 0.0;
      dpdot[j] = dxvdd[j] = dzdot[j] = dFsp[j] = 0.0;
    }
  }
};

struct Dynamics::Friction {
  double F = 0, dF_dv = 0, dF_dz = 0;           // friction force and its gradient
  double zdot = 0, dzdot_dv = 0, dzdot_dz = 0;  // LuGre bristle rate and its gradient
};

// Friction: the static law g(v) tanh(v / v_stick), or LuGre (Canudas de Wit et al. 1995):
// z' = v - sigma_0 |v| z / g(v),  F_f = sigma_0 z + sigma_1 z'  (its sigma_2 v is c v).
Dynamics::Friction Dynamics::friction(double v, double z) const noexcept {
  const Rig& r = rig_;
  Friction f;
  if (lugre_) {
    const double gv = friction_level(v), av = std::fabs(v);
    f.zdot = v - r.sigma_0 * av * z / gv;
    f.dzdot_dv = 1.0 - r.sigma_0 * z * (sgn(v) * gv - av * friction_level_slope(v)) / (gv * gv);
    f.dzdot_dz = -r.sigma_0 * av / gv;
    f.F = r.sigma_0 * z + r.sigma_1 * f.zdot;
    f.dF_dv = r.sigma_1 * f.dzdot_dv;
    f.dF_dz = r.sigma_0 + r.sigma_1 * f.dzdot_dz;
  } else {
    f.F = friction_force(v);
    f.dF_dv = friction_slope(v);
  }
  return f;
}

double Dynamics::specimen_force(const double* y) const noexcept {
  if (layout_.bw_z < 0 && layout_.mr_y < 0) return 0.0;
  Algebra g;
  g.zero<kCap>();
  specimen<kCap>(y, g);
  return g.Fsp;
}

double Dynamics::structure_force(double x, double v, double z) const noexcept {
  return friction(v, z).F + rig_.c * v + spring_force(x);
}

// Specimen elements in parallel with the structure: their force and state rates.
// Bouc-Wen (Wen 1976): F = bw_k z.  MR damper (Spencer et al. 1997):
// y' = (alpha z + c0 x' + k0 (x - y)) / (c0 + c1), z' = BW(x' - y', z), F = c1 y' + k1 (x - x0).
template <int W>
void Dynamics::specimen(const double* y, Algebra& g) const noexcept {
  const Rig& r = rig_;
  const double x = y[kX], v = y[kV];
  if (layout_.bw_z >= 0) {
    const int iz = layout_.bw_z;
    std::fill(g.dbw_zdot, g.dbw_zdot + W, 0.0);
    const Hysteretic h = hysteretic_rate(v, y[iz], r.bw_A, r.bw_beta, r.bw_gamma, r.bw_n);
    g.bw_zdot = h.f;
    g.dbw_zdot[kV] = h.df_dw;
    g.dbw_zdot[iz] = h.df_dz;
    g.Fsp += r.bw_k * y[iz];
    g.dFsp[iz] += r.bw_k;
  }
  if (layout_.mr_y >= 0) {
    const int iy = layout_.mr_y, iz = iy + 1;
    const double cs = mr_c0_ + mr_c1_;
    std::fill(g.dmr_ydot, g.dmr_ydot + W, 0.0);
    g.mr_ydot = (mr_alpha_ * y[iz] + mr_c0_ * v + r.mr_k0 * (x - y[iy])) / cs;
    g.dmr_ydot[kX] = r.mr_k0 / cs;
    g.dmr_ydot[kV] = mr_c0_ / cs;
    g.dmr_ydot[iy] = -r.mr_k0 / cs;
    g.dmr_ydot[iz] = mr_alpha_ / cs;
    const Hysteretic h = hysteretic_rate(v - g.mr_ydot, y[iz], r.mr_A, r.mr_gamma, r.mr_beta, r.mr_n);
    g.mr_zdot = h.f;
    for (int j = 0; j < W; ++j) g.dmr_zdot[j] = -h.df_dw * g.dmr_ydot[j];
    g.dmr_zdot[kV] += h.df_dw;
    g.dmr_zdot[iz] += h.df_dz;
    g.Fsp += mr_c1_ * g.mr_ydot + r.mr_k1 * (x - r.mr_x0);
    for (int j = 0; j < W; ++j) g.dFsp[j] += mr_c1_ * g.dmr_ydot[j];
    g.dFsp[kX] += r.mr_k1;
  }
}

// The Pade loop delay on the valve drive w: q' = (A' q + e_N w) / tau, w_delayed = C' q + d w.
template <int W>
void Dynamics::loop_delay(const double* y, Algebra& g) const noexcept {
  const Pade& P = pade_;
  const int i0 = layout_.pade, N = P.order;
  g.vdrive = P.d * g.drive;
  for (int j = 0; j < W; ++j) g.dvdrive[j] = P.d * g.ddrive[j];
  double last = g.drive;
  for (int k = 0; k < N; ++k) {
    g.vdrive += P.c[k] * y[i0 + k];
    g.dvdrive[i0 + k] += P.c[k];
    last -= P.a[k] * y[i0 + k];
  }
  g.qdot = last / P.tau;
  for (int j = 0; j < W; ++j) g.dqdot[j] = g.ddrive[j] / P.tau;
  for (int k = 0; k < N; ++k) g.dqdot[i0 + k] -= P.a[k] / P.tau;
}

template <int W>
void Dynamics::evaluate(const double* y, const Input& in, Algebra& g) const noexcept {
  g.zero<W>();
  const Rig& r = rig_;
  const bool actuator = mode_ != ControlMode::Free;
  const double x = y[kX], v = y[kV], p = y[kP];

  // Friction (the static law or LuGre, see friction()).
  const Friction f = friction(v, y[kZ]);
  const double Ff = f.F, dFf_dv = f.dF_dv, dFf_dz = f.dF_dz;
  if (lugre_) {
    g.zdot = f.zdot;
    g.dzdot[kV] = f.dzdot_dv;
    g.dzdot[kZ] = f.dzdot_dz;
  }

  // Structure, Eq (5) with the piston riding along: M a = pA - F_f - c v - f_s(x).
  const double applied = actuator ? p * r.A : in.u;  // Free: the command is an ideal force
  const bool specimen_on = layout_.bw_z >= 0 || layout_.mr_y >= 0;
  if (!specimen_on) {
    g.a = (applied - Ff - r.c * v - spring_force(x)) / M_;
    g.da[kX] = -spring_stiffness(x) / M_;
    g.da[kV] = -(dFf_dv + r.c) / M_;
  } else {
    specimen<W>(y, g);
    g.a = (applied - Ff - r.c * v - spring_force(x) - g.Fsp) / M_;
    for (int j = 0; j < W; ++j) g.da[j] = -g.dFsp[j] / M_;
    g.da[kX] = -(spring_stiffness(x) + g.dFsp[kX]) / M_;
    g.da[kV] = -(dFf_dv + r.c + g.dFsp[kV]) / M_;
  }
  g.da[kZ] = -dFf_dz / M_;
  g.da[kP] = actuator ? r.A / M_ : 0.0;
  g.da[ku_] = actuator ? 0.0 : 1.0 / M_;
  if (!actuator) {
    g.dF[ku_] = 1.0;
    g.F = in.u;
    return;
  }
  // Load cell between piston and structure: F = pA - m_p a.
  g.F = p * r.A - mp_ * g.a;
  for (int j = 0; j < W; ++j) g.dF[j] = -mp_ * g.da[j];
  g.dF[kP] += r.A;

  // Servo controller, Eq (1).
  double raw;
  double draw[kCap];
  std::fill(draw, draw + W, 0.0);
  if (mode_ == ControlMode::Displacement) {
    raw = CF_ * (r.G_p * (in.u - x) + r.G_d * (in.u_rate - v));
    draw[kX] = -CF_ * r.G_p;
    draw[kV] = -CF_ * r.G_d;
    draw[ku_] = CF_ * r.G_p;
  } else {
    raw = CF_ * r.G_p * (in.u - g.F);
    for (int j = 0; j < W; ++j) draw[j] = -CF_ * r.G_p * g.dF[j];
    draw[ku_] += CF_ * r.G_p;
  }
  g.drive_sat = r.effects.drive_saturation && std::fabs(raw) >= r.v_max;
  g.drive = g.drive_sat ? std::copysign(r.v_max, raw) : raw;
  for (int j = 0; j < W; ++j) g.ddrive[j] = g.drive_sat ? 0.0 : draw[j];
  // The drive the valve sees: delayed by the Pade loop delay when it is on.
  double vdrive = g.drive;
  const double* dvdrive = g.ddrive;
  if (layout_.pade >= 0) {
    loop_delay<W>(y, g);
    vdrive = g.vdrive;
    dvdrive = g.dvdrive;
  }

  // Servovalve: Eq (2) as x_v'' = w_v^2 (K_s v - x_v) - 2 zeta_v w_v x_v', or Eq (6).
  double xv;
  double dxv[kCap];
  std::fill(dxv, dxv + W, 0.0);
  if (r.effects.servovalve_dynamics) {
    xv = y[kXv];
    dxv[kXv] = 1.0;
    const double w2 = wv_ * wv_;
    g.xvdd = w2 * (r.K_s * vdrive - y[kXv]) - 2.0 * r.zeta_v * wv_ * y[kXvDot];
    for (int j = 0; j < W; ++j) g.dxvdd[j] = w2 * r.K_s * dvdrive[j];
    g.dxvdd[kXv] -= w2;
    g.dxvdd[kXvDot] -= 2.0 * r.zeta_v * wv_;
  } else {
    xv = r.K_s * vdrive;
    for (int j = 0; j < W; ++j) dxv[j] = r.K_s * dvdrive[j];
  }
  g.spool_sat = r.effects.spool_saturation && std::fabs(xv) >= r.x_v_max;
  g.s = g.spool_sat ? std::copysign(r.x_v_max, xv) : xv;
  for (int j = 0; j < W; ++j) g.ds[j] = g.spool_sat ? 0.0 : dxv[j];

  // Valve flow, Eq (3) (Eq 7 with the effects off).
  const double gs = flow_gain(g.s), R = pressure_factor(g.s, p);
  g.Q = r.K_v * gs * R;
  const double dQds = r.K_v * flow_gain_slope(g.s) * R;
  for (int j = 0; j < W; ++j) g.dQ[j] = dQds * g.ds[j];
  g.dQ[kP] += r.K_v * gs * pressure_factor_dp(g.s, p);

  // Actuator continuity, Eq (4): K_a p' = Q - C_l p - A x'.
  g.pdot = (g.Q - r.C_l * p - r.A * v) / r.K_a;
  for (int j = 0; j < W; ++j) g.dpdot[j] = g.dQ[j] / r.K_a;
  g.dpdot[kP] -= r.C_l / r.K_a;
  g.dpdot[kV] -= r.A / r.K_a;
}

// Dispatch on the gradient width num_states() + 1, a compile-time constant in each case.
void Dynamics::evaluate_any(const double* y, const Input& in, Algebra& g) const noexcept {
  static_assert(kCap == 17, "one case per width from kNumStates + 1 to kMaxStates + 1");
  switch (ng_) {
    case 7: return evaluate<7>(y, in, g);
    case 8: return evaluate<8>(y, in, g);
    case 9: return evaluate<9>(y, in, g);
    case 10: return evaluate<10>(y, in, g);
    case 11: return evaluate<11>(y, in, g);
    case 12: return evaluate<12>(y, in, g);
    case 13: return evaluate<13>(y, in, g);
    case 14: return evaluate<14>(y, in, g);
    case 15: return evaluate<15>(y, in, g);
    case 16: return evaluate<16>(y, in, g);
    default: return evaluate<kCap>(y, in, g);
  }
}

void Dynamics::rhs(const double* y, const Input& in, double* ydot) const noexcept {
  Algebra g;
  evaluate_any(y, in, g);
  ydot[kX] = y[kV];
  ydot[kV] = g.a;
  const bool actuator = mode_ != ControlMode::Free;
  ydot[kP] = actuator ? g.pdot : 0.0;
  const bool valve = actuator && rig_.effects.servovalve_dynamics;
  ydot[kXv] = valve ? y[kXvDot] : 0.0;
  ydot[kXvDot] = valve ? g.xvdd : 0.0;
  ydot[kZ] = lugre_ ? g.zdot : 0.0;
  const StateLayout& L = layout_;
  if (L.bw_z >= 0) ydot[L.bw_z] = g.bw_zdot;
  if (L.mr_y >= 0) {
    ydot[L.mr_y] = g.mr_ydot;
    ydot[L.mr_y + 1] = g.mr_zdot;
  }
  if (L.pade >= 0) {
    const int N = L.pade_order;
    for (int k = 0; k + 1 < N; ++k) ydot[L.pade + k] = y[L.pade + k + 1] / pade_.tau;
    ydot[L.pade + N - 1] = g.qdot;
  }
}

void Dynamics::jacobian(const double* y, const Input& in, Jacobian& J, State* B) const noexcept {
  Algebra g;
  evaluate_any(y, in, g);
  const int n = layout_.num_states;
  for (auto& row : J) row.fill(0.0);
  if (B) B->fill(0.0);
  J[kX][kV] = 1.0;
  for (int j = 0; j < n; ++j) J[kV][j] = g.da[j];
  if (B) (*B)[kV] = g.da[ku_];
  if (lugre_)
    for (int j = 0; j < n; ++j) J[kZ][j] = g.dzdot[j];
  jacobian_appended(g, J, B);
  if (mode_ == ControlMode::Free) return;
  for (int j = 0; j < n; ++j) J[kP][j] = g.dpdot[j];
  if (B) (*B)[kP] = g.dpdot[ku_];
  if (rig_.effects.servovalve_dynamics) {
    J[kXv][kXvDot] = 1.0;
    for (int j = 0; j < n; ++j) J[kXvDot][j] = g.dxvdd[j];
    if (B) (*B)[kXvDot] = g.dxvdd[ku_];
  }
}

// The rows of the appended states (specimen elements and the Pade loop delay).
void Dynamics::jacobian_appended(const Algebra& g, Jacobian& J, State* B) const noexcept {
  const StateLayout& L = layout_;
  const int n = L.num_states;
  auto row = [&](int i, const double* grad) {
    for (int j = 0; j < n; ++j) J[i][j] = grad[j];
    if (B) (*B)[i] = grad[ku_];
  };
  if (L.bw_z >= 0) row(L.bw_z, g.dbw_zdot);
  if (L.mr_y >= 0) {
    row(L.mr_y, g.dmr_ydot);
    row(L.mr_y + 1, g.dmr_zdot);
  }
  if (L.pade >= 0) {
    const int N = L.pade_order;
    for (int k = 0; k + 1 < N; ++k) J[L.pade + k][L.pade + k + 1] = 1.0 / pade_.tau;
    row(L.pade + N - 1, g.dqdot);
  }
}

void Dynamics::outputs(const double* y, const Input& in, Output& out, OutputGradients* grad) const noexcept {
  Algebra g;
  evaluate_any(y, in, g);
  if (grad) {
    const bool act = mode_ != ControlMode::Free;
    auto& G = *grad;
    for (auto& row : G) row.fill(0.0);
    for (int j = 0; j < ng_; ++j) {
      const int c = j == ku_ ? kMaxStates : j;  // the public column of u is kMaxStates
      G[0][c] = j == kX ? 1.0 : 0.0;
      G[1][c] = j == kV ? 1.0 : 0.0;
      G[2][c] = g.da[j];
      G[3][c] = g.dF[j];
      G[4][c] = act && j == kP ? 1.0 : 0.0;
      G[5][c] = act ? g.ds[j] : 0.0;
      G[6][c] = act ? g.ddrive[j] : 0.0;
      G[7][c] = act ? g.dQ[j] : 0.0;
      G[8][c] = g.dFsp[j];
    }
  }
  out.displacement = y[kX];
  out.velocity = y[kV];
  out.acceleration = g.a;
  out.force = g.F;
  const bool actuator = mode_ != ControlMode::Free;
  out.pressure = actuator ? y[kP] : 0.0;
  out.spool = actuator ? g.s : 0.0;
  out.drive = actuator ? g.drive : 0.0;
  out.flow = actuator ? g.Q : 0.0;
  out.specimen_force = g.Fsp;
  std::uint32_t f = 0;
  if (std::fabs(out.force) > rig_.F_cap) f |= kCapacityExceeded;
  if (actuator) {
    if (std::fabs(y[kP]) >= 0.98 * rig_.p_s) f |= kSupplyLimited;
    if (g.spool_sat) f |= kSpoolSaturated;
    if (g.drive_sat) f |= kDriveSaturated;
    if (std::fabs(y[kX]) > rig_.stroke) f |= kStrokeExceeded;
  }
  out.flags = f;
}

State Dynamics::equilibrium(double x0) const noexcept {
  State y{};
  y[kX] = x0;
  if (layout_.mr_y >= 0) y[layout_.mr_y] = x0;  // the MR damper at rest: y = x, z = 0
  if (mode_ == ControlMode::Free) return y;
  const double p = static_force(x0) / rig_.A;
  y[kP] = p;
  // Spool opening whose flow feeds the leakage C_l p (a few fixed-point passes
  // on the pressure factor, which is ~1 at equilibrium).
  double s = 0.0;
  for (int it = 0; it < 4; ++it) {
    const double R = std::max(pressure_factor(s == 0.0 ? std::copysign(1e-12, p) : s, p), 1e-6);
    const double q = rig_.C_l * p / (rig_.K_v * R);
    s = rig_.effects.flow_nonlinearity ? rig_.flow_curve.inverse(q) : q;
  }
  y[kXv] = rig_.effects.servovalve_dynamics ? s : 0.0;
  if (layout_.pade >= 0) y[layout_.pade] = s / (rig_.K_s * pade_.a[0]);  // q_1 = w / a_0 holds w = s / K_s
  return y;
}

Dynamics::OperatingPoint Dynamics::operating_point(double x0) const noexcept {
  OperatingPoint op;
  op.y0 = equilibrium(x0);
  if (mode_ == ControlMode::Free) {
    op.u0 = static_force(x0);  // the ideal force that holds the spring (friction is 0 at rest)
    return op;
  }
  // The rate that u drives: the spool rate with valve dynamics, else the pressure rate.
  const int idx = rig_.effects.servovalve_dynamics ? kXvDot : kP;
  if (mode_ == ControlMode::Displacement) {
    op.u0 = x0;
  } else {
    Output out;
    outputs(op.y0.data(), {}, out);
    op.u0 = out.force;
  }
  // That rate is affine in u (Eq 1 into Eq 2 or Eq 3) until the drive or the spool
  // saturates: Newton steps with B = df/du from the analytic Jacobian make it exact.
  Jacobian J;
  State B, f;
  // (A flow curve makes it piecewise affine: a few more steps cross its breakpoints.)
  for (int it = 0; it < 8; ++it) {
    const Input in{op.u0, 0.0};
    rhs(op.y0.data(), in, f.data());
    jacobian(op.y0.data(), in, J, &B);
    if (B[idx] == 0.0 || f[idx] == 0.0) break;
    const double u_next = op.u0 - f[idx] / B[idx];
    if (u_next == op.u0) break;
    op.u0 = u_next;
  }
  return op;
}

}  // namespace servohydraulics
