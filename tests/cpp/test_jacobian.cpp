// Analytic Jacobian df/dy, input gradient df/du and the linearised output
// matrices (C, D) against central finite differences of Dynamics::rhs and
// Dynamics::outputs, at many fixed-seed random states, in every control mode
// and for every combination of the thirteen effect switches (the nine of the
// paper's plant, the Bouc-Wen, MR damper and fluid damper specimens and the Pade loop delay,
// whose states are appended: every loop runs over Dynamics::num_states()).
//
// States are drawn away from the model's kinks (where the derivative is not
// defined or the finite difference straddles a switch): spring contact
// |x| = x_contact, the sign of the spool opening (load-pressure term, |x_v| in
// the flow curve), drive saturation |v| = v_max, spool end stops |x_v| = x_v_max,
// the breakpoints of a tabulated flow curve, and the C1 patch of the signed
// square root (|p| <= 0.9 p_s keeps its argument in [0.1, 1.9]).
//
// Tolerance.  The finite-difference step of state j is h_j = 1e-6 s_j (s_j: the
// state's scale below), so the truncation error is ~(1e-6)^2 relative and the
// round-off error is ~eps T_i / h_j, where T_i = |f_i| + sum_k |J_ik| (|y_k| + s_k)
// is the size of the terms that make up f_i.  An entry passes when
//   |J_an - J_fd| s_j <= 1e-6 T_i            (scaled: 1e-6 of the row's terms)
// and, where the entry is not negligible (|J_an| s_j > 1e-3 T_i), also
//   |J_an - J_fd| <= 1e-5 |J_an|             (element-wise relative).
// A wrong entry (sign, missing factor, missing term) is off by O(1) relative.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "check.hpp"
#include "randomizer.hpp"
#include "servohydraulics/elements/mr_damper.hpp"
#include "servohydraulics/linearize.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {

constexpr double kScale[kNumStates] = {1e-2, 1e-1, 1e6, 1e-1, 1e1, 1e-4};  // x [m], v [m/s], p [Pa], x_v [-], x_v' [1/s], z [m]

// Scale of state j of this plant: the base states above; the elements' states in m (Bouc-Wen z,
// the MR damper's y, z) 1e-3; the Pade states [V] 1.
double scale(const Dynamics& dyn, int j) {
  if (j < kNumStates) return kScale[j];
  return std::string(dyn.state_info(j).unit) == "m" ? 1e-3 : 1.0;
}
// Ultimate |z| of a Bouc-Wen law, (A / (beta + gamma))^(1/n).
double ultimate(double A, double bg, double n) { return bg > 0.0 ? std::pow(A / bg, 1.0 / n) : 0.01; }
constexpr double kRelStep = 1e-6;
constexpr int kOut = LinearModel::kOutputs;  // the linearised output channels
constexpr double kScaledTol = 1e-6;
constexpr double kElementTol = 1e-5;

double input_scale(ControlMode mode) { return mode == ControlMode::Displacement ? 1e-2 : 1e4; }

void set_effects(Effects& e, unsigned mask) {
  e.servovalve_dynamics = mask & 1u;
  e.load_pressure = mask & 2u;
  e.flow_nonlinearity = mask & 4u;
  e.coulomb_friction = mask & 8u;
  e.spring_softening = mask & 16u;
  e.piston_mass = mask & 32u;
  e.drive_saturation = mask & 64u;
  e.spool_saturation = mask & 128u;
  e.lugre_friction = mask & 256u;
  e.bouc_wen_hysteresis = mask & 512u;
  e.mr_damper = mask & 1024u;
  e.loop_delay = mask & 2048u;
  e.fluid_damper = mask & 4096u;
}

struct Draw {
  State y;
  Dynamics::Input in;
};

// Distances from the kinks, as the test computes them independently of the core.
bool away_from_kinks(const Dynamics& dyn, const Draw& d) {
  const Rig& r = dyn.rig();
  const double* y = d.y.data();
  const double margin_x = 1e-5, margin_v = 1e-3, margin_s = 1e-4;
  if (r.effects.spring_softening && std::fabs(std::fabs(y[kX]) - r.x_contact) < margin_x) return false;
  if (dyn.lugre() && std::fabs(y[kV]) < 1e-6) return false;  // |v| in the bristle equation
  if (dyn.exact_coulomb() && std::fabs(y[kV]) < margin_v) return false;  // the exact law's switch at v = 0
  // Bouc-Wen laws: |w| (w the deformation rate) and, with n = 1, |z|.
  const StateLayout& L = dyn.layout();
  if (const int iz = L.offset_of<BoucWen>(); iz >= 0) {
    if (std::fabs(y[kV]) < margin_v) return false;
    if (r.bw_n == 1.0 && std::fabs(y[iz]) < 1e-6) return false;
  }
  if (const int iy = L.offset_of<MrDamper>(); iy >= 0) {
    const MrLawValues law = mr_damper_law(r);  // the parameters at the rig's field input
    const double cs = law.c0 + law.c1;
    const double ydot = (law.alpha * y[iy + 1] + law.c0 * y[kV] + r.mr_k0 * (y[kX] - y[iy])) / cs;
    if (std::fabs(y[kV] - ydot) < margin_v) return false;
    if (r.mr_n == 1.0 && std::fabs(y[iy + 1]) < 1e-6) return false;
  }
  // Fluid damper: its rate (|F| / c)^(1/alpha) has a kink in its slope at F = 0 for alpha < 1.
  if (const int iu = L.offset_of<FluidDamper>(); iu >= 0 && r.fd_alpha < 1.0)
    if (std::fabs(y[kX] - y[iu]) < 1e-8) return false;
  if (dyn.mode() == ControlMode::Free) return true;
  Output o;
  dyn.outputs(y, d.in, o);
  double raw;
  if (dyn.mode() == ControlMode::Displacement) {
    const double CF = r.C_F_disp;
    raw = CF * (r.G_p * (d.in.u - y[kX]) + r.G_d * (d.in.u_rate - y[kV]));
  } else {
    raw = r.C_F_force * r.G_p * (d.in.u - o.force);
  }
  if (r.effects.drive_saturation && std::fabs(std::fabs(raw) - r.v_max) < margin_v) return false;
  const double drive = (r.effects.drive_saturation && std::fabs(raw) >= r.v_max) ? std::copysign(r.v_max, raw) : raw;
  const double xv = r.effects.servovalve_dynamics ? y[kXv] : r.K_s * drive;
  if (r.effects.spool_saturation && std::fabs(std::fabs(xv) - r.x_v_max) < margin_s) return false;
  const double s = (r.effects.spool_saturation && std::fabs(xv) >= r.x_v_max) ? std::copysign(r.x_v_max, xv) : xv;
  if ((r.effects.load_pressure || r.effects.flow_nonlinearity) && std::fabs(s) < margin_s) return false;
  if (r.effects.flow_nonlinearity && r.flow_curve.kind == FlowCurve::Kind::Table)
    for (double b : r.flow_curve.opening)
      if (std::fabs(std::fabs(s) - b) < margin_s) return false;
  return true;
}

Draw draw(sh_test::Randomizer& rnd, const Dynamics& dyn) {
  const Rig& r = dyn.rig();
  Draw d;
  d.y[kX] = rnd.signed_uniform(0.0, 2.4 * r.x_contact);
  // A quarter of the draws put v inside the steep part of the regularised friction.
  d.y[kV] = rnd.uniform(0.0, 1.0) < 0.25 ? rnd.signed_uniform(0.0, 3.0 * r.v_stick) : rnd.signed_uniform(0.0, 0.5);
  d.y[kP] = rnd.signed_uniform(0.0, 0.9 * r.p_s);
  d.y[kXv] = rnd.signed_uniform(0.0, 1.3 * r.x_v_max);
  d.y[kXvDot] = rnd.signed_uniform(0.0, 50.0);
  d.y[kZ] = rnd.signed_uniform(0.0, 1.5 * r.stribeck_ratio * r.F_c / r.sigma_0);  // bristle deflection [m]
  const StateLayout& L = dyn.layout();
  if (const int iz = L.offset_of<BoucWen>(); iz >= 0)
    d.y[iz] = rnd.signed_uniform(0.0, 1.5 * ultimate(r.bw_A, r.bw_beta + r.bw_gamma, r.bw_n));
  if (const int iy = L.offset_of<MrDamper>(); iy >= 0) {
    d.y[iy] = d.y[kX] + rnd.signed_uniform(0.0, 0.01);
    d.y[iy + 1] = rnd.signed_uniform(0.0, 1.5 * ultimate(r.mr_A, r.mr_beta + r.mr_gamma, r.mr_n));
  }
  // The fluid damper's series spring deflected by up to 1 mm (20 kN at the default fd_k).
  if (const int iu = L.offset_of<FluidDamper>(); iu >= 0) d.y[iu] = d.y[kX] + rnd.signed_uniform(0.0, 1e-3);
  for (int k = 0; k < L.count_of<PadeDelay>(); ++k) d.y[L.offset_of<PadeDelay>() + k] = rnd.signed_uniform(0.0, 5.0);
  if (dyn.mode() == ControlMode::Displacement) {
    d.in.u = rnd.signed_uniform(0.0, 0.06);
    d.in.u_rate = rnd.signed_uniform(0.0, 0.5);
  } else {
    d.in.u = rnd.signed_uniform(0.0, 1.6e5);
  }
  return d;
}

// Step of state j at this draw: relative to the scale, and well inside the
// friction regularisation width when v is in its steep part.
double fd_step(const Dynamics& dyn, const Draw& d, int j) {
  double h = kRelStep * scale(dyn, j);
  if (j == kV && std::fabs(d.y[kV]) < 10.0 * dyn.rig().v_stick) h = 1e-4 * dyn.rig().v_stick;
  return h;
}

struct Stats {
  long entries = 0;
  double worst_scaled = 0.0;
};

// Compares one column of analytic derivatives with its central difference.
// f(eps) evaluates the function with the perturbed variable, n values.
template <class F>
void compare_column(const char* what, int col, const double* analytic, int n, double h, double scale,
                    const double* terms, F&& f, Stats& st, const std::string& where) {
  std::vector<double> fp(n), fm(n);
  f(+h, fp.data());
  f(-h, fm.data());
  for (int i = 0; i < n; ++i) {
    const double fd = (fp[i] - fm[i]) / (2.0 * h);
    const double err = std::fabs(analytic[i] - fd);
    const double T = terms[i] + 1e-300;
    const double scaled = err * scale / T;
    st.worst_scaled = std::max(st.worst_scaled, scaled);
    ++st.entries;
    bool ok = scaled <= kScaledTol;
    if (ok && std::fabs(analytic[i]) * scale > 1e-3 * T) ok = err <= kElementTol * std::fabs(analytic[i]);
    if (!CHECK(ok))
      std::fprintf(stderr, "  %s: %s[%d][col %d] analytic %.12g fd %.12g (scaled err %.3g)\n", where.c_str(), what, i,
                   col, analytic[i], fd, scaled);
  }
}

Stats check_dynamics(const Dynamics& dyn, sh_test::Randomizer& rnd, int wanted, const std::string& name) {
  Stats st;
  int accepted = 0, attempts = 0;
  const double su = input_scale(dyn.mode());
  while (accepted < wanted && attempts < 50 * wanted) {
    ++attempts;
    Draw d = draw(rnd, dyn);
    if (!away_from_kinks(dyn, d)) continue;
    // Also every perturbed point must stay on the same side of every kink.
    const int n = dyn.num_states();
    bool all_away = true;
    for (int j = 0; j < n && all_away; ++j)
      for (double sgn : {-1.0, 1.0}) {
        Draw p = d;
        p.y[j] += sgn * fd_step(dyn, d, j);
        all_away = all_away && away_from_kinks(dyn, p);
      }
    for (double sgn : {-1.0, 1.0}) {
      Draw p = d;
      p.in.u += sgn * kRelStep * su;
      all_away = all_away && away_from_kinks(dyn, p);
    }
    if (!all_away) continue;
    ++accepted;
    const std::string where = name + " draw " + std::to_string(accepted);

    Jacobian J;
    State B;
    dyn.jacobian(d.y.data(), d.in, J, &B);
    State f;
    dyn.rhs(d.y.data(), d.in, f.data());
    {
      // rhs_jacobian (an implicit step's one evaluation) is rhs and jacobian to the bit, and
      // outputs without gradients (one evaluation without them) gives the values it gives with them.
      State f2;
      f2.fill(7.0);
      Jacobian J2;
      for (auto& row : J2) row.fill(7.0);
      dyn.rhs_jacobian(d.y.data(), d.in, f2.data(), J2);
      bool same = std::memcmp(f.data(), f2.data(), sizeof(double) * n) == 0;
      for (int i = 0; i < n; ++i) same = same && std::memcmp(J[i].data(), J2[i].data(), sizeof(double) * n) == 0;
      bool untouched = true;  // the rest of J2 as it was
      for (int i = 0; i < kMaxStates; ++i)
        for (int j = 0; j < kMaxStates; ++j) untouched = untouched && (i < n && j < n ? true : J2[i][j] == 7.0);
      Output with, without;
      Dynamics::OutputGradients G;
      dyn.outputs(d.y.data(), d.in, with, &G);
      dyn.outputs(d.y.data(), d.in, without);
      const double a[] = {with.displacement, with.velocity, with.acceleration, with.force, with.pressure,
                          with.spool, with.drive, with.flow, with.specimen_force};
      const double b[] = {without.displacement, without.velocity, without.acceleration, without.force,
                          without.pressure, without.spool, without.drive, without.flow, without.specimen_force};
      const bool outputs_same = std::memcmp(a, b, sizeof a) == 0 && with.flags == without.flags;
      if (!CHECK(same && untouched && outputs_same))
        std::printf("  %s: rhs_jacobian %s, rest of J %s, outputs %s\n", where.c_str(), same ? "same" : "DIFFERS",
                    untouched ? "untouched" : "WRITTEN", outputs_same ? "same" : "DIFFER");
    }
    double T[kMaxStates];
    for (int i = 0; i < n; ++i) {
      T[i] = std::fabs(f[i]) + std::fabs(B[i]) * (std::fabs(d.in.u) + su);
      for (int k = 0; k < n; ++k) T[i] += std::fabs(J[i][k]) * (std::fabs(d.y[k]) + scale(dyn, k));
    }
    for (int j = 0; j < n; ++j) {
      double col[kMaxStates];
      for (int i = 0; i < n; ++i) col[i] = J[i][j];
      compare_column("J", j, col, n, fd_step(dyn, d, j), scale(dyn, j), T,
                     [&](double e, double* out) {
                       State y = d.y;
                       y[j] += e;
                       dyn.rhs(y.data(), d.in, out);
                     },
                     st, where);
    }
    compare_column("B", n, B.data(), n, kRelStep * su, su, T,
                   [&](double e, double* out) {
                     Dynamics::Input in = d.in;
                     in.u += e;
                     dyn.rhs(d.y.data(), in, out);
                   },
                   st, where);

    // Output gradients through linearize() (u_rate = 0 there): C = d out / d y, D = d out / d u.
    Draw d0 = d;
    d0.in.u_rate = 0.0;
    if (!away_from_kinks(dyn, d0)) continue;
    const LinearModel lm = linearize(dyn, d0.y, d0.in.u);
    auto channels = [&](const State& y, double u, double* out) {
      Output o;
      dyn.outputs(y.data(), {u, 0.0}, o);
      const double v[kOut] = {o.displacement, o.velocity, o.acceleration, o.force, o.pressure,
                              o.spool,        o.drive,    o.flow,         o.specimen_force};
      std::copy(v, v + kOut, out);
    };
    double o0[kOut];
    channels(d0.y, d0.in.u, o0);
    double To[kOut];
    for (int i = 0; i < kOut; ++i) {
      To[i] = std::fabs(o0[i]) + std::fabs(lm.D(i)) * (std::fabs(d0.in.u) + su);
      for (int k = 0; k < n; ++k) To[i] += std::fabs(lm.C(i, k)) * (std::fabs(d0.y[k]) + scale(dyn, k));
    }
    for (int j = 0; j < n; ++j) {
      double col[kOut];
      for (int i = 0; i < kOut; ++i) col[i] = lm.C(i, j);
      compare_column("C", j, col, kOut, fd_step(dyn, d0, j), scale(dyn, j), To,
                     [&](double e, double* out) {
                       State y = d0.y;
                       y[j] += e;
                       channels(y, d0.in.u, out);
                     },
                     st, where);
    }
    double Dcol[kOut];
    for (int i = 0; i < kOut; ++i) Dcol[i] = lm.D(i);
    compare_column("D", n, Dcol, kOut, kRelStep * su, su, To,
                   [&](double e, double* out) { channels(d0.y, d0.in.u + e, out); }, st, where);
    // linearize's A, B are the Jacobian at u_rate = 0; inactive states have no dynamics.
    Jacobian J0;
    State B0;
    dyn.jacobian(d0.y.data(), d0.in, J0, &B0);
    CHECK(lm.A.rows() == n && lm.A.cols() == n && lm.C.cols() == n && static_cast<int>(lm.active.size()) == n);
    for (int i = 0; i < n; ++i) {
      CHECK(lm.B(i) == B0[i]);
      for (int k = 0; k < n; ++k) CHECK(lm.A(i, k) == J0[i][k]);
      if (!lm.active[i]) {
        State fi;
        dyn.rhs(d0.y.data(), d0.in, fi.data());
        CHECK(fi[i] == 0.0);
        for (int k = 0; k < n; ++k) CHECK(lm.A(i, k) == 0.0);
      }
    }
  }
  if (!CHECK(accepted == wanted))
    std::fprintf(stderr, "  %s: only %d of %d draws away from the kinks in %d attempts\n", name.c_str(), accepted, wanted,
                 attempts);
  return st;
}

}  // namespace

int main() {
  sh_test::Randomizer rnd(20030917);  // fixed seed: the same draws on every run
  const ControlMode modes[] = {ControlMode::Displacement, ControlMode::Force, ControlMode::Free};
  long entries = 0;
  double worst = 0.0;
  auto run = [&](const Rig& rig, ControlMode mode, int n, const std::string& name) {
    const Dynamics dyn(rig, mode);
    const Stats st = check_dynamics(dyn, rnd, n, name + " / " + to_string(mode));
    entries += st.entries;
    worst = std::max(worst, st.worst_scaled);
  };

  // Every combination of the thirteen effect switches, calibrated preset.
  for (unsigned mask = 0; mask < 8192; ++mask)
    for (ControlMode mode : modes) {
      Rig rig = zhao2003();
      set_effects(rig.effects, mask);
      run(rig, mode, 6, "calibrated effects mask " + std::to_string(mask));
    }
  // All effects on, more draws, on several rigs.
  for (ControlMode mode : modes) {
    run(zhao2003(), mode, 200, "calibrated");
    run(zhao2003(Zhao2003Variant::Printed, false), mode, 100, "printed, free-structure dissipation");
    Rig table = zhao2003();
    table.flow_curve.kind = FlowCurve::Kind::Table;
    table.flow_curve.opening = {0.0, 0.1, 0.4, 0.7, 1.0};
    table.flow_curve.flow = {0.0, 0.1, 0.33, 0.5, 0.6};
    run(table, mode, 100, "tabulated flow curve");
  }
  for (ControlMode mode : modes) {
    Rig lugre = zhao2003();
    lugre.effects.lugre_friction = true;
    lugre.F_c = 250.0;
    lugre.stribeck_ratio = 1.5;
    lugre.sigma_0 = 5e5;
    lugre.sigma_1 = 400.0;
    run(lugre, mode, 200, "LuGre with a Stribeck peak and bristle damping");
    Rig stribeck = lugre;
    stribeck.effects.lugre_friction = false;
    run(stribeck, mode, 100, "static friction law with a Stribeck peak");
    Rig exact = stribeck;  // the exact Coulomb law sliding (the draws' v != 0: Sliding::Auto picks the side)
    exact.v_stick = 0.0;
    run(exact, mode, 100, "exact Coulomb law with a Stribeck peak, sliding");
  }
  Rig derivative = zhao2003();
  derivative.G_d = 0.02;  // derivative term of Eq (1), displacement control only
  run(derivative, ControlMode::Displacement, 200, "G_d = 0.02 s");
  // The specimens and the loop delay at other parameters: n != 1, every Pade order, a voltage.
  for (ControlMode mode : modes) {
    Rig spec = zhao2003();
    spec.effects.bouc_wen_hysteresis = spec.effects.mr_damper = spec.effects.loop_delay = true;
    spec.bw_n = 2.5;
    spec.bw_beta = 3e4;
    spec.bw_gamma = -1e4 + 2e4;  // beta > gamma: a softening loop
    spec.mr_voltage = 1.5;
    spec.mr_n = 1.0;
    for (int order = 1; order <= kMaxPadeOrder; ++order) {
      spec.loop_delay_order = order;
      spec.loop_delay = 1e-3 * order;
      run(spec, mode, 40, "specimens, n 2.5 / 1, Pade order " + std::to_string(order));
    }
  }
  // The MR damper by the UTFSM thesis' law (Quiroz 2022) in the coil current, at three currents:
  // alpha quadratic, beta and gamma scaled by exp(-d i) (its parameters in SI: N/m, N s/m, 1/m^2).
  for (ControlMode mode : modes)
    for (double amps : {0.0, 0.5, 1.0}) {
      Rig q = zhao2003();
      q.effects.mr_damper = true;
      q.mr_input = MrInput::Current;
      q.mr_law = MrLaw::Quiroz2022;
      q.mr_current = amps;
      q.mr_law_max = 1.0;
      q.mr_alpha_a = 15.221e3, q.mr_alpha_b = 41.508e3, q.mr_alpha_c = -38.152e3;
      q.mr_c0_a = 0.92491e3, q.mr_c0_b = 7.6260e3, q.mr_c1_a = 9.8671e3, q.mr_c1_b = 78.337e3;
      q.mr_k0 = 0.15013, q.mr_k1 = 1.2388e3, q.mr_x0 = 2.3091e-6, q.mr_A = 300.0, q.mr_n = 2.0;
      q.mr_beta = q.mr_gamma = 1.8941e6;
      q.mr_bw_decay = 3.6561;
      run(q, mode, 60, "MR damper, thesis law at " + std::to_string(amps) + " A");
    }
  // The fluid damper linear (alpha = 1, a Maxwell element) and at alpha 0.3, with the specimens.
  for (ControlMode mode : modes)
    for (double alpha : {1.0, 0.3}) {
      Rig fd = zhao2003();
      fd.effects.fluid_damper = fd.effects.bouc_wen_hysteresis = fd.effects.loop_delay = true;
      fd.fd_alpha = alpha;
      fd.fd_k = 5e6;
      run(fd, mode, 100, "fluid damper, alpha " + std::to_string(alpha));
    }
  Rig underdamped = zhao2003();
  underdamped.zeta_v = 0.3;
  underdamped.f_v = 30.0;
  run(underdamped, ControlMode::Force, 100, "valve 30 Hz, zeta 0.3");

  std::printf("compared %ld Jacobian/output-gradient entries; worst scaled error %.3g (tolerance %.0e)\n", entries,
              worst, kScaledTol);
  return sh_test::report("test_jacobian");
}
