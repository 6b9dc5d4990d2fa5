// Internal: what the integrators (cvode_integrator, dopri5_integrator, rk4_integrator) need of
// the system they integrate, the small interface they are written over.  OdeSystem<S> is
// specialised for the single-actuator plant (Dynamics) and the coupled multi-actuator rig
// (MultiRig); the integrators are templates instantiated for both in their .cpp files, so the
// single actuator runs exactly the arithmetic it ran before (tests/cpp/dynamics_digest).
//
//   State, Input, kCapacity        the state vector (fixed capacity) and the held input of a sample
//   kMaxChecked                    most values the checks compare (checked_values)
//   kPrimeState                    where the CVODE priming step starts (for its error message)
//   size(s)                        the active state count
//   changed(a, b)                  the held input changed (a restart point for CVODE, FSAL)
//   rhs(s, y, in, ydot)            the right-hand side
//   jacobian(s, y, in, J)          df/dy into a dense column-major n x n array (SUNDIALS' layout)
//   jacobian_rhs(s, y, in, J, f)   both at one state (one evaluation where the system can)
//   tolerances(s, options, atol)   the absolute tolerances (the rig-scaled ones)
//   checked(s), checked_values(s, y, in, v), checked_scales(s, f)
//                                  what the checks compare (output_gap.hpp: dopri5's shadow,
//                                  RK4's companion; the displacements and load-cell forces) and
//                                  their scales (a fraction of which is the least peak they are
//                                  judged against)
//   rk4_substeps(s, dt, options)   the automatic RK4 rule
#pragma once

#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/multi_rig.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/solver_options.hpp"

namespace servohydraulics::detail {

// The divergence guard of the plants: a state beyond these is a failed run, not a result.
constexpr double kMaxDisplacement = 100.0;   // [m]
constexpr double kMaxPressureRatio = 100.0;  // [p_s]

template <class System>
struct OdeSystem;

template <>
struct OdeSystem<Dynamics> {
  using State = servohydraulics::State;
  using Input = Dynamics::Input;
  static constexpr int kCapacity = kMaxStates;
  static constexpr int kMaxChecked = 2;
  static constexpr const char* kPrimeState = "the equilibrium at x = 0, command 0";

  static int size(const Dynamics& d) noexcept { return d.num_states(); }
  //! (The exact Coulomb law's mode as well: a switch of the friction is a jump of the right-hand side.)
  static bool changed(const Input& a, const Input& b) noexcept {
    return a.u != b.u || a.u_rate != b.u_rate || a.sliding != b.sliding;
  }
  static void rhs(const Dynamics& d, const double* y, const Input& in, double* ydot) noexcept { d.rhs(y, in, ydot); }
  static void jacobian(const Dynamics& d, const double* y, const Input& in, double* J) noexcept {
    Jacobian Jl;
    d.jacobian(y, in, Jl);
    column_major(d, Jl, J);
  }
  //! jacobian() and rhs() at one state, from one evaluation of the plant.
  static void jacobian_rhs(const Dynamics& d, const double* y, const Input& in, double* J, double* ydot) noexcept {
    Jacobian Jl;
    d.rhs_jacobian(y, in, ydot, Jl);
    column_major(d, Jl, J);
  }
  //! The active n x n of Jl into J, column-major.
  static void column_major(const Dynamics& d, const Jacobian& Jl, double* J) noexcept {
    const int n = d.num_states();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) J[j * n + i] = Jl[i][j];
  }
  static void tolerances(const Dynamics& d, const SolverOptions& o, double* atol) noexcept {
    absolute_tolerances(d, o, atol);
  }
  static int checked(const Dynamics&) noexcept { return 2; }
  //! The displacement and the load-cell force.
  static void checked_values(const Dynamics& d, const double* y, const Input& in, double* v) noexcept {
    Output o;
    d.outputs(y, in, o);
    v[0] = o.displacement;
    v[1] = o.force;
  }
  //! The rig's displacement and force scales (OutputGap's floor is a fraction of them: a run that
  //! stays near rest is not judged against zero).
  static void checked_scales(const Dynamics& d, double* f) noexcept {
    f[0] = state_scale(d, kX);
    f[1] = state_scale(d, kP) * d.rig().A;
  }
  static int rk4_substeps(const Dynamics& d, double dt, const SolverOptions& o) {
    return rk4_automatic_substeps(d, dt, o);
  }
};

template <>
struct OdeSystem<MultiRig> {
  using State = MultiRig::State;
  using Input = MultiRig::Input;
  static constexpr int kCapacity = MultiRig::kCapacity;
  static constexpr int kMaxChecked = 2 * MultiRig::kMaxActuators;
  static constexpr const char* kPrimeState = "the rest state, commands 0";

  static int size(const MultiRig& r) noexcept { return r.num_states(); }
  static bool changed(const Input& a, const Input& b) noexcept { return a.u != b.u || a.u_rate != b.u_rate; }
  static void rhs(const MultiRig& r, const double* y, const Input& in, double* ydot) noexcept { r.rhs(y, in, ydot); }
  static void jacobian(const MultiRig& r, const double* y, const Input& in, double* J) noexcept {
    r.jacobian(y, in, J, 1, r.num_states());
  }
  static void jacobian_rhs(const MultiRig& r, const double* y, const Input& in, double* J, double* ydot) noexcept {
    jacobian(r, y, in, J);
    rhs(r, y, in, ydot);
  }
  static void tolerances(const MultiRig& r, const SolverOptions& o, double* atol) noexcept {
    for (int k = 0; k < r.num_states(); ++k) atol[k] = o.rtol * o.atol_fraction * r.state_scale(k);
  }
  static int checked(const MultiRig& r) noexcept { return 2 * r.actuators(); }
  //! Every actuator's stroke, then every actuator's load-cell force.
  static void checked_values(const MultiRig& r, const double* y, const Input& in, double* v) noexcept {
    MultiRigOutput o;
    r.outputs(y, in, o);
    const int n = r.actuators();
    for (int i = 0; i < n; ++i) {
      v[i] = o.actuator[static_cast<std::size_t>(i)].stroke;
      v[n + i] = o.actuator[static_cast<std::size_t>(i)].force;
    }
  }
  static void checked_scales(const MultiRig& r, double* f) noexcept {
    const int n = r.actuators();
    for (int i = 0; i < n; ++i) {
      const int p = r.offset(i);  // the actuator's load pressure
      f[i] = r.actuator(i).rig().stroke;
      f[n + i] = r.state_scale(p) * r.actuator(i).rig().A;
    }
  }
  static int rk4_substeps(const MultiRig& r, double dt, const SolverOptions& o) {
    return rk4_automatic_substeps(r, dt, o);
  }
};

}  // namespace servohydraulics::detail
