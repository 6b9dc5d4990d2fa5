// Determinism: two plants given the same inputs produce bit-identical outputs;
// a whole-record run (run_record) equals the same samples stepped one by one;
// reset() replays a run bit for bit.  CVODE (both restart policies) and RK4,
// every control mode, with a command that holds, jumps and varies.  The clock
// does not drift: after an hour of 2 kHz samples it reads t0 + k dt (an
// accumulated t += dt read 3600.000000504 s).
#include <cmath>
#include <cstdio>
#include <vector>

#include "check.hpp"
#include "same_output.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"
#include "servohydraulics/record.hpp"

using namespace servohydraulics;

namespace {
constexpr double kDt = 5e-4;
constexpr int kN = 2000;

using sh_test::same;

std::vector<double> command(ControlMode mode) {
  const double amp = mode == ControlMode::Displacement ? 0.02 : 3e4;
  std::vector<double> u(kN);
  for (int k = 0; k < kN; ++k) {
    const double t = k * kDt;
    u[k] = amp * std::sin(2.0 * 3.14159265358979323846 * 3.0 * t) * (k % 400 < 300 ? 1.0 : 0.0);
  }
  return u;
}
}  // namespace

// One hour at 2 kHz (7.2 million samples) of the structure alone, RK4 with one substep.
void check_clock() {
  Rig rig = zhao2003();
  rig.effects.coulomb_friction = false;
  SolverOptions rk4;
  rk4.method = SolverOptions::Method::Rk4;
  Plant plant(rig, ControlMode::Free, kDt, rk4);
  const double t0 = 10.0;
  plant.reset(0.001, t0);
  const long n = 7200000;
  Output o;
  bool ok = true;
  for (long k = 0; k < n; ++k) ok = plant.step(0.0, o).ok() && ok;
  CHECK(ok);
  CHECK(plant.time() == t0 + static_cast<double>(n) * kDt);
  CHECK(o.time == plant.time());
  CHECK_NEAR(plant.time(), t0 + 3600.0, 1e-10);
  std::printf("clock after %ld samples: %.12f s\n", n, plant.time() - t0);
}

int main() {
  check_clock();
  SolverOptions cvode, never, rk4;
  never.restart = SolverOptions::Restart::Never;
  rk4.method = SolverOptions::Method::Rk4;
  for (ControlMode mode : {ControlMode::Displacement, ControlMode::Force, ControlMode::Free}) {
    for (const SolverOptions* opt : {&cvode, &never, &rk4}) {
      const std::vector<double> u = command(mode);
      Plant a(zhao2003(), mode, kDt, *opt), b(zhao2003(), mode, kDt, *opt);
      std::vector<Output> first(kN);
      bool identical = true, ok = true;
      for (int k = 0; k < kN; ++k) {
        Output ob;
        const Status sa = a.step(u[k], first[k]);
        const Status sb = b.step(u[k], ob);
        ok = ok && sa.ok() && sb.ok();
        identical = identical && same(first[k], ob) && sa.internal_steps == sb.internal_steps;
      }
      CHECK(ok);
      CHECK(identical);
      CHECK(a.total_internal_steps() == b.total_internal_steps());
      CHECK(a.total_rhs_evals() == b.total_rhs_evals());

      // reset() replays the same run.
      a.reset();
      bool replay = true;
      for (int k = 0; k < kN; ++k) {
        Output o;
        replay = replay && a.step(u[k], o).ok() && same(o, first[k]);
      }
      CHECK(replay);

      // run_record: row k is the state before command[k] (row 0 the initial state).
      Plant c(zhao2003(), mode, kDt, *opt);
      std::vector<double> x(kN), f(kN), t(kN);
      Channels ch;
      ch[Channel::Displacement] = x.data();
      ch[Channel::Force] = f.data();
      ch[Channel::Time] = t.data();
      const RunSummary sum = run_record(c, u.data(), kN, ch);
      CHECK(sum.status.ok());
      CHECK(sum.rows == static_cast<std::size_t>(kN));
      bool rows = true;
      for (int k = 1; k < kN; ++k)
        rows = rows && x[k] == first[k - 1].displacement && f[k] == first[k - 1].force && t[k] == first[k - 1].time;
      CHECK(rows);
      CHECK(t[0] == 0.0 && x[0] == 0.0);
    }
  }
  return sh_test::report("test_determinism");
}
