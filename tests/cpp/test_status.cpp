// The hot path reports failures as a Status (never throws), setup throws
// servohydraulics::Error naming the field and the value.
//  - an overrun (max_steps_per_sample = 1) gives TooMuchWork with CVODE's flag
//    and the time reached, then NotReady until reset();
//  - a NaN or infinite command gives NonFinite, then NotReady until reset();
//    after reset the plant runs exactly like a new one;
//  - a run beyond the divergence guard (|x| > 100 m) gives NonFinite;
//  - with Restart::Never a step command in the middle of a motion is integrated
//    (the BDF history straddles the jump of the held command).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "check.hpp"
#include "same_output.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"
#include "servohydraulics/record.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;
constexpr double kPi = 3.14159265358979323846;
constexpr int kCvTooMuchWork = -1;  // CV_TOO_MUCH_WORK in cvode/cvode.h

using sh_test::same;

// Runs f and returns the Error's message, or "" if nothing was thrown.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

void overrun() {
  SolverOptions opt;
  opt.method = SolverOptions::Method::CvodeBdf;  // the flag and the time reached inside the sample are CVODE's
  opt.max_steps_per_sample = 1;
  Plant plant(zhao2003(), ControlMode::Displacement, kDt, opt);
  Output out;
  const Status st = plant.step(0.01, out);
  CHECK(st.code == Status::TooMuchWork);
  CHECK(st.cvode_flag == kCvTooMuchWork);
  CHECK(st.internal_steps == 1);
  CHECK(st.t > 0.0 && st.t < kDt);  // stopped inside the sample, at the time it reached
  CHECK(out.time == st.t);
  CHECK(std::strlen(st.message()) > 10);
  const Status again = plant.step(0.01, out);
  CHECK(again.code == Status::NotReady);
  CHECK(again.t == st.t);
  plant.reset();
  CHECK(plant.time() == 0.0);
  // Stepping again (not NotReady): the same overrun as at first.
  const Status after = plant.step(0.01, out);
  CHECK(after.code == Status::TooMuchWork);
  CHECK(after.t == st.t);
}

void non_finite_command() {
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free}) {
      const double amp = mode == ControlMode::Displacement ? 0.005 : 5e3;
      Plant plant(zhao2003(), mode, kDt), fresh(zhao2003(), mode, kDt);
      Output out, ref;
      for (int k = 0; k < 3; ++k) CHECK(plant.step(amp, out).ok());
      const State before = plant.state();
      const Status st = plant.step(bad, out);
      CHECK(st.code == Status::NonFinite);
      CHECK(st.t == 3 * kDt);         // the time of the sample that got the bad command
      CHECK(plant.state() == before);  // nothing was integrated
      CHECK(std::isfinite(out.displacement) && std::isfinite(out.force));
      CHECK(plant.step(amp, out).code == Status::NotReady);
      CHECK(plant.step(amp, out).code == Status::NotReady);
      CHECK(plant.time() == 3 * kDt);
      plant.reset();
      bool identical = true;
      for (int k = 0; k < 200; ++k) {
        const Status a = plant.step(amp * std::sin(0.05 * k), out);
        const Status b = fresh.step(amp * std::sin(0.05 * k), ref);
        identical = identical && a.ok() && b.ok() && same(out, ref);
      }
      CHECK(identical);  // reset() restores a plant that runs exactly like a new one
    }
  }
}

void divergence_guard() {
  // An absurd ideal force on the free structure: 1e9 N moves it past the
  // 100 m guard in about sqrt(2 * 100 m * 7084 kg / 1e9 N) = 38 ms.
  for (bool rk4 : {false, true}) {
    SolverOptions opt;
    if (rk4) opt.method = SolverOptions::Method::Rk4;
    Plant plant(zhao2003(), ControlMode::Free, kDt, opt);
    Output out;
    Status st;
    int k = 0;
    for (; k < 1000; ++k) {
      st = plant.step(1e9, out);
      if (!st.ok()) break;
    }
    CHECK(st.code == Status::NonFinite);
    CHECK(st.t > 0.030 && st.t < 0.045);
    CHECK(std::fabs(out.displacement) > 100.0);
    CHECK(plant.step(0.0, out).code == Status::NotReady);
  }
}

void step_input_without_restarts() {
  // A sine, then a jump of the held command in mid-motion (a step input):
  // Restart::Never keeps CVODE's history across the jump and must cope with it.
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force}) {
    const double amp = mode == ControlMode::Displacement ? 0.01 : 2e4;
    SolverOptions never;
    never.restart = SolverOptions::Restart::Never;
    Plant plant(zhao2003(), mode, kDt, never), restarting(zhao2003(), mode, kDt);
    Output out, ref;
    Status st;
    int failed_at = -1;
    double worst = 0.0;
    for (int k = 0; k < 2400; ++k) {
      const double t = k * kDt;
      double u = amp * (std::sin(2.0 * kPi * 2.0 * t) + 0.3 * std::sin(2.0 * kPi * 7.0 * t));
      if (k >= 1500 && k < 1700) u = 0.3 * amp;
      if (k >= 2000) u = -1.5 * amp;
      st = plant.step(u, out);
      restarting.step(u, ref);
      if (!st.ok()) {
        failed_at = k;
        break;
      }
      worst = std::fmax(worst, std::fabs(out.displacement - ref.displacement));
    }
    if (!CHECK(failed_at < 0))
      std::fprintf(stderr, "  %s, Restart::Never: status %d (CVODE flag %d) at t = %g s\n", to_string(mode), st.code,
                   st.cvode_flag, st.t);
    // Both integrations are accurate to the tolerances: they agree to 1e-4 of the motion.
    CHECK(worst < 1e-4 * 0.02);
  }
}

void setup_errors() {
  const Rig good = zhao2003();
  for (double dt : {0.0, -5e-4, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const std::string e = error_of([&] { Plant p(good, ControlMode::Displacement, dt); });
    CHECK(contains(e, "invalid dt = "));
  }
  CHECK(contains(error_of([&] { Plant p(good, ControlMode::Force, 0.0); }), "invalid dt = 0"));
  struct Bad {
    double Rig::*field;
    const char* name;
    double value;
  };
  const Bad bads[] = {{&Rig::m, "m", 0.0},        {&Rig::m, "m", -7084.0},
                      {&Rig::A, "A", 0.0},        {&Rig::A, "A", -1e-3},
                      {&Rig::p_s, "p_s", 0.0},    {&Rig::p_s, "p_s", -1.0},
                      {&Rig::K_a, "K_a", 0.0},    {&Rig::k, "k", -1.0},
                      {&Rig::c, "c", -1.0},       {&Rig::F_c, "F_c", -1.0},
                      {&Rig::f_v, "f_v", 0.0},    {&Rig::v_max, "v_max", 0.0}};
  for (const Bad& b : bads) {
    Rig r = good;
    r.*(b.field) = b.value;
    char expect[64];
    std::snprintf(expect, sizeof expect, "invalid %s = %g", b.name, b.value);
    const std::string e = error_of([&] { Plant p(r, ControlMode::Displacement, kDt); });
    if (!CHECK(contains(e, expect))) std::fprintf(stderr, "  expected '%s' in '%s'\n", expect, e.c_str());
  }
  for (double nonfinite : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    for (double Rig::*f : {&Rig::m, &Rig::A, &Rig::p_s}) {
      Rig r = good;
      r.*f = nonfinite;
      const std::string e = error_of([&] { Dynamics d(r, ControlMode::Force); });
      CHECK(contains(e, "invalid ") && (contains(e, "nan") || contains(e, "inf")));
    }
  }
  SolverOptions o;
  o.rtol = 0.0;
  CHECK(contains(error_of([&] { Plant p(good, ControlMode::Displacement, kDt, o); }), "invalid rtol = 0"));
  o = SolverOptions{};
  o.max_steps_per_sample = 0;
  CHECK(contains(error_of([&] { Plant p(good, ControlMode::Displacement, kDt, o); }), "invalid max_steps_per_sample = 0"));
  o = SolverOptions{};
  o.rk4_substeps = -1;
  CHECK(contains(error_of([&] { Plant p(good, ControlMode::Displacement, kDt, o); }), "invalid rk4_substeps = -1"));
  o = SolverOptions{};
  o.rk4_h_rho = 3.0;
  CHECK(contains(error_of([&] { Plant p(good, ControlMode::Displacement, kDt, o); }), "invalid rk4_h_rho = 3"));
  Rig gd = good;
  gd.G_d = 0.01;
  CHECK(contains(error_of([&] { Dynamics d(gd, ControlMode::Force); }), "invalid G_d = 0.01"));
  // The allocating convenience wrapper validates the command first.
  Plant p(good, ControlMode::Displacement, kDt);
  std::vector<double> cmd(10, 0.001);
  cmd[7] = std::numeric_limits<double>::quiet_NaN();
  CHECK(contains(error_of([&] { simulate(p, cmd); }), "invalid command[7] = nan"));
  CHECK(p.time() == 0.0);  // rejected before integration started
}
}  // namespace

int main() {
  overrun();
  non_finite_command();
  divergence_guard();
  step_input_without_restarts();
  setup_errors();
  return sh_test::report("test_status");
}
