// N actuators on one specimen (issue 23): the seam between a multi-actuator
// hybrid-simulation loop (the maRTHS benchmark's, marths/) and what stands
// behind the actuators' displacement transducers.
//
//   MultiActuatorSystem& plant = ...;   // the benchmark's identified linear MIMO
//                                       // plant, or N nonlinear servo-hydraulic actuators
//   plant.reset();
//   plant.displacements(y);             // y[i]: actuator i's displacement at t_k [m]
//   Status s = plant.step(u);           // hold the N commands u[i] [m] over [t_k, t_k + dt]
//
// and the multi-actuator tracking compensator the loop calls once per sample
// (decentralized single-actuator compensators, a MIMO model-based feedforward,
// RoDeAC, or a user's own in C++ or Python):
//
//   MultiTrackingInput in{n, desired, measured, desired_velocity, desired_acceleration};
//   controller.command(in, u);          // u[i]: the command for actuator i [m]
//
// Units are SI (m); a loop that reports mm converts at its edge.  Implementations
// validate at construction (throw Error naming the field and the value);
// reset(), displacements(), step() and command() are noexcept and allocation-free.
#pragma once

#include <cstddef>

#include "servohydraulics/status.hpp"

namespace servohydraulics {

//! N displacement-commanded actuators acting on one specimen, seen through their displacement sensors.
class MultiActuatorSystem {
 public:
  virtual ~MultiActuatorSystem() = default;
  virtual std::size_t actuators() const noexcept = 0;  //!< N
  virtual double dt() const noexcept = 0;              //!< the sample time step() advances [s]
  virtual void reset() noexcept = 0;                   //!< at rest, t = 0
  //! The N actuator displacements at the current time (no sensor noise) [m].
  virtual void displacements(double* y) const noexcept = 0;
  //! One sample dt with the N commands u [m] held; a failure is reported in the Status (never thrown).
  virtual Status step(const double* u) noexcept = 0;
};

//! What a multi-actuator tracking compensator reads at t_k (arrays of n values, owned by the loop).
//! The rates of the targets are optional (nullptr when the loop has none): the maRTHS loop gives the
//! numerical substructure's, carried through the fixture kinematics (coupler.hpp).
struct MultiTrackingInput {
  std::size_t n = 0;                //!< number of actuators
  const double* desired = nullptr;  //!< target actuator displacements [m]
  const double* measured = nullptr;  //!< measured actuator displacements (with sensor noise) [m]
  const double* desired_velocity = nullptr;      //!< rates of the targets [m/s] (nullptr: not given)
  const double* desired_acceleration = nullptr;  //!< their second derivatives [m/s^2] (nullptr: not given)
};

//! The interface: reset() to rest, command() once per sample.
class MultiTrackingController {
 public:
  virtual ~MultiTrackingController() = default;
  virtual std::size_t actuators() const noexcept = 0;  //!< N
  virtual void reset() noexcept = 0;
  //! Write the N commands to hold over [t_k, t_k + dt] [m].
  virtual void command(const MultiTrackingInput& in, double* u) noexcept = 0;
};

}  // namespace servohydraulics
