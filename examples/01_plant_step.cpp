// A 2 kHz digital controller on the host clock driving the simulated rig: the
// way the plant is embedded in a real-time loop (pairs with
// examples/01_plant_step.py).
//
//   01_plant_step [duration_s = 2] [amplitude_m = 0.01] [frequency_Hz = 1] [cvode|rk4]
//
// Each period: sleep to an absolute deadline (realtime.hpp's Pacer:
// clock_nanosleep, CLOCK_MONOTONIC, TIMER_ABSTIME), read the sensors of the last
// sample, compute the next displacement command (a sine), step the plant one
// sample (0.5 ms of simulated time).  A deadline miss is a step that ends after
// the next deadline.  SCHED_FIFO 80 and mlockall are asked for; the fifo= and
// mlockall= lines say whether the system permitted them.  Prints step-time
// statistics [us] (the Pacer's compute time), misses, the wake-up latency and
// the physical result (peak displacement [mm], peak load-cell force [kN], over
// the whole run and over its second half, after the start-up transient).
// Nothing is allocated inside the loop.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "servohydraulics/plant.hpp"
#include "servohydraulics/realtime.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace sh = servohydraulics;

namespace {
constexpr double kPi = 3.14159265358979323846;
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
  const std::size_t n = static_cast<std::size_t>(std::llround(duration / dt));

  // Setup (may allocate, may throw): the plant, the pacer.
  sh::SolverOptions options;
  if (solver == "rk4") {
    options.method = sh::SolverOptions::Method::Rk4;
    options.rk4_substeps = 2;
  }
  sh::Plant plant(sh::zhao2003(), sh::ControlMode::Displacement, dt, options);
  sh::Output out;
  plant.observe(out);
  // Best effort real-time settings: they need privileges, the loop runs without them.
  sh::realtime::PacerOptions rt;
  rt.fifo_priority = 80;
  rt.lock_memory = true;
  sh::realtime::Pacer pacer(dt, rt);

  long failures = 0;
  double peak_x = 0.0, peak_F = 0.0, max_track = 0.0;
  double steady_x = 0.0, steady_F = 0.0;  // peaks over the second half (start-up transient gone)
  pacer.start();
  for (std::size_t k = 0; k < n; ++k) {
    pacer.wait();  // sleep to deadline k + 1; records the wake-up latency and the previous step's time
    // Controller: sensors of the last sample -> the command held over this one.
    const double t = static_cast<double>(k) * dt;
    const double command = amplitude * std::sin(2.0 * kPi * frequency * t);
    max_track = std::max(max_track, std::fabs(amplitude * std::sin(2.0 * kPi * frequency * (t - dt)) - out.displacement));
    const sh::Status st = plant.step(command, out);
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

  pacer.wait();  // closes the last step's time (and keeps the loop's rhythm)
  pacer.stop();
  const sh::realtime::PacerStats rs = pacer.stats();
  const bool fifo = rs.fifo.granted, locked = rs.mlockall.granted;
  std::printf("servohydraulics controller example: %zu steps at 2 kHz on CLOCK_MONOTONIC (%s, %s, %s)\n", n,
              solver.c_str(), fifo ? "SCHED_FIFO" : "no SCHED_FIFO (needs privileges)",
              locked ? "memory locked" : "memory not locked");
  std::printf("steps=%zu\n", n);
  std::printf("deadline_misses=%lld\n", static_cast<long long>(rs.misses));
  std::printf("solver_failures=%ld\n", failures);
  std::printf("step_us_mean=%.3f\nstep_us_median=%.3f\nstep_us_p99=%.3f\nstep_us_p999=%.3f\nstep_us_max=%.3f\n",
              rs.compute_us.mean, rs.compute_us.p50, rs.compute_us.p99, rs.compute_us.p999, rs.compute_us.max);
  std::printf("wakeup_latency_us_median=%.3f\nwakeup_latency_us_max=%.3f\n", rs.latency_us.p50, rs.latency_us.max);
  std::printf("fifo=%s\nmlockall=%s\n", rs.fifo.reason.c_str(), rs.mlockall.reason.c_str());
  std::printf("simulated_time_s=%.6f\n", plant.time());
  std::printf("peak_displacement_mm=%.4f\n", 1e3 * peak_x);
  std::printf("peak_tracking_error_mm=%.4f\n", 1e3 * max_track);
  std::printf("peak_force_kN=%.4f\n", 1e-3 * peak_F);
  std::printf("steady_peak_displacement_mm=%.4f\n", 1e3 * steady_x);
  std::printf("steady_peak_force_kN=%.4f\n", 1e-3 * steady_F);
  return failures == 0 ? 0 : 1;
}
