// The RTHS benchmark's ground-motion record.  The numerical substructure (the
// NumericalSubstructure interface, LinearSubstructure and the schemes) moved to
// the core (servohydraulics/substructure.hpp, issue 22); the rths:: names are
// kept as aliases for one release.
#pragma once

#include <cstddef>
#include <vector>

#include "servohydraulics/substructure.hpp"

namespace servohydraulics::rths {

//! The core's numerical substructure (servohydraulics/substructure.hpp), under its RTHS names.
using servohydraulics::LinearSubstructure;
using servohydraulics::LinearSubstructureModel;
using servohydraulics::NumericalSubstructure;
using servohydraulics::SubstructureScheme;

//! A ground-motion record evaluated by linear interpolation on its stored time
//! row (Simulink From File), scaled; holds the end values outside the record.
class GroundMotion {
 public:
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

}  // namespace servohydraulics::rths
