#include "servohydraulics/rths/converters.hpp"

#include <cmath>
#include <limits>

#include "servohydraulics/error.hpp"

namespace servohydraulics::rths {

void Saturation::validate() const {
  require(std::isfinite(lower), "saturation.lower", lower, "finite");
  require(std::isfinite(upper) && upper > lower, "saturation.upper", upper, "finite and > lower");
}

void Quantizer::validate() const {
  require(std::isfinite(step) && step >= 0.0, "quantizer.step", step, "finite and >= 0");
}

double Quantizer::operator()(double u) const noexcept {
  return step > 0.0 ? step * std::round(u / step) : u;  // std::round: half away from zero, as MATLAB
}

void Converter::validate() const {
  saturation.validate();
  quantizer.validate();
}

Converter benchmark_converter(Converter::Kind kind) {
  Converter c;
  c.kind = kind;
  c.saturation = {-3.8, 3.8};
  c.quantizer.step = std::ldexp(1.0, -18);
  return c;
}

Converter ideal_converter(Converter::Kind kind) {
  Converter c;
  c.kind = kind;
  c.enabled = false;
  c.saturation = {-std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};  // never acts
  return c;
}

void GaussianSequence::reset(std::uint64_t seed) noexcept {
  gen_.seed(seed);
  has_spare_ = false;
}

double GaussianSequence::next() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  // Marsaglia polar method on 53-bit uniforms in (-1, 1): portable, unlike std::normal_distribution.
  double u, v, s;
  do {
    u = 2.0 * (static_cast<double>(gen_() >> 11) * 0x1.0p-53) - 1.0;
    v = 2.0 * (static_cast<double>(gen_() >> 11) * 0x1.0p-53) - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * f;
  has_spare_ = true;
  return u * f;
}

void SensorNoise::validate() const {
  require(std::isfinite(sigma) && sigma >= 0.0, "noise.sigma", sigma, "finite and >= 0");
  require(std::isfinite(gain), "noise.gain", gain, "finite");
}

double SensorNoise::band_limited_sigma(double noise_power, double sample_time) {
  require(std::isfinite(noise_power) && noise_power >= 0.0, "noise_power", noise_power, "finite and >= 0");
  require(std::isfinite(sample_time) && sample_time > 0.0, "sample_time", sample_time, "finite and > 0");
  return std::sqrt(noise_power / sample_time);
}

BackwardDifference::BackwardDifference(double h) : h_(h) {
  require(std::isfinite(h) && h > 0.0, "h", h, "finite and > 0");
}

}  // namespace servohydraulics::rths
