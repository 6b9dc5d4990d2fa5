// The converter blocks moved to the core (servohydraulics/converters.hpp, issue 22);
// their rths:: names are kept as aliases for one release.
#pragma once

#include "servohydraulics/converters.hpp"

namespace servohydraulics::rths {

using servohydraulics::BackwardDifference;
using servohydraulics::benchmark_converter;
using servohydraulics::Converter;
using servohydraulics::GaussianSequence;
using servohydraulics::ideal_converter;
using servohydraulics::NoiseGenerator;
using servohydraulics::Quantizer;
using servohydraulics::Saturation;
using servohydraulics::SensorNoise;
using servohydraulics::UnitDelay;

}  // namespace servohydraulics::rths
