// Fault injection into every SUNDIALS setup call (cpp/src/detail/sundials_check.hpp).
//
// For each integrator that makes checked SUNDIALS calls (CVODE today; any method
// whose setup goes through check_flag/check_ptr joins automatically) and each
// control mode: count the checked calls of a normal Plant construction, then
// fail call k = 0, 1, ..., n-1 in turn.  Each must end in an Error that names
// the call, never a crash; what was built must be freed: allocations and frees
// balance (interposed counter), and under scripts/run.sh sanitize LeakSanitizer
// checks the same at exit (a leak fails the run).  After the injections a Plant
// still builds and runs.
#include <cstdio>
#include <string>

#include "alloc_counter.hpp"
#include "check.hpp"
#include "detail/sundials_check.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;

long count_setup_calls(ControlMode mode, const SolverOptions& opt) {
  auto& f = detail::setup_fault();
  f.fail_at = -1;
  f.calls = 0;
  { Plant p(zhao2003(), mode, kDt, opt); }
  return f.calls.load();
}

// Fails call k of a construction; returns true if it threw an Error naming a SUNDIALS call and freed everything.
bool inject(ControlMode mode, const SolverOptions& opt, long k, std::string& what) {
  auto& f = detail::setup_fault();
  what.clear();
  bool threw = false;
  long allocated = 0, freed = 0;
  {
    sh_test::AllocationCounter counter;
    f.calls = 0;
    f.fail_at = k;
    try {
      Plant p(zhao2003(), mode, kDt, opt);
    } catch (const Error& e) {
      threw = true;
      what = e.what();
    }
    f.fail_at = -1;
    allocated = counter.count();
    freed = counter.frees();
  }
  const bool named = what.find("SUNDIALS call") != std::string::npos || what.find("priming step") != std::string::npos;
  CHECK(threw);
  CHECK(named);
  CHECK(allocated == freed);
  if (!threw || !named || allocated != freed)
    std::fprintf(stderr, "  injection %ld: threw %d, %ld allocations, %ld frees: %s\n", k, threw, allocated, freed,
                 what.c_str());
  return threw && named && allocated == freed;
}
}  // namespace

int main() {
  std::string what;
  what.reserve(1024);
  int points = 0, clean = 0, methods = 0;
  // Every method the enum may hold; those without SUNDIALS setup calls (RK4) are skipped.
  for (int m = 0; m < 8; ++m) {
    SolverOptions opt;
    opt.method = static_cast<SolverOptions::Method>(m);
    opt.max_internal_step = 1e-3;  // the optional CVodeSetMaxStep call too
    try {
      opt.validate();
      Plant probe(zhao2003(), ControlMode::Force, kDt, opt);
    } catch (const Error&) {
      continue;  // not a method (or not valid with these options)
    }
    bool any = false;
    for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force}) {
      const long n = count_setup_calls(mode, opt);
      if (n == 0) break;
      any = true;
      for (long k = 0; k < n; ++k) {
        ++points;
        clean += inject(mode, opt, k, what);
      }
      std::printf("method %d, %s control: %ld checked setup calls, each failed in turn (last: %s)\n", m,
                  mode == ControlMode::Force ? "force" : "displacement", n, what.c_str());
    }
    methods += any;
  }
  std::printf("failure injection: %d points over %d method(s), %d clean (Error, no leak)\n", points, methods, clean);
  CHECK(methods >= 1);
  CHECK(points >= 20);
  CHECK(clean == points);
  // Nothing left armed: a Plant builds and steps.
  Plant p(zhao2003(), ControlMode::Displacement, kDt);
  Output o;
  CHECK(p.step(1e-3, o).ok());
  return sh_test::report("test_failure_injection");
}
