// The RTHS benchmark's numerical substructure and ground motion under their rths:: names: the
// numerical substructure (the NumericalSubstructure interface, LinearSubstructure and the schemes)
// moved to the core (servohydraulics/substructure.hpp, issue 22) and the ground-motion record to
// servohydraulics/ground_motion.hpp (issue 23, shared with the maRTHS benchmark); the rths:: names
// are kept as aliases for one release.
#pragma once

#include "servohydraulics/ground_motion.hpp"
#include "servohydraulics/substructure.hpp"

namespace servohydraulics::rths {

//! The core's numerical substructure (servohydraulics/substructure.hpp), under its RTHS names.
using servohydraulics::LinearSubstructure;
using servohydraulics::LinearSubstructureModel;
using servohydraulics::NumericalSubstructure;
using servohydraulics::SubstructureScheme;
//! The core's ground-motion record (servohydraulics/ground_motion.hpp).
using servohydraulics::GroundMotion;

}  // namespace servohydraulics::rths
