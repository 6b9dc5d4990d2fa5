// Right-hand side, analytic Jacobian and outputs of the plant, Eqs (1)-(5).
#include "servohydraulics/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "detail/math.hpp"

namespace servohydraulics {

using detail::kPi;
using detail::sgn;
using detail::ssqrt;
using detail::ssqrt_slope;

Dynamics::Dynamics(const Rig& rig, ControlMode mode) : rig_(rig), mode_(mode) {
  rig_.validate();
  if (mode == ControlMode::Force && rig_.G_d != 0.0)
    require(false, "G_d", rig_.G_d, "derivative gain in force control is not modelled; set G_d = 0");
  const bool actuator = mode != ControlMode::Free;
  mp_ = (actuator && rig_.effects.piston_mass) ? rig_.m_p : 0.0;
  M_ = rig_.m + mp_;
  CF_ = mode == ControlMode::Force ? rig_.C_F_force : rig_.C_F_disp;
  wv_ = 2.0 * kPi * rig_.f_v;
  std::apply([&](auto&... law) { ((law = std::decay_t<decltype(law)>::value_type::from(rig_, mode_)), ...); },
             laws_);
  coulomb_ = ExactCoulomb::from(rig_, mode_);
  // The elements' states are appended in the order of Elements, each only when it is on.
  int n = kNumStates;
  std::size_t idx = 0;
  std::apply(
      [&](auto&... e) {
        auto place = [&](auto& slot) {
          using E = typename std::decay_t<decltype(slot)>::value_type;
          slot = E::from(rig_, mode_);
          if (slot) {
            layout_.offset[idx] = n;
            layout_.count[idx] = slot->count();
            n += slot->count();
            if constexpr (E::kPort == Port::Structure) specimen_on_ = true;
          }
          ++idx;
        };
        (place(e), ...);
      },
      elements_);
  layout_.num_states = n;
  ku_ = n;
  ng_ = n + 1;
}

const StateInfo& Dynamics::state_info(int i) const noexcept {
  const StateInfo* info = &kStates[i >= 0 && i < kNumStates ? i : 0];
  each([&](const auto& e, int off) {
    if (i >= off && i < off + e.count()) info = &e.states()[i - off];
  });
  return *info;
}

double Dynamics::state_scale(int i) const noexcept {
  double scale = 1e-3;
  each([&](const auto& e, int off) {
    if (i >= off && i < off + e.count()) scale = e.scale(i - off);
  });
  return scale;
}

// The structure's laws (each adds its force at rest; kNoStaticForce adds nothing), then the
// structure elements.
double Dynamics::static_force(double x) const noexcept {
  double f = kNoStaticForce;
  each_law([&](const auto& law) { f += law.static_force(x); });
  each([&](const auto& e, int) {
    if constexpr (std::decay_t<decltype(e)>::kPort == Port::Structure) {
      const double fe = e.static_force(x);
      if (fe != 0.0) f += fe;
    }
  });
  return f;
}

double Dynamics::element_rate_bound(double v_ref) const noexcept {
  double rho = 0.0;
  each([&](const auto& e, int) { rho = std::max(rho, e.rate_bound(v_ref)); });
  return rho;
}

double Dynamics::rate_bound(double v_ref) const noexcept {
  double rho = 0.0;
  each_law([&](const auto& law) { rho = std::max(rho, law.rate_bound(v_ref)); });
  return std::max(rho, element_rate_bound(v_ref));
}

double Dynamics::no_load_speed() const noexcept {
  return rig_.K_v * flow_gain(std::min(rig_.x_v_max, 1.0)) / rig_.A;
}

const Dynamics::Pade& Dynamics::pade() const noexcept {
  static const Pade off{};
  const Pade* p = element<PadeDelay>();
  return p ? *p : off;
}

double Dynamics::spring_force(double x) const noexcept { return law<Spring>()->force(x); }
double Dynamics::spring_stiffness(double x) const noexcept { return law<Spring>()->stiffness(x); }
double Dynamics::friction_level(double v) const noexcept { return StribeckLevel::of(rig_).at(v).level; }
double Dynamics::friction_level_slope(double v) const noexcept { return StribeckLevel::of(rig_).at(v).slope; }
double Dynamics::friction_force(double v) const noexcept {
  if (coulomb_) return coulomb_->sliding_at(v).F;
  return TanhFriction::acts(rig_) ? TanhFriction::of(rig_).at(v).F : 0.0;
}
double Dynamics::friction_slope(double v) const noexcept {
  if (coulomb_) return coulomb_->sliding_at(v).dF_dv;
  return TanhFriction::acts(rig_) ? TanhFriction::of(rig_).at(v).dF_dv : 0.0;
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
constexpr int kCap = Algebra::kCap;

double Dynamics::specimen_force(const double* y) const noexcept {
  if (!specimen_on_) return 0.0;
  Algebra g;
  g.zero<kCap>();
  specimen<kCap>(y, g);
  return g.Fsp;
}

// The structure's laws' forces, in the order of StructureLaws.
double Dynamics::structure_force(double x, double v, double z) const noexcept {
  double y[kNumStates] = {};
  y[kX] = x;
  y[kV] = v;
  y[kZ] = z;
  Algebra g;
  double F = kNoStaticForce;
  each_law([&](const auto& law) { F += law.eval(y, g).F; });
  if (coulomb_ && v != 0.0) F += friction_force(v);  // stuck (v = 0) it holds whatever acts: not a function of x, v
  return F;
}

double Dynamics::held_force(const double* y, const Input& in) const noexcept {
  if (!coulomb_) return 0.0;
  Algebra g;
  g.zero<0>();
  structure<0>(y, in, g);
  return g.held;
}

Sliding Dynamics::sliding(const double* y, const Input& in) const noexcept {
  return coulomb_ ? coulomb_->mode(y[kV], held_force(y, in)) : Sliding::Auto;
}

// The structure elements (specimens in parallel with the structure): their force and state rates.
template <int W>
void Dynamics::specimen(const double* y, Algebra& g) const noexcept {
  each([&](const auto& e, int off) {
    if constexpr (std::decay_t<decltype(e)>::kPort == Port::Structure) e.template eval<W>(y, off, g);
  });
}

// The drive elements (the Pade loop delay): the drive as the valve sees it, in g.vdrive.
template <int W>
bool Dynamics::delay_drive(const double* y, Algebra& g) const noexcept {
  bool on = false;
  each([&](const auto& e, int off) {
    if constexpr (std::decay_t<decltype(e)>::kPort == Port::Drive) {
      e.template eval<W>(y, off, g);
      on = true;
    }
  });
  return on;
}

// Structure, Eq (5): M a = pA - (the structure's laws: friction, damping, spring, in the order
// of StructureLaws) - (the structure elements), the piston riding along.  The acceleration and
// its gradient.
template <int W>
void Dynamics::structure(const double* y, const Input& in, Algebra& g) const noexcept {
  const bool actuator = mode_ != ControlMode::Free;
  double net = actuator ? y[kP] * rig_.A : in.u;  // Free: the command is an ideal force
  LawForce laws;                                   // the laws' gradients, summed
  each_law([&](const auto& law) {
    const LawForce f = law.eval(y, g);
    net -= f.F;
    laws.dF_dx += f.dF_dx;
    laws.dF_dv += f.dF_dv;
    laws.dF_dz += f.dF_dz;
  });
  if (specimen_on_) specimen<W>(y, g);
  if (coulomb_) {  // out of line: a rig without the exact law keeps this function small enough to inline
    structure_exact<W>(y, in, net, laws, g);
    return;
  }
  structure_rates<W>(net, laws, g);
}

// The exact Coulomb law last: stuck, it holds the sum of the others (the acceleration is 0).
template <int W>
void Dynamics::structure_exact(const double* y, const Input& in, double net, LawForce laws,
                               Algebra& g) const noexcept {
  g.held = specimen_on_ ? net - g.Fsp : net;
  const Sliding sliding = in.sliding == Sliding::Auto ? coulomb_->mode(y[kV], g.held) : in.sliding;
  const LawForce f = coulomb_->at(y[kV], sliding, g.held);
  net -= f.F;
  laws.dF_dv += f.dF_dv;
  if (sliding != Sliding::Stuck) {
    structure_rates<W>(net, laws, g);
    return;
  }
  g.a = 0.0;  // not held - held's rounding
  for (int j = 0; j < W; ++j) g.da[j] = 0.0;  // v stays 0 whatever the other states do
}

// The acceleration from the net force on the structure (and its gradient: laws' summed, the
// specimens' in g).
template <int W>
void Dynamics::structure_rates(double net, const LawForce& laws, Algebra& g) const noexcept {
  const bool actuator = mode_ != ControlMode::Free;
  g.a = specimen_on_ ? (net - g.Fsp) / M_ : net / M_;
  if constexpr (W == 0) return;  // the values alone (rhs)
  if (!specimen_on_) {
    g.da[kX] = -laws.dF_dx / M_;
    g.da[kV] = -laws.dF_dv / M_;
  } else {
    for (int j = 0; j < W; ++j) g.da[j] = -g.dFsp[j] / M_;
    g.da[kX] = -(laws.dF_dx + g.dFsp[kX]) / M_;
    g.da[kV] = -(laws.dF_dv + g.dFsp[kV]) / M_;
  }
  g.da[kZ] = -laws.dF_dz / M_;
  g.da[kP] = actuator ? rig_.A / M_ : 0.0;
  g.da[ku_] = actuator ? 0.0 : 1.0 / M_;
}

// Servo controller, Eq (1), the drive saturation and the drive elements (the Pade loop delay):
// true when the valve sees the delayed drive g.vdrive rather than g.drive.
template <int W>
bool Dynamics::servo_controller(const double* y, const Input& in, Algebra& g) const noexcept {
  const Rig& r = rig_;
  double raw;
  double draw[kCap];
  std::fill(draw, draw + W, 0.0);
  if (mode_ == ControlMode::Displacement) {
    raw = CF_ * (r.G_p * (in.u - y[kX]) + r.G_d * (in.u_rate - y[kV]));
    if constexpr (W > 0) {
      draw[kX] = -CF_ * r.G_p;
      draw[kV] = -CF_ * r.G_d;
      draw[ku_] = CF_ * r.G_p;
    }
  } else {
    raw = CF_ * r.G_p * (in.u - g.F);
    for (int j = 0; j < W; ++j) draw[j] = -CF_ * r.G_p * g.dF[j];
    if constexpr (W > 0) draw[ku_] += CF_ * r.G_p;
  }
  g.drive_sat = r.effects.drive_saturation && std::fabs(raw) >= r.v_max;
  g.drive = g.drive_sat ? std::copysign(r.v_max, raw) : raw;
  for (int j = 0; j < W; ++j) g.ddrive[j] = g.drive_sat ? 0.0 : draw[j];
  return delay_drive<W>(y, g);
}

// Servovalve (Eqs 2, 6), spool end stops, valve flow (Eq 3, or Eq 7 with the effects off) and
// actuator continuity (Eq 4), driven by the drive the valve sees.
template <int W>
void Dynamics::valve(const double* y, double vdrive, const double* dvdrive, Algebra& g) const noexcept {
  const Rig& r = rig_;
  const double v = y[kV], p = y[kP];
  // Eq (2) as x_v'' = w_v^2 (K_s v - x_v) - 2 zeta_v w_v x_v', or Eq (6).
  double xv;
  double dxv[kCap];
  std::fill(dxv, dxv + W, 0.0);
  if (r.effects.servovalve_dynamics) {
    xv = y[kXv];
    const double w2 = wv_ * wv_;
    g.xvdd = w2 * (r.K_s * vdrive - y[kXv]) - 2.0 * r.zeta_v * wv_ * y[kXvDot];
    if constexpr (W > 0) {
      dxv[kXv] = 1.0;
      for (int j = 0; j < W; ++j) g.dxvdd[j] = w2 * r.K_s * dvdrive[j];
      g.dxvdd[kXv] -= w2;
      g.dxvdd[kXvDot] -= 2.0 * r.zeta_v * wv_;
    }
  } else {
    xv = r.K_s * vdrive;
    for (int j = 0; j < W; ++j) dxv[j] = r.K_s * dvdrive[j];
  }
  g.spool_sat = r.effects.spool_saturation && std::fabs(xv) >= r.x_v_max;
  g.s = g.spool_sat ? std::copysign(r.x_v_max, xv) : xv;
  for (int j = 0; j < W; ++j) g.ds[j] = g.spool_sat ? 0.0 : dxv[j];

  // Valve flow, Eq (3).
  const double gs = flow_gain(g.s), R = pressure_factor(g.s, p);
  g.Q = r.K_v * gs * R;
  // Actuator continuity, Eq (4): K_a p' = Q - C_l p - A x'.
  g.pdot = (g.Q - r.C_l * p - r.A * v) / r.K_a;
  if constexpr (W == 0) return;  // the values alone (rhs)
  const double dQds = r.K_v * flow_gain_slope(g.s) * R;
  for (int j = 0; j < W; ++j) g.dQ[j] = dQds * g.ds[j];
  g.dQ[kP] += r.K_v * gs * pressure_factor_dp(g.s, p);
  for (int j = 0; j < W; ++j) g.dpdot[j] = g.dQ[j] / r.K_a;
  g.dpdot[kP] -= r.C_l / r.K_a;
  g.dpdot[kV] -= r.A / r.K_a;
}

template <int W>
void Dynamics::evaluate(const double* y, const Input& in, Algebra& g) const noexcept {
  g.zero<W>();
  structure<W>(y, in, g);
  if (mode_ == ControlMode::Free) {
    if constexpr (W > 0) g.dF[ku_] = 1.0;
    g.F = in.u;
    return;
  }
  // Load cell between piston and structure: F = pA - m_p a.
  g.F = y[kP] * rig_.A - mp_ * g.a;
  if constexpr (W > 0) {
    for (int j = 0; j < W; ++j) g.dF[j] = -mp_ * g.da[j];
    g.dF[kP] += rig_.A;
  }
  const bool delayed = servo_controller<W>(y, in, g);
  valve<W>(y, delayed ? g.vdrive : g.drive, delayed ? g.dvdrive : g.ddrive, g);
}

// Dispatch on the gradient width num_states() + 1, a compile-time constant in each case.
template <class F>
decltype(auto) Dynamics::at_width(F&& f) const noexcept {
  static_assert(kCap == kMaxStates + 1, "the widths kNumStates + 1 .. kMaxStates + 1");
  return detail::with_constant<kNumStates + 1, kCap - 1>(
      ng_, f, [&] { return f(std::integral_constant<int, kCap>{}); });
}

void Dynamics::evaluate_any(const double* y, const Input& in, Algebra& g) const noexcept {
  at_width([&](auto w) { evaluate<decltype(w)::value>(y, in, g); });
}

// The actuator without the structure (Dynamics::actuator): the friction laws along the stroke, then
// the servo controller (Eq 1) and the valve (Eqs 2-4), as evaluate does them.
template <int W>
LawForce Dynamics::evaluate_actuator(const double* y, const Input& in, Algebra& g) const noexcept {
  g.zero<W>();
  LawForce f;
  each_law([&](const auto& law) {
    using L = std::decay_t<decltype(law)>;
    if constexpr (std::is_same_v<L, TanhFriction> || std::is_same_v<L, LuGreFriction>) {
      const LawForce l = law.eval(y, g);
      f.F += l.F;
      f.dF_dx += l.dF_dx;
      f.dF_dv += l.dF_dv;
      f.dF_dz += l.dF_dz;
    }
  });
  const bool delayed = servo_controller<W>(y, in, g);
  valve<W>(y, delayed ? g.vdrive : g.drive, delayed ? g.dvdrive : g.ddrive, g);
  return f;
}

LawForce Dynamics::actuator(const double* y, const Input& in, Algebra& g) const noexcept {
  return at_width([&](auto w) { return evaluate_actuator<decltype(w)::value>(y, in, g); });
}

void Dynamics::rhs(const double* y, const Input& in, double* ydot) const noexcept {
  Algebra g;
  evaluate<0>(y, in, g);  // the values alone: no gradient (the same values as every width computes)
  rates(y, g, ydot);
}

void Dynamics::rhs_jacobian(const double* y, const Input& in, double* ydot, Jacobian& J) const noexcept {
  Algebra g;
  evaluate_any(y, in, g);  // the values as evaluate<0> computes them, and the gradients
  rates(y, g, ydot);
  const int n = layout_.num_states;
  for (int i = 0; i < n; ++i) std::fill(J[i].begin(), J[i].begin() + n, 0.0);
  jacobian_rows(g, J, nullptr);
}

void Dynamics::rates(const double* y, const Algebra& g, double* ydot) const noexcept {
  ydot[kX] = y[kV];
  ydot[kV] = g.a;
  actuator_rates(y, g, ydot);
}

void Dynamics::actuator_rates(const double* y, const Algebra& g, double* ydot) const noexcept {
  const bool actuator = mode_ != ControlMode::Free;
  ydot[kP] = actuator ? g.pdot : 0.0;
  const bool valve = actuator && rig_.effects.servovalve_dynamics;
  ydot[kXv] = valve ? y[kXvDot] : 0.0;
  ydot[kXvDot] = valve ? g.xvdd : 0.0;
  ydot[kZ] = g.zdot;  // the bristle's rate (0 unless a friction law has one)
  for (int i = kNumStates; i < layout_.num_states; ++i) ydot[i] = g.rate[i];
}

void Dynamics::jacobian(const double* y, const Input& in, Jacobian& J, State* B) const noexcept {
  Algebra g;
  evaluate_any(y, in, g);
  for (auto& row : J) row.fill(0.0);
  if (B) B->fill(0.0);
  jacobian_rows(g, J, B);
}

// Every row of J (and B) from an evaluation g; the entries they do not write are 0 on entry.
void Dynamics::jacobian_rows(const Algebra& g, Jacobian& J, State* B) const noexcept {
  const int n = layout_.num_states;
  J[kX][kV] = 1.0;
  for (int j = 0; j < n; ++j) J[kV][j] = g.da[j];
  if (B) (*B)[kV] = g.da[ku_];
  actuator_jacobian(g, J, B);
}

void Dynamics::actuator_jacobian(const Algebra& g, Jacobian& J, State* B) const noexcept {
  const int n = layout_.num_states;
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

// The rows of the elements' states.
void Dynamics::jacobian_appended(const Algebra& g, Jacobian& J, State* B) const noexcept {
  each([&](const auto& e, int off) { e.jacobian(g, off, layout_.num_states, ku_, J, B); });
}

void Dynamics::outputs(const double* y, const Input& in, Output& out, OutputGradients* grad) const noexcept {
  Algebra g;
  if (grad)
    evaluate_any(y, in, g);
  else
    evaluate<0>(y, in, g);  // the values alone (every width computes the same values)
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
  out.flags = flags(y, g.spool_sat, g.drive_sat, out.force);
}

std::uint32_t Dynamics::flags(const double* y, bool spool_saturated, bool drive_saturated, double force) const
    noexcept {
  std::uint32_t f = 0;
  if (std::fabs(force) > rig_.F_cap) f |= kCapacityExceeded;
  if (mode_ != ControlMode::Free) {
    if (std::fabs(y[kP]) >= 0.98 * rig_.p_s) f |= kSupplyLimited;
    if (spool_saturated) f |= kSpoolSaturated;
    if (drive_saturated) f |= kDriveSaturated;
    if (std::fabs(y[kX]) > rig_.stroke) f |= kStrokeExceeded;
  }
  return f;
}

State Dynamics::equilibrium(double x0) const noexcept {
  State y{};
  y[kX] = x0;
  if (mode_ == ControlMode::Free) {
    each([&](const auto& e, int off) { e.rest(RestPoint{x0, 0.0}, &y[off]); });
    return y;
  }
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
  each([&](const auto& e, int off) { e.rest(RestPoint{x0, s}, &y[off]); });
  return y;
}

namespace {
// The kinematic driver's automatic RK4 substeps: h rho <= 1, rho the elements' rate bound at the
// motion's largest speed.
int driver_substeps(const Dynamics& d, const double* v, std::size_t n, double dt) {
  double vmax = 0.0;
  for (std::size_t k = 0; k < n; ++k) vmax = std::max(vmax, std::fabs(v[k]));
  const double steps = std::ceil(dt * d.element_rate_bound(vmax));
  require(std::isfinite(steps) && steps <= 100000, "substeps (automatic)", steps,
          "exceeds 100000 per sample: give substeps, or a finer dt");
  return std::max(1, static_cast<int>(steps));
}
}  // namespace

void Dynamics::specimen_forces(const double* x, const double* v, std::size_t n, double dt, int substeps,
                               double* F) const {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "sample time must be finite and > 0 [s]");
  require(substeps >= 0 && substeps <= 100000, "substeps", substeps, "must be in 1..100000, or 0 for automatic");
  if (n == 0) return;
  // The structure elements' states (the drive elements do not see the motion).
  int idx[kMaxStates];
  int m = 0;
  State y{};
  y[kX] = x[0];
  y[kV] = v[0];
  each([&](const auto& e, int off) {
    if constexpr (std::decay_t<decltype(e)>::kPort == Port::Structure) {
      e.rest(RestPoint{x[0], 0.0}, &y[off]);
      for (int k = 0; k < e.count(); ++k) idx[m++] = off + k;
    }
  });
  if (substeps == 0) substeps = driver_substeps(*this, v, n, dt);
  // Rates of those states at (xt, vt, s) into r[0..m-1]; returns the specimen force.
  auto rates = [&](double xt, double vt, const State& s, double* r) {
    State at = s;
    at[kX] = xt;
    at[kV] = vt;
    Algebra g;
    specimen<0>(at.data(), g);  // the values alone
    for (int i = 0; i < m; ++i) r[i] = g.rate[idx[i]];
    return g.Fsp;
  };
  double k1[kMaxStates], k2[kMaxStates], k3[kMaxStates], k4[kMaxStates];
  const double h = 1.0 / substeps;
  State tmp;
  for (std::size_t k = 0;; ++k) {
    F[k] = rates(x[k], v[k], y, k1);
    if (k + 1 == n) break;
    const double x0 = x[k], dx = x[k + 1] - x[k], v0 = v[k], dv = v[k + 1] - v[k];
    for (int j = 0; j < substeps; ++j) {
      const double w0 = j * h, wm = (j + 0.5) * h, w1 = (j + 1) * h;
      if (j > 0) rates(x0 + w0 * dx, v0 + w0 * dv, y, k1);
      tmp = y;
      for (int i = 0; i < m; ++i) tmp[idx[i]] = y[idx[i]] + 0.5 * h * dt * k1[i];
      rates(x0 + wm * dx, v0 + wm * dv, tmp, k2);
      for (int i = 0; i < m; ++i) tmp[idx[i]] = y[idx[i]] + 0.5 * h * dt * k2[i];
      rates(x0 + wm * dx, v0 + wm * dv, tmp, k3);
      for (int i = 0; i < m; ++i) tmp[idx[i]] = y[idx[i]] + h * dt * k3[i];
      rates(x0 + w1 * dx, v0 + w1 * dv, tmp, k4);
      for (int i = 0; i < m; ++i) y[idx[i]] += h * dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
  }
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
