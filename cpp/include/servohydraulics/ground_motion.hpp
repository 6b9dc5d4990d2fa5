// A ground-motion record as the hybrid-simulation loops read it (the RTHS benchmark's
// rths::GroundMotion, the maRTHS benchmark's marths/): Simulink's From File block with
// linear interpolation on the record's stored time row, scaled; it holds the end values
// outside the record.
#pragma once

#include <cstddef>
#include <vector>

namespace servohydraulics {

class GroundMotion {
 public:
  //! time [s] strictly increasing, acceleration [m/s^2] (unscaled), scale [-]; throws Error on bad input.
  GroundMotion(std::vector<double> time, std::vector<double> acceleration, double scale = 1.0);
  //! scale * a(t); a cursor makes monotone queries O(1).  noexcept, no allocation.
  double operator()(double t) const noexcept;
  double end_time() const noexcept { return t_.back(); }
  double scale() const noexcept { return scale_; }

 private:
  std::vector<double> t_, a_;
  double scale_;
  mutable std::size_t cursor_ = 0;
};

}  // namespace servohydraulics
