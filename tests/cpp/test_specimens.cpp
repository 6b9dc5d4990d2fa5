// Specimens (Bouc-Wen, MR damper, fluid damper) and delays inside the loop (command, measurement,
// Pade loop delay): the state layout, the digital command delay against the closed
// form of a linear oscillator, the exact split of a sample at a fractional delay,
// equilibria with every element on, zero allocations in step, and bad input.
// The physical oracles of the specimens (closed-form Bouc-Wen loop, loop area,
// Spencer's model, the Bingham limit) are in tests/python/test_specimens.py.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "check.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {
constexpr double kPi = 3.14159265358979323846;

Rig all_on() {
  Rig r = zhao2003();
  r.effects.bouc_wen_hysteresis = r.effects.mr_damper = r.effects.loop_delay = r.effects.fluid_damper = true;
  return r;
}

// The layout: base states fixed, the elements appended in order, only when on.
void check_layout() {
  const Dynamics paper(zhao2003(), ControlMode::Displacement);
  CHECK(paper.num_states() == kNumStates);
  CHECK(paper.layout().offset_of<BoucWen>() == -1 && paper.layout().offset_of<MrDamper>() == -1 &&
        paper.layout().offset_of<PadeDelay>() == -1);
  const Dynamics d(all_on(), ControlMode::Displacement);
  CHECK(d.num_states() == kNumStates + 1 + 2 + 3 + 1);
  CHECK(d.layout().offset_of<FluidDamper>() == 12 && std::string(d.state_info(12).name) == "fd_u");
  CHECK(d.layout().offset_of<BoucWen>() == 6 && d.layout().offset_of<MrDamper>() == 7 &&
        d.layout().offset_of<PadeDelay>() == 9 && d.layout().count_of<PadeDelay>() == 3);
  CHECK(std::string(d.state_info(6).name) == "bw_z" && std::string(d.state_info(8).name) == "mr_z");
  CHECK(std::string(d.state_info(11).name) == "delay_3");
  // No actuator in free mode: no loop delay.
  const Dynamics f(all_on(), ControlMode::Free);
  CHECK(f.num_states() == kNumStates + 4 && f.layout().offset_of<PadeDelay>() == -1);
  CHECK(f.layout().offset_of<FluidDamper>() == kNumStates + 3);
  Rig mr = zhao2003();
  mr.effects.mr_damper = true;
  const Dynamics m(mr, ControlMode::Force);
  CHECK(m.layout().offset_of<MrDamper>() == kNumStates && m.num_states() == kNumStates + 2);
}

// The operating point holds the plant at rest with every element on (incl. the
// MR damper's accumulator force k1 (x - x0) and the Pade states), in every mode.
void check_equilibria() {
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free})
    for (double x0 : {0.0, 0.01, -0.02}) {
      const Dynamics d(all_on(), mode);
      const Dynamics::OperatingPoint op = d.operating_point(x0);
      State f{};
      d.rhs(op.y0.data(), {op.u0, 0.0}, f.data());
      const Rig& r = d.rig();
      const double scales[3] = {1e-9, r.p_s * 1e-12, 1e-9};  // |v'| [m/s^2], |p'| [Pa/s], others
      bool ok = std::fabs(f[kV]) < scales[0] && std::fabs(f[kP]) < 1e-3 * r.p_s;
      for (int i = kNumStates; i < d.num_states(); ++i) ok = ok && std::fabs(f[i]) < scales[2];
      if (!CHECK(ok))
        std::fprintf(stderr, "  equilibrium %s x0 %g: a %g p' %g\n", to_string(mode), x0, f[kV], f[kP]);
      (void)scales[1];
    }
}

// A command delay of (D + f) samples on an undamped linear oscillator in free mode
// (command = ideal force): a force step F at sample j acts from t_j + tau, so
// x(t) = F/k (1 - cos(w (t - t_j - tau))) after it.  Integer and fractional delays,
// CVODE at rtol 1e-10 and RK4 (same total substeps, split at the switch).
void check_command_delay_closed_form() {
  Rig r = zhao2003();
  r.effects.coulomb_friction = false;
  r.effects.spring_softening = false;
  r.c = 0.0;
  const double dt = 1.0 / 1024.0, F = 1000.0, j = 10;
  const double w = std::sqrt(r.k / r.m);
  double worst_all = 0.0;
  for (double samples : {0.0, 1.0, 3.0, 0.25, 2.6, 7.5}) {
    for (int method = 0; method < 3; ++method) {  // CVODE restarting on input changes, never, RK4
      const bool rk4 = method == 2;
      r.command_delay = samples * dt;
      SolverOptions o;
      o.rtol = 1e-10;
      if (method == 1) o.restart = SolverOptions::Restart::Never;
      if (rk4) {
        o.method = SolverOptions::Method::Rk4;
        o.rk4_substeps = 16;
      }
      Plant p(r, ControlMode::Free, dt, o);
      Output out;
      double worst = 0.0;
      for (int k = 0; k < 400; ++k) {
        const Status st = p.step(k >= j ? F : 0.0, out);
        CHECK(st.ok());
        const double t = (k + 1) * dt, ts = j * dt + r.command_delay;
        const double exact = t > ts ? F / r.k * (1.0 - std::cos(w * (t - ts))) : 0.0;
        worst = std::max(worst, std::fabs(out.displacement - exact));
      }
      // 3e-8 of the amplitude 2F/k (CVODE at rtol 1e-10, restarting or not); holding the command
      // a fraction f of a sample off would be off by ~v f dt ~ 1e-5 m.
      const double tol = 3e-8 * F / r.k * 2.0;
      worst_all = std::max(worst_all, worst / (2.0 * F / r.k));
      if (!CHECK(worst < tol))
        std::fprintf(stderr, "  command delay %g samples (method %d): worst error %.3g m (tol %.3g)\n", samples,
                     method, worst, tol);
    }
  }
  std::printf("command delay vs closed form: worst error %.3g of the amplitude 2F/k (tolerance 3e-8)\n", worst_all);
}

// An integer command delay shifts the whole response by D samples (displacement
// control, all effects, nonlinear plant): out_delayed[k + D] = out[k] (RK4: the same
// arithmetic on the same states, up to the rounding of the sample times).
void check_integer_shift() {
  const double dt = 1.0 / 1024.0;
  const int D = 5, n = 600;
  Rig r = zhao2003();
  SolverOptions o;
  o.method = SolverOptions::Method::Rk4;
  Plant a(r, ControlMode::Displacement, dt, o);
  r.command_delay = D * dt;
  Plant b(r, ControlMode::Displacement, dt, o);
  std::vector<double> xa(n), xb(n);
  Output out;
  for (int k = 0; k < n; ++k) {
    const double u = 0.01 * std::sin(2.0 * kPi * 3.0 * k * dt);
    a.step(u, out);
    xa[k] = out.displacement;
    b.step(u, out);
    xb[k] = out.displacement;
  }
  double worst = 0.0;
  for (int k = 0; k + D < n; ++k) worst = std::max(worst, std::fabs(xb[k + D] - xa[k]));
  if (!CHECK(worst < 1e-12)) std::fprintf(stderr, "  integer shift: worst %.3g m\n", worst);
}

// Measurement delay: the measured displacement is the true one D + f samples back,
// linearly interpolated between samples (docs/specimens.md).
void check_measurement_delay() {
  const double dt = 1.0 / 1024.0;
  Rig r = zhao2003();
  Plant truth(r, ControlMode::Displacement, dt);
  r.measurement_delay_displacement = 2.25 * dt;
  r.measurement_delay_force = 3.0 * dt;
  Plant meas(r, ControlMode::Displacement, dt);
  std::vector<double> x{0.0}, f;
  Output o;
  truth.observe(o);
  f.push_back(o.force);
  double worst_x = 0.0, worst_f = 0.0;
  for (int k = 1; k <= 300; ++k) {
    const double u = 0.01 * std::sin(2.0 * kPi * 2.0 * k * dt);
    truth.step(u, o);
    x.push_back(o.displacement);
    f.push_back(o.force);
    meas.step(u, o);
    auto at = [](const std::vector<double>& s, int j) { return s[j < 0 ? 0 : j]; };
    const double xe = 0.75 * at(x, k - 2) + 0.25 * at(x, k - 3);
    worst_x = std::max(worst_x, std::fabs(o.displacement - xe));
    worst_f = std::max(worst_f, std::fabs(o.force - at(f, k - 3)));
  }
  CHECK(worst_x == 0.0);
  CHECK(worst_f == 0.0);
}

void check_no_allocation() {
  Rig r = all_on();
  const double dt = 1.0 / 1024.0;
  r.command_delay = 2.4 * dt;
  r.measurement_delay_displacement = 1.5 * dt;
  r.measurement_delay_force = 3.0 * dt;
  for (bool rk4 : {false, true}) {
    SolverOptions o;
    if (rk4) {
      o.method = SolverOptions::Method::Rk4;
      o.rk4_substeps = 200;
    }
    Plant p(r, ControlMode::Displacement, dt, o);
    Output out;
    long allocations;
    {
      sh_test::AllocationCounter counter;
      for (int k = 0; k < 500; ++k) p.step(0.01 * std::sin(2.0 * kPi * 2.0 * k * dt), out);
      p.reset(0.0);
      allocations = counter.count();
    }
    if (!CHECK(allocations == 0))
      std::fprintf(stderr, "  %s: %ld allocations in step\n", rk4 ? "rk4" : "cvode", allocations);
  }
}

template <class F>
void expect_error(F&& f, const std::string& needle) {
  try {
    f();
    CHECK(false);
    std::fprintf(stderr, "  no error for %s\n", needle.c_str());
  } catch (const Error& e) {
    if (!CHECK(std::string(e.what()).find(needle) != std::string::npos))
      std::fprintf(stderr, "  '%s' does not name '%s'\n", e.what(), needle.c_str());
  }
}

void check_bad_input() {
  auto rig_with = [](auto set) {
    Rig r = zhao2003();
    set(r);
    return r;
  };
  expect_error([&] { rig_with([](Rig& r) { r.bw_n = 0.5; }).validate(); }, "invalid bw_n = 0.5");
  expect_error([&] { rig_with([](Rig& r) { r.mr_n = 0.0; }).validate(); }, "invalid mr_n = 0");
  expect_error([&] { rig_with([](Rig& r) { r.bw_beta = -1.0; }).validate(); }, "invalid bw_beta = -1");
  expect_error([&] { rig_with([](Rig& r) { r.mr_c0_a = NAN; }).validate(); }, "invalid mr_c0_a = nan");
  expect_error([&] { rig_with([](Rig& r) { r.mr_voltage = -1.0; }).validate(); }, "invalid mr_voltage = -1");
  expect_error([&] { rig_with([](Rig& r) { r.command_delay = -1e-3; }).validate(); }, "invalid command_delay = -0.001");
  expect_error([&] { rig_with([](Rig& r) { r.loop_delay_order = 2.5; }).validate(); },
               "invalid loop_delay_order = 2.5");
  expect_error([&] { rig_with([](Rig& r) { r.loop_delay_order = 7.0; }).validate(); }, "invalid loop_delay_order = 7");
  expect_error([&] { rig_with([](Rig& r) { r.loop_delay = 0.0; }).validate(); }, "invalid loop_delay = 0");
  expect_error([&] { rig_with([](Rig& r) { r.fd_alpha = 0.0; }).validate(); }, "invalid fd_alpha = 0");
  expect_error([&] { rig_with([](Rig& r) { r.fd_k = -1.0; }).validate(); }, "invalid fd_k = -1");
  expect_error(
      [&] {
        Dynamics d(rig_with([](Rig& r) {
                     r.effects.fluid_damper = true;
                     r.fd_alpha = 1.5;
                   }),
                   ControlMode::Displacement);
      },
      "invalid fd_alpha = 1.5: must be in (0, 1]");
  // Longer than kMaxDelaySamples samples of the plant's dt.
  const double dt = 1.0 / 1024.0;
  expect_error([&] { Plant p(rig_with([dt](Rig& r) { r.command_delay = 65 * dt; }), ControlMode::Displacement, dt); },
               "invalid command_delay = 0.0634765625: must be at most 64 samples");
  expect_error(
      [&] { Plant p(rig_with([](Rig& r) { r.measurement_delay_force = 1.0; }), ControlMode::Force, dt); },
      "invalid measurement_delay_force = 1");
  Plant ok(rig_with([dt](Rig& r) { r.command_delay = 64 * dt; }), ControlMode::Displacement, dt);  // the maximum
  CHECK(ok.time() == 0.0);
}

}  // namespace

int main() {
  check_layout();
  check_equilibria();
  check_command_delay_closed_form();
  check_integer_shift();
  check_measurement_delay();
  check_no_allocation();
  check_bad_input();
  return sh_test::report("test_specimens");
}
