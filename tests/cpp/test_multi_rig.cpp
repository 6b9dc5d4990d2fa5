// The coupled multi-actuator rig (multi_rig.hpp) against its oracles:
//
// 1. The analytic Jacobian df/dy and input gradient df/du against central finite differences of
//    the right-hand side, at fixed-seed random states of random rigs (1 to 4 actuators on random
//    arms, theta free or locked, random specimens, random effects: friction (static or LuGre),
//    load pressure, flow curve, saturations, piston mass, the Pade loop delay), away from the
//    model's kinks (as test_jacobian.cpp: the tolerance is 1e-6 of the row's terms, and 1e-5
//    element-wise where the entry is not negligible).  The strokes' gradient of linearize()
//    against differences of strokes().
// 2. The degenerate fixture: one actuator on a translating node (theta locked) with the rig's own
//    structure as the specimen is the single-actuator Plant: the linearisations agree to 1e-12
//    and a closed-loop run agrees with Plant to integrator tolerance with dopri5, CVODE and RK4
//    (the load cells differ by the friction, which the single plant puts on its structure and the
//    coupled rig on the piston).
// 3. Symmetry: two identical actuators on the benchmark's symmetric arms and a specimen without
//    x-theta coupling, commanded equally, never rotate the node and keep equal strokes.
// 4. No allocation in reset, step, displacements, observe and run_multi_record (dopri5 with its
//    CVODE fallback taking stiff samples, CVODE, RK4).
// 5. Bad input: errors name the field and the value; a non-finite command fails the sample, then
//    NotReady until reset.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

// Eigen (linearize.hpp) declares posix_memalign itself: include it before the allocation counter.
#include "servohydraulics/linearize.hpp"
// (after)
#include "alloc_counter.hpp"
#include "check.hpp"
#include "randomizer.hpp"
#include "servohydraulics/multi_rig.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRelStep = 1e-6;
constexpr double kScaledTol = 1e-6;
constexpr double kElementTol = 1e-5;

// A rig around the paper's with random parameters and effects (no specimen element: the coupled
// rig rejects them).  With the loop delay on, the valve dynamics are on too (the kink check below
// reads the spool from the state).
Rig random_rig(sh_test::Randomizer& rnd) {
  Rig r = zhao2003();
  r.A *= rnd.uniform(0.3, 2.0);
  r.K_v *= rnd.uniform(0.3, 2.0);
  r.C_l *= rnd.uniform(0.0, 5.0);
  r.K_a *= rnd.uniform(0.3, 3.0);
  r.f_v = rnd.uniform(30.0, 150.0);
  r.zeta_v = rnd.uniform(0.4, 1.2);
  r.G_p = rnd.uniform(0.3, 3.0);
  r.G_d = rnd.coin() ? 0.0 : rnd.uniform(0.0, 0.02);
  r.F_c = rnd.uniform(0.0, 500.0);
  r.m_p = rnd.uniform(0.0, 80.0);
  r.stribeck_ratio = rnd.coin() ? 1.0 : rnd.uniform(1.0, 2.0);
  r.sigma_1 = rnd.uniform(0.0, 300.0);
  Effects& e = r.effects;
  e.servovalve_dynamics = rnd.coin();
  e.load_pressure = rnd.coin();
  e.flow_nonlinearity = rnd.coin();
  e.coulomb_friction = rnd.coin();
  e.piston_mass = rnd.coin();
  e.drive_saturation = rnd.coin();
  e.spool_saturation = rnd.coin();
  e.lugre_friction = rnd.coin();
  e.loop_delay = rnd.uniform(0.0, 1.0) < 0.3;
  if (e.loop_delay) {
    e.servovalve_dynamics = true;
    r.loop_delay_order = std::floor(rnd.uniform(1.0, 4.999));
  }
  return r;
}

// A positive semidefinite symmetric 2 x 2 with diagonal a, d and coupling up to 0.9 sqrt(a d).
std::array<double, 4> psd(sh_test::Randomizer& rnd, double a, double d) {
  const double c = rnd.signed_uniform(0.0, 0.9) * std::sqrt(a * d);
  return {a, c, c, d};
}

NodeSpecimen random_specimen(sh_test::Randomizer& rnd, bool rotation) {
  NodeSpecimen sp;
  sp.rotation = rotation;
  sp.M = psd(rnd, rnd.uniform(5.0, 5000.0), rnd.uniform(0.5, 500.0));
  sp.C = psd(rnd, rnd.uniform(0.0, 5e4), rnd.uniform(0.0, 5e3));
  sp.K = psd(rnd, rnd.uniform(1e5, 1e8), rnd.uniform(1e4, 1e7));
  sp.fixture_mass = rnd.uniform(0.0, 100.0);
  sp.fixture_inertia = rnd.uniform(0.0, 10.0);
  return sp;
}

Coupler random_coupler(sh_test::Randomizer& rnd, int n) {
  std::vector<double> d(static_cast<std::size_t>(n)), a(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    d[static_cast<std::size_t>(i)] = rnd.uniform(0.1, 1.0);
    a[static_cast<std::size_t>(i)] = -1.2 + 2.4 * (i + rnd.uniform(0.1, 0.9)) / n;  // distinct angles
  }
  return Coupler(static_cast<std::size_t>(n), d.data(), a.data());
}

// The test's own scale of each state (the finite-difference step is 1e-6 of it).
double scale(const MultiRig& rig, int k) {
  const int m = rig.dofs();
  if (k < m) return 1e-2;          // x [m], theta [rad]
  if (k < 2 * m) return 1e-1;      // x', theta'
  const std::string u = rig.state_unit(k);
  if (u == "Pa") return 1e6;
  if (u == "-") return 1e-1;       // x_v
  if (u == "1/s") return 1e1;      // x_v'
  if (u == "m") return 1e-4;       // the bristle z
  return 1.0;                      // the Pade states [V]
}

struct Draw {
  MultiRig::State y{};
  MultiRig::Input in{};
};

Draw draw(sh_test::Randomizer& rnd, const MultiRig& rig) {
  Draw d;
  const int m = rig.dofs();
  d.y[0] = rnd.signed_uniform(0.0, 0.05);
  if (m == 2) d.y[1] = rnd.signed_uniform(0.0, 0.3);
  const bool slow = rnd.uniform(0.0, 1.0) < 0.25;  // a quarter inside the steep part of the friction
  d.y[static_cast<std::size_t>(m)] = slow ? rnd.signed_uniform(0.0, 2e-4) : rnd.signed_uniform(0.0, 0.5);
  if (m == 2) d.y[3] = slow ? rnd.signed_uniform(0.0, 2e-4) : rnd.signed_uniform(0.0, 2.0);
  for (int i = 0; i < rig.actuators(); ++i) {
    const Rig& r = rig.actuator(i).rig();
    d.y[static_cast<std::size_t>(rig.index(i, kP))] = rnd.signed_uniform(0.0, 0.9 * r.p_s);
    d.y[static_cast<std::size_t>(rig.index(i, kXv))] = rnd.signed_uniform(0.0, 1.3 * r.x_v_max);
    d.y[static_cast<std::size_t>(rig.index(i, kXvDot))] = rnd.signed_uniform(0.0, 50.0);
    d.y[static_cast<std::size_t>(rig.index(i, kZ))] = rnd.signed_uniform(0.0, 1.5 * r.stribeck_ratio * r.F_c / r.sigma_0);
    for (int k = kNumStates; k < rig.actuator(i).num_states(); ++k)
      d.y[static_cast<std::size_t>(rig.index(i, k))] = rnd.signed_uniform(0.0, 5.0);
    d.in.u[static_cast<std::size_t>(i)] = rnd.signed_uniform(0.0, 0.06);
    d.in.u_rate[static_cast<std::size_t>(i)] = rnd.signed_uniform(0.0, 0.5);
  }
  return d;
}

// Distances from the kinks of every actuator, computed here from the fixture's kinematics.
bool away_from_kinks(const MultiRig& rig, const Draw& d) {
  const int m = rig.dofs();
  const double th = m == 2 ? d.y[1] : 0.0, thd = m == 2 ? d.y[3] : 0.0;
  double s[MultiRig::kMaxActuators];
  rig.coupler().strokes(d.y[0], th, s);
  for (int i = 0; i < rig.actuators(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Rig& r = rig.actuator(i).rig();
    const double sd = d.y[static_cast<std::size_t>(m)] + (m == 2 ? rig.coupler().dstroke_dtheta(k, th) * thd : 0.0);
    if (rig.actuator(i).lugre() && std::fabs(sd) < 1e-6) return false;
    const double raw = r.C_F_disp * (r.G_p * (d.in.u[k] - s[i]) + r.G_d * (d.in.u_rate[k] - sd));
    if (r.effects.drive_saturation && std::fabs(std::fabs(raw) - r.v_max) < 1e-3) return false;
    const double drive = (r.effects.drive_saturation && std::fabs(raw) >= r.v_max) ? std::copysign(r.v_max, raw) : raw;
    const double xv = r.effects.servovalve_dynamics ? d.y[static_cast<std::size_t>(rig.index(i, kXv))] : r.K_s * drive;
    if (r.effects.spool_saturation && std::fabs(std::fabs(xv) - r.x_v_max) < 1e-4) return false;
    const double so = (r.effects.spool_saturation && std::fabs(xv) >= r.x_v_max) ? std::copysign(r.x_v_max, xv) : xv;
    if ((r.effects.load_pressure || r.effects.flow_nonlinearity) && std::fabs(so) < 1e-4) return false;
  }
  return true;
}

double fd_step(const MultiRig& rig, const Draw& d, int j) {
  double h = kRelStep * scale(rig, j);
  const int m = rig.dofs();
  if (j >= m && j < 2 * m) {  // a velocity: inside the friction's regularisation width when it is steep
    for (int i = 0; i < rig.actuators(); ++i) {
      const double th = m == 2 ? d.y[1] : 0.0;
      const double sd = d.y[static_cast<std::size_t>(m)] +
                        (m == 2 ? rig.coupler().dstroke_dtheta(static_cast<std::size_t>(i), th) * d.y[3] : 0.0);
      const double vs = rig.actuator(i).rig().v_stick;
      if (std::fabs(sd) < 10.0 * vs) h = std::min(h, 1e-4 * vs);
    }
  }
  return h;
}

long g_entries = 0;
double g_worst = 0.0;

// One column of analytic derivatives against its central difference (test_jacobian.cpp's rule).
template <class F>
void compare_column(const char* what, int col, const std::vector<double>& analytic, int n, double h, double sc,
                    const std::vector<double>& terms, F&& f, const std::string& where) {
  std::vector<double> fp(static_cast<std::size_t>(n)), fm(static_cast<std::size_t>(n));
  f(+h, fp.data());
  f(-h, fm.data());
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double fd = (fp[k] - fm[k]) / (2.0 * h);
    const double err = std::fabs(analytic[k] - fd);
    const double T = terms[k] + 1e-300;
    const double scaled = err * sc / T;
    g_worst = std::max(g_worst, scaled);
    ++g_entries;
    bool ok = scaled <= kScaledTol;
    if (ok && std::fabs(analytic[k]) * sc > 1e-3 * T) ok = err <= kElementTol * std::fabs(analytic[k]);
    if (!CHECK(ok))
      std::fprintf(stderr, "  %s: %s[%d][col %d] analytic %.12g fd %.12g (scaled err %.3g)\n", where.c_str(), what, i,
                   col, analytic[k], fd, scaled);
  }
}

void check_jacobian(const MultiRig& rig, sh_test::Randomizer& rnd, int wanted, const std::string& name) {
  const int n = rig.num_states(), N = rig.actuators();
  int accepted = 0;
  for (int attempt = 0; accepted < wanted && attempt < 100 * wanted; ++attempt) {
    const Draw d = draw(rnd, rig);
    bool ok = away_from_kinks(rig, d);
    for (int j = 0; j < n && ok; ++j)
      for (double sg : {-1.0, 1.0}) {
        Draw p = d;
        p.y[static_cast<std::size_t>(j)] += sg * fd_step(rig, d, j);
        ok = ok && away_from_kinks(rig, p);
      }
    for (int i = 0; i < N && ok; ++i)
      for (double sg : {-1.0, 1.0}) {
        Draw p = d;
        p.in.u[static_cast<std::size_t>(i)] += sg * kRelStep * 1e-2;
        ok = ok && away_from_kinks(rig, p);
      }
    if (!ok) continue;
    ++accepted;
    const std::string where = name + " draw " + std::to_string(accepted);
    std::vector<double> J(static_cast<std::size_t>(n) * n), B(static_cast<std::size_t>(n) * N), f(static_cast<std::size_t>(n));
    rig.jacobian(d.y.data(), d.in, J.data(), n, 1, B.data());
    rig.rhs(d.y.data(), d.in, f.data());
    std::vector<double> T(static_cast<std::size_t>(n));
    for (int r = 0; r < n; ++r) {
      double t = std::fabs(f[static_cast<std::size_t>(r)]);
      for (int c = 0; c < n; ++c)
        t += std::fabs(J[static_cast<std::size_t>(r * n + c)]) * (std::fabs(d.y[static_cast<std::size_t>(c)]) + scale(rig, c));
      for (int i = 0; i < N; ++i) t += std::fabs(B[static_cast<std::size_t>(r * N + i)]) * (std::fabs(d.in.u[static_cast<std::size_t>(i)]) + 1e-2);
      T[static_cast<std::size_t>(r)] = t;
    }
    std::vector<double> col(static_cast<std::size_t>(n));
    for (int c = 0; c < n; ++c) {
      for (int r = 0; r < n; ++r) col[static_cast<std::size_t>(r)] = J[static_cast<std::size_t>(r * n + c)];
      compare_column("J", c, col, n, fd_step(rig, d, c), scale(rig, c), T,
                     [&](double e, double* out) {
                       MultiRig::State y = d.y;
                       y[static_cast<std::size_t>(c)] += e;
                       rig.rhs(y.data(), d.in, out);
                     },
                     where);
    }
    for (int i = 0; i < N; ++i) {
      for (int r = 0; r < n; ++r) col[static_cast<std::size_t>(r)] = B[static_cast<std::size_t>(r * N + i)];
      compare_column("B", i, col, n, kRelStep * 1e-2, 1e-2, T,
                     [&](double e, double* out) {
                       MultiRig::Input in = d.in;
                       in.u[static_cast<std::size_t>(i)] += e;
                       rig.rhs(d.y.data(), in, out);
                     },
                     where);
    }
    // The strokes' gradient (linearize's C).
    const MultiRigLinearModel lm = linearize(rig, d.y, d.in.u.data());
    for (int c = 0; c < n; ++c) {
      const double h = kRelStep * scale(rig, c);
      MultiRig::State yp = d.y, ym = d.y;
      yp[static_cast<std::size_t>(c)] += h;
      ym[static_cast<std::size_t>(c)] -= h;
      double sp[MultiRig::kMaxActuators], sm[MultiRig::kMaxActuators];
      rig.strokes(yp.data(), sp);
      rig.strokes(ym.data(), sm);
      for (int i = 0; i < N; ++i)
        CHECK_NEAR(lm.C[static_cast<std::size_t>(i * n + c)], (sp[i] - sm[i]) / (2.0 * h), 1e-7);
    }
  }
  CHECK(accepted == wanted);
}

// 1. The analytic Jacobian.
void test_jacobian() {
  sh_test::Randomizer rnd(20261201);
  int rigs = 0;
  for (int n_act = 1; n_act <= 4; ++n_act)
    for (bool rotation : {true, false})
      for (int rep = 0; rep < 6; ++rep) {
        std::vector<Rig> rs;
        for (int i = 0; i < n_act; ++i) rs.push_back(random_rig(rnd));
        const MultiRig rig(rs, random_coupler(rnd, n_act), random_specimen(rnd, rotation));
        check_jacobian(rig, rnd, 4, "N=" + std::to_string(n_act) + (rotation ? " theta" : " locked") + " rig " +
                                        std::to_string(rep));
        ++rigs;
      }
  std::printf("jacobian: %d rigs, %ld entries, worst scaled error %.3g\n", rigs, g_entries, g_worst);
}

// The paper's rig as a one-actuator coupled rig on a translating node: its own structure (linear
// spring) as the specimen.
MultiRig single_as_multi(const Rig& r) {
  NodeSpecimen sp;
  sp.rotation = false;
  sp.M[0] = r.m;
  sp.C[0] = r.c;
  sp.K[0] = r.k;
  const double d = 0.3, a = 0.2;
  return MultiRig({r}, Coupler(1, &d, &a), sp);
}

// 2. The degenerate fixture against the single-actuator plant.
void test_single_actuator() {
  for (int variant = 0; variant < 3; ++variant) {
    Rig r = zhao2003();
    r.effects.spring_softening = false;  // the node's specimen is linear
    if (variant == 1) {
      r.effects.lugre_friction = true;
      r.F_c = 300.0;
      r.sigma_1 = 200.0;
    }
    if (variant == 2) {
      r.effects.loop_delay = true;
      r.G_d = 0.01;
      r.stribeck_ratio = 1.5;
    }
    const MultiRig rig = single_as_multi(r);
    const Dynamics dyn(r, ControlMode::Displacement);
    CHECK(rig.num_states() == dyn.num_states());
    // Linearisations about a displaced operating point.
    const Dynamics::OperatingPoint op = dyn.operating_point(0.004);
    MultiRig::State y0{};
    for (int k = 0; k < dyn.num_states(); ++k) y0[static_cast<std::size_t>(k)] = op.y0[static_cast<std::size_t>(k)];
    const LinearModel ls = linearize(dyn, op.y0, op.u0);
    const MultiRigLinearModel lm = linearize(rig, y0, &op.u0);
    const int n = dyn.num_states();
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
      double row = 1e-300;
      for (int j = 0; j < n; ++j) row = std::max(row, std::fabs(ls.A(i, j)));
      for (int j = 0; j < n; ++j)
        worst = std::max(worst, std::fabs(lm.A[static_cast<std::size_t>(i * n + j)] - ls.A(i, j)) / row);
      worst = std::max(worst, std::fabs(lm.B[static_cast<std::size_t>(i)] - ls.B(i)) / std::max(row, std::fabs(ls.B(i))));
      CHECK_NEAR(lm.C[static_cast<std::size_t>(i)], ls.C(0, i), 0.0);  // the stroke is the displacement
    }
    CHECK(worst <= 1e-12);
    if (worst > 1e-12) std::fprintf(stderr, "variant %d: linearisations differ by %.3g of a row\n", variant, worst);
    // Closed-loop runs: a ramped 2 Hz sine and a held step, every sample compared.
    for (auto method : {SolverOptions::Method::Dopri5, SolverOptions::Method::CvodeBdf, SolverOptions::Method::Rk4}) {
      SolverOptions opt;
      opt.method = method;
      const double dt = 1.0 / 1024;
      Plant plant(r, ControlMode::Displacement, dt, opt);
      MultiRigPlant multi(rig, dt, opt);
      Output o;
      MultiRigOutput mo;
      double peak_x = 0.0, peak_f = 0.0, dx = 0.0, dF = 0.0;
      for (int k = 0; k < 3000; ++k) {
        const double t = k * dt;
        const double u = t < 2.0 ? 0.02 * std::min(1.0, t / 0.5) * std::sin(2.0 * kPi * 2.0 * t) : 0.01;
        const Status a = plant.step(u, o);
        const Status b = multi.step(&u);
        CHECK(a.ok() && b.ok());
        multi.observe(mo);
        peak_x = std::max(peak_x, std::fabs(o.displacement));
        peak_f = std::max(peak_f, std::fabs(o.force));
        dx = std::max(dx, std::fabs(o.displacement - mo.actuator[0].stroke));
        // The single plant's friction acts on its structure, behind the load cell; the coupled rig's
        // on the piston, in front of it: the load cells differ by the friction force.
        dF = std::max(dF, std::fabs(o.force - (mo.actuator[0].force + mo.actuator[0].friction)));
        if (std::fabs(o.force) < 0.99 * r.F_cap) CHECK(o.flags == mo.actuator[0].flags);
      }
      // Integrator tolerance: both integrate the same equations at rtol 1e-8 (RK4: the same fixed steps).
      CHECK(dx <= 1e-7 * peak_x);
      CHECK(dF <= 1e-6 * peak_f);
      std::printf("single vs coupled (variant %d, method %d): max |dx| %.3g m of %.3g, |dF| %.3g N of %.3g\n", variant,
                  static_cast<int>(method), dx, peak_x, dF, peak_f);
    }
  }
}

// 3. Symmetry.
void test_symmetry() {
  Rig r = zhao2003();
  r.F_c = 200.0;
  NodeSpecimen sp;
  sp.M = {50.0, 0.0, 0.0, 2.0};
  sp.C = {2e3, 0.0, 0.0, 50.0};
  sp.K = {2e6, 0.0, 0.0, 1e5};
  const MultiRig rig({r, r}, Coupler::marths(), sp);
  for (auto method : {SolverOptions::Method::Dopri5, SolverOptions::Method::CvodeBdf}) {
    SolverOptions opt;
    opt.method = method;
    MultiRigPlant plant(rig, 1.0 / 1024, opt);
    MultiRigOutput o;
    double worst_theta = 0.0, worst_ds = 0.0, peak = 0.0;
    for (int k = 0; k < 2048; ++k) {
      const double t = k / 1024.0;
      const double u[2] = {0.01 * std::sin(2.0 * kPi * 1.5 * t), 0.01 * std::sin(2.0 * kPi * 1.5 * t)};
      CHECK(plant.step(u).ok());
      plant.observe(o);
      worst_theta = std::max(worst_theta, std::fabs(o.node.theta));
      worst_ds = std::max(worst_ds, std::fabs(o.actuator[0].stroke - o.actuator[1].stroke));
      peak = std::max(peak, std::fabs(o.node.x));
    }
    CHECK(peak > 5e-3);
    CHECK(worst_theta <= 1e-15);
    CHECK(worst_ds <= 1e-15);
    std::printf("symmetry (method %d): peak x %.3g m, max |theta| %.3g rad, max |s1 - s2| %.3g m\n",
                static_cast<int>(method), peak, worst_theta, worst_ds);
  }
}

// 4. No allocation on the hot path.
void test_allocations() {
  Rig r = zhao2003();
  r.F_c = 400.0;  // sharp friction on light pistons: the pair turns stiff and CVODE takes samples
  r.m_p = 5.0;
  NodeSpecimen sp;
  sp.M = {8.0, 0.0, 0.0, 0.8};
  sp.K = {2.3e6, 8.6e5, 8.6e5, 1.1e6};
  sp.C = {500.0, 0.0, 0.0, 20.0};
  const MultiRig rig({r, r}, Coupler::marths(), sp);
  for (auto method : {SolverOptions::Method::Dopri5, SolverOptions::Method::CvodeBdf, SolverOptions::Method::Rk4}) {
    SolverOptions opt;
    opt.method = method;
    MultiRigPlant plant(rig, 1.0 / 1024, opt);
    const int n = 600;
    std::vector<double> u(2 * n), col(n);
    for (int k = 0; k < n; ++k) {
      u[static_cast<std::size_t>(2 * k)] = 0.005 * std::sin(2.0 * kPi * 2.0 * k / 1024.0);
      u[static_cast<std::size_t>(2 * k + 1)] = 0.004 * std::sin(2.0 * kPi * 3.0 * k / 1024.0);
    }
    MultiRigChannels ch;
    ch.actuator[0][3] = col.data();
    MultiRigOutput o;
    double y[2];
    long stiff = 0;
    sh_test::AllocationCounter counter;
    plant.reset();
    for (int k = 0; k < n; ++k) {
      plant.displacements(y);
      const Status st = plant.step(&u[static_cast<std::size_t>(2 * k)]);
      stiff += st.stiff;
      plant.observe(o);
    }
    plant.reset();
    const RunSummary sum = run_multi_record(plant, u.data(), n, ch);
    const long allocs = counter.count();
    CHECK(sum.ok() && sum.rows == static_cast<std::size_t>(n));
    if (sh_test::kCountingAllocations) CHECK(allocs == 0);
    if (method == SolverOptions::Method::Dopri5) CHECK(stiff > 0);  // the fallback was exercised
    std::printf("allocations (method %d): %ld in %d steps and a run (%ld stiff samples)\n", static_cast<int>(method),
                allocs, 2 * n, stiff);
  }
}

template <class F>
void expect_error(F&& f, const char* needle) {
  try {
    f();
    CHECK(false);
    std::fprintf(stderr, "  no error, expected one naming %s\n", needle);
  } catch (const Error& e) {
    const bool named = std::string(e.what()).find(needle) != std::string::npos;
    if (!CHECK(named)) std::fprintf(stderr, "  error '%s' does not name %s\n", e.what(), needle);
  }
}

// 5. Bad input.
void test_bad_input() {
  const Rig r = zhao2003();
  NodeSpecimen sp;
  sp.M = {50.0, 0.0, 0.0, 2.0};
  sp.K = {2e6, 0.0, 0.0, 1e5};
  expect_error([&] { MultiRig({r}, Coupler::marths(), sp); }, "invalid actuators = 1");
  expect_error([&] {
    NodeSpecimen s = sp;
    s.K[2] = 5.0;
    MultiRig({r, r}, Coupler::marths(), s);
  }, "invalid specimen.K[1][0] = 5");
  expect_error([&] {
    NodeSpecimen s = sp;
    s.C = {1.0, 10.0, 10.0, 1.0};
    MultiRig({r, r}, Coupler::marths(), s);
  }, "invalid specimen.C[0][1] = 10");
  expect_error([&] {
    NodeSpecimen s = sp;
    s.M[3] = std::nan("");
    MultiRig({r, r}, Coupler::marths(), s);
  }, "invalid specimen.M[1][1] = nan");
  expect_error([&] {
    NodeSpecimen s = sp;
    s.M = {0.0, 0.0, 0.0, 0.0};
    Rig light = r;
    light.m_p = 0.0;
    MultiRig({light, light}, Coupler::marths(), s);
  }, "invalid specimen.M[0][0] = 0");
  expect_error([&] {
    NodeSpecimen s = sp;
    s.fixture_mass = -1.0;
    MultiRig({r, r}, Coupler::marths(), s);
  }, "invalid specimen.fixture_mass = -1");
  expect_error([&] {
    Rig bad = r;
    bad.K_v = -2.0;
    MultiRig({r, bad}, Coupler::marths(), sp);
  }, "invalid actuators[1].K_v = -2");
  expect_error([&] {
    Rig bad = r;
    bad.effects.bouc_wen_hysteresis = true;
    MultiRig({bad, r}, Coupler::marths(), sp);
  }, "invalid actuators[0].effects.bouc_wen_hysteresis = 1");
  expect_error([&] {
    Rig bad = r;
    bad.command_delay = 1e-3;
    MultiRig({r, bad}, Coupler::marths(), sp);
  }, "invalid actuators[1].command_delay = 0.001");
  const MultiRig rig({r, r}, Coupler::marths(), sp);
  expect_error([&] { MultiRigPlant(rig, -1.0); }, "invalid dt = -1");
  expect_error([&] {
    SolverOptions o;
    o.method = SolverOptions::Method::ArkodeErk;
    MultiRigPlant(rig, 1e-3, o);
  }, "invalid method = 3");
  MultiRigPlant plant(rig, 1e-3);
  const double bad[2] = {0.001, std::nan("")};
  CHECK(plant.step(bad).code == Status::NonFinite);
  const double good[2] = {0.001, 0.001};
  CHECK(plant.step(good).code == Status::NotReady);
  plant.reset();
  CHECK(plant.step(good).ok());
}

}  // namespace

int main() {
  test_jacobian();
  test_single_actuator();
  test_symmetry();
  test_allocations();
  test_bad_input();
  return sh_test::report("test_multi_rig");
}
