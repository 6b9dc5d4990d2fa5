// Sensors and converters as general blocks of the core, usable in every loop (EFT, RPsD, the
// RTHS benchmark; rths:: keeps the old names as aliases): a saturation, a quantizer, A/D and D/A converters built from
// them, Gaussian sensor noise held over each sample (seeded, reproducible), a
// unit delay and a backward difference.  As the RTHS benchmark's official code
// does them (Silva et al. 2020; BENCHMARK.md section 3.2):
//   A/D = saturation then quantizer, D/A = quantizer then saturation,
//   Q(u) = q round(u / q) with round half away from zero (MATLAB round),
//   noise sigma w_k, w_k ~ N(0, 1) drawn once per sample and held.
// Construction validates (throws Error); the per-sample calls are noexcept and
// allocation-free.
#pragma once

#include <cstdint>
#include <random>

namespace servohydraulics {

//! Clamp to [lower, upper].
struct Saturation {
  double lower = -3.8;  //!< [signal units]
  double upper = 3.8;   //!< [signal units]
  void validate() const;
  double operator()(double u) const noexcept { return u < lower ? lower : (u > upper ? upper : u); }
};

//! Q(u) = q round(u / q), round half away from zero; q = 0 passes u through.
struct Quantizer {
  double step = 0.0;  //!< quantum q [signal units]; 0 = none
  void validate() const;
  double operator()(double u) const noexcept;
};

//! A/D or D/A converter: a saturation and a quantizer in the converter's order.
struct Converter {
  enum class Kind { AnalogToDigital, DigitalToAnalog };
  Kind kind = Kind::AnalogToDigital;
  Saturation saturation;
  Quantizer quantizer;
  bool enabled = true;  //!< false = ideal (passes the signal through)
  void validate() const;
  double operator()(double u) const noexcept {
    if (!enabled) return u;
    return kind == Kind::AnalogToDigital ? quantizer(saturation(u)) : saturation(quantizer(u));
  }
};

//! The benchmark's converters (F1_input_file.m L186-189): 18 bit over +-3.8 in
//! the code's units (metres: q = 2^-18, the saturation never acts in practice).
Converter benchmark_converter(Converter::Kind kind);
//! An ideal converter (enabled = false; the saturation at +-DBL_MAX and no quantizer if it is enabled).
Converter ideal_converter(Converter::Kind kind = Converter::Kind::AnalogToDigital);

//! Which generator draws the standard normals of the sensor noise.
enum class NoiseGenerator {
  //! A 64-bit Mersenne twister and the Marsaglia polar method, both variates of a pair used.
  MersenneTwister,
  //! The algorithm of Simulink's Random Number block, inside the Band-Limited White Noise
  //! block that the benchmark's SENSORS subsystem uses: the block's seed scrambling, the
  //! Lewis-Goodman-Miller "minimal standard" generator u <- 16807 u mod (2^31 - 1) (Park
  //! and Miller 1988, by Schrage's method), uniforms u / (2^31 - 1), and the polar method
  //! keeping one variate per accepted pair.  With the official run's seed this is the
  //! official noise realisation, sample for sample (BENCHMARK.md section 3.2).
  SimulinkRandomNumber,
};

//! Standard normal draws, one per sample, from a seeded generator (the same
//! sequence on every platform for one seed and generator).
class GaussianSequence {
 public:
  explicit GaussianSequence(std::uint64_t seed = 0,
                            NoiseGenerator generator = NoiseGenerator::MersenneTwister) noexcept {
    reset(seed, generator);
  }
  void reset(std::uint64_t seed, NoiseGenerator generator = NoiseGenerator::MersenneTwister) noexcept;
  double next() noexcept;  //!< w_k ~ N(0, 1)
  NoiseGenerator generator() const noexcept { return generator_; }

  //! The Random Number block's initial generator state for a seed (its
  //! scrambling of the seed's 32 low bits, clamped to [1, 2^31 - 2]).
  static std::uint32_t simulink_state(std::uint64_t seed) noexcept;
  //! One uniform in (0, 1) from the Simulink stream (the Uniform Random Number
  //! block's draw): advances the minimal-standard state and returns state / (2^31 - 1).
  double simulink_uniform() noexcept;
  //! The minimal-standard generator's state (Simulink generator).
  std::uint32_t simulink_generator_state() const noexcept { return lcg_; }

 private:
  NoiseGenerator generator_ = NoiseGenerator::MersenneTwister;
  std::mt19937_64 gen_;
  std::uint32_t lcg_ = 1;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

//! Additive Gaussian sensor noise held over each sample: y_k = gain u_k + sigma w_k.
struct SensorNoise {
  double sigma = 0.0;  //!< standard deviation per sample [signal units]
  double gain = 1.0;   //!< sensor gain (1 in the benchmark)
  void validate() const;
  double operator()(double u, double w) const noexcept { return gain * u + sigma * w; }
  //! sigma of Simulink's Band-Limited White Noise block: sqrt(power / Ts).
  static double band_limited_sigma(double noise_power, double sample_time);
};

//! One-sample delay: returns the previous input (initial value y0).
class UnitDelay {
 public:
  explicit UnitDelay(double y0 = 0.0) noexcept : y0_(y0), prev_(y0) {}
  void reset() noexcept { prev_ = y0_; }
  double operator()(double u) noexcept {
    const double y = prev_;
    prev_ = u;
    return y;
  }

 private:
  double y0_, prev_;
};

//! Simulink's Derivative block at the major steps: (u_k - u_{k-1}) / h, 0 at the first step.
class BackwardDifference {
 public:
  explicit BackwardDifference(double h);
  void reset() noexcept { first_ = true; }
  double operator()(double u) noexcept {
    const double d = first_ ? 0.0 : (u - prev_) / h_;
    first_ = false;
    prev_ = u;
    return d;
  }

 private:
  double h_, prev_ = 0.0;
  bool first_ = true;
};

}  // namespace servohydraulics
