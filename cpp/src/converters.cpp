#include "servohydraulics/converters.hpp"

#include <cmath>
#include <limits>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

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

void GaussianSequence::reset(std::uint64_t seed, NoiseGenerator generator) noexcept {
  generator_ = generator;
  gen_.seed(seed);
  lcg_ = simulink_state(seed);
  has_spare_ = false;
}

std::uint32_t GaussianSequence::simulink_state(std::uint64_t seed) noexcept {
  // The block takes floor(seed) mod 2^32 as an unsigned 32-bit integer, swaps in
  // its high half and folds bit 15, then clamps into the generator's range.
  std::uint32_t s = static_cast<std::uint32_t>(seed & 0xFFFFFFFFull);
  const std::uint32_t r = s >> 16U;
  const std::uint32_t t = s & 32768U;
  s = ((((s - (r << 16U)) + t) << 16U) + t) + r;
  if (s < 1U) return 1144108930U;  // the block's replacement for a zero state
  if (s > 2147483646U) return 2147483646U;
  return s;
}

double GaussianSequence::simulink_uniform() noexcept {
  // 16807 u mod (2^31 - 1) without overflow (Schrage: 2^31 - 1 = 16807 * 127773 + 2836).
  const std::uint32_t lo = (lcg_ % 127773U) * 16807U;
  const std::uint32_t hi = (lcg_ / 127773U) * 2836U;
  lcg_ = lo < hi ? 2147483647U - (hi - lo) : lo - hi;
  return static_cast<double>(lcg_) * 4.6566128752457969e-10;  // 1 / (2^31 - 1)
}

double GaussianSequence::next() noexcept {
  if (generator_ == NoiseGenerator::SimulinkRandomNumber) {
    // Polar method as the block does it: accept s <= 1, keep the first variate only.
    double u, s;
    do {
      u = 2.0 * simulink_uniform() - 1.0;
      const double v = 2.0 * simulink_uniform() - 1.0;
      s = u * u + v * v;
    } while (s > 1.0 || s == 0.0);
    return std::sqrt(-2.0 * std::log(s) / s) * u;
  }
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

}  // namespace servohydraulics
