// How the plant is integrated across one controller sample (the ODE integrator,
// not the structural integration scheme of Eq 15).
#pragma once

#include <variant>

#include "servohydraulics/enum_name.hpp"
#include "servohydraulics/state.hpp"

namespace servohydraulics {

class Dynamics;

struct SolverOptions {
  enum class Method {
    Dopri5,      //!< Dormand-Prince 5(4) with error control, the sample as maximum step, FSAL; a sample where
                 //!< it turns stiff is redone by CVODE (stiff_fallback) or reported as Status::Stiff (default)
    CvodeBdf,    //!< CVODE, BDF, Newton with the analytic dense Jacobian (the reference)
    Rk4,         //!< classical fixed-step Runge-Kutta, rk4_substeps per sample, checked by a companion
                 //!< run at twice the substeps that flags a sample (real-time option: fixed cost)
    ArkodeErk,   //!< SUNDIALS ARKODE ARKStep, explicit table (Dormand-Prince 5(4)), error-controlled (reference)
    ArkodeDirk,  //!< SUNDIALS ARKODE ARKStep, implicit DIRK table, Newton with the analytic Jacobian (reference)
    Ros2,        //!< Verwer's ROS2, fixed-step linearly implicit (L-stable, second order), ros2_substeps per
                 //!< sample, the analytic Jacobian each substep: a fixed cost on rigs too stiff for RK4
  };
  enum class Restart {
    OnInputChange,  //!< CVodeReInit when the held command changes (ZOH jump): safest
    Never,          //!< keep the BDF history across samples (the sample end is a stop time, never straddled)
  };
  Method method = Method::Dopri5;
  Restart restart = Restart::OnInputChange;
  //! Relative tolerance of every error-controlled method [-].  1e-8 keeps the default's error within
  //! 1e-3 of the peak displacement and force on random rigs (evaluation/accuracy_random_rigs.py): at
  //! 1e-6 a fifth of them were off by up to 3e-3, at 1e-7 one in 200 by 2e-3 (stick-slip with a
  //! large Coulomb force, where the sticking times amplify the local errors).
  double rtol = 1e-8;
  //! Absolute tolerance of state i = rtol * atol_fraction * state_scale(dynamics, i): the scales follow
  //! the rig (stroke, no-load speed, pressure that makes the rig's force, ...; see state_scale).
  double atol_fraction = 1e-2;
  int max_order = 5;                  //!< BDF maximum order
  long max_steps_per_sample = 2000;   //!< cap on internal steps in one step() (CVODE, ARKODE, Dopri5); then TooMuchWork
  double max_internal_step = 0.0;     //!< CVODE/ARKODE hmax [s], 0 = no limit
  //! Dopri5: a sample that needs more than this many steps (accepted + rejected) is stiff for the
  //! explicit pair: redone by CVODE if stiff_fallback, else Status::Stiff.
  int stiff_steps = 24;
  //! Dopri5: redo a stiff sample with CVODE (Status::stiff set).  A run that has turned stiff is
  //! checked from then to its end by a second run at rtol / 10 (dopri5, CVODE for its stiff
  //! samples) that flags Status::inaccurate where the two differ by more than 5e-4 of the run's
  //! peak displacement or force (dopri5_integrator.hpp); a whole record can be checked from its
  //! start as well (check_record, record.hpp).
  bool stiff_fallback = true;
  //! Dopri5 with stiff_fallback: check a run that turned stiff (the shadow above, and for a whole
  //! record run_record's caller may run check_record: record.hpp).  false: no check (the second run
  //! of check_record itself; a caller that pays for neither).
  bool stiff_check = true;
  //! Dopri5 with stiff_fallback: a stiff sample by an error-controlled Rosenbrock method (the
  //! second-order L-stable Rosenbrock formula of Shampine & Reichelt 1997, MATLAB's ode23s, with its third-order
  //! error estimate; the step carried from sample to sample: a one-step method needs no restart at each
  //! sample's input jump) instead of CVODE's BDF, which restarts at order 1 with a small first step at
  //! every such jump.  A sample it cannot finish in 200 steps is CVODE's.  false: CVODE (the reference).
  bool stiff_rosenbrock = false;
  //! Dopri5 with stiff_rosenbrock: the Rosenbrock method's order, 2 (Shampine & Reichelt's formula above)
  //! or 4 (Hairer & Wanner's RODAS4: six stages, L-stable and stiffly accurate, with an embedded third-order
  //! solution; Solving ODEs II, sec. VI.4): at the tolerances of 1e-6 and below fewer steps a sample.
  int rosenbrock_order = 2;
  //! Dopri5: Hairer's stiffness test as well (Hairer & Wanner, Solving ODEs II, sec. IV.2; their DOPRI5): after
  //! each accepted step h |f(y5) - f(y6)| / |y5 - y6| (y6 the sixth stage's state) estimates h times the
  //! dominant eigenvalue; 15 accepted steps in one sample with it above 3.25 (the method's stability
  //! boundary), never 6 in a row below it between them, and the sample is stiff before stiff_steps steps.
  bool stiffness_test = false;
  //! Rk4: substeps per sample; 0 = automatic (rk4_automatic_substeps in plant.hpp): the fewest with
  //! h * rho(J) <= rk4_h_rho, rho the largest spectral radius of the Jacobian over the operating
  //! states the loop can reach (rest, pressure up to 0.9 p_s, spool at its stops, sliding), chosen at
  //! construction; with LuGre friction also h sigma_0 v_ref / F_c <= rk4_h_rho.  At most kMaxSubsteps.
  int rk4_substeps = 0;
  double rk4_h_rho = 1.0;             //!< Rk4 automatic substeps: bound on h * rho(J) (stability limit ~2.8)
  //! Rk4 automatic substeps with LuGre: the sliding speed v_ref [m/s] that bounds the
  //! bristle rate; 0 = the no-load actuator speed K_v g(x_v_max) / A (1 m/s in free mode).
  double rk4_v_ref = 0.0;
  //! Rk4: the check's tolerance [-], a fraction of the run's peak displacement and load-cell
  //! force.  A companion state is integrated by the same RK4 at twice the substeps (1/16 of the
  //! error; 8 more evaluations of the right-hand side per substep, about 2.5x the cost of a step);
  //! a sample where the result's displacement or force departs from the companion's by more than
  //! this fraction of the peak so far is flagged (Status::inaccurate): "this run probably misses
  //! RK4's stated 1e-2 of the peaks".  0: no companion and no flag (the cheapest step).
  //! 5e-3 is calibrated (docs/benchmarks.md, issue 26): on the wide and random families every run
  //! off by more than 1e-2 is flagged up to 1.4 times this bound (at twice it one of 62 wide and
  //! one of 70 random misses are not); false alarms on about 4 % of the accurate runs.
  double rk4_flag_rtol = 5e-3;
  //! Rk4: a flagged sample ends on the companion's state and the rest of the run takes twice the
  //! substeps (the companion too), up to this many times (0 = flag only: fixed cost); the flagged
  //! sample stays flagged.  Bounded by kMaxSubsteps substeps per sample.
  int rk4_max_refinements = 0;
  //! Ros2: substeps per sample.  No error estimate: its accuracy on a rig is judged against an
  //! error-controlled run (the diagnosis' search_options picks the fewest that agree).
  int ros2_substeps = 4;

  static constexpr int kMaxSubsteps = 100000;  //!< cap on RK4 substeps per sample (work per call)

  //! Throws Error naming the first invalid field.
  void validate() const;
};

//! The integrators by name (sh.solver_options(method=...), the FMU's solver.method, the CLI's --method).
inline constexpr EnumName<SolverOptions::Method> kMethodNames[] = {
    {SolverOptions::Method::Dopri5, "dopri5", "Dopri5"},
    {SolverOptions::Method::CvodeBdf, "cvode", "CvodeBdf"},
    {SolverOptions::Method::Rk4, "rk4", "Rk4"},
    {SolverOptions::Method::ArkodeErk, "arkode_erk", "ArkodeErk"},
    {SolverOptions::Method::ArkodeDirk, "arkode_dirk", "ArkodeDirk"},
    {SolverOptions::Method::Ros2, "ros2", "Ros2"},
};
static_assert(in_enum_order(kMethodNames), "kMethodNames: one row per enumerator, in order");
inline constexpr EnumName<SolverOptions::Restart> kRestartNames[] = {
    {SolverOptions::Restart::OnInputChange, "on_input_change", "OnInputChange"},
    {SolverOptions::Restart::Never, "never", "Never"},
};
static_assert(in_enum_order(kRestartNames), "kRestartNames: one row per enumerator, in order");

//! One field of SolverOptions: the Python attribute, the FMU's variable "solver.<name>" and its
//! fmu.toml key.  The binding (def_readwrite, the object protocol) and the FMU's parameters
//! follow this table, so a new option needs its member and one row here.
struct SolverOptionField {
  const char* name;
  std::variant<SolverOptions::Method SolverOptions::*, SolverOptions::Restart SolverOptions::*,
               double SolverOptions::*, int SolverOptions::*, long SolverOptions::*, bool SolverOptions::*>
      member;
  const char* unit;  //!< "" for none
  const char* doc;
};

inline constexpr SolverOptionField kSolverOptionFields[] = {
    {"method", &SolverOptions::method, "", "the plant's ODE integrator (solver_options.hpp)"},
    {"restart", &SolverOptions::restart, "", "CVODE restart on a command jump"},
    {"rtol", &SolverOptions::rtol, "", "relative tolerance (dopri5, CVODE, ARKODE)"},
    {"atol_fraction", &SolverOptions::atol_fraction, "",
     "absolute tolerance of state i = rtol * atol_fraction * the state's scale"},
    {"max_order", &SolverOptions::max_order, "", "BDF maximum order"},
    {"max_steps_per_sample", &SolverOptions::max_steps_per_sample, "",
     "cap on internal steps in one sample (CVODE, ARKODE, dopri5)"},
    {"max_internal_step", &SolverOptions::max_internal_step, "s", "CVODE/ARKODE maximum step (0 = no limit)"},
    {"stiff_steps", &SolverOptions::stiff_steps, "", "dopri5: steps in one sample beyond which it is stiff"},
    {"stiff_fallback", &SolverOptions::stiff_fallback, "", "dopri5: redo a stiff sample with CVODE"},
    {"stiff_rosenbrock", &SolverOptions::stiff_rosenbrock, "",
     "dopri5: a stiff sample by an error-controlled Rosenbrock method (one-step) instead of CVODE"},
    {"rosenbrock_order", &SolverOptions::rosenbrock_order, "",
     "dopri5 with stiff_rosenbrock: the Rosenbrock method's order, 2 (ode23s's formula) or 4 (RODAS4)"},
    {"stiffness_test", &SolverOptions::stiffness_test, "",
     "dopri5: Hairer's stiffness test (h lambda above 3.25 in 15 accepted steps of a sample) as well"},
    {"stiff_check", &SolverOptions::stiff_check, "",
     "dopri5: check a run that turned stiff against a run at rtol / 10 (flags where it may miss 1e-3)"},
    {"rk4_substeps", &SolverOptions::rk4_substeps, "", "RK4 substeps per sample (0 = automatic)"},
    {"rk4_h_rho", &SolverOptions::rk4_h_rho, "", "RK4 automatic substeps: bound on h * rho(J)"},
    {"rk4_v_ref", &SolverOptions::rk4_v_ref, "m/s",
     "RK4 automatic substeps with LuGre: sliding speed (0 = the no-load actuator speed)"},
    {"rk4_flag_rtol", &SolverOptions::rk4_flag_rtol, "",
     "RK4: flag where a run at twice the substeps departs by more than this of the peaks (0 = no check)"},
    {"rk4_max_refinements", &SolverOptions::rk4_max_refinements, "",
     "RK4: times a flagged sample switches the rest of the run to twice the substeps"},
    {"ros2_substeps", &SolverOptions::ros2_substeps, "", "ROS2 substeps per sample"},
};

//! The magnitude of state i of this rig, the unit of its absolute tolerance: x: the half-stroke;
//! v: the no-load actuator speed K_v g(x_v_max) / A (free mode: stroke sqrt(k / m)); p: the pressure
//! that makes the rig's force scale, min(p_s, k stroke / A) (p_s if k = 0); x_v: x_v_max; x_v_dot:
//! 2 pi f_v x_v_max; z: F_c / sigma_0 (the presliding deflection).  States past the six of the
//! servo-hydraulic plant: 1 (the documented default scale of an added state).
double state_scale(const Dynamics& dynamics, int i) noexcept;

//! atol[i] = options.rtol * options.atol_fraction * state_scale(dynamics, i) for i < num_states():
//! the one home of the absolute tolerances of every error-controlled integrator.
void absolute_tolerances(const Dynamics& dynamics, const SolverOptions& options, double* atol) noexcept;

}  // namespace servohydraulics
