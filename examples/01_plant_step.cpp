// A 2 kHz digital controller on the host clock driving the simulated rig: the
// way the plant is embedded in a real-time loop (pairs with
// examples/01_plant_step.py).
//
//   01_plant_step [duration_s = 2] [amplitude_m = 0.01] [frequency_Hz = 1] [cvode|rk4]
//
// Each period: sleep to an absolute deadline (clock_nanosleep, CLOCK_MONOTONIC,
// TIMER_ABSTIME), read the sensors of the last sample, compute the next
// displacement command (a sine), step the plant one sample (0.5 ms of
// simulated time).  A deadline miss is a step that ends after the next
// deadline.  Prints step-time statistics [us], misses, the wake-up latency and
// the physical result (peak displacement [mm], peak load-cell force [kN], over
// the whole run and over its second half, after the start-up transient).
// Nothing is allocated inside the loop.
#include <sys/mman.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "realtime_clock.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace sh = servohydraulics;

namespace {
using examples::add_ns;
using examples::kNsPerS;
using examples::seconds;
constexpr double kPi = 3.14159265358979323846;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, i == 0 ? 0 : i - 1)];
}
}  // namespace

int main(int argc, char** argv) {
  const double duration = argc > 1 ? std::atof(argv[1]) : 2.0;      // [s]
  const double amplitude = argc > 2 ? std::atof(argv[2]) : 0.01;    // [m]
  const double frequency = argc > 3 ? std::atof(argv[3]) : 1.0;     // [Hz]
  const std::string solver = argc > 4 ? argv[4] : "cvode";
  if (!(duration > 0.0) || !std::isfinite(amplitude) || !(frequency > 0.0) || (solver != "cvode" && solver != "rk4")) {
    std::fprintf(stderr, "usage: %s [duration_s > 0] [amplitude_m] [frequency_Hz > 0] [cvode|rk4]\n", argv[0]);
    return 2;
  }
  const double dt = 5e-4;  // [s] 2 kHz, the paper's DSP
  const long period_ns = 500000;
  const std::size_t n = static_cast<std::size_t>(std::llround(duration / dt));

  // Setup (may allocate, may throw): the plant, the statistics buffers.
  sh::SolverOptions options;
  if (solver == "rk4") {
    options.method = sh::SolverOptions::Method::Rk4;
    options.rk4_substeps = 2;
  }
  sh::Plant plant(sh::zhao2003(), sh::ControlMode::Displacement, dt, options);
  std::vector<double> step_us(n), wake_us(n);
  sh::Output out;
  plant.observe(out);

  // Best effort real-time settings: they need privileges, the loop runs without them.
  const bool locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  sched_param sp{};
  sp.sched_priority = 80;
  const bool fifo = sched_setscheduler(0, SCHED_FIFO, &sp) == 0;

  long misses = 0, failures = 0;
  double peak_x = 0.0, peak_F = 0.0, max_track = 0.0;
  double steady_x = 0.0, steady_F = 0.0;  // peaks over the second half (start-up transient gone)
  timespec next{}, now{}, done{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (std::size_t k = 0; k < n; ++k) {
    add_ns(next, period_ns);
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    clock_gettime(CLOCK_MONOTONIC, &now);
    wake_us[k] = 1e6 * (seconds(now) - seconds(next));
    // Controller: sensors of the last sample -> the command held over this one.
    const double t = static_cast<double>(k) * dt;
    const double command = amplitude * std::sin(2.0 * kPi * frequency * t);
    max_track = std::max(max_track, std::fabs(amplitude * std::sin(2.0 * kPi * frequency * (t - dt)) - out.displacement));
    const sh::Status st = plant.step(command, out);
    clock_gettime(CLOCK_MONOTONIC, &done);
    step_us[k] = 1e6 * (seconds(done) - seconds(now));
    if (seconds(done) > seconds(next) + 1e-9 * period_ns) ++misses;
    if (!st.ok()) {
      ++failures;
      plant.reset_state(plant.state(), plant.time());
    }
    peak_x = std::max(peak_x, std::fabs(out.displacement));
    peak_F = std::max(peak_F, std::fabs(out.force));
    if (2 * k >= n) {
      steady_x = std::max(steady_x, std::fabs(out.displacement));
      steady_F = std::max(steady_F, std::fabs(out.force));
    }
  }

  double mean = 0.0;
  for (double s : step_us) mean += s / static_cast<double>(n);
  std::printf("servohydraulics controller example: %zu steps at 2 kHz on CLOCK_MONOTONIC (%s, %s, %s)\n", n,
              solver.c_str(), fifo ? "SCHED_FIFO" : "no SCHED_FIFO (needs privileges)",
              locked ? "memory locked" : "memory not locked");
  std::printf("steps=%zu\n", n);
  std::printf("deadline_misses=%ld\n", misses);
  std::printf("solver_failures=%ld\n", failures);
  std::printf("step_us_mean=%.3f\nstep_us_median=%.3f\nstep_us_p99=%.3f\nstep_us_p999=%.3f\nstep_us_max=%.3f\n", mean,
              percentile(step_us, 0.5), percentile(step_us, 0.99), percentile(step_us, 0.999),
              *std::max_element(step_us.begin(), step_us.end()));
  std::printf("wakeup_latency_us_median=%.3f\nwakeup_latency_us_max=%.3f\n", percentile(wake_us, 0.5),
              *std::max_element(wake_us.begin(), wake_us.end()));
  std::printf("simulated_time_s=%.6f\n", plant.time());
  std::printf("peak_displacement_mm=%.4f\n", 1e3 * peak_x);
  std::printf("peak_tracking_error_mm=%.4f\n", 1e3 * max_track);
  std::printf("peak_force_kN=%.4f\n", 1e-3 * peak_F);
  std::printf("steady_peak_displacement_mm=%.4f\n", 1e3 * steady_x);
  std::printf("steady_peak_force_kN=%.4f\n", 1e-3 * steady_F);
  return failures == 0 ? 0 : 1;
}
