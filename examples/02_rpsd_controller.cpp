// Real-time pseudodynamic testing as a laboratory runs it: the RPsD controller
// (controllers.hpp) on a 2 kHz loop, wired to the rig's I/O -- read the
// sensors, compute the command, write the command -- with the simulated plant
// standing in for the rig (pairs with examples/02_rpsd_controller.py).
//
//   02_rpsd_controller [ramp_s = 2] [hold_s = 1] [free_s = 2]
//
// The test is Fig 9's: an external force ramps (half cosine) to 1.6 % of k x 1 m
// into the solver of Eq (15), is held, then released; the modelled structure
// (m_m = 7084 kg, c_m = 3.5 kN s/m, k = the rig's) vibrates freely.  Restoring
// force option (b), k_m times the measured displacement, with the delay
// compensation T_ld = 11.2 ms and the amplitude compensation T_d = 68 ms.
// Prints the loop's timing and the physics against its oracles: the held
// displacement P/k, the free-vibration frequency of the modelled system.
// Nothing is allocated inside the loop.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "servohydraulics/controllers.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/realtime.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace sh = servohydraulics;

namespace {
constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------
// The rig's I/O: THE PLACE A REAL RIG'S I/O GOES.  Here the simulated plant
// stands in.  On a real rig, read() samples the ADCs (LVDT displacement, load
// cell, differential pressure, accelerometer; velocity from a differentiator or
// a tachometer) into an sh::Output in SI units, and write() sends the
// displacement command [m] to the servo controller's DAC (x C_F_disp [V/m]);
// the hardware then moves during the sample.
// ---------------------------------------------------------------------------
class RigIo {
 public:
  RigIo(const sh::Rig& rig, double dt) : plant_(rig, sh::ControlMode::Displacement, dt) {
    plant_.reset(0.0, 0.0);
    plant_.observe(sensors_);
  }
  void read(sh::Output& sensors) const noexcept { sensors = sensors_; }
  bool write(double command) noexcept { return plant_.step(command, sensors_).ok(); }

 private:
  sh::Plant plant_;
  sh::Output sensors_;
};


// Frequency [Hz] from the zero crossings of x[i0..] (linear interpolation).
double crossing_frequency(const std::vector<double>& x, std::size_t i0, double dt) {
  double first = -1.0, last = -1.0;
  int n = 0;
  for (std::size_t i = i0 + 1; i < x.size(); ++i) {
    if ((x[i - 1] < 0.0) == (x[i] < 0.0)) continue;
    const double t = dt * (static_cast<double>(i - 1) + x[i - 1] / (x[i - 1] - x[i]));
    if (n == 0) first = t;
    last = t;
    ++n;
  }
  return n > 1 ? 0.5 * (n - 1) / (last - first) : 0.0;
}
}  // namespace

int main(int argc, char** argv) {
  const double ramp = argc > 1 ? std::atof(argv[1]) : 2.0;  // [s]
  const double hold = argc > 2 ? std::atof(argv[2]) : 1.0;  // [s]
  const double free = argc > 3 ? std::atof(argv[3]) : 2.0;  // [s]
  if (!(ramp > 0.0) || !(hold > 0.0) || !(free > 0.0)) {
    std::fprintf(stderr, "usage: %s [ramp_s > 0] [hold_s > 0] [free_s > 0]\n", argv[0]);
    return 2;
  }
  // Setup (may allocate, may throw): the controller, the I/O, the buffers.
  const sh::Rig rig = sh::zhao2003();
  sh::RpsdConfig cfg;  // Table I: 2 kHz, m_m, c_m, T_d = 68 ms, T_ld = 11.2 ms, alpha = 0.1
  cfg.restoring_force = sh::RestoringForce::MeasuredDisplacement;
  sh::RpsdController controller(cfg, rig);  // the physical rig: k_m = rig.k
  RigIo io(rig, cfg.dt);
  const double P = 0.016 * rig.k;  // [N] Fig 9: 16 mm of static displacement
  const std::size_t n_ramp = std::llround(ramp / cfg.dt), n_hold = std::llround(hold / cfg.dt);
  const std::size_t n = n_ramp + n_hold + static_cast<std::size_t>(std::llround(free / cfg.dt));
  std::vector<double> calc(n);
  sh::realtime::Pacer pacer(cfg.dt);  // absolute CLOCK_MONOTONIC deadlines, one per sample

  long failures = 0;
  double peak_command = 0.0, held = 0.0;
  sh::Output sensors;
  pacer.start();
  for (std::size_t k = 0; k < n; ++k) {
    pacer.wait();  // sleep to deadline k + 1 (records the wake-up latency and the previous step's time)
    // The external force of the test (Fig 9): half-cosine ramp, hold, release.
    const double s = std::min(1.0, static_cast<double>(k) / static_cast<double>(n_ramp));
    const double p_ext = k < n_ramp + n_hold ? 0.5 * P * (1.0 - std::cos(kPi * s)) : 0.0;

    io.read(sensors);                                                         // 1. read the sensors at t_k
    const double u = controller.command(sensors, 0.0, p_ext);                 // 2. compute the command
    if (!io.write(u)) ++failures;                                             // 3. write it; it holds until t_k+1

    calc[k] = controller.integrator_state().displacement;
    peak_command = std::max(peak_command, std::fabs(u));
    if (k >= n_ramp && k < n_ramp + n_hold) held += calc[k] / static_cast<double>(n_hold);
  }

  const double wn = std::sqrt(rig.k / cfg.model.m_m), zeta = cfg.model.c_m / (2.0 * cfg.model.m_m * wn);
  pacer.wait();  // closes the last step's time
  pacer.stop();
  const sh::realtime::PacerStats rs = pacer.stats();
  std::printf("servohydraulics RPsD controller example: %zu samples at 2 kHz on CLOCK_MONOTONIC\n", n);
  std::printf("steps=%zu\n", n);
  std::printf("deadline_misses=%lld\n", static_cast<long long>(rs.misses));
  std::printf("solver_failures=%ld\n", failures);
  std::printf("step_us_median=%.3f\nstep_us_max=%.3f\n", rs.compute_us.p50, rs.compute_us.max);
  std::printf("wakeup_latency_us_median=%.3f\nwakeup_latency_us_max=%.3f\n", rs.latency_us.p50, rs.latency_us.max);
  std::printf("held_displacement_mm=%.6f\n", 1e3 * held);
  std::printf("held_displacement_oracle_mm=%.6f\n", 1e3 * P / rig.k);
  std::printf("peak_command_mm=%.6f\n", 1e3 * peak_command);
  std::printf("free_frequency_Hz=%.6f\n", crossing_frequency(calc, n_ramp + n_hold, cfg.dt));
  std::printf("free_frequency_oracle_Hz=%.6f\n", wn * std::sqrt(1.0 - zeta * zeta) / (2.0 * kPi));
  std::printf("final_calc_displacement_mm=%.6f\n", 1e3 * calc.back());
  return failures == 0 ? 0 : 1;
}
