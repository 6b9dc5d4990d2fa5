// The fixture kinematics of a multi-actuator test (issue 23): N axial
// actuators pinned by rigid arms to one frame node with two degrees of
// freedom, the node's translation x [m] and rotation theta [rad].
//
// Arm i reaches from the node to actuator i's attachment at distance d_i and
// angle alpha_i from the actuator axis (the maRTHS benchmark's coupler:
// d = sqrt(0.2667^2 + 0.127^2) m, alpha = -/+25.4633 deg, fcn_coupler_geometry.m).
// The actuators stay parallel to x, so actuator i's stroke is
//
//   s_i(x, theta) = x + d_i (cos(theta + alpha_i) - cos(alpha_i))        (the benchmark's frame -> actuator)
//
// with ds_i/dx = 1, ds_i/dtheta = -d_i sin(theta + alpha_i),
// d2s_i/dtheta2 = -d_i cos(theta + alpha_i) and d3s_i/dtheta3 = d_i sin(theta + alpha_i);
// by virtual work the actuator forces F_i [N] load the node with Q = J^T F (force along x,
// moment about the node).  A nonlinear geometry: the benchmark and a simulated fixture use the
// same functions.
//
// Construction validates (Error naming the field and the value); every other
// member is noexcept and allocation-free.
#pragma once

#include <array>
#include <cstddef>

namespace servohydraulics {

class Coupler {
 public:
  static constexpr std::size_t kMaxActuators = 8;

  //! n arms of length d[i] [m] at angle alpha[i] [rad]; throws Error on bad input.
  Coupler(std::size_t n, const double* d, const double* alpha);

  //! The maRTHS benchmark's two-actuator coupler.
  static Coupler marths();

  std::size_t actuators() const noexcept { return n_; }
  double arm(std::size_t i) const noexcept { return d_[i]; }     //!< d_i [m]
  double angle(std::size_t i) const noexcept { return alpha_[i]; }  //!< alpha_i [rad]

  //! Strokes s[i] [m] of the node at (x [m], theta [rad]).
  void strokes(double x, double theta, double* s) const noexcept;
  //! ds_i/dtheta [m/rad] at theta (ds_i/dx = 1).
  double dstroke_dtheta(std::size_t i, double theta) const noexcept;
  //! d2s_i/dtheta2 [m/rad^2] at theta.
  double d2stroke_dtheta2(std::size_t i, double theta) const noexcept;
  //! d3s_i/dtheta3 [m/rad^3] at theta (the pistons' inertia in a coupled rig's Jacobian).
  double d3stroke_dtheta3(std::size_t i, double theta) const noexcept;
  //! Generalised node load (Fx [N], M [N m]) of the actuator forces F[i] [N]: Q = J(theta)^T F.
  void node_load(double theta, const double* F, double* Fx, double* M) const noexcept;

  //! The node's exact (x, theta) from two strokes (actuators 0 and 1, Newton to machine precision);
  //! false when the strokes are out of the geometry's reach (no solution with |theta| < pi/2).
  bool node_from_strokes(const double* s, double* x, double* theta) const noexcept;

  //! The maRTHS model's actuator -> frame estimate (BENCHMARK.md section 6):
  //! s = (s_0 - s_1) / (2 d_1 sin alpha_1), theta = asin(s), x = s_0 - d_0 (cos(alpha_0 + s) - cos alpha_0)
  //! (the model puts s, not asin(s), inside the cosine).  Two actuators; |s| > 1 gives theta = +-pi/2.
  void benchmark_estimate(const double* s, double* x, double* theta) const noexcept;

 private:
  std::size_t n_ = 0;
  std::array<double, kMaxActuators> d_{};
  std::array<double, kMaxActuators> alpha_{};
};

}  // namespace servohydraulics
