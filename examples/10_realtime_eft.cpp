// The paper's effective force test (EFT, force control, Fig 1a) paced to the
// wall clock, one sample per period, measured the way cyclictest measures a
// loop: the wake-up latency, the compute time of each step and the deadline
// misses (realtime.hpp's Pacer).
//
//   10_realtime_eft [rate_Hz = 2000] [seconds = 5] [--fifo PRIO] [--cpu N] [--mlock]
//
// The ground motion is a 0.05 g, 2 Hz sine.  Each period: sleep to the
// absolute deadline (CLOCK_MONOTONIC, TIMER_ABSTIME), then one sample of the
// closed loop (sensors -> EFT controller -> force command -> one sample of the
// plant).  SCHED_FIFO, mlockall and pinning are asked for only when given, and
// each line "fifo=", "mlockall=", "cpu_affinity=" says what the system
// permitted and why not.  Pacing changes when a sample runs, never what it
// computes: the same test run unpaced first (run_eft, as fast as it goes) is
// the oracle, and paced_vs_unpaced_max_diff_m must be 0.
// Nothing is allocated inside the loop.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "servohydraulics/error.hpp"
#include "servohydraulics/loops.hpp"
#include "servohydraulics/realtime.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace sh = servohydraulics;
namespace rt = servohydraulics::realtime;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;  // [m/s^2]

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s [rate_Hz in 100..10000] [seconds > 0] [--fifo 1..99] [--cpu N] [--mlock]\n", argv0);
  return 2;
}

bool parse_number(const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(out);
}

void print_percentiles(const char* name, const sh::realtime::Percentiles& p) {
  std::printf("%s_us_min=%.3f\n%s_us_p50=%.3f\n%s_us_p99=%.3f\n%s_us_p999=%.3f\n%s_us_max=%.3f\n", name, p.min, name,
              p.p50, name, p.p99, name, p.p999, name, p.max);
}
}  // namespace

int main(int argc, char** argv) {
  double rate = 2000.0, seconds = 5.0;
  rt::PacerOptions options;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    double v = 0.0;
    if ((a == "--fifo" || a == "--cpu") && i + 1 < argc && parse_number(argv[i + 1], v) && v == std::floor(v)) {
      (a == "--fifo" ? options.fifo_priority : options.cpu) = static_cast<int>(v);
      ++i;
    } else if (a == "--mlock") {
      options.lock_memory = true;
    } else if (positional < 2 && parse_number(argv[i], v)) {
      (positional++ == 0 ? rate : seconds) = v;
    } else {
      return usage(argv[0]);
    }
  }
  if (!(rate >= 100.0 && rate <= 10000.0) || !(seconds > 0.0) || seconds * rate > 1e8) return usage(argv[0]);

  // Setup (may allocate, may throw): the test, the ground motion, the oracle, the pacer.
  const sh::Rig rig = sh::zhao2003();
  sh::EftConfig cfg;
  cfg.dt = 1.0 / rate;
  const std::size_t n = static_cast<std::size_t>(std::llround(seconds * rate));
  std::vector<double> ag(n);
  for (std::size_t k = 0; k < n; ++k) ag[k] = 0.05 * kG * std::sin(2.0 * kPi * 2.0 * static_cast<double>(k) * cfg.dt);
  std::vector<sh::EftOutput> reference(n);
  std::vector<double> displacement(n);
  try {
    sh::EffectiveForceTest unpaced(rig, cfg);
    const sh::RunSummary ref = sh::run_eft(unpaced, ag.data(), n, reference.data());
    if (!ref.status.ok()) {
      std::fprintf(stderr, "the unpaced reference run failed: %s\n", ref.status.message());
      return 1;
    }
    sh::EffectiveForceTest test(rig, cfg);
    rt::Pacer pacer(cfg.dt, options);

    long failures = 0;
    sh::EftOutput row;
    pacer.start();
    for (std::size_t k = 0; k < n; ++k) {
      pacer.wait();                                    // sleep to deadline k + 1
      if (!test.step(ag[k], row).ok()) ++failures;     // one sample of the closed loop
      displacement[k] = row.plant.displacement;
    }
    pacer.stop();

    double diff = 0.0, peak_x = 0.0, peak_F = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      diff = std::max(diff, std::fabs(displacement[k] - reference[k].plant.displacement));
      peak_x = std::max(peak_x, std::fabs(reference[k].plant.displacement));
      peak_F = std::max(peak_F, std::fabs(reference[k].plant.force));
    }
    const rt::PacerStats s = pacer.stats();
    std::printf("servohydraulics EFT loop paced to CLOCK_MONOTONIC: %zu samples at %g Hz (period %.3f us)\n", n, rate,
                1e6 * cfg.dt);
    std::printf("T: 0 C: %8lld Min: %8.1f Avg: %8.1f P50: %8.1f P99: %8.1f P99.9: %8.1f Max: %8.1f [us]  Misses: %lld\n",
                static_cast<long long>(s.samples), s.latency_us.min, s.latency_us.mean, s.latency_us.p50, s.latency_us.p99,
                s.latency_us.p999, s.latency_us.max, static_cast<long long>(s.misses));
    std::printf("rate_hz=%g\nsamples=%lld\ndeadline_misses=%lld\nsolver_failures=%ld\n", rate,
                static_cast<long long>(s.samples), static_cast<long long>(s.misses), failures);
    print_percentiles("wakeup_latency", s.latency_us);
    print_percentiles("compute", s.compute_us);
    std::printf("fifo=%s\nmlockall=%s\ncpu_affinity=%s\n", s.fifo.reason.c_str(), s.mlockall.reason.c_str(),
                s.cpu_affinity.reason.c_str());
    std::printf("peak_displacement_mm=%.4f\npeak_force_kN=%.4f\n", 1e3 * peak_x, 1e-3 * peak_F);
    std::printf("paced_vs_unpaced_max_diff_m=%.3g\n", diff);
    return failures == 0 && diff == 0.0 ? 0 : 1;
  } catch (const sh::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
