// Contracts of Dynamics' helpers that Python uses instead of re-deriving the model:
//
// 1. operating_point(x0): the equilibrium at x0 and the held command u0 that
//    keeps it at rest: the rate that u drives (spool rate with valve dynamics,
//    pressure rate with a static valve) is zero and the structure is in
//    balance, in every mode and over random effect sets; the plant held at u0
//    from there stays put.
// 2. structure_force(x, v, z) is the force Eq (5) subtracts: in Free mode
//    M dv/dt = u - structure_force, over random states, with the static law,
//    the Stribeck peak and LuGre.
// 3. simulate() (the allocating Trace wrapper) gives the rows run_record's
//    convention promises: row k is the state before command[k], stepping by hand.
// 4. The structure's laws (StructureLaws): which are on for each friction switch (at most one
//    friction law; LuGre only with F_c > 0), the spring's closed form across the contact point,
//    the RK4 rule's bound (rate_bound: LuGre's sigma_0 v / F_c with the elements') apart from the
//    kinematic driver's (element_rate_bound and specimen_forces see the specimens only).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "check.hpp"
#include "randomizer.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"
#include "servohydraulics/record.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;

void random_effects(Effects& e, sh_test::Randomizer& rnd) {
  e.servovalve_dynamics = rnd.coin();
  e.load_pressure = rnd.coin();
  e.flow_nonlinearity = rnd.coin();
  e.coulomb_friction = rnd.coin();
  e.spring_softening = rnd.coin();
  e.piston_mass = rnd.coin();
  e.lugre_friction = rnd.coin();
}

void check_operating_point(sh_test::Randomizer& rnd) {
  for (int draw = 0; draw < 60; ++draw) {
    for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free}) {
      Rig rig = zhao2003();
      random_effects(rig.effects, rnd);
      const double x0 = rnd.signed_uniform(0.0, 0.03);
      const Dynamics dyn(rig, mode);
      const auto op = dyn.operating_point(x0);
      CHECK(op.y0 == dyn.equilibrium(x0));
      State f, B;
      Jacobian J;
      dyn.rhs(op.y0.data(), {op.u0, 0.0}, f.data());
      dyn.jacobian(op.y0.data(), {op.u0, 0.0}, J, &B);
      // Balance of the structure: |M a| at round-off of the spring force.
      CHECK(std::fabs(f[kV]) * dyn.moving_mass() <= 1e-9 * (std::fabs(dyn.spring_force(x0)) + 1.0));
      if (mode == ControlMode::Free) {
        CHECK(op.u0 == dyn.spring_force(x0));
        continue;
      }
      // The driven rate is zero: what a change of u by one unit of command would move it, times 1e-9.
      const int idx = rig.effects.servovalve_dynamics ? kXvDot : kP;
      const double unit = mode == ControlMode::Displacement ? 1e-3 : 1e3;  // [m] or [N]
      CHECK(std::fabs(f[idx]) <= 1e-9 * std::fabs(B[idx]) * unit);
    }
  }
  // The plant held at u0 from the operating point stays there (CVODE, full model).
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force}) {
    Plant plant(zhao2003(), mode, kDt);
    const double x0 = 0.012;
    const auto op = plant.dynamics().operating_point(x0);
    plant.reset_state(op.y0);
    Output o;
    for (int k = 0; k < 400; ++k) CHECK(plant.step(op.u0, o).ok());
    CHECK_NEAR(o.displacement, x0, 1e-6 * x0);
  }
}

void check_structure_force(sh_test::Randomizer& rnd) {
  double worst = 0.0;
  for (int draw = 0; draw < 300; ++draw) {
    Rig rig = zhao2003();
    random_effects(rig.effects, rnd);
    rig.stribeck_ratio = rnd.coin() ? 1.0 : rnd.uniform(1.0, 2.0);
    rig.sigma_1 = rnd.coin() ? 0.0 : rnd.uniform(0.0, 2e3);
    const Dynamics dyn(rig, ControlMode::Free);
    State y{};
    y[kX] = rnd.signed_uniform(0.0, 0.05);
    y[kV] = rnd.signed_uniform(0.0, 0.5);
    y[kZ] = dyn.lugre() ? rnd.signed_uniform(0.0, rig.F_c / rig.sigma_0) : 0.0;
    const double u = rnd.signed_uniform(0.0, 5e4);
    State f;
    dyn.rhs(y.data(), {u, 0.0}, f.data());
    const double F = dyn.structure_force(y[kX], y[kV], y[kZ]);
    const double scale = std::fabs(u) + std::fabs(F) + 1.0;
    worst = std::fmax(worst, std::fabs(dyn.moving_mass() * f[kV] - (u - F)) / scale);
    if (!dyn.lugre())  // the static law: spring + damping + g(v) tanh(v / v_stick)
      CHECK(F == dyn.friction_force(y[kV]) + rig.c * y[kV] + dyn.spring_force(y[kX]));
  }
  std::printf("structure_force: worst |M a - (u - F)| / scale = %.3g\n", worst);
  CHECK(worst < 1e-14);
}

void check_simulate_trace() {
  std::vector<double> cmd(400);
  for (std::size_t k = 0; k < cmd.size(); ++k) cmd[k] = 0.01 * std::sin(0.02 * static_cast<double>(k));
  Plant a(zhao2003(), ControlMode::Displacement, kDt), b(zhao2003(), ControlMode::Displacement, kDt);
  const Trace tr = simulate(a, cmd);
  CHECK(tr.summary.status.ok() && tr.summary.rows == cmd.size());
  bool rows = true;
  Output o;
  b.observe(o);
  for (std::size_t k = 0; k < cmd.size(); ++k) {
    for (std::size_t i = 0; i < kNumPlantChannels; ++i) rows = rows && tr.channel[i][k] == o.*kPlantChannels[i].member;
    rows = rows && tr.flags[k] == o.flags && tr.command[k] == cmd[k];
    b.step(cmd[k], o);
  }
  CHECK(rows);
  CHECK(&tr[Channel::Force] == &tr.channel[static_cast<std::size_t>(Channel::Force)]);
}
void check_structure_laws() {
  for (int mask = 0; mask < 8; ++mask) {
    Rig rig = zhao2003();
    rig.effects.coulomb_friction = mask & 1;
    rig.effects.lugre_friction = mask & 2;
    rig.F_c = (mask & 4) ? 0.0 : 40.0;
    const Dynamics dyn(rig, ControlMode::Displacement);
    const bool coulomb = rig.effects.coulomb_friction && rig.F_c > 0.0;
    const bool lugre = coulomb && rig.effects.lugre_friction;
    CHECK((dyn.law<LuGreFriction>() != nullptr) == lugre);
    CHECK(dyn.lugre() == lugre);
    CHECK((dyn.law<TanhFriction>() != nullptr) == (coulomb && !lugre));
    CHECK(dyn.law<Spring>() != nullptr && dyn.law<ViscousDamping>() != nullptr);
    CHECK(dyn.rate_bound(0.3) == (lugre ? rig.sigma_0 * 0.3 / rig.F_c : 0.0));
    CHECK(dyn.element_rate_bound(0.3) == 0.0);
  }
  // The spring: k x inside the contact point, k x_c + k_2 (|x| - x_c) beyond, odd, continuous.
  const Rig rig = zhao2003();
  const Dynamics dyn(rig, ControlMode::Displacement);
  const double xc = rig.x_contact;
  CHECK_NEAR(dyn.spring_force(0.5 * xc), rig.k * 0.5 * xc, 1e-9 * rig.k * xc);
  CHECK_NEAR(dyn.spring_force(2.0 * xc), rig.k * xc + rig.k_2 * xc, 1e-9 * rig.k * xc);
  CHECK(dyn.spring_force(-2.0 * xc) == -dyn.spring_force(2.0 * xc));
  CHECK_NEAR(dyn.spring_force(xc * (1.0 + 1e-12)), rig.k * xc, 1e-6 * rig.k * xc);
  CHECK(dyn.spring_stiffness(2.0 * xc) == rig.k_2 && dyn.spring_stiffness(0.5 * xc) == rig.k);
  // LuGre with a Bouc-Wen specimen: the RK4 rule takes the larger bound, the driver only the specimen's;
  // the driver's force is the specimen's whichever friction law acts.
  Rig both = zhao2003();
  both.effects.lugre_friction = true;
  both.effects.bouc_wen_hysteresis = true;
  const Dynamics with_lugre(both, ControlMode::Displacement);
  const double specimen = with_lugre.element_rate_bound(0.3);
  CHECK(specimen > 0.0);
  CHECK(with_lugre.rate_bound(0.3) == std::max(specimen, both.sigma_0 * 0.3 / both.F_c));
  Rig none = both;
  none.effects.coulomb_friction = false;
  const Dynamics without(none, ControlMode::Displacement);
  std::vector<double> x(300), v(300), Fa(300), Fb(300);
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k] = 0.01 * std::sin(0.05 * static_cast<double>(k));
    v[k] = 0.01 * 0.05 / 1e-3 * std::cos(0.05 * static_cast<double>(k));
  }
  with_lugre.specimen_forces(x.data(), v.data(), x.size(), 1e-3, 4, Fa.data());
  without.specimen_forces(x.data(), v.data(), x.size(), 1e-3, 4, Fb.data());
  CHECK(Fa == Fb);
  CHECK(std::fabs(Fa.back()) > 0.0);
}
}  // namespace

int main() {
  sh_test::Randomizer rnd(20031105);
  check_operating_point(rnd);
  check_structure_force(rnd);
  check_simulate_trace();
  check_structure_laws();
  return sh_test::report("test_dynamics");
}
