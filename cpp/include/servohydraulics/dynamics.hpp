// The plant's equations: analog servo controller (Eq 1), servovalve (Eqs 2-3),
// actuator (Eq 4) and structure (Eq 5), as a right-hand side with its analytic
// Jacobian and the algebraic outputs.  Implemented in dynamics.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "servohydraulics/elements.hpp"
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
    //! The exact Coulomb law's mode over the stretch (ExactCoulomb; the plant sets it, Auto reads
    //! it from the state); no effect with any other friction law.
    Sliding sliding = Sliding::Auto;
  };

  //! A held command and the state it holds at rest (see operating_point).
  struct OperatingPoint {
    State y0{};       //!< the static equilibrium state
    double u0 = 0.0;  //!< the held command [m in displacement, N in force/free mode]
  };

  //! Gradients of the 9 output channels (displacement, velocity, acceleration,
  //! force, pressure, spool, drive, flow, specimen force) by the states (columns
  //! 0..num_states()-1; the rest of the capacity is 0) and, in the last column kMaxStates, by u.
  using OutputGradients = std::array<std::array<double, kMaxStates + 1>, 9>;

  void rhs(const double* y, const Input& in, double* ydot) const noexcept;
  //! J = df/dy; if B is given, also B = df/du.
  void jacobian(const double* y, const Input& in, Jacobian& J, State* B = nullptr) const noexcept;
  //! rhs() and jacobian() at one state from one evaluation (an implicit step needs both there):
  //! ydot as rhs() writes it, J's first num_states() rows and columns as jacobian() writes them
  //! (the rest of J untouched).
  void rhs_jacobian(const double* y, const Input& in, double* ydot, Jacobian& J) const noexcept;
  void outputs(const double* y, const Input& in, Output& out, OutputGradients* grad = nullptr) const noexcept;

  // The actuator alone, for a rig that moves its piston by other equations (the coupled
  // multi-actuator rig, multi_rig.hpp).  Displacement mode only.
  //! Eqs (1)-(4) and the friction on the piston at a local state y whose y[kX], y[kV] are the
  //! stroke and its rate (set by the caller): writes into g the drive, spool, flow, pressure rate,
  //! spool acceleration, the bristle's rate (LuGre) and the drive elements' rates, with their
  //! gradients by the states (columns 0..num_states()-1) and u (column num_states()), and returns
  //! the piston friction (the structure's friction laws of Eq 5 along the stroke) with its
  //! derivatives.  The structure's spring, damping and specimens are not evaluated.
  LawForce actuator(const double* y, const Input& in, Algebra& g) const noexcept;
  //! The rates of the actuator's own states (kP, kXv, kXvDot, kZ and the elements') from an
  //! evaluation g at y, into ydot (the rows rhs writes past x and v).
  void actuator_rates(const double* y, const Algebra& g, double* ydot) const noexcept;
  //! Their rows of J (columns 0..num_states()-1) and of B from an evaluation g; the other rows untouched.
  void actuator_jacobian(const Algebra& g, Jacobian& J, State* B = nullptr) const noexcept;
  //! The OutputFlag bits of state y (its x and p) with the spool and the drive saturated or not and
  //! the load-cell force [N].
  std::uint32_t flags(const double* y, bool spool_saturated, bool drive_saturated, double force) const noexcept;

  //! Static equilibrium for a held command u with the structure at x0: v = 0,
  //! the pressure that holds the springs, the spool that feeds the leakage.
  State equilibrium(double x0) const noexcept;
  //! The equilibrium at x0 and the held command u0 that keeps it at rest: the
  //! rate that u drives (the spool rate, or the pressure rate with a static
  //! valve) is zero.  Free mode: u0 is the spring force.  Exact while the
  //! drive and the spool are not saturated (that rate is affine in u there).
  OperatingPoint operating_point(double x0) const noexcept;

  //! The active length of the state vector: the base states plus those of the
  //! switched-on elements (elements.hpp).
  int num_states() const noexcept { return layout_.num_states; }
  //! Where the switched-on elements' states are (offset -1: off).
  const StateLayout& layout() const noexcept { return layout_; }
  //! Name, unit and meaning of state i < num_states().
  const StateInfo& state_info(int i) const noexcept;
  //! Absolute scale of an appended state i >= kNumStates (an element's); the base
  //! states' scales follow the rig (servohydraulics::state_scale in solver_options.hpp, which
  //! calls this for the appended ones).
  double state_scale(int i) const noexcept;
  //! Force of the switched-on structure elements (the specimens) at state y [N] (0 when
  //! none is on); part of the structure's force against the applied one.
  double specimen_force(const double* y) const noexcept;
  //! The kinematic driver: the specimen force [N] along a given motion x[k], v[k] [m, m/s] sampled
  //! at dt [s], the elements' states starting at rest at x[0] and integrated by RK4 with
  //! `substeps` steps per sample (0: from the elements' rate bound at the largest |v|), the motion
  //! interpolated linearly between samples.  Writes F[0..n-1].
  void specimen_forces(const double* x, const double* v, std::size_t n, double dt, int substeps,
                       double* F) const;
  //! Upper estimate of |d rate / d state| of the elements' states when sliding at v_ref [m/s]:
  //! their stiffness for an explicit integrator [1/s] (0 when no element bounds it).
  double element_rate_bound(double v_ref) const noexcept;
  //! The same over the structure's laws' states too (LuGre's bristle) and the elements': the
  //! bound the automatic RK4 rule takes with the Jacobian's spectral radius [1/s].
  double rate_bound(double v_ref) const noexcept;
  //! The actuator's no-load speed K_v g(min(x_v_max, 1)) / A [m/s].
  double no_load_speed() const noexcept;
  //! The switched-on element E, or nullptr when it is off.
  template <class E>
  const E* element() const noexcept {
    const auto& e = std::get<element_index<E>>(elements_);
    return e ? &*e : nullptr;
  }
  //! The structure's law L (StructureLaws), or nullptr when it is off.
  template <class L>
  const L* law() const noexcept {
    const auto& l = std::get<std::optional<L>>(laws_);
    return l ? &*l : nullptr;
  }
  //! The Pade loop delay's realisation (order 0 when it is off).
  using Pade = PadeDelay;
  const Pade& pade() const noexcept;

  const Rig& rig() const noexcept { return rig_; }
  ControlMode mode() const noexcept { return mode_; }
  double moving_mass() const noexcept { return M_; }
  //! The piston mass that moves with the structure and that the load cell sees [kg] (0 when
  //! effects.piston_mass is off or in free mode).
  double piston_mass() const noexcept { return mp_; }

  // Pieces of the model, exposed for compensators and tests (the laws' own, elements/*.hpp).
  //! The structure's force against the applied one in Eq (5), f_s(x) + c v + F_f [N]:
  //! its laws, spring, damping and friction (the static law, or LuGre with bristle deflection z).
  double structure_force(double x, double v, double z = 0.0) const noexcept;
  double spring_force(double x) const noexcept;         //!< f_s(x) [N]
  double spring_stiffness(double x) const noexcept;     //!< df_s/dx [N/m]
  double friction_force(double v) const noexcept;       //!< static friction law g(v) tanh(v / v_stick) [N] (either law on; the exact law: g(v) sgn(v), 0 at v = 0)
  double friction_slope(double v) const noexcept;       //!< its derivative [N s/m]
  double friction_level(double v) const noexcept;       //!< sliding level g(v) with the Stribeck peak [N]
  double friction_level_slope(double v) const noexcept; //!< g'(v) [N s/m]
  bool lugre() const noexcept { return law<LuGreFriction>() != nullptr; }  //!< friction is LuGre (state kZ active)
  //! The exact Coulomb law (v_stick = 0), or nullptr when friction is off or another law.
  const ExactCoulomb* exact_coulomb() const noexcept { return coulomb_ ? &*coulomb_ : nullptr; }
  //! The force the exact Coulomb law holds when stuck at y: every other force on the structure
  //! (pA, or the ideal force in free mode, less damping, spring and specimens) [N].
  double held_force(const double* y, const Input& in) const noexcept;
  //! The exact law's mode at y (Sliding::Auto's rule; Auto when the law is off).
  Sliding sliding(const double* y, const Input& in) const noexcept;
  double flow_gain(double s) const noexcept;            //!< g(s) with the effect switches applied
  double flow_gain_slope(double s) const noexcept;      //!< g'(s)
  double pressure_factor(double s, double p) const noexcept;        //!< the square-root term of Eq (3)
  double pressure_factor_dp(double s, double p) const noexcept;     //!< its derivative by p [1/Pa]

 private:
  // W: the gradient width the loops run over, a constant so that they unroll (the paper
  // plant's kNumStates + 1, or the capacity with appended states).
  template <int W>
  void evaluate(const double* y, const Input& in, Algebra& a) const noexcept;
  void evaluate_any(const double* y, const Input& in, Algebra& a) const noexcept;
  template <int W>
  LawForce evaluate_actuator(const double* y, const Input& in, Algebra& a) const noexcept;
  // f(std::integral_constant<int, W>) with W = num_states() + 1, a compile-time constant in each case.
  template <class F>
  decltype(auto) at_width(F&& f) const noexcept;
  template <int W>
  [[gnu::always_inline]] inline void structure(const double* y, const Input& in, Algebra& a) const noexcept;
  template <int W>
  [[gnu::cold, gnu::noinline]] void structure_exact(const double* y, const Input& in, double net, LawForce laws,
                                                    Algebra& a) const noexcept;
  template <int W>
  void structure_rates(double net, const LawForce& laws, Algebra& a) const noexcept;
  template <int W>
  bool servo_controller(const double* y, const Input& in, Algebra& a) const noexcept;
  template <int W>
  void valve(const double* y, double vdrive, const double* dvdrive, Algebra& a) const noexcept;
  template <int W>
  void specimen(const double* y, Algebra& a) const noexcept;
  template <int W>
  bool delay_drive(const double* y, Algebra& a) const noexcept;
  void jacobian_appended(const Algebra& g, Jacobian& J, State* B) const noexcept;
  // The rates (rhs) and every row of J and B (jacobian) from an evaluation g at y.
  [[gnu::always_inline]] inline void rates(const double* y, const Algebra& g, double* ydot) const noexcept;
  void jacobian_rows(const Algebra& g, Jacobian& J, State* B) const noexcept;
  // f(law) for each law of the structure that is on, in the order of StructureLaws.
  template <class F>
  void each_law(F&& f) const {
    std::apply([&](const auto&... l) { ((l ? f(*l) : void()), ...); }, laws_);
  }
  // f(element, offset) for each switched-on element, in the order of Elements.
  template <class F>
  void each(F&& f) const {
    each_impl(f, std::make_index_sequence<kNumElements>{});
  }
  template <class F, std::size_t... I>
  void each_impl(F& f, std::index_sequence<I...>) const {
    ((std::get<I>(elements_) ? f(*std::get<I>(elements_), layout_.offset[I]) : void()), ...);
  }
  double static_force(double x) const noexcept;  // the structure's force at rest at x

  Rig rig_;
  ControlMode mode_;
  double M_;        // moving mass [kg]
  double mp_;       // piston mass seen by the load cell [kg]
  double CF_;       // conversion factor of the mode [V/m or V/N]
  double wv_;       // valve natural frequency [rad/s]
  StateLayout layout_;
  int ku_ = kNumStates;      // gradient column of the command u (= num_states())
  int ng_ = kNumStates + 1;  // gradient width
  bool specimen_on_ = false;  // a structure element is on
  detail::Optionals<StructureLaws>::type laws_;
  std::optional<ExactCoulomb> coulomb_;  // the exact Coulomb law, applied after the other forces
  detail::Optionals<Elements>::type elements_;
};

}  // namespace servohydraulics
