// N of the single-actuator model's servo-hydraulic actuators (Zhao, French, Shield, Posbergh 2003,
// Eqs 1-4, each with its own Rig) coupled through a fixture (Coupler: rigid arms to one frame
// node) and a linear specimen at that node (issue 23, docs/multi-actuator.md).
//
//   MultiRig rig({rig1, rig2}, Coupler::marths(), specimen);   // validates (Error naming the field)
//   MultiRigPlant plant(rig, 1.0 / 1024);                      // a MultiActuatorSystem
//   plant.reset();
//   plant.displacements(y);                                    // the N strokes [m]
//   Status st = plant.step(u);                                 // the N commands [m], held over dt
//   plant.observe(out);                                        // every channel (MultiRigOutput)
//
// The node has the coordinates q = (x, theta) (or x alone, theta locked at 0).  Actuator i's
// stroke is s_i(q) (coupler.hpp), its piston (mass m_p) moves with it, and its force loads the
// node by virtual work, J^T F.  Each actuator is the paper's actuator in displacement control:
// the servo controller (Eq 1) on its own stroke, the servovalve (Eq 2), the valve flow with the
// load pressure and the spool limits (Eq 3), the oil's compressibility and the leakage (Eq 4),
// the friction on its piston (the structure's friction laws of Eq 5 along the stroke) and the
// drive saturation.  Those equations are the single-actuator Dynamics' own (Dynamics::actuator):
// nothing of Eqs (1)-(4) is written here.  The rig's structure (m, c, k, k_2, x_contact) is not
// used: the specimen is the node's.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/coupler.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/multi_actuator.hpp"
#include "servohydraulics/output.hpp"
#include "servohydraulics/record.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics {

//! The specimen and the fixture at the frame node, condensed to the node's coordinates
//! q = (x [m], theta [rad]): M q'' + C q' + K q = J^T F (with the pistons' inertia, MultiRig).
//! Matrices are row-major 2 x 2; with rotation = false only their [0] (the x entries) are used.
struct NodeSpecimen {
  //! theta is free (two coordinates); false: theta is locked at 0 and the node only translates.
  bool rotation = true;
  std::array<double, 4> M{};  //!< specimen mass [[kg, kg m], [kg m, kg m^2]]
  std::array<double, 4> C{};  //!< specimen damping [[N s/m, N s], [N s, N m s]]
  std::array<double, 4> K{};  //!< specimen stiffness [[N/m, N], [N, N m]]
  double fixture_mass = 0.0;     //!< the fixture's mass, moving with the node [kg]
  double fixture_inertia = 0.0;  //!< the fixture's rotary inertia about the node [kg m^2]

  //! Throws Error naming the first bad field (specimen.K[0][1], ...) and its value: finite,
  //! symmetric, C and K positive semidefinite, fixture mass and inertia >= 0.
  void validate() const;
};

//! One actuator's channels at one instant (names and units: kActuatorChannels).
struct ActuatorOutput {
  double stroke = 0.0;        //!< s_i [m]
  double velocity = 0.0;      //!< ds_i/dt [m/s]
  double acceleration = 0.0;  //!< d2s_i/dt2 [m/s^2]
  double force = 0.0;         //!< load cell between the piston and the fixture, A p - F_f - m_p s'' [N]
  double pressure = 0.0;      //!< load pressure p [Pa]
  double spool = 0.0;         //!< metering spool opening [-]
  double drive = 0.0;         //!< valve drive [V]
  double flow = 0.0;          //!< valve flow Q [m^3/s]
  double friction = 0.0;      //!< friction on the piston F_f [N]
  std::uint32_t flags = 0;    //!< OutputFlag bits (stroke, capacity, supply, spool, drive)
};

//! The node's channels at one instant (names and units: kNodeChannels).
struct NodeOutput {
  double x = 0.0;                   //!< translation [m]
  double theta = 0.0;               //!< rotation [rad]
  double x_velocity = 0.0;          //!< [m/s]
  double theta_velocity = 0.0;      //!< [rad/s]
  double x_acceleration = 0.0;      //!< [m/s^2]
  double theta_acceleration = 0.0;  //!< [rad/s^2]
  double force = 0.0;               //!< the actuators' load on the node along x, (J^T F)_x [N]
  double moment = 0.0;              //!< and about it, (J^T F)_theta [N m]
  //! The force fighting: the 2-norm of the actuator forces' component in the null space of J^T
  //! (forces that load the fixture but do no work on the node) [N].  0 when N <= the node's
  //! coordinates (two actuators on (x, theta): J^T is invertible).
  double force_fighting = 0.0;
  //! The part of the actuator forces that cancels in the x resultant, (sum |F_i| - |sum F_i|) / 2 [N]:
  //! with two actuators, the smaller force when they push against each other (a moment on the node
  //! with theta free, pure fighting with theta locked).
  double opposing_force = 0.0;
};

//! Every channel of the coupled rig at one instant.
struct MultiRigOutput {
  double time = 0.0;  //!< [s]
  NodeOutput node;
  std::array<ActuatorOutput, Coupler::kMaxActuators> actuator{};  //!< the first N are used
  std::uint32_t flags = 0;  //!< OR of the actuators' flags
};

//! Actuator i's channels, named "actuator<i+1>.<name>" in records and Python.
inline constexpr ChannelInfoOf<ActuatorOutput> kActuatorChannels[] = {
    {"stroke", "m", "actuator stroke s_i", &ActuatorOutput::stroke},
    {"velocity", "m/s", "stroke velocity", &ActuatorOutput::velocity},
    {"acceleration", "m/s^2", "stroke acceleration", &ActuatorOutput::acceleration},
    {"force", "N", "load cell between piston and fixture, A p - F_f - m_p s''", &ActuatorOutput::force},
    {"pressure", "Pa", "load pressure p", &ActuatorOutput::pressure},
    {"spool", "-", "metering spool opening x_v", &ActuatorOutput::spool},
    {"drive", "V", "valve drive v", &ActuatorOutput::drive},
    {"flow", "m^3/s", "valve flow Q", &ActuatorOutput::flow},
    {"friction", "N", "friction on the piston F_f", &ActuatorOutput::friction},
};
//! The node's channels, named "node.<name>".
inline constexpr ChannelInfoOf<NodeOutput> kNodeChannels[] = {
    {"x", "m", "node translation", &NodeOutput::x},
    {"theta", "rad", "node rotation", &NodeOutput::theta},
    {"x_velocity", "m/s", "node translation velocity", &NodeOutput::x_velocity},
    {"theta_velocity", "rad/s", "node rotation velocity", &NodeOutput::theta_velocity},
    {"x_acceleration", "m/s^2", "node translation acceleration", &NodeOutput::x_acceleration},
    {"theta_acceleration", "rad/s^2", "node rotation acceleration", &NodeOutput::theta_acceleration},
    {"force", "N", "actuator load on the node along x, (J^T F)_x", &NodeOutput::force},
    {"moment", "N m", "actuator moment on the node, (J^T F)_theta", &NodeOutput::moment},
    {"force_fighting", "N", "norm of the actuator forces in the null space of J^T", &NodeOutput::force_fighting},
    {"opposing_force", "N", "actuator force cancelling in the x resultant, (sum|F_i| - |sum F_i|)/2",
     &NodeOutput::opposing_force},
};
constexpr std::size_t kNumActuatorChannels = sizeof(kActuatorChannels) / sizeof(kActuatorChannels[0]);
constexpr std::size_t kNumNodeChannels = sizeof(kNodeChannels) / sizeof(kNodeChannels[0]);

//! The coupled rig's equations: right-hand side, analytic Jacobian and outputs, pure functions of
//! (state, input) like Dynamics.  The state is
//!   y = [q, q', actuator 1's states, ..., actuator N's states]
//! with q = (x, theta) (or x), and actuator i's states those of its Dynamics after the first two
//! (x and v are its stroke and stroke rate, functions of q and q'): p, x_v, x_v', z and its drive
//! elements' (the Pade loop delay).
class MultiRig {
 public:
  static constexpr int kMaxActuators = static_cast<int>(Coupler::kMaxActuators);
  //! Capacity of the state vector: the node's four and every actuator's own at their most.
  static constexpr int kCapacity = 4 + kMaxActuators * (kMaxStates - 2);
  using State = std::array<double, kCapacity>;
  //! The held inputs of one sample: each actuator's command [m] and its rate [m/s] (used when G_d != 0).
  struct Input {
    std::array<double, kMaxActuators> u{};
    std::array<double, kMaxActuators> u_rate{};
  };

  //! rigs[i] is actuator i's (validated, in displacement control), on arm i of the coupler.  Throws
  //! Error naming the field ("actuators[1].K_v", "specimen.M[1][1]", ...) and its value: as many rigs
  //! as arms; no specimen element on an actuator (bouc_wen_hysteresis, mr_damper, fluid_damper: the
  //! specimen is the node's) and no digital delay; a node mass matrix (specimen, fixture, pistons)
  //! positive definite at q = 0.
  MultiRig(const std::vector<Rig>& rigs, const Coupler& coupler, const NodeSpecimen& specimen);

  int actuators() const noexcept { return n_act_; }  //!< N
  int dofs() const noexcept { return m_; }           //!< the node's coordinates: 2 (x, theta) or 1 (x)
  int num_states() const noexcept { return n_; }
  //! Index of actuator i's first state (its load pressure p).
  int offset(int i) const noexcept { return off_[static_cast<std::size_t>(i)]; }
  //! Index in y of actuator i's state `local` in its Dynamics' layout (kP, kXv, kXvDot, kZ, appended; not kX, kV).
  int index(int i, int local) const noexcept { return off_[static_cast<std::size_t>(i)] + local - 2; }
  const Dynamics& actuator(int i) const noexcept { return dyn_[static_cast<std::size_t>(i)]; }
  const Coupler& coupler() const noexcept { return coupler_; }
  const NodeSpecimen& specimen() const noexcept { return spec_; }
  //! State k's name ("x", "theta", "x_dot", "theta_dot", "actuator1.p", ...) and unit.
  std::string state_name(int k) const;
  const char* state_unit(int k) const noexcept;
  //! The magnitude of state k, the unit of its absolute tolerance (docs/multi-actuator.md).
  double state_scale(int k) const noexcept;

  //! The state at rest with every command 0 (q = 0, each actuator at its equilibrium).
  State rest() const noexcept;
  void rhs(const double* y, const Input& in, double* ydot) const noexcept;
  //! J = df/dy, element (r, c) written to J[r * row_stride + c * col_stride] (n x n); if B is given,
  //! B = df/du, n x N row-major (B[r * N + i]).
  void jacobian(const double* y, const Input& in, double* J, std::ptrdiff_t row_stride, std::ptrdiff_t col_stride,
                double* B = nullptr) const noexcept;
  void outputs(const double* y, const Input& in, MultiRigOutput& out) const noexcept;
  //! The N strokes s_i(q) [m].
  void strokes(const double* y, double* s) const noexcept;

 private:
  struct Node;  // the node's kinematics and mass at one state (multi_rig.cpp)
  // Actuator i's local state (its Dynamics' layout: stroke, stroke rate, then its own states).
  void local_state(const double* y, int i, const Node& nd, servohydraulics::State& yl) const noexcept;
  void node(const double* y, Node& nd) const noexcept;

  int n_act_ = 0;
  int m_ = 2;
  int n_ = 0;
  Coupler coupler_;
  NodeSpecimen spec_;
  std::vector<Dynamics> dyn_;  // each actuator's equations (displacement mode)
  std::array<int, kMaxActuators> off_{};    // first state of actuator i
  std::array<int, kMaxActuators> count_{};  // its states (Dynamics::num_states() - 2)
  std::array<double, kMaxActuators> mp_{};  // piston masses [kg]
  std::array<double, kMaxActuators> area_{};  // piston areas [m^2]
  std::array<double, 4> M0_{};  // specimen + fixture mass, row-major m x m in the first entries
};

//! The linearised coupled rig about (y0, u0): dy/dt = A dy + B du, strokes = C dy.
struct MultiRigLinearModel {
  std::vector<double> A;  //!< n x n, row-major
  std::vector<double> B;  //!< n x N, row-major
  std::vector<double> C;  //!< N x n, row-major: the strokes' gradient
  int n = 0, inputs = 0;
};
MultiRigLinearModel linearize(const MultiRig& rig, const MultiRig::State& y0, const double* u0);

//! The automatic RK4 rule of the coupled rig: the fewest substeps per sample of dt [s] with
//! h rho(J) <= options.rk4_h_rho, rho the largest spectral radius of the coupled Jacobian at rest
//! and with every actuator's load pressure at 0, +-0.5 and +-0.9 p_s combined with its spool
//! shut, half open and at its stops, and every actuator's own rule (LuGre).  Throws Error past
//! 100000.
int rk4_automatic_substeps(const MultiRig& rig, double dt, const SolverOptions& options);

//! The coupled rig stepped at the loop's rate: the N commands held over each sample (zero-order
//! hold), integrated by the core's integrators (dopri5 with the CVODE fallback by default, CVODE
//! or RK4; ARKODE is not offered here).  Construct once (allocates), then reset, displacements and
//! step are noexcept and allocation-free.
class MultiRigPlant final : public MultiActuatorSystem {
 public:
  MultiRigPlant(const MultiRig& rig, double dt, const SolverOptions& options = {});
  ~MultiRigPlant() override;
  MultiRigPlant(const MultiRigPlant&) = delete;
  MultiRigPlant& operator=(const MultiRigPlant&) = delete;

  std::size_t actuators() const noexcept override;
  double dt() const noexcept override;
  //! At rest (MultiRig::rest), t = 0.
  void reset() noexcept override;
  //! Restart from an explicit state (its first num_states() entries) at t = 0; throws Error if an
  //! entry is not finite.
  void reset_state(const MultiRig::State& y);
  void displacements(double* y) const noexcept override;
  //! Holds u[0..N-1] [m] over one sample.  A non-finite command, a failed integration or a diverged
  //! state (|x| > 100 m, |p_i| > 100 p_s) returns a failure and leaves the plant NotReady until reset.
  Status step(const double* u) noexcept override;
  //! Every channel at the current time.
  void observe(MultiRigOutput& out) const noexcept;

  double time() const noexcept;
  const MultiRig& rig() const noexcept;
  const MultiRig::State& state() const noexcept;
  const SolverOptions& options() const noexcept;
  int rk4_substeps() const noexcept;  //!< RK4 substeps per sample in use (0 for the other methods)
  long total_internal_steps() const noexcept;
  long total_rhs_evals() const noexcept;
  long total_restarts() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

//! Destination arrays of a multi-actuator run, each of length n (nullptr skips a channel).
struct MultiRigChannels {
  double* time = nullptr;
  std::array<double*, kNumNodeChannels> node{};  //!< indexed like kNodeChannels
  //! actuator[i][c]: actuator i's channel kActuatorChannels[c]
  std::array<std::array<double*, kNumActuatorChannels>, Coupler::kMaxActuators> actuator{};
  std::array<std::uint32_t*, Coupler::kMaxActuators> flags{};  //!< actuator i's OutputFlag bits
  int* internal_steps = nullptr;
  int* rhs_evals = nullptr;
};

//! Runs n samples from the plant's current state with commands u[k * N + i] [m] (row k: the N
//! commands of sample k), row k of the channels measured before command row k is applied (the
//! record convention of run_record).  No allocation, no throw; stops at the first failed sample.
//! The summary's peaks are over the actuators: |force|, |stroke|, |stroke velocity|.
RunSummary run_multi_record(MultiRigPlant& plant, const double* u, std::size_t n,
                            const MultiRigChannels& out) noexcept;

}  // namespace servohydraulics
