// The coupled multi-actuator rig (multi_rig.hpp, docs/multi-actuator.md): the node's equations
// of motion with the pistons' inertia, each actuator's Eqs (1)-(4) and piston friction from its
// Dynamics (Dynamics::actuator), the analytic Jacobian by the chain rule through the fixture's
// kinematics, the outputs, and the plant that integrates it with the core's integrators.
#include "servohydraulics/multi_rig.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "detail/cvode_integrator.hpp"
#include "detail/dopri5_integrator.hpp"
#include "detail/ode_system.hpp"
#include "detail/rk4_integrator.hpp"
#include "detail/ros2_integrator.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
std::string entry(const char* matrix, int r, int c) {
  return std::string("specimen.") + matrix + "[" + std::to_string(r) + "][" + std::to_string(c) + "]";
}

std::string actuator_field(std::size_t i, const char* field) {
  return "actuators[" + std::to_string(i) + "]." + field;
}

// A rig's own validation error with the actuator named in its field: "invalid actuators[1].K_v = ...".
[[noreturn]] void rethrow_for(std::size_t i, const Error& e) {
  std::string msg = e.what();
  const std::string head = "invalid ";
  if (msg.compare(0, head.size(), head) == 0)
    msg.insert(head.size(), "actuators[" + std::to_string(i) + "].");
  else
    msg = "actuators[" + std::to_string(i) + "]: " + msg;
  throw Error(msg);
}

Dynamics::Input input_of(const MultiRig::Input& in, int i) noexcept {
  return {in.u[static_cast<std::size_t>(i)], in.u_rate[static_cast<std::size_t>(i)]};
}
}  // namespace

void NodeSpecimen::validate() const {
  const int m = rotation ? 2 : 1;
  const std::pair<const char*, const std::array<double, 4>*> mats[] = {{"M", &M}, {"C", &C}, {"K", &K}};
  for (const auto& [name, X] : mats) {
    for (int r = 0; r < m; ++r)
      for (int c = 0; c < m; ++c) {
        const double v = (*X)[static_cast<std::size_t>(2 * r + c)];
        require(std::isfinite(v), entry(name, r, c).c_str(), v, "must be finite");
      }
    for (int r = 0; r < m; ++r) {
      const double d = (*X)[static_cast<std::size_t>(3 * r)];
      require(d >= 0.0, entry(name, r, r).c_str(), d, "a diagonal entry must be >= 0 (positive semidefinite)");
    }
    if (m == 2) {
      const double a = (*X)[0], b = (*X)[1], c = (*X)[2], d = (*X)[3];
      const double scale = std::max({std::fabs(a), std::fabs(b), std::fabs(c), std::fabs(d)});
      const std::string sym = "must equal " + entry(name, 0, 1) + " (a symmetric matrix)";
      require(std::fabs(b - c) <= 1e-12 * scale, entry(name, 1, 0).c_str(), c, sym.c_str());
      const std::string psd = "makes " + std::string("specimen.") + name +
                              " indefinite: it must be positive semidefinite, [0][1]^2 <= [0][0] [1][1]";
      require(a * d - b * c >= -1e-12 * scale * scale, entry(name, 0, 1).c_str(), b, psd.c_str());
    }
  }
  require(std::isfinite(fixture_mass) && fixture_mass >= 0.0, "specimen.fixture_mass", fixture_mass,
          "must be finite and >= 0 [kg]");
  require(std::isfinite(fixture_inertia) && fixture_inertia >= 0.0, "specimen.fixture_inertia", fixture_inertia,
          "must be finite and >= 0 [kg m^2]");
}

// The node's kinematics and mass matrix at one state.
struct MultiRig::Node {
  double x = 0.0, th = 0.0, xd = 0.0, thd = 0.0;  // theta and its rate are 0 with theta locked
  std::array<double, kMaxActuators> s{}, sd{};    // strokes and their rates
  std::array<double, kMaxActuators> a{}, b{};     // ds/dtheta, d2s/dtheta2 (0 with theta locked)
  double M[4] = {0.0, 0.0, 0.0, 0.0};             // the node's mass with the pistons', 2 x 2 row-major
  double Minv[4] = {0.0, 0.0, 0.0, 0.0};          // its inverse (the first entry only with one coordinate)
};

MultiRig::MultiRig(const std::vector<Rig>& rigs, const Coupler& coupler, const NodeSpecimen& specimen)
    : coupler_(coupler), spec_(specimen) {
  const std::string arms = "must be one rig per coupler arm: the coupler has " +
                           std::to_string(coupler.actuators()) + " arms";
  require(rigs.size() == coupler.actuators(), "actuators", static_cast<double>(rigs.size()), arms.c_str());
  spec_.validate();
  n_act_ = static_cast<int>(rigs.size());
  m_ = spec_.rotation ? 2 : 1;
  dyn_.reserve(rigs.size());
  int next = 2 * m_;
  for (std::size_t i = 0; i < rigs.size(); ++i) {
    const Rig& r = rigs[i];
    try {
      r.validate();
    } catch (const Error& e) {
      rethrow_for(i, e);
    }
    const char* specimen_why =
        "a specimen on one actuator is not modelled in the coupled rig: give the specimen at the node "
        "(NodeSpecimen)";
    require(!r.effects.bouc_wen_hysteresis, actuator_field(i, "effects.bouc_wen_hysteresis").c_str(), 1.0,
            specimen_why);
    require(!r.effects.mr_damper, actuator_field(i, "effects.mr_damper").c_str(), 1.0, specimen_why);
    require(!r.effects.fluid_damper, actuator_field(i, "effects.fluid_damper").c_str(), 1.0, specimen_why);
    require(!ExactCoulomb::from(r, ControlMode::Displacement),
            actuator_field(i, "v_stick").c_str(), r.v_stick,
            "the exact Coulomb law (v_stick = 0: stick and slip located in time) is not modelled in the coupled "
            "rig; give v_stick > 0 (the regularised law) or LuGre");
    const char* delay_why = "digital delays are not modelled in the coupled rig (the loop holds them); "
                            "the analog loop_delay is";
    require(r.command_delay == 0.0, actuator_field(i, "command_delay").c_str(), r.command_delay, delay_why);
    require(r.measurement_delay_displacement == 0.0,
            actuator_field(i, "measurement_delay_displacement").c_str(), r.measurement_delay_displacement,
            delay_why);
    require(r.measurement_delay_force == 0.0, actuator_field(i, "measurement_delay_force").c_str(),
            r.measurement_delay_force, delay_why);
    try {
      dyn_.emplace_back(r, ControlMode::Displacement);
    } catch (const Error& e) {
      rethrow_for(i, e);
    }
    off_[i] = next;
    count_[i] = dyn_.back().num_states() - 2;
    next += count_[i];
    mp_[i] = dyn_.back().piston_mass();
    area_[i] = r.A;
  }
  n_ = next;
  M0_ = spec_.M;
  M0_[0] += spec_.fixture_mass;
  if (m_ == 2) M0_[3] += spec_.fixture_inertia;
  Node nd;
  node(rest().data(), nd);
  require(nd.M[0] > 0.0, "specimen.M[0][0]", spec_.M[0],
          "the node's mass along x (specimen.M[0][0] + fixture_mass + the pistons' m_p) must be > 0");
  if (m_ == 2)
    require(nd.M[0] * nd.M[3] - nd.M[1] * nd.M[2] > 0.0, "specimen.M[1][1]", spec_.M[3],
            "the node's mass matrix (specimen.M + the fixture's + the pistons' m_p J^T J) must be positive "
            "definite at q = 0: give the node a rotary inertia (specimen.M[1][1] or fixture_inertia)");
}

void MultiRig::node(const double* y, Node& nd) const noexcept {
  const bool rot = m_ == 2;
  nd.x = y[0];
  nd.th = rot ? y[1] : 0.0;
  nd.xd = y[m_];
  nd.thd = rot ? y[3] : 0.0;
  coupler_.strokes(nd.x, nd.th, nd.s.data());
  for (int i = 0; i < 4; ++i) nd.M[i] = M0_[static_cast<std::size_t>(i)];
  for (std::size_t i = 0; i < static_cast<std::size_t>(n_act_); ++i) {
    nd.a[i] = rot ? coupler_.dstroke_dtheta(i, nd.th) : 0.0;
    nd.b[i] = rot ? coupler_.d2stroke_dtheta2(i, nd.th) : 0.0;
    nd.sd[i] = nd.xd + nd.a[i] * nd.thd;
    // The piston moves with s_i(q): its kinetic energy m_p (J_i q')^2 / 2 adds m_p J_i^T J_i.
    nd.M[0] += mp_[i];
    if (rot) {
      nd.M[1] += mp_[i] * nd.a[i];
      nd.M[2] += mp_[i] * nd.a[i];
      nd.M[3] += mp_[i] * nd.a[i] * nd.a[i];
    }
  }
  if (rot) {
    const double det = nd.M[0] * nd.M[3] - nd.M[1] * nd.M[2];
    nd.Minv[0] = nd.M[3] / det;
    nd.Minv[1] = -nd.M[1] / det;
    nd.Minv[2] = -nd.M[2] / det;
    nd.Minv[3] = nd.M[0] / det;
  } else {
    nd.Minv[0] = 1.0 / nd.M[0];
  }
}

void MultiRig::local_state(const double* y, int i, const Node& nd, servohydraulics::State& yl) const noexcept {
  const auto k = static_cast<std::size_t>(i);
  yl[kX] = nd.s[k];
  yl[kV] = nd.sd[k];
  for (int j = 0; j < count_[k]; ++j) yl[static_cast<std::size_t>(2 + j)] = y[off_[k] + j];
}

// The node's accelerations from the generalised force R (the actuators' J^T phi): the specimen's
// damping and stiffness subtracted, then M^-1 (one coordinate: a division, as Dynamics divides).
namespace {
void node_acceleration(const double* C, const double* K, const double* y, int m, const double* Minv,
                       const double* M, double* R, double* qdd) noexcept {
  for (int r = 0; r < m; ++r) {
    for (int j = 0; j < m; ++j) R[r] -= C[2 * r + j] * y[m + j];
    for (int j = 0; j < m; ++j) R[r] -= K[2 * r + j] * y[j];
  }
  if (m == 1) {
    qdd[0] = R[0] / M[0];
  } else {
    qdd[0] = Minv[0] * R[0] + Minv[1] * R[1];
    qdd[1] = Minv[2] * R[0] + Minv[3] * R[1];
  }
}
}  // namespace

// The generalised force of actuator i before its piston's inertia in the node's mass matrix:
// phi_i = A p - F_f - m_p (d2s/dtheta2) theta'^2 (the piston's centripetal part of s'').
void MultiRig::rhs(const double* y, const Input& in, double* ydot) const noexcept {
  Node nd;
  node(y, nd);
  double R[2] = {0.0, 0.0};
  servohydraulics::State yl{};
  double ydl[kMaxStates];
  for (int i = 0; i < n_act_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    local_state(y, i, nd, yl);
    Algebra g;
    const LawForce fr = dyn_[k].actuator(yl.data(), input_of(in, i), g);
    dyn_[k].actuator_rates(yl.data(), g, ydl);
    for (int j = 0; j < count_[k]; ++j) ydot[off_[k] + j] = ydl[2 + j];
    const double phi = area_[k] * yl[kP] - fr.F - mp_[k] * nd.b[k] * nd.thd * nd.thd;
    R[0] += phi;
    if (m_ == 2) R[1] += nd.a[k] * phi;
  }
  double qdd[2];
  node_acceleration(spec_.C.data(), spec_.K.data(), y, m_, nd.Minv, nd.M, R, qdd);
  for (int j = 0; j < m_; ++j) {
    ydot[j] = y[m_ + j];
    ydot[m_ + j] = qdd[j];
  }
}

void MultiRig::jacobian(const double* y, const Input& in, double* J, std::ptrdiff_t rs, std::ptrdiff_t cs,
                        double* B) const noexcept {
  const int n = n_, m = m_, N = n_act_;
  const bool rot = m == 2;
  auto at = [&](int r, int c) -> double& { return J[r * rs + c * cs]; };
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) at(r, c) = 0.0;
  if (B) std::fill(B, B + static_cast<std::ptrdiff_t>(n) * N, 0.0);
  for (int j = 0; j < m; ++j) at(j, m + j) = 1.0;
  Node nd;
  node(y, nd);
  double dR[2][kCapacity];  // the generalised force's gradient, m rows
  for (int r = 0; r < m; ++r) std::fill(dR[r], dR[r] + n, 0.0);
  double R[2] = {0.0, 0.0};
  servohydraulics::State yl{}, Bl{};
  Jacobian Jl;
  const double th2 = nd.thd * nd.thd;
  for (int i = 0; i < N; ++i) {
    const auto k = static_cast<std::size_t>(i);
    local_state(y, i, nd, yl);
    Algebra g;
    const LawForce fr = dyn_[k].actuator(yl.data(), input_of(in, i), g);
    for (auto& row : Jl) row.fill(0.0);
    Bl.fill(0.0);
    dyn_[k].actuator_jacobian(g, Jl, &Bl);
    // Chain rule through the fixture: s = s(q), s' = J_i(q) q', so ds/dq = J_i, ds'/dq' = J_i and
    // ds'/dtheta = (d2s/dtheta2) theta'.
    const double Ji[2] = {1.0, nd.a[k]};
    const double dsd_dq[2] = {0.0, nd.b[k] * nd.thd};
    for (int r = kP; r < 2 + count_[k]; ++r) {
      const int row = off_[k] + r - 2;
      for (int j = 0; j < m; ++j) {
        at(row, j) = Jl[r][kX] * Ji[j] + Jl[r][kV] * dsd_dq[j];
        at(row, m + j) = Jl[r][kV] * Ji[j];
      }
      for (int c = kP; c < 2 + count_[k]; ++c) at(row, off_[k] + c - 2) = Jl[r][c];
      if (B) B[static_cast<std::ptrdiff_t>(row) * N + i] = Bl[static_cast<std::size_t>(r)];
    }
    // The node: phi_i and its gradient.
    const double c3 = rot ? coupler_.d3stroke_dtheta3(k, nd.th) : 0.0;
    const double phi = area_[k] * yl[kP] - fr.F - mp_[k] * nd.b[k] * th2;
    const double dphi_q[2] = {-fr.dF_dx, -fr.dF_dx * nd.a[k] - fr.dF_dv * dsd_dq[1] - mp_[k] * c3 * th2};
    const double dphi_qd[2] = {-fr.dF_dv, -fr.dF_dv * nd.a[k] - 2.0 * mp_[k] * nd.b[k] * nd.thd};
    for (int r = 0; r < m; ++r) {
      const double w = Ji[r];
      for (int j = 0; j < m; ++j) {
        dR[r][j] += w * dphi_q[j];
        dR[r][m + j] += w * dphi_qd[j];
      }
      dR[r][index(i, kP)] += w * area_[k];
      dR[r][index(i, kZ)] -= w * fr.dF_dz;
      R[r] += w * phi;
    }
    if (rot) dR[1][1] += nd.b[k] * phi;  // dJ_i/dtheta = (0, d2s/dtheta2)
  }
  for (int r = 0; r < m; ++r)
    for (int j = 0; j < m; ++j) {
      dR[r][j] -= spec_.K[static_cast<std::size_t>(2 * r + j)];
      dR[r][m + j] -= spec_.C[static_cast<std::size_t>(2 * r + j)];
    }
  double qdd[2];
  node_acceleration(spec_.C.data(), spec_.K.data(), y, m, nd.Minv, nd.M, R, qdd);
  if (rot) {
    // M depends on theta through the pistons: dM/dtheta = sum m_p [[0, b], [b, 2 a b]]; q'' = M^-1 R
    // gives d q''/d theta = M^-1 (dR/dtheta - (dM/dtheta) q'').
    double v0 = 0.0, v1 = 0.0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(N); ++k) {
      v0 += mp_[k] * nd.b[k] * qdd[1];
      v1 += mp_[k] * (nd.b[k] * qdd[0] + 2.0 * nd.a[k] * nd.b[k] * qdd[1]);
    }
    dR[0][1] -= v0;
    dR[1][1] -= v1;
    for (int c = 0; c < n; ++c) {
      at(m, c) = nd.Minv[0] * dR[0][c] + nd.Minv[1] * dR[1][c];
      at(m + 1, c) = nd.Minv[2] * dR[0][c] + nd.Minv[3] * dR[1][c];
    }
  } else {
    for (int c = 0; c < n; ++c) at(m, c) = dR[0][c] / nd.M[0];
  }
}

void MultiRig::outputs(const double* y, const Input& in, MultiRigOutput& out) const noexcept {
  Node nd;
  node(y, nd);
  double R[2] = {0.0, 0.0};
  std::array<double, kMaxActuators> phi{};
  std::array<bool, kMaxActuators> spool_sat{}, drive_sat{};
  servohydraulics::State yl{};
  for (int i = 0; i < n_act_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    local_state(y, i, nd, yl);
    Algebra g;
    const LawForce fr = dyn_[k].actuator(yl.data(), input_of(in, i), g);
    phi[k] = area_[k] * yl[kP] - fr.F - mp_[k] * nd.b[k] * nd.thd * nd.thd;
    R[0] += phi[k];
    if (m_ == 2) R[1] += nd.a[k] * phi[k];
    ActuatorOutput& a = out.actuator[k];
    a.stroke = nd.s[k];
    a.velocity = nd.sd[k];
    a.pressure = yl[kP];
    a.spool = g.s;
    a.drive = g.drive;
    a.flow = g.Q;
    a.friction = fr.F;
    spool_sat[k] = g.spool_sat;
    drive_sat[k] = g.drive_sat;
  }
  double qdd[2] = {0.0, 0.0};
  node_acceleration(spec_.C.data(), spec_.K.data(), y, m_, nd.Minv, nd.M, R, qdd);
  NodeOutput& o = out.node;
  o.x = nd.x;
  o.theta = nd.th;
  o.x_velocity = nd.xd;
  o.theta_velocity = nd.thd;
  o.x_acceleration = qdd[0];
  o.theta_acceleration = m_ == 2 ? qdd[1] : 0.0;
  std::array<double, kMaxActuators> F{};
  out.flags = 0;
  double sum_abs = 0.0, sum = 0.0;
  for (int i = 0; i < n_act_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ActuatorOutput& a = out.actuator[k];
    const double Jqdd = qdd[0] + nd.a[k] * o.theta_acceleration;  // J_i q''
    a.acceleration = Jqdd + nd.b[k] * nd.thd * nd.thd;
    a.force = phi[k] - mp_[k] * Jqdd;  // A p - F_f - m_p s''
    F[k] = a.force;
    const double yf[kP + 1] = {a.stroke, a.velocity, a.pressure};
    a.flags = dyn_[k].flags(yf, spool_sat[k], drive_sat[k], a.force);
    out.flags |= a.flags;
    sum_abs += std::fabs(a.force);
    sum += a.force;
  }
  coupler_.node_load(nd.th, F.data(), &o.force, &o.moment);
  o.opposing_force = 0.5 * (sum_abs - std::fabs(sum));
  // The forces' component in the null space of J^T: F less its projection on the columns of J (the
  // N-vector of ones, and the ds_i/dtheta with theta free), orthonormalised.
  const double root_n = std::sqrt(static_cast<double>(n_act_));
  double p1 = 0.0;
  for (int i = 0; i < n_act_; ++i) p1 += F[static_cast<std::size_t>(i)] / root_n;
  int rank = 1;
  std::array<double, kMaxActuators> e2{};
  double p2 = 0.0;
  if (m_ == 2) {
    double mean_a = 0.0, norm = 0.0, norm_a = 0.0;
    for (int i = 0; i < n_act_; ++i) mean_a += nd.a[static_cast<std::size_t>(i)] / n_act_;
    for (int i = 0; i < n_act_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      e2[k] = nd.a[k] - mean_a;
      norm += e2[k] * e2[k];
      norm_a += nd.a[k] * nd.a[k];
    }
    norm = std::sqrt(norm);
    if (norm > 1e-12 * std::sqrt(norm_a)) {
      rank = 2;
      for (int i = 0; i < n_act_; ++i) {
        e2[static_cast<std::size_t>(i)] /= norm;
        p2 += e2[static_cast<std::size_t>(i)] * F[static_cast<std::size_t>(i)];
      }
    }
  }
  double fight = 0.0;
  if (n_act_ > rank) {
    for (int i = 0; i < n_act_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double r = F[k] - p1 / root_n - (rank == 2 ? p2 * e2[k] : 0.0);
      fight += r * r;
    }
    fight = std::sqrt(fight);
  }
  o.force_fighting = fight;
}

void MultiRig::strokes(const double* y, double* s) const noexcept {
  coupler_.strokes(y[0], m_ == 2 ? y[1] : 0.0, s);
}

MultiRig::State MultiRig::rest() const noexcept {
  State y{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(n_act_); ++i) {
    const servohydraulics::State e = dyn_[i].equilibrium(0.0);
    for (int j = 0; j < count_[i]; ++j) y[static_cast<std::size_t>(off_[i] + j)] = e[static_cast<std::size_t>(2 + j)];
  }
  return y;
}

namespace {
constexpr const char* kNodeStates[2][4] = {{"x", "x_dot", "", ""}, {"x", "theta", "x_dot", "theta_dot"}};
constexpr const char* kNodeUnits[2][4] = {{"m", "m/s", "", ""}, {"m", "rad", "m/s", "rad/s"}};
}  // namespace

std::string MultiRig::state_name(int k) const {
  if (k < 2 * m_) return kNodeStates[m_ - 1][k];
  for (int i = 0; i < n_act_; ++i) {
    const auto a = static_cast<std::size_t>(i);
    if (k >= off_[a] && k < off_[a] + count_[a])
      return "actuator" + std::to_string(i + 1) + "." + dyn_[a].state_info(k - off_[a] + 2).name;
  }
  return "";
}

const char* MultiRig::state_unit(int k) const noexcept {
  if (k < 2 * m_) return kNodeUnits[m_ - 1][k];
  for (int i = 0; i < n_act_; ++i) {
    const auto a = static_cast<std::size_t>(i);
    if (k >= off_[a] && k < off_[a] + count_[a]) return dyn_[a].state_info(k - off_[a] + 2).unit;
  }
  return "";
}

// x: the largest half-stroke; theta: that over the longest arm; their rates: the largest no-load speed
// (and over the longest arm); an actuator's load pressure: the pressure that makes the force of the
// node's translational stiffness over the half-stroke (or its friction), min(p_s, max(K_xx stroke, F_c) / A);
// its other states: the single actuator's scales (servohydraulics::state_scale).
double MultiRig::state_scale(int k) const noexcept {
  if (k < 2 * m_) {
    double stroke = 0.0, speed = 0.0, arm = 0.0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(n_act_); ++i) {
      stroke = std::max(stroke, dyn_[i].rig().stroke);
      speed = std::max(speed, dyn_[i].no_load_speed());
      arm = std::max(arm, coupler_.arm(i));
    }
    const double base = k < m_ ? stroke : speed;
    return (k % m_ == 0) ? base : base / arm;
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n_act_); ++i) {
    if (k < off_[i] || k >= off_[i] + count_[i]) continue;
    const int local = k - off_[i] + 2;
    if (local != kP) return servohydraulics::state_scale(dyn_[i], local);
    const Rig& r = dyn_[i].rig();
    const double force = std::max(spec_.K[0] * r.stroke, r.F_c);
    return force > 0.0 ? std::min(r.p_s, force / r.A) : r.p_s;
  }
  return 1.0;
}

MultiRigLinearModel linearize(const MultiRig& rig, const MultiRig::State& y0, const double* u0) {
  MultiRigLinearModel lm;
  const int n = rig.num_states(), N = rig.actuators();
  lm.n = n;
  lm.inputs = N;
  lm.A.assign(static_cast<std::size_t>(n) * n, 0.0);
  lm.B.assign(static_cast<std::size_t>(n) * N, 0.0);
  lm.C.assign(static_cast<std::size_t>(N) * n, 0.0);
  MultiRig::Input in;
  for (int i = 0; i < N; ++i) {
    require(std::isfinite(u0[i]), ("u0[" + std::to_string(i) + "]").c_str(), u0[i], "must be finite [m]");
    in.u[static_cast<std::size_t>(i)] = u0[i];
  }
  rig.jacobian(y0.data(), in, lm.A.data(), n, 1, lm.B.data());
  for (int i = 0; i < N; ++i) {
    lm.C[static_cast<std::size_t>(i) * n] = 1.0;  // ds_i/dx
    if (rig.dofs() == 2) lm.C[static_cast<std::size_t>(i) * n + 1] = rig.coupler().dstroke_dtheta(i, y0[1]);
  }
  return lm;
}

// ---- the plant ------------------------------------------------------------------------------------

namespace {
using MultiIntegrator = std::variant<detail::BasicDopri5Integrator<MultiRig>, detail::BasicCvodeIntegrator<MultiRig>,
                                     detail::BasicRk4Integrator<MultiRig>, detail::BasicRos2Integrator<MultiRig>>;

SolverOptions checked_options(const SolverOptions& o, double dt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "the loop's sample time must be finite and > 0 [s]");
  o.validate();
  const bool arkode = o.method == SolverOptions::Method::ArkodeErk || o.method == SolverOptions::Method::ArkodeDirk;
  require(!arkode, "method", static_cast<double>(o.method),
          "ARKODE is a reference of the single-actuator plant; the coupled rig takes dopri5, cvode, rk4 or ros2");
  return o;
}

MultiIntegrator make_integrator(const MultiRig& rig, double dt, const SolverOptions& opt) {
  using M = SolverOptions::Method;
  const MultiRig::State y0 = rig.rest();
  if (opt.method == M::CvodeBdf)
    return MultiIntegrator(std::in_place_type<detail::BasicCvodeIntegrator<MultiRig>>, rig, dt, opt, y0);
  if (opt.method == M::Rk4) return MultiIntegrator(std::in_place_type<detail::BasicRk4Integrator<MultiRig>>, rig, dt, opt);
  if (opt.method == M::Ros2)
    return MultiIntegrator(std::in_place_type<detail::BasicRos2Integrator<MultiRig>>, rig, dt, opt);
  return MultiIntegrator(std::in_place_type<detail::BasicDopri5Integrator<MultiRig>>, rig, dt, opt, y0, opt.stiff_check);
}
}  // namespace

struct MultiRigPlant::Impl {
  MultiRig rig;  // before integ: the integrators keep its address
  SolverOptions opt;
  double dt;
  double t = 0.0;
  long k = 0;  // samples since the reset: sample times are k dt
  MultiRig::State y{};
  MultiRig::Input input{};
  std::array<double, MultiRig::kMaxActuators> prev_u{};
  bool have_prev_u = false;
  bool failed = false;
  MultiIntegrator integ;

  Impl(const MultiRig& r, double dt_, const SolverOptions& o)
      : rig(r), opt(checked_options(o, dt_)), dt(dt_), integ(make_integrator(rig, dt, opt)) {
    if (auto* rk4 = std::get_if<detail::BasicRk4Integrator<MultiRig>>(&integ)) opt.rk4_substeps = rk4->substeps();
  }

  bool state_ok() const noexcept {
    for (int i = 0; i < rig.num_states(); ++i)
      if (!std::isfinite(y[static_cast<std::size_t>(i)])) return false;
    if (std::fabs(y[0]) > detail::kMaxDisplacement) return false;
    for (int i = 0; i < rig.actuators(); ++i)
      if (std::fabs(y[static_cast<std::size_t>(rig.index(i, kP))]) > detail::kMaxPressureRatio * rig.actuator(i).rig().p_s)
        return false;
    return true;
  }
};

MultiRigPlant::MultiRigPlant(const MultiRig& rig, double dt, const SolverOptions& options)
    : impl_(std::make_unique<Impl>(rig, dt, options)) {
  reset();
}
MultiRigPlant::~MultiRigPlant() = default;

std::size_t MultiRigPlant::actuators() const noexcept { return static_cast<std::size_t>(impl_->rig.actuators()); }
double MultiRigPlant::dt() const noexcept { return impl_->dt; }

void MultiRigPlant::reset() noexcept {
  Impl& m = *impl_;
  m.y = m.rig.rest();
  m.t = 0.0;
  m.k = 0;
  m.input = {};
  m.have_prev_u = false;
  m.failed = false;
  std::visit([&](auto& integ) { integ.reset(m.y, m.t); }, m.integ);
}

void MultiRigPlant::reset_state(const MultiRig::State& y) {
  for (int i = 0; i < impl_->rig.num_states(); ++i) {
    const std::string field = "y[" + std::to_string(i) + "] (" + impl_->rig.state_name(i) + ")";
    require(std::isfinite(y[static_cast<std::size_t>(i)]), field.c_str(), y[static_cast<std::size_t>(i)],
            "a state must be finite");
  }
  reset();
  impl_->y = y;
  std::visit([&](auto& integ) { integ.reset(impl_->y, 0.0); }, impl_->integ);
}

void MultiRigPlant::displacements(double* y) const noexcept { impl_->rig.strokes(impl_->y.data(), y); }

Status MultiRigPlant::step(const double* u) noexcept {
  Impl& m = *impl_;
  Status st;
  st.t = m.t;
  if (m.failed) {
    st.code = Status::NotReady;
    return st;
  }
  const int N = m.rig.actuators();
  for (int i = 0; i < N; ++i) {
    if (!std::isfinite(u[i])) {
      st.code = Status::NonFinite;
      m.failed = true;
      return st;
    }
  }
  // Zero-order hold: each command held over the sample, its rate the last increment / dt.
  for (std::size_t i = 0; i < static_cast<std::size_t>(N); ++i) {
    m.input.u[i] = u[i];
    m.input.u_rate[i] = m.have_prev_u ? (u[i] - m.prev_u[i]) / m.dt : 0.0;
    m.prev_u[i] = u[i];
  }
  m.have_prev_u = true;
  const double t_next = static_cast<double>(m.k + 1) * m.dt;
  st = std::visit([&](auto& integ) { return integ.advance(m.rig, m.input, m.y, m.t, t_next); }, m.integ);
  if (st.ok() && !m.state_ok()) st.code = Status::NonFinite;
  if (st.ok())
    ++m.k;
  else
    m.failed = true;
  return st;
}

void MultiRigPlant::observe(MultiRigOutput& out) const noexcept {
  impl_->rig.outputs(impl_->y.data(), impl_->input, out);
  out.time = impl_->t;
}

double MultiRigPlant::time() const noexcept { return impl_->t; }
const MultiRig& MultiRigPlant::rig() const noexcept { return impl_->rig; }
const MultiRig::State& MultiRigPlant::state() const noexcept { return impl_->y; }
const SolverOptions& MultiRigPlant::options() const noexcept { return impl_->opt; }
int MultiRigPlant::rk4_substeps() const noexcept {
  const auto* rk4 = std::get_if<detail::BasicRk4Integrator<MultiRig>>(&impl_->integ);
  return rk4 ? rk4->substeps() : 0;
}
long MultiRigPlant::total_internal_steps() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_steps(); }, impl_->integ);
}
long MultiRigPlant::total_rhs_evals() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_rhs_evals(); }, impl_->integ);
}
long MultiRigPlant::total_restarts() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_restarts(); }, impl_->integ);
}

RunSummary run_multi_record(MultiRigPlant& plant, const double* u, std::size_t n,
                            const MultiRigChannels& out) noexcept {
  RunSummary sum;
  const long ns0 = plant.total_internal_steps(), nf0 = plant.total_rhs_evals(), nr0 = plant.total_restarts();
  const std::size_t N = plant.actuators();
  MultiRigOutput o;
  plant.observe(o);
  for (std::size_t k = 0; k < n; ++k) {
    if (out.time) out.time[k] = o.time;
    for (std::size_t c = 0; c < kNumNodeChannels; ++c)
      if (out.node[c]) out.node[c][k] = o.node.*kNodeChannels[c].member;
    for (std::size_t i = 0; i < N; ++i) {
      const ActuatorOutput& a = o.actuator[i];
      for (std::size_t c = 0; c < kNumActuatorChannels; ++c)
        if (out.actuator[i][c]) out.actuator[i][c][k] = a.*kActuatorChannels[c].member;
      if (out.flags[i]) out.flags[i][k] = a.flags;
      sum.peaks(a.force, a.stroke, a.velocity);
      if (sum.first_capacity_time < 0.0 && (a.flags & kCapacityExceeded)) sum.first_capacity_time = o.time;
    }
    sum.flags_any |= o.flags;
    sum.rows = k + 1;
    if (k + 1 == n) break;  // the last command row is held but its effect is past the record
    const double t = o.time;
    const Status st = plant.step(u + k * N);
    plant.observe(o);
    if (out.internal_steps) out.internal_steps[k] = st.internal_steps;
    if (out.rhs_evals) out.rhs_evals[k] = st.rhs_evals;
    if (!sum.count(st, t)) break;
  }
  sum.internal_steps = plant.total_internal_steps() - ns0;
  sum.rhs_evals = plant.total_rhs_evals() - nf0;
  sum.restarts = plant.total_restarts() - nr0;
  return sum;
}

}  // namespace servohydraulics
