// The controller/plant seam: a Plant and a controller stepped by hand (sensors
// at t_k, then command, then plant step), as a laboratory wires a controller to
// its rig's I/O, reproduce the whole-record runners run_eft / run_rpsd sample
// for sample, bit for bit; and command() never touches the heap.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "servohydraulics/controllers.hpp"
#include "servohydraulics/loops.hpp"
#include "servohydraulics/zhao2003.hpp"

#include "alloc_counter.hpp"  // after the headers that pull in mm_malloc.h (Eigen)
#include "check.hpp"
#include "same_output.hpp"

using namespace servohydraulics;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kN = 3000;  // 1.5 s at 2 kHz

std::vector<double> ground_motion(double amplitude, double f, double dt) {
  std::vector<double> a(kN);
  for (std::size_t k = 0; k < kN; ++k) a[k] = amplitude * std::sin(2 * kPi * f * k * dt) * std::min(1.0, k * dt);
  return a;
}

using sh_test::same;

// Steps the plant by hand, command(k, sensors) at each sample, and counts the
// rows where the sensors or the command differ from the runner's rows.
template <class Row, class Command>
std::size_t mismatches_by_hand(Plant& plant, const std::vector<Row>& rows, Command&& command) {
  plant.reset(0.0, 0.0);
  Output sensors;
  plant.observe(sensors);
  std::size_t mismatches = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double u = command(k, sensors);
    if (!same(sensors, rows[k].plant) || u != rows[k].command) ++mismatches;
    plant.step(u, sensors);
  }
  return mismatches;
}

void eft_seam(VelocityFeedbackCompensator::Kind kind, bool other_model) {
  const Rig rig = zhao2003();
  Rig model = zhao2003();
  if (other_model) model.K_v *= 1.2, model.A *= 0.95, model.m *= 1.1;
  EftConfig cfg;
  cfg.compensation = kind;
  cfg.compute_delay = other_model ? 1 : 0;
  const auto ag = ground_motion(2.0, 1.3, cfg.dt);
  EffectiveForceTest loop(rig, cfg, model);
  std::vector<EftOutput> rows(kN);
  const RunSummary sum = run_eft(loop, ag.data(), kN, rows.data());
  CHECK(sum.status.ok() && sum.rows == kN);

  EftConfig ccfg = cfg;
  ccfg.mass = rig.m;  // the loop's P_eff uses the plant's mass
  EftController ctrl(ccfg, model);
  Plant plant(rig, ControlMode::Force, cfg.dt);
  const std::size_t mismatches =
      mismatches_by_hand(plant, rows, [&](std::size_t k, const Output& s) { return ctrl.command(s, ag[k]); });
  std::printf("EFT seam kind %d, other model %d: %zu mismatches in %zu samples\n", static_cast<int>(kind),
              static_cast<int>(other_model), mismatches, kN);
  CHECK(mismatches == 0);
}

void rpsd_seam(IntegrationScheme scheme, RestoringForce rf, ForceMeasurement fm, double fraction) {
  const Rig rig = zhao2003();
  RpsdConfig cfg;
  cfg.scheme = scheme;
  cfg.restoring_force = rf;
  cfg.force_measurement = fm;
  const auto ag = ground_motion(1.0, 1.1, cfg.dt);
  std::vector<double> pe(kN), fe(kN);
  for (std::size_t k = 0; k < kN; ++k) pe[k] = 2e3 * std::min(1.0, k * cfg.dt), fe[k] = 50.0 * std::cos(0.01 * k);
  RpsdLoopOptions options;
  options.physical_mass_fraction = fraction;
  RealTimePseudoDynamicTest loop(rig, cfg, {}, nullptr, nullptr, options);
  std::vector<RpsdOutput> rows(kN);
  const RunSummary sum = run_rpsd(loop, ag.data(), pe.data(), fe.data(), kN, rows.data());
  CHECK(sum.status.ok() && sum.rows == kN);

  const Rig physical = RealTimePseudoDynamicTest::physical_rig(rig, cfg, options);
  RpsdController ctrl(cfg, physical);
  Plant plant(physical, ControlMode::Displacement, cfg.dt);
  std::size_t solver_mismatches = 0;
  std::size_t mismatches = mismatches_by_hand(plant, rows, [&](std::size_t k, const Output& s) {
    const double u = ctrl.command(s, ag[k], pe[k], fe[k]);
    if (ctrl.integrator_state().displacement != rows[k].calc_displacement) ++solver_mismatches;
    return u;
  });
  mismatches += solver_mismatches;
  std::printf("RPsD seam scheme %d, option %d, force %d, mass fraction %g: %zu mismatches\n",
              static_cast<int>(scheme), static_cast<int>(rf), static_cast<int>(fm), fraction, mismatches);
  CHECK(mismatches == 0);
}

template <class F>
long count_allocations(F&& f) {
  sh_test::AllocationCounter counter;
  f();
  return counter.count();
}

// command() with and without the out-parameter, reset(): no heap.
void commands_do_not_allocate() {
  const Rig rig = zhao2003();
  Output s;
  s.velocity = 0.01, s.force = 500.0, s.pressure = 2e6, s.displacement = 1e-3, s.acceleration = 0.1;
  for (auto kind : {VelocityFeedbackCompensator::Kind::Linear, VelocityFeedbackCompensator::Kind::Nonlinear}) {
    EftConfig cfg;
    cfg.compensation = kind;
    cfg.compute_delay = 2;
    EftController ctrl(cfg, rig);
    EftOutput out;
    double sink = 0.0;
    const long n = count_allocations([&] {
      for (int k = 0; k < 1000; ++k) sink += ctrl.command(s, 0.1 * k, (k % 2) ? &out : nullptr);
      ctrl.reset();
    });
    CHECK(n == 0);
    CHECK(std::isfinite(sink));
  }
  for (auto scheme : {IntegrationScheme::CentralDifference, IntegrationScheme::ExplicitNewmark}) {
    for (auto rf : {RestoringForce::CalculatedDisplacement, RestoringForce::MeasuredDisplacement,
                    RestoringForce::MeasuredForce, RestoringForce::MeasuredForceCorrected}) {
      RpsdConfig cfg;
      cfg.scheme = scheme;
      cfg.restoring_force = rf;
      cfg.compute_delay = 1;
      RpsdController ctrl(cfg, rig);
      RpsdOutput out;
      double sink = 0.0;
      const long n = count_allocations([&] {
        for (int k = 0; k < 1000; ++k) sink += ctrl.command(s, 0.01, 10.0, 0.0, (k % 2) ? &out : nullptr);
        ctrl.reset();
      });
      CHECK(n == 0);
      CHECK(std::isfinite(sink));
    }
  }
}

// The optional defaults resolve from the rig the controller is given.
void defaults_come_from_the_physical_rig() {
  Rig r = zhao2003();
  r.m = 140.0, r.c = 900.0, r.k = 6e5;
  RpsdConfig cfg;
  cfg.force_measurement = ForceMeasurement::ActuatorPressure;
  RpsdController a(cfg, r);
  CHECK(a.k_m() == 6e5 && a.subtract_mass() == 140.0 + r.m_p && a.subtract_damping() == 900.0);
  cfg.k_m = 0.0, cfg.subtract_mass = 7084.0, cfg.subtract_damping = 0.0;
  RpsdController b(cfg, r);
  CHECK(b.k_m() == 0.0 && b.subtract_mass() == 7084.0 && b.subtract_damping() == 0.0);
  EftConfig ec;
  CHECK(EftController(ec, r).mass() == 140.0);
  ec.mass = 500.0;
  CHECK(EftController(ec, r).mass() == 500.0);
  ec.mass = -1.0;
  bool threw = false;
  try {
    EftController bad(ec, r);
  } catch (const Error& e) {
    threw = std::string(e.what()).find("mass = -1") != std::string::npos;
  }
  CHECK(threw);
}
}  // namespace

int main() {
  eft_seam(VelocityFeedbackCompensator::Kind::Linear, false);
  eft_seam(VelocityFeedbackCompensator::Kind::Nonlinear, false);
  eft_seam(VelocityFeedbackCompensator::Kind::Linear, true);
  eft_seam(VelocityFeedbackCompensator::Kind::Nonlinear, true);
  for (auto scheme : {IntegrationScheme::CentralDifference, IntegrationScheme::ExplicitNewmark})
    for (auto rf : {RestoringForce::CalculatedDisplacement, RestoringForce::MeasuredDisplacement,
                    RestoringForce::MeasuredForce, RestoringForce::MeasuredForceCorrected})
      rpsd_seam(scheme, rf, ForceMeasurement::LoadCell, 1.0);
  rpsd_seam(IntegrationScheme::ExplicitNewmark, RestoringForce::MeasuredForceCorrected,
            ForceMeasurement::ActuatorPressure, 0.02);
  commands_do_not_allocate();
  defaults_come_from_the_physical_rig();
  return sh_test::report("test_seam");
}
