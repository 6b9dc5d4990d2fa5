// Linearisation of the plant about an operating point from its analytic
// Jacobian: dy/dt = A dy + B du, out = C dy + D du.
#pragma once

#include <Eigen/Dense>
#include <array>

#include "servohydraulics/plant.hpp"

namespace servohydraulics {

struct LinearModel {
  static constexpr int kOutputs = 8;
  Eigen::Matrix<double, kNumStates, kNumStates> A;
  Eigen::Matrix<double, kNumStates, 1> B;
  //! Rows: displacement, velocity, acceleration, force, pressure, spool, drive, flow.
  Eigen::Matrix<double, kOutputs, kNumStates> C;
  Eigen::Matrix<double, kOutputs, 1> D;
  //! States that take part in this mode/effect set (the others have zero dynamics).
  std::array<bool, kNumStates> active{};
};

//! Linearises about state y0 with the command held at u0 (u_rate = 0).
LinearModel linearize(const Dynamics& dyn, const State& y0, double u0);

}  // namespace servohydraulics
