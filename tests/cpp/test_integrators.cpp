// The internal integrators (cpp/src/detail): resource ownership and the RK4 rule.
//
// 1. A CvodeIntegrator whose constructor throws after every SUNDIALS object
//    exists (the priming step fails from a non-finite state) frees all it made:
//    allocations and frees balance (interposed counter, alloc_counter.hpp,
//    which sees SUNDIALS' C allocations).  A normal construct/destroy balances
//    too, and the counter sees the SUNDIALS objects being made; so does a Plant
//    whose RK4 integrator throws (too stiff for the automatic rule).
// 2. The automatic RK4 rule is one function: the Plant, the Rk4Integrator and
//    rk4_automatic_substeps agree; rk4_v_ref = 0 is the no-load actuator speed.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "alloc_counter.hpp"
#include "check.hpp"
#include "detail/cvode_integrator.hpp"
#include "detail/rk4_integrator.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;

void check_no_leak_on_throw() {
  const Dynamics dyn(zhao2003(), ControlMode::Displacement);
  State bad = dyn.equilibrium(0.0);
  bad[kX] = std::numeric_limits<double>::quiet_NaN();
  long allocated = 0, freed = 0;
  bool threw = false;
  std::string what;
  what.reserve(512);  // the message is copied inside the counted scope: no allocation of ours there
  {
    sh_test::AllocationCounter counter;
    try {
      detail::CvodeIntegrator integ(dyn, kDt, SolverOptions{}, bad);
    } catch (const Error& e) {
      threw = true;
      what = e.what();
    }
    allocated = counter.count();
    freed = counter.frees();
  }
  CHECK(threw);
  CHECK(what.find("priming step") != std::string::npos);  // thrown after every SUNDIALS object existed
  CHECK(allocated >= 6 || !sh_test::kCountingAllocations);  // context, 2 vectors, matrix, solver, CVODE memory
  CHECK(allocated == freed);
  std::printf("throwing constructor: %ld allocations, %ld frees (%s)\n", allocated, freed, what.c_str());
}

void check_no_leak_on_success() {
  const Dynamics dyn(zhao2003(), ControlMode::Force);
  long allocated = 0, freed = 0;
  {
    sh_test::AllocationCounter counter;
    {
      auto integ = std::make_unique<detail::CvodeIntegrator>(dyn, kDt, SolverOptions{}, dyn.equilibrium(0.0));
      integ->reset(dyn.equilibrium(0.0), 0.0);
      State y = dyn.equilibrium(0.0);
      double t = 0.0;
      const Status st = integ->advance(dyn, {1e3, 0.0}, y, t, kDt);
      CHECK(st.ok() && st.restarted && t == kDt);
    }
    allocated = counter.count();
    freed = counter.frees();
  }
  CHECK(allocated >= 6 || !sh_test::kCountingAllocations);
  CHECK(allocated == freed);
  // A Plant whose RK4 integrator refuses the rig (too many automatic substeps) frees the rest.
  {
    SolverOptions stiff;
    stiff.method = SolverOptions::Method::Rk4;
    stiff.rk4_h_rho = 1e-6;
    bool threw = false;
    sh_test::AllocationCounter counter;
    try {
      Plant p(zhao2003(), ControlMode::Displacement, kDt, stiff);
    } catch (const Error&) {
      threw = true;
    }
    CHECK(threw);
    CHECK((counter.count() > 0 || !sh_test::kCountingAllocations) && counter.count() == counter.frees());
  }
  // A whole Plant, CVODE and RK4, balances as well.
  for (auto method : {SolverOptions::Method::CvodeBdf, SolverOptions::Method::Rk4}) {
    SolverOptions opt;
    opt.method = method;
    sh_test::AllocationCounter counter;
    { Plant p(zhao2003(), ControlMode::Displacement, kDt, opt); }
    CHECK(counter.count() == counter.frees());
  }
}

void check_rk4_rule() {
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free}) {
    for (bool lugre : {false, true}) {
      Rig rig = zhao2003();
      rig.effects.lugre_friction = lugre;
      SolverOptions opt;
      opt.method = SolverOptions::Method::Rk4;
      const Plant plant(rig, mode, kDt, opt);
      const int n = rk4_automatic_substeps(plant.dynamics(), kDt, opt);
      CHECK(n >= 1);
      CHECK(plant.rk4_substeps() == n);
      CHECK(plant.options().rk4_substeps == n);
      CHECK(detail::Rk4Integrator(plant.dynamics(), kDt, opt).substeps() == n);
      // v_ref: 0 means the no-load actuator speed K_v g(x_v_max) / A (1 m/s in free mode).
      const Dynamics& d = plant.dynamics();
      SolverOptions given = opt;
      given.rk4_v_ref =
          mode == ControlMode::Free ? 1.0 : rig.K_v * d.flow_gain(std::fmin(rig.x_v_max, 1.0)) / rig.A;
      CHECK(rk4_automatic_substeps(d, kDt, given) == n);
      given.rk4_v_ref = 50.0;  // a faster slide: the bristles are stiffer, more substeps (LuGre only)
      const int n_fast = rk4_automatic_substeps(d, kDt, given);
      CHECK(lugre ? n_fast > n : n_fast == n);
      // Half the sample, at most as many substeps.
      CHECK(rk4_automatic_substeps(d, kDt / 2, opt) <= n);
    }
  }
  SolverOptions bad;
  bad.rk4_v_ref = -1.0;
  bool threw = false;
  try {
    rk4_automatic_substeps(Dynamics(zhao2003(), ControlMode::Free), kDt, bad);
  } catch (const Error& e) {
    threw = std::string(e.what()).find("rk4_v_ref = -1") != std::string::npos;
  }
  CHECK(threw);
}
}  // namespace

int main() {
  check_no_leak_on_throw();
  check_no_leak_on_success();
  check_rk4_rule();
  return sh_test::report("test_integrators");
}
