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
}  // namespace

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

// Gradients carry one extra column, index kU, for the derivative by the command u.
constexpr int kU = kNumStates;
constexpr int kNG = kNumStates + 1;

struct Dynamics::Algebra {
  double a = 0, da[kNG] = {};          // acceleration and its gradient
  double F = 0, dF[kNG] = {};          // load-cell force
  double drive = 0, ddrive[kNG] = {};  // valve drive after saturation
  double s = 0, ds[kNG] = {};          // metering opening after saturation
  double Q = 0, dQ[kNG] = {};          // valve flow
  double pdot = 0, dpdot[kNG] = {};
  double xvdd = 0, dxvdd[kNG] = {};
  double zdot = 0, dzdot[kNG] = {};    // LuGre bristle rate
  bool drive_sat = false, spool_sat = false;
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

double Dynamics::structure_force(double x, double v, double z) const noexcept {
  return friction(v, z).F + rig_.c * v + spring_force(x);
}

void Dynamics::evaluate(const double* y, const Input& in, Algebra& g) const noexcept {
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
  g.a = (applied - Ff - r.c * v - spring_force(x)) / M_;
  g.da[kX] = -spring_stiffness(x) / M_;
  g.da[kV] = -(dFf_dv + r.c) / M_;
  g.da[kZ] = -dFf_dz / M_;
  g.da[kP] = actuator ? r.A / M_ : 0.0;
  g.da[kU] = actuator ? 0.0 : 1.0 / M_;
  if (!actuator) {
    g.dF[kU] = 1.0;
    g.F = in.u;
    return;
  }
  // Load cell between piston and structure: F = pA - m_p a.
  g.F = p * r.A - mp_ * g.a;
  for (int j = 0; j < kNG; ++j) g.dF[j] = -mp_ * g.da[j];
  g.dF[kP] += r.A;

  // Servo controller, Eq (1).
  double raw;
  double draw[kNG] = {};
  if (mode_ == ControlMode::Displacement) {
    raw = CF_ * (r.G_p * (in.u - x) + r.G_d * (in.u_rate - v));
    draw[kX] = -CF_ * r.G_p;
    draw[kV] = -CF_ * r.G_d;
    draw[kU] = CF_ * r.G_p;
  } else {
    raw = CF_ * r.G_p * (in.u - g.F);
    for (int j = 0; j < kNG; ++j) draw[j] = -CF_ * r.G_p * g.dF[j];
    draw[kU] += CF_ * r.G_p;
  }
  g.drive_sat = r.effects.drive_saturation && std::fabs(raw) >= r.v_max;
  g.drive = g.drive_sat ? std::copysign(r.v_max, raw) : raw;
  for (int j = 0; j < kNG; ++j) g.ddrive[j] = g.drive_sat ? 0.0 : draw[j];

  // Servovalve: Eq (2) as x_v'' = w_v^2 (K_s v - x_v) - 2 zeta_v w_v x_v', or Eq (6).
  double xv;
  double dxv[kNG] = {};
  if (r.effects.servovalve_dynamics) {
    xv = y[kXv];
    dxv[kXv] = 1.0;
    const double w2 = wv_ * wv_;
    g.xvdd = w2 * (r.K_s * g.drive - y[kXv]) - 2.0 * r.zeta_v * wv_ * y[kXvDot];
    for (int j = 0; j < kNG; ++j) g.dxvdd[j] = w2 * r.K_s * g.ddrive[j];
    g.dxvdd[kXv] -= w2;
    g.dxvdd[kXvDot] -= 2.0 * r.zeta_v * wv_;
  } else {
    xv = r.K_s * g.drive;
    for (int j = 0; j < kNG; ++j) dxv[j] = r.K_s * g.ddrive[j];
  }
  g.spool_sat = r.effects.spool_saturation && std::fabs(xv) >= r.x_v_max;
  g.s = g.spool_sat ? std::copysign(r.x_v_max, xv) : xv;
  for (int j = 0; j < kNG; ++j) g.ds[j] = g.spool_sat ? 0.0 : dxv[j];

  // Valve flow, Eq (3) (Eq 7 with the effects off).
  const double gs = flow_gain(g.s), R = pressure_factor(g.s, p);
  g.Q = r.K_v * gs * R;
  const double dQds = r.K_v * flow_gain_slope(g.s) * R;
  for (int j = 0; j < kNG; ++j) g.dQ[j] = dQds * g.ds[j];
  g.dQ[kP] += r.K_v * gs * pressure_factor_dp(g.s, p);

  // Actuator continuity, Eq (4): K_a p' = Q - C_l p - A x'.
  g.pdot = (g.Q - r.C_l * p - r.A * v) / r.K_a;
  for (int j = 0; j < kNG; ++j) g.dpdot[j] = g.dQ[j] / r.K_a;
  g.dpdot[kP] -= r.C_l / r.K_a;
  g.dpdot[kV] -= r.A / r.K_a;
}

void Dynamics::rhs(const double* y, const Input& in, double* ydot) const noexcept {
  Algebra g;
  evaluate(y, in, g);
  ydot[kX] = y[kV];
  ydot[kV] = g.a;
  const bool actuator = mode_ != ControlMode::Free;
  ydot[kP] = actuator ? g.pdot : 0.0;
  const bool valve = actuator && rig_.effects.servovalve_dynamics;
  ydot[kXv] = valve ? y[kXvDot] : 0.0;
  ydot[kXvDot] = valve ? g.xvdd : 0.0;
  ydot[kZ] = lugre_ ? g.zdot : 0.0;
}

void Dynamics::jacobian(const double* y, const Input& in, Jacobian& J, State* B) const noexcept {
  Algebra g;
  evaluate(y, in, g);
  for (auto& row : J) row.fill(0.0);
  if (B) B->fill(0.0);
  J[kX][kV] = 1.0;
  for (int j = 0; j < kNumStates; ++j) J[kV][j] = g.da[j];
  if (B) (*B)[kV] = g.da[kU];
  if (lugre_)
    for (int j = 0; j < kNumStates; ++j) J[kZ][j] = g.dzdot[j];
  if (mode_ == ControlMode::Free) return;
  for (int j = 0; j < kNumStates; ++j) J[kP][j] = g.dpdot[j];
  if (B) (*B)[kP] = g.dpdot[kU];
  if (rig_.effects.servovalve_dynamics) {
    J[kXv][kXvDot] = 1.0;
    for (int j = 0; j < kNumStates; ++j) J[kXvDot][j] = g.dxvdd[j];
    if (B) (*B)[kXvDot] = g.dxvdd[kU];
  }
}

void Dynamics::outputs(const double* y, const Input& in, Output& out, OutputGradients* grad) const noexcept {
  Algebra g;
  evaluate(y, in, g);
  if (grad) {
    const bool act = mode_ != ControlMode::Free;
    for (int j = 0; j < kNG; ++j) {
      auto& G = *grad;
      G[0][j] = j == kX ? 1.0 : 0.0;
      G[1][j] = j == kV ? 1.0 : 0.0;
      G[2][j] = g.da[j];
      G[3][j] = g.dF[j];
      G[4][j] = act && j == kP ? 1.0 : 0.0;
      G[5][j] = act ? g.ds[j] : 0.0;
      G[6][j] = act ? g.ddrive[j] : 0.0;
      G[7][j] = act ? g.dQ[j] : 0.0;
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
  if (mode_ == ControlMode::Free) return y;
  const double p = spring_force(x0) / rig_.A;
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
  return y;
}

Dynamics::OperatingPoint Dynamics::operating_point(double x0) const noexcept {
  OperatingPoint op;
  op.y0 = equilibrium(x0);
  if (mode_ == ControlMode::Free) {
    op.u0 = spring_force(x0);  // the ideal force that holds the spring (friction is 0 at rest)
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
