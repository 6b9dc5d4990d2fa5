// The real-time promise: Plant::step, reset, observe and run_record allocate
// nothing, in every control mode, with the default Dormand-Prince pair (and its
// CVODE fallback on a stiff rig), CVODE (restarting at every input change or
// never), RK4 (with refinement), ARKODE ERK and DIRK, on success and on the
// failure paths.  Allocations are
// counted by interposing malloc & co. and operator new (alloc_counter.hpp), so
// C allocations inside SUNDIALS count too; the first block of main checks that
// the counter really sees both kinds.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "alloc_counter.hpp"
#include "check.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"
#include "servohydraulics/record.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;
constexpr double kPi = 3.14159265358979323846;

// A command that changes every sample (every CVODE step restarts with
// OnInputChange), with a hold and a jump: [m] or [N] by mode.
double command(ControlMode mode, int k) {
  const double t = k * kDt;
  const double amp = mode == ControlMode::Displacement ? 0.01 : 2e4;
  if (k >= 1500 && k < 1700) return 0.3 * amp;  // held: no restart with OnInputChange
  return amp * (std::sin(2.0 * kPi * 2.0 * t) + 0.3 * std::sin(2.0 * kPi * 7.0 * t));
}

const char* method_name(const SolverOptions& o) {
  switch (o.method) {
    case SolverOptions::Method::Rk4: return "rk4";
    case SolverOptions::Method::Dopri5: return "dopri5";
    case SolverOptions::Method::ArkodeErk: return "arkode-erk";
    case SolverOptions::Method::ArkodeDirk: return "arkode-dirk";
    case SolverOptions::Method::Ros2: return "ros2";
    case SolverOptions::Method::CvodeBdf: break;
  }
  return o.restart == SolverOptions::Restart::Never ? "cvode/never" : "cvode/on-input-change";
}

void check_plant(ControlMode mode, const SolverOptions& opt, const Rig& rig = zhao2003()) {
  Plant plant(rig, mode, kDt, opt);
  const int n = 3000;
  // run_record's destinations are allocated before counting.
  std::vector<double> cmd(n);
  std::vector<std::vector<double>> columns(kNumPlantChannels, std::vector<double>(n));
  std::vector<std::uint32_t> flags(n);
  std::vector<int> steps(n), rhs(n);
  for (int k = 0; k < n; ++k) cmd[k] = command(mode, k);
  Channels ch;
  for (std::size_t i = 0; i < kNumPlantChannels; ++i) ch.channel[i] = columns[i].data();
  ch.flags = flags.data();
  ch.internal_steps = steps.data();
  ch.rhs_evals = rhs.data();

  Output out;
  int failed = 0;
  long restarts = 0;
  long allocations, frees;
  {
    sh_test::AllocationCounter counter;
    for (int k = 0; k < n; ++k) {
      const Status st = plant.step(cmd[k], out);
      failed += !st.ok();
      restarts += st.restarted;
    }
    plant.observe(out);
    plant.reset(0.005, 1.0);  // restart mid-run from another equilibrium
    for (int k = 0; k < 500; ++k) failed += !plant.step(cmd[k], out).ok();
    State y = plant.state();
    plant.reset_state(y, plant.time());
    const RunSummary sum = run_record(plant, cmd.data(), cmd.size(), ch);
    failed += !sum.status.ok();
    restarts += sum.restarts;
    // Failure paths: a NaN command, then a step while failed, then reset.
    failed += plant.step(std::nan(""), out).code != Status::NonFinite;
    failed += plant.step(0.0, out).code != Status::NotReady;
    plant.reset();
    failed += !plant.step(cmd[1], out).ok();
    allocations = counter.count();
    frees = counter.frees();
  }
  std::printf("%-13s %-22s %5d samples: %ld allocations, %ld frees, %ld restarts%s\n", to_string(mode),
              method_name(opt), 2 * n + 502, allocations, frees, restarts, rig.m < 100.0 ? " (stiff rig)" : "");
  CHECK(failed == 0);
  CHECK(allocations == 0);
  CHECK(frees == 0);
  if (opt.method == SolverOptions::Method::CvodeBdf && opt.restart == SolverOptions::Restart::OnInputChange)
    CHECK(restarts > n);  // the restart path was exercised
}

// An overrun (CVODE's too-much-work return) must not allocate either, e.g. for
// an error message.
void check_overrun(SolverOptions::Method method) {
  SolverOptions opt;
  opt.method = method;
  opt.max_steps_per_sample = 1;
  Plant plant(zhao2003(), ControlMode::Displacement, kDt, opt);
  Output out;
  Status st, st2;
  long allocations;
  {
    sh_test::AllocationCounter counter;
    st = plant.step(0.01, out);
    st2 = plant.step(0.01, out);
    allocations = counter.count();
  }
  CHECK(st.code == Status::TooMuchWork);
  CHECK(st2.code == Status::NotReady);
  CHECK(allocations == 0);
}
}  // namespace

int main() {
  // The counter must see C++ and C allocations, including those made inside
  // SUNDIALS (CVodeCreate, N_VNew_Serial, ...).
  if (sh_test::kCountingAllocations) {
    sh_test::AllocationCounter counter;
    std::vector<double>* v = new std::vector<double>(16);
    delete v;
    CHECK(counter.count() == 2);
    CHECK(counter.frees() == 2);
    void* (*volatile cmalloc)(std::size_t) = &std::malloc;
    void* p = cmalloc(32);
    std::free(p);
    CHECK(counter.count() == 3);
  }
  long rk4_construct, cvode_construct;
  {
    SolverOptions rk4;
    rk4.method = SolverOptions::Method::Rk4;
    sh_test::AllocationCounter counter;
    { Plant p(zhao2003(), ControlMode::Force, kDt, rk4); }
    rk4_construct = counter.count();
    counter.restart();
    SolverOptions cv;
    cv.method = SolverOptions::Method::CvodeBdf;
    { Plant p(zhao2003(), ControlMode::Force, kDt, cv); }
    cvode_construct = counter.count();
  }
  std::printf("construction: %ld allocations with RK4, %ld with CVODE (SUNDIALS' own mallocs are seen)\n",
              rk4_construct, cvode_construct);
  if (sh_test::kCountingAllocations) {
    CHECK(rk4_construct >= 1);
    CHECK(cvode_construct >= rk4_construct + 5);
  }

  SolverOptions dopri5;
  SolverOptions cvode;
  cvode.method = SolverOptions::Method::CvodeBdf;
  SolverOptions never = cvode;
  never.restart = SolverOptions::Restart::Never;
  SolverOptions rk4;
  rk4.method = SolverOptions::Method::Rk4;
  rk4.rk4_max_refinements = 3;
  SolverOptions erk, dirk;
  erk.method = SolverOptions::Method::ArkodeErk;
  dirk.method = SolverOptions::Method::ArkodeDirk;
  SolverOptions ros2;
  ros2.method = SolverOptions::Method::Ros2;
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free})
    for (const SolverOptions* o : {&dopri5, &cvode, &never, &rk4, &erk, &dirk, &ros2}) check_plant(mode, *o);
  // A small installed mass with sharp friction: the pair turns stiff and CVODE takes those samples.
  Rig light = zhao2003();
  light.m = 2.0;
  light.m_p = 1.0;
  light.v_stick = 1e-6;
  check_plant(ControlMode::Displacement, dopri5, light);
  SolverOptions dopri5_rosenbrock;  // the stiff samples by the error-controlled Rosenbrock: fixed-capacity LU
  dopri5_rosenbrock.stiff_rosenbrock = true;
  check_plant(ControlMode::Displacement, dopri5_rosenbrock, light);
  SolverOptions dopri5_rodas4 = dopri5_rosenbrock;  // RODAS4's six stages, found stiff by Hairer's test as well
  dopri5_rodas4.rosenbrock_order = 4;
  dopri5_rodas4.stiffness_test = true;
  check_plant(ControlMode::Displacement, dopri5_rodas4, light);
  check_plant(ControlMode::Displacement, ros2, light);  // the LU of the stiff matrix: fixed capacity
  // The exact Coulomb law: stretches, located switches and re-integrations, every method.
  Rig exact = zhao2003();
  exact.effects.coulomb_friction = true;
  exact.F_c = 3000.0;
  exact.v_stick = 0.0;
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Free})
    for (const SolverOptions* o : {&dopri5, &cvode, &rk4, &erk, &dirk, &ros2}) check_plant(mode, *o, exact);
  for (auto m : {SolverOptions::Method::CvodeBdf, SolverOptions::Method::Dopri5, SolverOptions::Method::ArkodeErk})
    check_overrun(m);
  return sh_test::report("test_allocations");
}
