// The plant's equations: analog servo controller (Eq 1), servovalve (Eqs 2-3),
// actuator (Eq 4) and structure (Eq 5), as a right-hand side with its analytic
// Jacobian and the algebraic outputs.  Implemented in dynamics.cpp.
#pragma once

#include <array>

#include "servohydraulics/output.hpp"
#include "servohydraulics/rig.hpp"
#include "servohydraulics/state.hpp"

namespace servohydraulics {

//! The right-hand side of the plant's ODE, its analytic Jacobian and its
//! algebraic outputs, for one rig and mode.  Pure functions of (state, input):
//! shared by CVODE, the fixed-step integrator, linearisation and tests.
class Dynamics {
 public:
  Dynamics(const Rig& rig, ControlMode mode);

  //! Held inputs of one controller sample: command u and its rate du/dt (only
  //! used when G_d != 0; the rate of a held command is its last increment / dt).
  struct Input {
    double u = 0.0;
    double u_rate = 0.0;
  };

  //! A held command and the state it holds at rest (see operating_point).
  struct OperatingPoint {
    State y0{};       //!< the static equilibrium state
    double u0 = 0.0;  //!< the held command [m in displacement, N in force/free mode]
  };

  //! Gradients of the 8 output channels (displacement, velocity, acceleration,
  //! force, pressure, spool, drive, flow) by the states and, last, by u.
  using OutputGradients = std::array<std::array<double, kNumStates + 1>, 8>;

  void rhs(const double* y, const Input& in, double* ydot) const noexcept;
  //! J = df/dy; if B is given, also B = df/du.
  void jacobian(const double* y, const Input& in, Jacobian& J, State* B = nullptr) const noexcept;
  void outputs(const double* y, const Input& in, Output& out, OutputGradients* grad = nullptr) const noexcept;

  //! Static equilibrium for a held command u with the structure at x0: v = 0,
  //! the pressure that holds the springs, the spool that feeds the leakage.
  State equilibrium(double x0) const noexcept;
  //! The equilibrium at x0 and the held command u0 that keeps it at rest: the
  //! rate that u drives (the spool rate, or the pressure rate with a static
  //! valve) is zero.  Free mode: u0 is the spring force.  Exact while the
  //! drive and the spool are not saturated (that rate is affine in u there).
  OperatingPoint operating_point(double x0) const noexcept;

  const Rig& rig() const noexcept { return rig_; }
  //! Length of the state vector of this rig (integrators loop over it).
  int num_states() const noexcept { return kNumStates; }
  ControlMode mode() const noexcept { return mode_; }
  double moving_mass() const noexcept { return M_; }

  // Pieces of the model, exposed for compensators and tests.
  //! The structure's force against the applied one in Eq (5), f_s(x) + c v + F_f [N]:
  //! spring, damping and friction (the static law, or LuGre with bristle deflection z).
  double structure_force(double x, double v, double z = 0.0) const noexcept;
  double spring_force(double x) const noexcept;         //!< f_s(x) [N]
  double spring_stiffness(double x) const noexcept;     //!< df_s/dx [N/m]
  double friction_force(double v) const noexcept;       //!< static friction law g(v) tanh(v / v_stick) [N]
  double friction_slope(double v) const noexcept;       //!< its derivative [N s/m]
  double friction_level(double v) const noexcept;       //!< sliding level g(v) with the Stribeck peak [N]
  double friction_level_slope(double v) const noexcept; //!< g'(v) [N s/m]
  bool lugre() const noexcept { return lugre_; }        //!< friction is the LuGre model (state kZ active)
  double flow_gain(double s) const noexcept;            //!< g(s) with the effect switches applied
  double flow_gain_slope(double s) const noexcept;      //!< g'(s)
  double pressure_factor(double s, double p) const noexcept;        //!< the square-root term of Eq (3)
  double pressure_factor_dp(double s, double p) const noexcept;     //!< its derivative by p [1/Pa]

 private:
  struct Algebra;  // intermediate quantities of one evaluation
  struct Friction;  // friction force, bristle rate and their gradients
  void evaluate(const double* y, const Input& in, Algebra& a) const noexcept;
  Friction friction(double v, double z) const noexcept;

  Rig rig_;
  ControlMode mode_;
  double M_;        // moving mass [kg]
  double mp_;       // piston mass seen by the load cell [kg]
  bool lugre_;      // LuGre friction on (coulomb_friction && lugre_friction && F_c > 0)
  double CF_;       // conversion factor of the mode [V/m or V/N]
  double wv_;       // valve natural frequency [rad/s]
};

}  // namespace servohydraulics
