// Linearisation of the plant about an operating point from its analytic
// Jacobian: dy/dt = A dy + B du, out = C dy + D du.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "servohydraulics/plant.hpp"

namespace servohydraulics {

//! The linearised plant over its dyn.num_states() active states (the base states,
//! then those of the switched-on elements: Dynamics::layout, Dynamics::state_info).
struct LinearModel {
  static constexpr int kOutputs = 9;
  Eigen::MatrixXd A;  //!< n x n
  Eigen::VectorXd B;  //!< n
  //! Rows: displacement, velocity, acceleration, force, pressure, spool, drive, flow, specimen force.
  Eigen::MatrixXd C;  //!< kOutputs x n
  Eigen::VectorXd D;  //!< kOutputs
  //! States that take part in this mode/effect set (the others have zero dynamics).
  std::vector<bool> active;
};

//! Linearises about state y0 with the command held at u0 (u_rate = 0).
LinearModel linearize(const Dynamics& dyn, const State& y0, double u0);

}  // namespace servohydraulics
