// Hostile random rigs through the C++ API (fixed seed; scripts/run.sh sanitize
// runs this under ASan + UBSan, where a memory error or undefined behaviour
// fails it).  Each draw scales 1-4 parameters of the preset by 1e-4..1e4 or sets
// them to 0, a negative, NaN or inf, toggles effects, and picks a mode, an
// integrator and a command (sine, step, noise, 1e300, NaN).  Contract: the Plant
// is refused with an Error naming a field ("invalid <field> = ...") or a setup
// step, or it steps: every step returns ok with finite outputs, or a failure
// code (and then NotReady until reset), never a non-finite output with ok.
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "check.hpp"
#include "randomizer.hpp"
#include "servohydraulics/parameters.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;
constexpr int kSteps = 200;

struct Counts {
  int refused = 0, ran_ok = 0, failed = 0;
};

Rig random_rig(sh_test::Randomizer& r) {
  Rig rig = zhao2003();
  constexpr std::size_t n = sizeof(kRigParameters) / sizeof(kRigParameters[0]);
  const int changes = 1 + static_cast<int>(r.bits() % 4);
  for (int i = 0; i < changes; ++i) {
    const ParameterInfo& p = kRigParameters[r.bits() % n];
    double& v = rig.*p.member;
    switch (r.bits() % 12) {
      case 0: v = 0.0; break;
      case 1: v = -r.uniform(1e-3, 1e3); break;
      case 2: v = std::numeric_limits<double>::quiet_NaN(); break;
      case 3: v = std::numeric_limits<double>::infinity(); break;
      default: v = (v != 0.0 ? v : 1.0) * std::pow(10.0, r.uniform(-4.0, 4.0)); break;
    }
  }
  rig.effects.coulomb_friction = r.coin();
  rig.effects.lugre_friction = r.coin() && r.coin();
  rig.effects.load_pressure = r.bits() % 4 != 0;
  rig.effects.servovalve_dynamics = r.bits() % 4 != 0;
  return rig;
}

double command(int shape, ControlMode mode, int k, sh_test::Randomizer& r) {
  const double scale = mode == ControlMode::Force ? 5e4 : mode == ControlMode::Free ? 1e3 : 5e-3;
  switch (shape) {
    case 0: return scale * std::sin(2 * 3.141592653589793 * 5.0 * k * kDt);
    case 1: return k > 20 ? scale : 0.0;
    case 2: return scale * r.uniform(-1.0, 1.0);
    case 3: return 1e300;
    default: return k == 50 ? std::numeric_limits<double>::quiet_NaN() : 0.0;
  }
}

bool finite(const Output& o) {
  return std::isfinite(o.displacement) && std::isfinite(o.velocity) && std::isfinite(o.force) &&
         std::isfinite(o.pressure) && std::isfinite(o.spool) && std::isfinite(o.flow);
}

void one(sh_test::Randomizer& r, Counts& c) {
  const Rig rig = random_rig(r);
  const ControlMode mode = static_cast<ControlMode>(r.bits() % 3);
  SolverOptions opt;
  opt.method = r.coin() ? SolverOptions::Method::Rk4 : SolverOptions::Method::CvodeBdf;
  const int shape = static_cast<int>(r.bits() % 5);
  try {
    Plant plant(rig, mode, kDt, opt);
    plant.reset(0.0, 0.0);
    Output out;
    bool failed = false;
    for (int k = 0; k < kSteps; ++k) {
      const Status st = plant.step(command(shape, mode, k, r), out);
      if (failed) {
        CHECK(st.code == Status::NotReady);
        continue;
      }
      if (st.ok()) {
        CHECK(finite(out));
      } else {
        CHECK(std::string(st.message()).size() > 0);
        failed = true;
      }
    }
    ++(failed ? c.failed : c.ran_ok);
  } catch (const Error& e) {
    const std::string w = e.what();
    CHECK(w.rfind("invalid ", 0) == 0 || w.find("setup") != std::string::npos || w.find("substep") != std::string::npos);
    if (!(w.rfind("invalid ", 0) == 0 || w.find("setup") != std::string::npos || w.find("substep") != std::string::npos))
      std::fprintf(stderr, "  unnamed error: %s\n", w.c_str());
    ++c.refused;
  }
}
}  // namespace

int main() {
  sh_test::Randomizer r(16);
  Counts c;
  const int draws = 1000;
  for (int i = 0; i < draws; ++i) one(r, c);
  std::printf("%d random rigs: %d refused with a named error, %d ran ok, %d ended in a failure status\n", draws,
              c.refused, c.ran_ok, c.failed);
  CHECK(c.refused + c.ran_ok + c.failed == draws);
  CHECK(c.ran_ok > draws / 5);  // the draw is not all hostile
  return sh_test::report("test_random_rigs");
}
