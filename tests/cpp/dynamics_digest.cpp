// A digest of everything Dynamics computes, to prove a refactoring of the plant bit-identical:
// FNV-1a over the bytes of rhs, the analytic Jacobian (J and B), the outputs with their
// gradients, equilibrium, operating_point, the structure's force laws, the RK4 rule, the state
// names and scales and the kinematic driver, for every combination of the thirteen Effects
// switches x the three control modes at fixed-seed random states and inputs, on three rigs
// (Stribeck peak and LuGre micro-damping; the plain paper rig; no Coulomb force), plus full
// simulations (dopri5, rk4, cvode, ros2) of the paper's rig with friction, LuGre, spring softening,
// specimens and the loop delay.  Not a ctest: the digest depends on the compiler and libm
// (tanh, exp, pow); compare it before and after a change on one machine and build.
//
//   dynamics_digest [--quick] [--expect HEX]     prints "digest <hex>" (exit 1 if it differs)
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "randomizer.hpp"
#include "servohydraulics/linearize.hpp"
#include "servohydraulics/parameters.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {

long g_models = 0, g_errors = 0;  // models built and refused (reported, not hashed)

struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  void d(double x) { bytes(&x, sizeof x); }
  void i(long long x) { bytes(&x, sizeof x); }
  void s(const char* t) { bytes(t, std::strlen(t) + 1); }
  void arr(const double* x, int n) {
    for (int k = 0; k < n; ++k) d(x[k]);
  }
  void out(const Output& o) {
    for (double x : {o.time, o.displacement, o.velocity, o.acceleration, o.force, o.pressure, o.spool, o.drive,
                     o.flow, o.specimen_force})
      d(x);
    i(o.flags);
  }
  void status(const Status& st) {
    i(st.code);
    i(st.cvode_flag);
    d(st.t);
    i(st.internal_steps);
    i(st.rhs_evals);
    i(st.restarted);
    i(st.stiff);
    i(st.inaccurate);
    d(st.error_estimate);
  }
};

// Bit i of mask is the switch of row i of kEffects (servovalve_dynamics = 1, ..., fluid_damper = 4096).
void set_effects(Effects& e, unsigned mask) {
  for (std::size_t i = 0; i < std::size(kEffects); ++i) e.*kEffects[i].member = (mask >> i) & 1u;
}
static_assert(std::size(kEffects) == 13, "one mask bit per effect");
constexpr unsigned kMasks = 1u << 13;

std::vector<Rig> rigs() {
  Rig a = zhao2003();
  a.stribeck_ratio = 1.6;  // the Stribeck level's exp branch
  a.sigma_1 = 300.0;       // LuGre micro-damping
  a.F_c = 400.0;
  Rig b = zhao2003();      // stribeck_ratio 1, sigma_1 0: the plain branches
  Rig c = zhao2003();
  c.F_c = 0.0;             // Coulomb switch on, no force: both friction laws off
  return {a, b, c};
}

// A random state over the whole layout and an input; deterministic.
void draw(sh_test::Randomizer& rnd, const Dynamics& dyn, State& y, Dynamics::Input& in) {
  const Rig& r = dyn.rig();
  y.fill(0.0);
  y[kX] = rnd.signed_uniform(0.0, 2.0 * r.x_contact);
  y[kV] = rnd.coin() ? rnd.signed_uniform(0.0, 3.0 * r.v_stick) : rnd.signed_uniform(0.0, 0.5);
  y[kP] = rnd.signed_uniform(0.0, 0.95 * r.p_s);
  y[kXv] = rnd.signed_uniform(0.0, 1.3 * r.x_v_max);
  y[kXvDot] = rnd.signed_uniform(0.0, 50.0);
  y[kZ] = rnd.signed_uniform(0.0, 2.0 * r.stribeck_ratio * std::max(r.F_c, 1.0) / r.sigma_0);
  for (int i = kNumStates; i < dyn.num_states(); ++i)
    y[i] = std::string(dyn.state_info(i).unit) == "m" ? y[kX] + rnd.signed_uniform(0.0, 1e-3)
                                                      : rnd.signed_uniform(0.0, 5.0);
  in.u = dyn.mode() == ControlMode::Displacement ? rnd.signed_uniform(0.0, 0.06) : rnd.signed_uniform(0.0, 1.6e5);
  in.u_rate = rnd.signed_uniform(0.0, 0.5);
}

void model(Hash& H, const Rig& rig0, unsigned mask, ControlMode mode, int draws, sh_test::Randomizer& rnd) {
  Rig rig = rig0;
  set_effects(rig.effects, mask);
  H.i(mask);
  H.i(static_cast<int>(mode));
  ++g_models;
  try {
    const Dynamics dyn(rig, mode);
    const int n = dyn.num_states();
    H.i(n);
    H.i(dyn.lugre());
    for (int i = 0; i < n; ++i) {
      H.s(dyn.state_info(i).name);
      H.s(dyn.state_info(i).unit);
      H.d(state_scale(dyn, i));
    }
    for (double v : {0.05, 1.0}) H.d(dyn.element_rate_bound(v));
    try {
      H.i(rk4_automatic_substeps(dyn, 5e-4, SolverOptions{}));
    } catch (const Error& e) {
      H.s(e.what());
    }
    for (double x0 : {0.0, 0.012, -0.031}) {
      const State e = dyn.equilibrium(x0);
      H.arr(e.data(), kMaxStates);
      const Dynamics::OperatingPoint op = dyn.operating_point(x0);
      H.arr(op.y0.data(), kMaxStates);
      H.d(op.u0);
    }
    State y, ydot;
    Dynamics::Input in;
    Jacobian J;
    State B;
    Output out;
    Dynamics::OutputGradients G;
    for (int k = 0; k < draws; ++k) {
      draw(rnd, dyn, y, in);
      ydot.fill(0.0);
      dyn.rhs(y.data(), in, ydot.data());
      H.arr(ydot.data(), n);
      dyn.jacobian(y.data(), in, J, &B);
      for (int i = 0; i < kMaxStates; ++i) H.arr(J[i].data(), kMaxStates);
      H.arr(B.data(), kMaxStates);
      dyn.jacobian(y.data(), in, J);  // without B
      for (int i = 0; i < kMaxStates; ++i) H.arr(J[i].data(), kMaxStates);
      dyn.outputs(y.data(), in, out, &G);
      H.out(out);
      for (const auto& row : G) H.arr(row.data(), kMaxStates + 1);
      dyn.outputs(y.data(), in, out);
      H.out(out);
      H.d(dyn.specimen_force(y.data()));
      H.d(dyn.structure_force(y[kX], y[kV], y[kZ]));
      H.d(dyn.structure_force(y[kX], y[kV]));
      H.d(dyn.spring_force(y[kX]));
      H.d(dyn.spring_stiffness(y[kX]));
      H.d(dyn.friction_force(y[kV]));
      H.d(dyn.friction_slope(y[kV]));
      H.d(dyn.friction_level(y[kV]));
      H.d(dyn.friction_level_slope(y[kV]));
    }
    if (mask % 97 == 0) {  // linearisation and the kinematic driver on a sample of the combinations
      const Dynamics::OperatingPoint op = dyn.operating_point(0.004);
      const LinearModel lm = linearize(dyn, op.y0, op.u0);
      H.arr(lm.A.data(), static_cast<int>(lm.A.size()));
      H.arr(lm.B.data(), static_cast<int>(lm.B.size()));
      H.arr(lm.C.data(), static_cast<int>(lm.C.size()));
      H.arr(lm.D.data(), static_cast<int>(lm.D.size()));
      for (bool a : lm.active) H.i(static_cast<long long>(a));
      const int m = 400;
      std::vector<double> x(m), v(m), F(m);
      for (int k = 0; k < m; ++k) {
        const double t = k * 1e-3;
        x[k] = 0.02 * std::sin(2.0 * 3.0 * t);
        v[k] = 0.02 * 6.0 * std::cos(6.0 * t);
      }
      for (int sub : {0, 3}) {
        try {
          dyn.specimen_forces(x.data(), v.data(), m, 1e-3, sub, F.data());
          H.arr(F.data(), m);
        } catch (const Error& e) {
          H.s(e.what());
        }
      }
    }
  } catch (const Error& e) {
    H.s(e.what());
    ++g_errors;
  }
}

// The paper's rig in a closed displacement (or force) loop, driven by a 1.5 Hz sine that reaches
// beyond the springs' contact point, every output and status hashed in H, the outputs alone in O
// (a change of a method's work or flags leaves O as it was).  Returns a summary line.
std::string simulate(Hash& H, Hash& O, Rig rig, ControlMode mode, SolverOptions::Method method, long steps) {
  SolverOptions opt;
  opt.method = method;
  try {
    Plant plant(rig, mode, 5e-4, opt);
    plant.reset(0.0);
    Output out;
    double peak_x = 0.0, peak_F = 0.0;
    long failed = 0;
    for (long k = 0; k < steps; ++k) {
      const double t = k * 5e-4;
      const double ramp = std::min(1.0, t / 0.3);
      const double u = mode == ControlMode::Displacement ? 0.045 * ramp * std::sin(2.0 * 3.141592653589793 * 1.5 * t)
                                                         : 4e4 * ramp * std::sin(2.0 * 3.141592653589793 * 1.5 * t);
      const Status st = plant.step(u, out);
      H.status(st);
      H.out(out);
      O.out(out);
      failed += !st.ok();
      peak_x = std::max(peak_x, std::fabs(out.displacement));
      peak_F = std::max(peak_F, std::fabs(out.force));
    }
    H.arr(plant.state().data(), kMaxStates);
    H.i(plant.total_internal_steps());
    H.i(plant.total_rhs_evals());
    H.i(plant.total_restarts());
    H.i(plant.rk4_substeps());
    char line[160];
    std::snprintf(line, sizeof line, "peak |x| %.4g m, |F| %.4g N, %ld failed steps, %ld rhs", peak_x, peak_F,
                  failed, plant.total_rhs_evals());
    return line;
  } catch (const Error& e) {
    H.s(e.what());
    return std::string("error: ") + e.what();
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string expect;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") quick = true;
    else if (a == "--expect" && i + 1 < argc) expect = argv[++i];
    else {
      std::fprintf(stderr, "usage: dynamics_digest [--quick] [--expect HEX]\n");
      return 2;
    }
  }
  Hash total;
  Hash part;
  sh_test::Randomizer rnd(20261125);
  for (const Rig& rig : rigs())
    for (unsigned mask = 0; mask < kMasks; ++mask)
      for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free})
        model(part, rig, mask, mode, quick ? 1 : 3, rnd);
  std::printf("models      %016llx  (%ld built, %ld refused by a check)\n", static_cast<unsigned long long>(part.h),
              g_models, g_errors);
  total.i(static_cast<long long>(part.h));

  Hash sims, outputs;
  const long steps = quick ? 400 : 2400;
  struct Case {
    const char* name;
    unsigned mask;  // Effects bits as in set_effects
  };
  const unsigned paper = 1u | 2u | 4u | 8u | 16u | 32u | 64u | 128u;
  const Case cases[] = {
      {"friction+softening", paper},
      {"lugre+softening", paper | 256u},
      {"lugre+bouc_wen+delay", paper | 256u | 512u | 2048u},
      {"friction+mr+fluid", paper | 1024u | 4096u},
  };
  for (const Case& c : cases)
    for (auto method : {SolverOptions::Method::Dopri5, SolverOptions::Method::Rk4, SolverOptions::Method::CvodeBdf,
                        SolverOptions::Method::Ros2}) {
      Rig rig = zhao2003();
      rig.stribeck_ratio = 1.4;
      rig.sigma_1 = 200.0;
      rig.F_c = 300.0;
      set_effects(rig.effects, c.mask);
      Hash one;
      const std::string summary = simulate(one, outputs, rig, ControlMode::Displacement, method, steps);
      std::printf("sim %-22s %-6s %016llx  %s\n", c.name, method == SolverOptions::Method::Dopri5 ? "dopri5"
                                                       : method == SolverOptions::Method::Rk4  ? "rk4"
                                                       : method == SolverOptions::Method::Ros2 ? "ros2"
                                                                                               : "cvode",
                  static_cast<unsigned long long>(one.h), summary.c_str());
      sims.i(static_cast<long long>(one.h));
    }
  {
    Rig rig = zhao2003();
    rig.effects.lugre_friction = true;
    Hash one;
    const std::string summary = simulate(one, outputs, rig, ControlMode::Force, SolverOptions::Method::Dopri5, steps);
    std::printf("sim %-22s %-6s %016llx  %s\n", "force lugre", "dopri5", static_cast<unsigned long long>(one.h),
                summary.c_str());
    sims.i(static_cast<long long>(one.h));
  }
  total.i(static_cast<long long>(sims.h));
  std::printf("sim outputs %016llx  (the simulations' outputs alone: unchanged by a change of work or flags)\n",
              static_cast<unsigned long long>(outputs.h));
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(total.h));
  std::printf("digest %s%s\n", hex, quick ? " (quick)" : "");
  if (!expect.empty() && expect != hex) {
    std::printf("MISMATCH: expected %s\n", expect.c_str());
    return 1;
  }
  return 0;
}
