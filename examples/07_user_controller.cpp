// Your own tracking controller in C++: the PI + phase lead of
// examples/07_user_controller.py moved to C++ (docs/rths-benchmark.md, "Bring your
// own controller": when a Python controller is too slow).  PiLead (pi_lead.hpp)
// derives the core's interface
//
//   class rths::TrackingController {
//     virtual void reset() noexcept = 0;
//     virtual double command(const TrackingInput& in) noexcept = 0;   // the command [m]
//   };
//
// (TrackingInput: desired [m], desired_velocity [m/s], desired_acceleration [m/s^2],
// measured [m], measured_force [N]) and plugs into the RTHS loop as the built-ins do.
// Construct once; reset() and command() must not allocate or throw.  To use it from
// Python instead, see examples/07_user_controller_module.cpp.
//
// The run: the benchmark's control plant as the experimental substructure under a
// 3-storey shear building (6, 5, 4 MN/m storeys, 1000 kg floors, 5 % Rayleigh
// damping; NOT one of the benchmark's cases) shaken by a 2 Hz sine, once with the
// built-in SampleController and once with PiLead.  PiLead is the same algorithm, so
// the commands agree (max_command_difference_m, expected 0); after the start-up
// transient the specimen follows the building's first floor
// (steady_peak_displacement_mm: its peak over the last 2 s, against the building's
// steady-state 2 Hz response).  The per-sample wall times (the whole sample: plant,
// substructure, controller) are printed for both.
//
//   07_user_controller [seconds=10]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pi_lead.hpp"
#include "servohydraulics/rths/loop.hpp"

namespace {

//! The shear building less the specimen at the first floor (the numerical substructure).
rths::LinearSubstructureModel partitioned_building(const rths::SpecimenModel& sp) {
  const double k[3] = {6e6, 5e6, 4e6}, m = 1000.0, zeta = 0.05;
  Eigen::Matrix3d K;
  K << k[0] + k[1], -k[1], 0.0, -k[1], k[1] + k[2], -k[2], 0.0, -k[2], k[2];
  const Eigen::Matrix3d M = m * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d w = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(K / m).eigenvalues().cwiseSqrt();
  Eigen::Matrix2d A;  // Rayleigh C = a M + b K with zeta at the first and last modes
  A << 1.0 / (2.0 * w(0)), w(0) / 2.0, 1.0 / (2.0 * w(2)), w(2) / 2.0;
  const Eigen::Vector2d ab = A.partialPivLu().solve(Eigen::Vector2d(zeta, zeta));
  rths::LinearSubstructureModel model{M, ab(0) * M + ab(1) * K, K, M * Eigen::Vector3d::Ones(),
                                      Eigen::Vector3d(1.0, 0.0, 0.0)};
  model.M(0, 0) -= sp.m;
  model.C(0, 0) -= sp.c;
  model.K(0, 0) -= sp.k;
  return model;
}

struct Run {
  std::vector<rths::RthsOutput> rows;  //!< one per sample, channels as rths::kRthsChannels
  std::vector<double> step_seconds;
  servohydraulics::RunSummary summary;  // every loop's summary (record.hpp)
};

Run run(rths::TrackingController& controller, double seconds) {
  const double dt = 1.0 / 4096.0;
  rths::BenchmarkPlant plant(rths::BenchmarkPlantParameters{}, dt);
  rths::LinearSubstructure building(partitioned_building(plant.specimen()), dt);
  rths::RthsLoop loop(plant, building, controller);
  std::vector<double> t, a;
  for (double ti = 0.0; ti <= seconds + 1.0; ti += 0.01) {
    t.push_back(ti);
    a.push_back(1.0 * std::sin(2.0 * 3.14159265358979323846 * 2.0 * ti));  // 2 Hz, 1 m/s^2
  }
  const rths::GroundMotion ag(t, a);
  const auto n = static_cast<std::size_t>(seconds / dt);
  Run out;
  out.rows.resize(n);
  out.step_seconds.resize(n);
  loop.reset();
  out.summary = loop.run(ag, n, out.rows.data(), nullptr, out.step_seconds.data());
  return out;
}

double percentile_us(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return 1e6 * v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  if (!(std::isfinite(seconds) && seconds > 0.0 && seconds <= 3600.0)) {
    std::fprintf(stderr, "invalid seconds = %s: expected 0 < seconds <= 3600\n", argc > 1 ? argv[1] : "");
    return 2;
  }
  rths::SampleController builtin;
  PiLead mine;
  const Run b = run(builtin, seconds), p = run(mine, seconds);
  double diff = 0.0, peak = 0.0, steady = 0.0;
  const std::size_t last = b.rows.size() - std::min(b.rows.size(), static_cast<std::size_t>(2 * 4096));
  for (std::size_t k = 0; k < b.rows.size(); ++k) {
    diff = std::max(diff, std::fabs(b.rows[k].command - p.rows[k].command));
    peak = std::max(peak, std::fabs(b.rows[k].command));
    if (k >= last) steady = std::max(steady, std::fabs(b.rows[k].displacement));  // the last 2 s
  }
  std::printf("samples=%zu\nok=%d\npeak_command_mm=%.6f\nsteady_peak_displacement_mm=%.6f\n"
              "max_command_difference_m=%.3e\n",
              b.rows.size(), b.summary.ok() && p.summary.ok() ? 1 : 0, 1e3 * peak, 1e3 * steady, diff);
  std::printf("builtin_step_us_median=%.3f\nbuiltin_step_us_p99=%.3f\n", percentile_us(b.step_seconds, 0.5),
              percentile_us(b.step_seconds, 0.99));
  std::printf("pilead_step_us_median=%.3f\npilead_step_us_p99=%.3f\n", percentile_us(p.step_seconds, 0.5),
              percentile_us(p.step_seconds, 0.99));
  return b.summary.ok() && p.summary.ok() ? 0 : 1;
}
