// Tracking controllers of a real-time hybrid simulation: they read the
// numerical substructure's desired displacement (and, if they wish, its
// velocity and acceleration) and the measured specimen displacement and force
// at t_k, and return the actuator command to hold over [t_k, t_k + dt].  On a
// real rig the same object runs against the lab's I/O:
//
//   TrackingInput in{desired, desired_velocity, desired_acceleration, x_meas, f_meas};
//   double u = controller.command(in);   // write u to the D/A; wait for the next sample
//
// Construct once (validates, throws Error); reset() and command() are noexcept
// and allocation-free.  Every controller reads the desired and measured
// displacements through its A/D converters and writes the command through its
// D/A converter (converters.hpp; the benchmark's 18-bit converters by default).
#pragma once

#include <array>

#include "servohydraulics/rths/benchmark_plant.hpp"
#include "servohydraulics/rths/converters.hpp"
#include "servohydraulics/tracking.hpp"

namespace servohydraulics::rths {

//! The core's tracking interface and compensators (servohydraulics/tracking.hpp), under their RTHS names.
using TrackingInput = servohydraulics::TrackingInput;
using TrackingController = servohydraulics::TrackingController;
using servohydraulics::TustinFirstOrder;
using servohydraulics::ControllerConverters;
using servohydraulics::PiGains;
using servohydraulics::SampleControllerConfig;
using servohydraulics::SampleController;
using servohydraulics::PolynomialConfig;
using servohydraulics::PolynomialExtrapolation;
using servohydraulics::AtsConfig;
using servohydraulics::AdaptiveTimeSeries;
using servohydraulics::ModelBasedConfig;
using servohydraulics::ModelBasedCompensator;

//! The model-based feedforward's coefficients from the benchmark plant (G_P = b0 / (A5 s^5 + ... + A0)),
//! up to the given order (0..3).
ModelBasedConfig model_based_config(const BenchmarkPlantParameters& plant, int order = 2);

//! The plant's low-frequency delay A1/A0 [s] (phase delay as omega -> 0).
double plant_delay(const BenchmarkPlantParameters& plant) noexcept;

}  // namespace servohydraulics::rths
