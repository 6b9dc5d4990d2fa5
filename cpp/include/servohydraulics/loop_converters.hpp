// Sensors and converters as optional blocks of the EFT and RPsD closed loops
// (loops.hpp), built from the core's converter blocks (converters.hpp):
// per measured channel (displacement, velocity, force)
//   y_k = AD(gain x_k + sigma w_k), then optionally one sample of delay,
// with w_k ~ N(0, 1) drawn once per sample (seeded, one generator per channel),
// AD = saturation then quantizer; and on the command
//   u_plant = DA(u_k) (quantizer then saturation), optionally one sample of delay.
// All blocks are off by default: an inactive LoopConverters leaves the loop
// bit-for-bit as without it.  The controller sees the measured channels; the
// row's plant channels stay the plant's true outputs.  Construction validates
// (throws Error); reset(), measure() and actuate() are noexcept and allocation-free.
#pragma once

#include <cstdint>

#include "servohydraulics/output.hpp"
#include "servohydraulics/converters.hpp"

namespace servohydraulics {

//! One measured channel: noise and sensor gain, A/D converter, optional unit delay.
struct SensorChannel {
  SensorNoise noise{0.0, 1.0};             //!< sigma [channel units], gain [-]
  Converter converter = ideal_converter();  //!< A/D (kind AnalogToDigital), off by default
  bool unit_delay = false;                             //!< the controller sees y_{k-1} (0 at k = 0)
  bool active() const noexcept;
  void validate(const char* name) const;
};

//! The sensor and converter blocks of a closed loop (all off by default).
struct LoopConverters {
  SensorChannel displacement;  //!< Output::displacement [m]
  SensorChannel velocity;      //!< Output::velocity [m/s]
  SensorChannel force;         //!< Output::force (load cell) [N]
  Converter command = ideal_converter(Converter::Kind::DigitalToAnalog);  //!< D/A on the command [m or N], off by default
  bool command_unit_delay = false;  //!< the plant receives u_{k-1} (0 at k = 0)
  std::uint64_t seed = 0;           //!< of the noise generators
  NoiseGenerator generator = NoiseGenerator::MersenneTwister;  //!< which generator draws the noise
  bool active() const noexcept;
  void validate() const;
};

//! The blocks' state in a loop.
class LoopIo {
 public:
  explicit LoopIo(const LoopConverters& config = {});
  void reset() noexcept;
  bool active() const noexcept { return active_; }
  //! measured = truth with the displacement, velocity and force channels passed through their blocks.
  void measure(const Output& truth, Output& measured) noexcept;
  double actuate(double command) noexcept;  //!< the command the plant receives
  const LoopConverters& config() const noexcept { return cfg_; }

 private:
  struct Channel {
    GaussianSequence w;
    UnitDelay delay;
  };
  double channel(const SensorChannel& c, Channel& s, double x) noexcept;
  LoopConverters cfg_;
  bool active_ = false;
  Channel d_, v_, f_;
  UnitDelay u_delay_;
};

}  // namespace servohydraulics
