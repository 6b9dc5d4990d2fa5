// The servo-hydraulic plant: analog servo controller (Eq 1), servovalve (Eqs 2-3),
// actuator (Eq 4) and structure (Eq 5), integrated with SUNDIALS CVODE between
// the samples of the digital controller, whose output it holds (zero-order hold).
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! What the analog servo controller feeds back (Eq 1), or no actuator at all.
enum class ControlMode {
  Displacement,  //!< LVDT displacement; command in [m]
  Force,         //!< load-cell force; command in [N]
  Free,          //!< structure alone, no actuator; command is an ideal external force [N]
};

const char* to_string(ControlMode mode) noexcept;

//! Indices of the state vector.
//! kZ is the LuGre bristle deflection [m] (held at 0 unless effects.lugre_friction).
enum StateIndex : int { kX = 0, kV = 1, kP = 2, kXv = 3, kXvDot = 4, kZ = 5, kNumStates = 6 };
using State = std::array<double, kNumStates>;
using Jacobian = std::array<std::array<double, kNumStates>, kNumStates>;  //!< J[row][col] = d f_row / d y_col

//! Bit flags raised by a step (OR-ed over the sample's end state).
enum OutputFlag : std::uint32_t {
  kCapacityExceeded = 1u << 0,  //!< |load-cell force| > F_cap
  kSupplyLimited = 1u << 1,     //!< |p| >= 0.98 p_s: the force demand is at the supply-pressure limit
  kSpoolSaturated = 1u << 2,    //!< |x_v| >= x_v_max
  kDriveSaturated = 1u << 3,    //!< |valve drive| >= v_max
  kStrokeExceeded = 1u << 4,    //!< |x| > stroke: a real actuator would hit its end stop (not modelled)
};

//! Every channel of the plant at one instant.
struct Output {
  double t = 0.0;             //!< time [s]
  double displacement = 0.0;  //!< x [m]
  double velocity = 0.0;      //!< dx/dt [m/s]
  double acceleration = 0.0;  //!< d2x/dt2 [m/s^2]
  double force = 0.0;         //!< load-cell force between piston and structure [N]
  double pressure = 0.0;      //!< load pressure p [Pa]
  double spool = 0.0;         //!< metering spool opening x_v [-]
  double drive = 0.0;         //!< valve drive v [V]
  double flow = 0.0;          //!< valve flow Q [m^3/s]
  std::uint32_t flags = 0;    //!< OutputFlag bits
};

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

  const Rig& rig() const noexcept { return rig_; }
  ControlMode mode() const noexcept { return mode_; }
  double moving_mass() const noexcept { return M_; }

  // Pieces of the model, exposed for compensators and tests.
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
  void evaluate(const double* y, const Input& in, Algebra& a) const noexcept;

  Rig rig_;
  ControlMode mode_;
  double M_;        // moving mass [kg]
  double mp_;       // piston mass seen by the load cell [kg]
  bool lugre_;      // LuGre friction on (coulomb_friction && lugre_friction && F_c > 0)
  double CF_;       // conversion factor of the mode [V/m or V/N]
  double wv_;       // valve natural frequency [rad/s]
};

//! How the plant is integrated across one controller sample.
struct SolverOptions {
  enum class Method {
    CvodeBdf,  //!< CVODE, BDF, Newton with the analytic dense Jacobian (reference, default)
    Rk4,       //!< classical fixed-step Runge-Kutta, rk4_substeps per sample (real-time option)
  };
  enum class Restart {
    OnInputChange,  //!< CVodeReInit when the held command changes (ZOH jump): safest
    Never,          //!< keep the BDF history across samples (the sample end is a stop time, never straddled)
  };
  Method method = Method::CvodeBdf;
  Restart restart = Restart::OnInputChange;
  double rtol = 1e-6;                 //!< CVODE relative tolerance [-]
  //! CVODE absolute tolerance = rtol * atol_scale[i]: [m, m/s, Pa, -, 1/s, m]
  std::array<double, kNumStates> atol_scale{1e-3, 1e-2, 1e5, 1e-2, 1.0, 1e-6};
  int max_order = 5;                  //!< BDF maximum order
  long max_steps_per_sample = 2000;   //!< cap on CVODE internal steps in one step(); then TooMuchWork
  double max_internal_step = 0.0;     //!< CVODE hmax [s], 0 = no limit
  //! Rk4: substeps per controller sample; 0 = automatic: the fewest with
  //! h * rho(J) <= rk4_h_rho, rho the spectral radius of the Jacobian at the
  //! equilibrium (where friction is steepest), chosen at construction; with
  //! LuGre friction also h sigma_0 v_ref / F_c <= rk4_h_rho, v_ref the no-load
  //! actuator speed K_v g(x_v_max) / A (1 m/s in free mode).
  int rk4_substeps = 0;
  double rk4_h_rho = 1.0;             //!< Rk4 automatic substeps: bound on h * rho(J) (stability limit ~2.8)

  void validate() const;
};

//! Result of one controller sample.  Never thrown: the hot path returns it.
struct Status {
  enum Code : int {
    Ok = 0,
    SolverFailure = 1,  //!< CVODE returned an error flag (see cvode_flag)
    TooMuchWork = 2,    //!< more than max_steps_per_sample internal steps: an overrun
    NonFinite = 3,      //!< the state became NaN or infinite (diverged)
    NotReady = 4,       //!< step() after a failure without reset()
  };
  Code code = Ok;
  int cvode_flag = 0;      //!< CVODE return flag when code != Ok
  double t = 0.0;          //!< time reached [s] (where the failure happened)
  int internal_steps = 0;  //!< CVODE internal steps taken in this sample (or RK4 substeps)
  int rhs_evals = 0;       //!< right-hand-side evaluations in this sample
  bool restarted = false;  //!< CVodeReInit was called at the start of this sample

  bool ok() const noexcept { return code == Ok; }
  const char* message() const noexcept;  //!< static text for the code
};

//! The plant stepped at the controller rate.  Construct once (allocates), then
//! step(command) advances one sample of dt seconds: no allocation, no throw.
class Plant {
 public:
  Plant(const Rig& rig, ControlMode mode, double dt, const SolverOptions& options = {});
  ~Plant();
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;
  Plant(Plant&&) noexcept;
  Plant& operator=(Plant&&) noexcept;

  //! Restart at time t0 from the static equilibrium at displacement x0 (in
  //! Free mode: released from x0 at rest).  Allocates nothing.
  void reset(double x0 = 0.0, double t0 = 0.0) noexcept;
  //! Restart from an explicit state.
  void reset_state(const State& y0, double t0 = 0.0) noexcept;

  //! Hold command u for one sample [m in displacement, N in force/free mode]
  //! and integrate to t + dt.  Output is the state at the end of the sample.
  Status step(double command, Output& out) noexcept;

  //! The outputs at the current time without stepping.
  void observe(Output& out) const noexcept;

  double time() const noexcept;
  double dt() const noexcept;
  const State& state() const noexcept;
  const Dynamics& dynamics() const noexcept;
  const SolverOptions& options() const noexcept;
  //! Rk4 substeps per sample in use (resolved if automatic); 0 for CVODE.
  int rk4_substeps() const noexcept;

  //! Totals since construction/reset.
  long total_internal_steps() const noexcept;
  long total_rhs_evals() const noexcept;
  long total_restarts() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace servohydraulics
