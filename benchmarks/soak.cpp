// Soak benchmark of the plant: a long run at the controller rate with every
// step timed, for benchmarks/soak.py (docs/benchmarks.md, "Soak").
//
//   sh_bench_soak --method rk4|cvode|default --minutes M [--dt 0.0005] [--cpu-time 1] --json out.json
//
// The command (displacement control) is a sum of two sines (5 mm at 1 Hz, 2 mm
// at 3.7 Hz) for all but the last simulated minute, then 0: the structure must
// come back to rest where it started.  Per simulated minute: step-time median,
// p99, p99.9 and max [us] of wall time, and with --cpu-time 1 the same of the
// thread's CPU time (the step's cost without the OS preempting it on a shared
// machine, where the wall-time tail is scheduler ticks of 4 ms; the CPU clock is
// a system call of ~0.5 us, so it is for steps much longer than that), the
// resident set size [kB] (from
// /proc/self/statm), failed steps.  At the end: the displacement and velocity
// at rest, the clock against k dt.  The plant is built outside the timed
// region; the per-minute buffer of step times is allocated once.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

namespace sh = servohydraulics;
using Clock = std::chrono::steady_clock;

namespace {
constexpr double kPi = 3.14159265358979323846;

struct Args {
  std::string method = "default", json;
  double minutes = 1.0, dt = 5e-4;
  bool cpu_time = false;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--method") a.method = v;
    else if (k == "--minutes") a.minutes = std::stod(v);
    else if (k == "--dt") a.dt = std::stod(v);
    else if (k == "--json") a.json = v;
    else if (k == "--cpu-time") a.cpu_time = v == "1";
    else throw std::runtime_error("unknown argument " + k);
  }
  if (a.json.empty()) throw std::runtime_error("--json is required");
  return a;
}

long rss_kb() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

double thread_cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e6 * ts.tv_sec + 1e-3 * ts.tv_nsec;
}

double percentile(std::vector<double>& v, double q) {  // v is sorted
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  return v[i];
}
}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  sh::SolverOptions opt;  // "default": whatever the core's default is
  if (a.method == "rk4") opt.method = sh::SolverOptions::Method::Rk4;
  else if (a.method == "cvode") opt.method = sh::SolverOptions::Method::CvodeBdf;
  else if (a.method != "default") throw std::runtime_error("unknown --method " + a.method);
  sh::Plant plant(sh::zhao2003(), sh::ControlMode::Displacement, a.dt, opt);
  plant.reset(0.0, 0.0);
  const long per_minute = std::lround(60.0 / a.dt);
  const long minutes = std::lround(a.minutes);
  const long n = per_minute * minutes;
  std::vector<double> us(static_cast<std::size_t>(per_minute)), cpu(us.size());
  sh::Output out;
  std::ofstream js(a.json);
  js << "{\"method\": \"" << a.method << "\", \"dt\": " << a.dt << ", \"samples\": " << n << ", \"minutes\": [";
  long failed_total = 0;
  const auto wall0 = Clock::now();
  const std::clock_t cpu0 = std::clock();
  for (long m = 0; m < minutes; ++m) {
    long failed = 0;
    for (long j = 0; j < per_minute; ++j) {
      const long k = m * per_minute + j;
      const double t = k * a.dt;
      const double u = m + 1 < minutes ? 5e-3 * std::sin(2 * kPi * 1.0 * t) + 2e-3 * std::sin(2 * kPi * 3.7 * t) : 0.0;
      const double c0 = a.cpu_time ? thread_cpu_us() : 0.0;
      const auto t0 = Clock::now();
      const sh::Status st = plant.step(u, out);
      us[static_cast<std::size_t>(j)] = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
      if (a.cpu_time) cpu[static_cast<std::size_t>(j)] = thread_cpu_us() - c0;
      if (!st.ok()) {
        ++failed;
        plant.reset(out.displacement, plant.time());
      }
    }
    failed_total += failed;
    std::sort(us.begin(), us.end());
    if (a.cpu_time) std::sort(cpu.begin(), cpu.end());
    std::fprintf(stderr, "%s minute %ld: median %.2f us, p99.9 %.2f us, RSS %ld kB\n", a.method.c_str(), m + 1,
                 percentile(us, 0.5), percentile(us, 0.999), rss_kb());
    js << (m ? ", " : "") << "{\"minute\": " << m + 1 << ", \"median_us\": " << percentile(us, 0.5)
       << ", \"p99_us\": " << percentile(us, 0.99) << ", \"p999_us\": " << percentile(us, 0.999)
       << ", \"max_us\": " << us.back();
    if (a.cpu_time)
      js << ", \"cpu_median_us\": " << percentile(cpu, 0.5) << ", \"cpu_p999_us\": " << percentile(cpu, 0.999)
         << ", \"cpu_max_us\": " << cpu.back();
    js << ", \"rss_kb\": " << rss_kb() << ", \"failed\": " << failed << "}";
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
  const double cpu_s = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  plant.observe(out);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "], \"failed\": %ld, \"wall_s\": %.3f, \"cpu_s\": %.3f, \"end_displacement_m\": %.6g, "
                "\"end_velocity_m_s\": %.6g, \"end_time_s\": %.17g, \"clock_error_s\": %.6g}\n",
                failed_total, wall, cpu_s, out.displacement, out.velocity, plant.time(),
                plant.time() - static_cast<double>(n) * a.dt);
  js << buf;
  return failed_total == 0 ? 0 : 1;
}
