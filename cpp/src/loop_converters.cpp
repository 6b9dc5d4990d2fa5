#include "servohydraulics/loop_converters.hpp"

#include <cmath>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

bool SensorChannel::active() const noexcept {
  return noise.sigma != 0.0 || noise.gain != 1.0 || converter.enabled || unit_delay;
}

void SensorChannel::validate(const char* name) const {
  const std::string n(name);
  require(std::isfinite(noise.sigma) && noise.sigma >= 0.0, (n + ".noise.sigma").c_str(), noise.sigma,
          "finite and >= 0");
  require(std::isfinite(noise.gain), (n + ".noise.gain").c_str(), noise.gain, "finite");
  require(converter.kind == Converter::Kind::AnalogToDigital, (n + ".converter.kind").c_str(),
          static_cast<double>(converter.kind), "AnalogToDigital (a sensor channel's converter is an A/D)");
  converter.validate();
}

bool LoopConverters::active() const noexcept {
  return displacement.active() || velocity.active() || force.active() || command.enabled || command_unit_delay;
}

void LoopConverters::validate() const {
  displacement.validate("converters.displacement");
  velocity.validate("converters.velocity");
  force.validate("converters.force");
  require(command.kind == Converter::Kind::DigitalToAnalog, "converters.command.kind",
          static_cast<double>(command.kind), "DigitalToAnalog (the command's converter is a D/A)");
  command.validate();
}

LoopIo::LoopIo(const LoopConverters& config) : cfg_(config) {
  cfg_.validate();
  active_ = cfg_.active();
  reset();
}

void LoopIo::reset() noexcept {
  // One generator per channel, seeds spread so that the channels are independent.
  d_.w.reset(cfg_.seed, cfg_.generator);
  v_.w.reset(cfg_.seed ^ 0x9E3779B97F4A7C15ull, cfg_.generator);
  f_.w.reset(cfg_.seed ^ 0xC2B2AE3D27D4EB4Full, cfg_.generator);
  d_.delay.reset();
  v_.delay.reset();
  f_.delay.reset();
  u_delay_.reset();
}

double LoopIo::channel(const SensorChannel& c, Channel& s, double x) noexcept {
  const double w = c.noise.sigma != 0.0 ? s.w.next() : 0.0;
  const double y = c.converter(c.noise(x, w));
  return c.unit_delay ? s.delay(y) : y;
}

void LoopIo::measure(const Output& truth, Output& measured) noexcept {
  measured = truth;
  measured.displacement = channel(cfg_.displacement, d_, truth.displacement);
  measured.velocity = channel(cfg_.velocity, v_, truth.velocity);
  measured.force = channel(cfg_.force, f_, truth.force);
}

double LoopIo::actuate(double command) noexcept {
  const double u = cfg_.command(command);
  return cfg_.command_unit_delay ? u_delay_(u) : u;
}

}  // namespace servohydraulics
