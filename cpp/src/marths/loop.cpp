#include "servohydraulics/marths/loop.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "servohydraulics/error.hpp"

namespace servohydraulics::marths {

void CommandVoltage::validate() const {
  require(std::isfinite(gain) && gain != 0.0, "voltage.gain", gain, "finite and nonzero [mm/V]");
  require(std::isfinite(offset), "voltage.offset", offset, "finite [mm]");
  require(std::isfinite(correction) && correction != 0.0, "voltage.correction", correction, "finite and nonzero");
}

void MarthsLoopConfig::validate() const {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0 [s]");
  require(std::isfinite(noise_power) && noise_power >= 0.0, "noise_power", noise_power, "finite and >= 0 [mm^2 s]");
  require(std::isfinite(sensor_unit) && sensor_unit > 0.0, "sensor_unit", sensor_unit, "finite and > 0 [m]");
  for (const CommandVoltage& v : voltage) v.validate();
  require(std::isfinite(daq_quantum) && daq_quantum > 0.0, "daq_quantum", daq_quantum, "finite and > 0 [V]");
  require(std::isfinite(daq_limit) && daq_limit > 0.0, "daq_limit", daq_limit, "finite and > 0 [V]");
}

double MarthsLoopConfig::noise_sigma() const { return SensorNoise::band_limited_sigma(noise_power, dt) * sensor_unit; }

namespace {
Converter daq(const MarthsLoopConfig& c) {
  Converter d = ideal_converter(Converter::Kind::DigitalToAnalog);
  d.enabled = c.daq_quantizer || c.daq_saturation;
  if (c.daq_quantizer) d.quantizer.step = c.daq_quantum;
  if (c.daq_saturation) d.saturation = {-c.daq_limit, c.daq_limit};
  d.validate();
  return d;
}
}  // namespace

MarthsLoop::MarthsLoop(MultiActuatorSystem& plant, MultiTrackingController& controller,
                       const MarthsStructures& structures, const MarthsLoopConfig& config, const Coupler& coupler)
    : plant_(plant),
      ctrl_(controller),
      cfg_(config),
      coupler_(coupler),
      dofs_(structures.dofs),
      ref_(structures.reference, config.dt),
      num_(structures.numerical, config.dt),
      frame_(structures.frame, config.dt),
      da_(daq(config)) {
  cfg_.validate();
  require(plant_.actuators() == 2, "plant.actuators", static_cast<double>(plant_.actuators()),
          "2 (the benchmark's coupler)");
  require(coupler_.actuators() == 2, "coupler.actuators", static_cast<double>(coupler_.actuators()), "2");
  require(ctrl_.actuators() == 2, "controller.actuators", static_cast<double>(ctrl_.actuators()),
          "2 (one command per actuator)");
  require(std::fabs(plant_.dt() - cfg_.dt) <= 1e-12 * cfg_.dt, "plant.dt", plant_.dt(), "the loop's dt");
  require(structures.reference.size() == structures.numerical.size(), "numerical.size",
          static_cast<double>(structures.numerical.size()), "the reference structure's size");
  dofs_.validate(structures.numerical.size());
  sigma_ = cfg_.noise_sigma();
  F_.setZero(structures.numerical.size());
  reset();
}

void MarthsLoop::reset() noexcept {
  plant_.reset();
  ctrl_.reset();
  ref_.reset();
  num_.reset();
  frame_.reset();
  w1_.reset(cfg_.seed, cfg_.generator);
  w2_.reset(cfg_.seed ^ 0x9E3779B97F4A7C15ull, cfg_.generator);
}

RunSummary MarthsLoop::run(const GroundMotion& ag, std::size_t n, MarthsOutput* rows, double* step_seconds) noexcept {
  using clock = std::chrono::steady_clock;
  RunSummary sum;
  const double h = cfg_.dt, unit = cfg_.sensor_unit;
  const Eigen::Index ix = dofs_.x - 1, ith = dofs_.theta - 1, ithb = dofs_.theta_b - 1;
  const Eigen::Index ix2 = dofs_.x_2nd - 1, ith2 = dofs_.theta_2nd - 1, ix3 = dofs_.x_3rd - 1,
                     ith3 = dofs_.theta_3rd - 1;
  double y_prev[2] = {0.0, 0.0};
  for (std::size_t k = 0; k < n; ++k) {
    const auto t0 = step_seconds ? clock::now() : clock::time_point{};
    const double t = static_cast<double>(k) * h;
    // 1-2. ground motion, reference
    const double a = ag(t);
    ref_.step(a, nullptr);
    const Eigen::VectorXd& Ur = ref_.displacement();
    // 3. sensors
    double y[2], xm[2];
    plant_.displacements(y);
    const double w = w1_.next();
    const double w2 = cfg_.independent_noise ? w2_.next() : w;
    xm[0] = y[0] + sigma_ * w;
    xm[1] = y[1] + sigma_ * w2;
    // 4. actuator -> frame
    double xe = 0.0, the = 0.0;
    if (cfg_.exact_kinematics) {
      if (!coupler_.node_from_strokes(xm, &xe, &the)) xe = the = std::numeric_limits<double>::quiet_NaN();
    } else {
      coupler_.benchmark_estimate(xm, &xe, &the);
    }
    // 5-6. feedback force, numerical substructure (same sample)
    double f[5];
    frame_(xe, the, f);
    F_(ix) = f[0];
    F_(ith) = -f[1];
    F_(ithb) = -f[2];
    num_.step(a, F_.data());
    const Eigen::VectorXd &Un = num_.displacement(), &Vn = num_.velocity(), &An = num_.acceleration();
    // 7. frame -> actuator targets and their rates
    const double xN = Un(ix), thN = -Un(ith), vN = Vn(ix), wN = -Vn(ith), aN = An(ix), alN = -An(ith);
    double target[2], dtarget[2], ddtarget[2], u[2];
    coupler_.strokes(xN, thN, target);
    for (std::size_t i = 0; i < 2; ++i) {
      const double s1 = coupler_.dstroke_dtheta(i, thN), s2 = coupler_.d2stroke_dtheta2(i, thN);
      dtarget[i] = vN + s1 * wN;
      ddtarget[i] = aN + s1 * alN + s2 * wN * wN;
    }
    // 8. controller
    const MultiTrackingInput in{2, target, xm, dtarget, ddtarget};
    ctrl_.command(in, u);
    // 9. voltages (and the optional D/A)
    double v[2], up[2];
    for (std::size_t i = 0; i < 2; ++i) {
      v[i] = cfg_.voltage[i].volts(u[i] / unit);
      if (da_.enabled) {
        v[i] = da_(v[i]);
        up[i] = cfg_.voltage[i].millimetres(v[i]) * unit;
      } else {
        up[i] = u[i];
      }
    }
    // 10. log, then the plant holds the commands
    if (rows)
      rows[k] = MarthsOutput{t,
                             a,
                             target[0],
                             target[1],
                             xm[0],
                             xm[1],
                             y[0],
                             y[1],
                             u[0],
                             u[1],
                             v[0],
                             v[1],
                             xe,
                             the,
                             xN,
                             thN,
                             Ur(ix),
                             -Ur(ith),
                             Un(ix2),
                             Un(ith2),
                             Un(ix3),
                             Un(ith3),
                             Ur(ix2),
                             Ur(ith2),
                             Ur(ix3),
                             Ur(ith3),
                             F_(ix),
                             F_(ith),
                             F_(ithb)};
    sum.rows = k + 1;
    const double vel = k == 0 ? 0.0 : std::fmax(std::fabs(y[0] - y_prev[0]), std::fabs(y[1] - y_prev[1])) / h;
    sum.peaks(f[0], std::fmax(std::fabs(y[0]), std::fabs(y[1])), vel);
    y_prev[0] = y[0];
    y_prev[1] = y[1];
    const Status st = plant_.step(up);
    if (step_seconds) step_seconds[k] = std::chrono::duration<double>(clock::now() - t0).count();
    sum.internal_steps += st.internal_steps;
    sum.rhs_evals += st.rhs_evals;
    sum.restarts += st.restarted ? 1 : 0;
    const bool own = std::isfinite(xm[0]) && std::isfinite(xm[1]) && std::isfinite(u[0]) && std::isfinite(u[1]) &&
                     std::isfinite(up[0]) && std::isfinite(up[1]) && std::isfinite(xe) && std::isfinite(the) &&
                     num_.healthy() && ref_.healthy();
    if (!sum.count(st, t) || !own) {
      if (st.ok()) {  // the loop's own signals, a structure or the controller
        sum.status = st;
        sum.status.code = Status::NonFinite;
        sum.failure_time = t;
      }
      sum.status.t = t;
      break;
    }
  }
  return sum;
}

}  // namespace servohydraulics::marths
