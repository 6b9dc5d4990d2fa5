// Internal: the plant's default integrator, the Dormand-Prince 5(4) embedded
// Runge-Kutta pair with error control inside each controller sample (the
// sample is the maximum step; first-same-as-last within a sample and across
// samples while the held input and the state are unchanged), and an automatic
// switch to CVODE (or an error-controlled Rosenbrock method) for a sample where
// the pair turns stiff; a run that has turned stiff is checked to its end by a
// shadow run at a tighter tolerance that flags the samples it cannot vouch for.
#pragma once

#include <array>
#include <memory>

#include "detail/cvode_integrator.hpp"
#include "detail/ode_system.hpp"
#include "detail/output_gap.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

//! The pair over a system of the OdeSystem interface (ode_system.hpp): the single-actuator plant
//! (Dopri5Integrator) or the coupled multi-actuator rig, both with the check below (its measure,
//! OutputGap, compares the system's checked values: the displacement and load-cell force of the
//! plant, every actuator's stroke and force of the rig).
template <class System>
class BasicDopri5Integrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! Creates the CVODE fallback (if options.stiff_fallback) primed from y_prime, and with it (if
  //! `checked`: the plants pass options.stiff_check) the check below: a second BasicDopri5Integrator
  //! at rtol / kShadowTighten, unchecked; may throw Error.
  BasicDopri5Integrator(const System& sys, double dt, const SolverOptions& options, const State& y_prime,
                        bool checked = true);

  void reset(const State& y, double t) noexcept;
  //! Goes on from y at t as from a new start (the state was set from outside: the plant's
  //! re-integration to a located friction switch), its counters running on.
  //! (The shadow, if any, starts again from the result at its next check.)
  void restart(const State&, double) noexcept {
    fsal_ = false;
    shadow_live_ = false;
  }
  //! Integrates from t to t_next with the input held.  Stiffness (more than stiff_steps steps in the
  //! sample, a step below 1e-12 of the sample, or a non-finite stage) redoes the sample from its start
  //! with CVODE (Status::stiff) and stays on CVODE for kImplicitHold samples; without the fallback it
  //! returns Status::Stiff.  More than max_steps_per_sample steps: TooMuchWork.
  //! With the fallback, a run that has turned stiff is checked from its first stiff sample to its
  //! end: a shadow state, started from the state at which that sample began, is integrated by a
  //! second BasicDopri5Integrator at rtol / kShadowTighten (its own CVODE fallback at that tolerance) over
  //! every sample, stiff or not; where its displacement or load-cell force (Sys::checked_values)
  //! differs from the result's by more than kShadowGap x kVerifyTolerance of the run's peak so far (OutputGap), the
  //! sample is flagged (Status::inaccurate, Status::error_estimate the gap over that bound): the
  //! result is kept but may be off by more than kVerifyTolerance.  Such rigs (stiff oil, a high loop
  //! gain, the load pressure against the supply) amplify the integration error up to a million
  //! times, in the stiff samples and in the explicit ones between them (a force reversal 85 samples
  //! after a stiff stretch was 3.8e-3 off); a run that never turns stiff pays nothing.
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;

  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return restarts_; }
  long total_stiff_samples() const noexcept { return stiff_samples_; }

  //! Samples that stay on CVODE after a stiff one before the pair is tried again.
  static constexpr int kImplicitHold = 16;
  //! The accuracy the default states (of the run's peak displacement and force), which the check of
  //! a run that turned stiff verifies, and the factor by which the shadow's tolerance is tighter.
  static constexpr double kVerifyTolerance = 1e-3;
  static constexpr double kShadowTighten = 10.0;
  //! The gap (in kVerifyTolerance) beyond which a sample is flagged.  The result's error e falls
  //! by 2x-40x per decade of rtol on the stiff rigs (evaluation/accuracy_random_rigs.py), so the
  //! shadow is off by e/2 at most and the gap is between e/2 and 3e/2: a gap above half the
  //! tolerance says the result may miss it.
  static constexpr double kShadowGap = 0.5;
  //! stiff_rosenbrock: the Rosenbrock steps (accepted and rejected) in one sample past which the sample is
  //! CVODE's after all (its BDF goes to order 5 where a second-order method needs many steps).
  static constexpr long kRosenbrockAttempts = 200;

 private:
  enum class Outcome { Done, Stiff, TooMuchWork };
  Outcome explicit_sample(const System& sys, const Input& in, State& y, double& t, double t_next,
                          Status& st) noexcept;
  //! One trial step of size h from (y, k1): the 5th-order solution in y5, its slope in k7, and the
  //! weighted RMS norm of the embedded error estimate (returned).
  double trial_step(const System& sys, const Input& in, const State& y, double h, State& y5) noexcept;
  Status implicit_sample(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;
  //! The stiff sample by the error-controlled Rosenbrock method (options.stiff_rosenbrock), its step
  //! carried across samples.
  Status rosenbrock_sample(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;
  //! The same by RODAS4 (options.rosenbrock_order 4).
  Status rodas4_sample(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;
  //! The step control both share: equal steps to the sample's end from the proposed h_rosenbrock_, at most
  //! kRosenbrockAttempts; step(size, h, yn, st) makes one trial step from y into yn and returns its weighted
  //! error norm, factor(err) is err^(-1 / (order + 1)).
  template <class Step, class Factor>
  Status rosenbrock_steps(State& y, double& t, double t_next, Step&& step, Factor&& factor) noexcept;
  //! Advances the shadow over the sample just done, from t_start to t_next (starting it at y_start
  //! if it is not following the run yet), compares it with the result y and flags st.
  void verify(const System& sys, const Input& in, const State& y_start, double t_start, const State& y,
              double t_next, Status& st) noexcept;

  int n_;
  double rtol_;
  double atol_[Sys::kCapacity];
  long max_steps_;
  int stiff_steps_;
  double dt_;
  std::unique_ptr<BasicCvodeIntegrator<System>> implicit_;  // the stiff fallback, or null
  std::unique_ptr<BasicDopri5Integrator> shadow_;           // the check at rtol / kShadowTighten, or null
  State shadow_y_{};           // the shadow's state at the current time, while shadow_live_
  bool shadow_live_ = false;   // the shadow follows the run (from its first stiff sample on)
  OutputGap<System> gap_;      // the run's peaks and the gap between the result and the shadow
  State k_[7];         // the stages; k_[0] is the slope at the current state
  State ysti_{};       // the last trial step's stage-6 state (the stiffness test)
  static constexpr int kHairerStiff = 15;  // accepted steps above the boundary that make a sample stiff
  bool fsal_ = false;  // k_[0] is f(y, in) of the state and input the next sample starts from
  Input fsal_in_{};
  double h_;           // the step the controller proposes next [s]
  int hold_ = 0;       // samples left on CVODE
  bool rosenbrock_ = false;  // stiff samples by rosenbrock_sample, not CVODE
  int rosenbrock_order_ = 2;        // 2: rosenbrock_sample, 4: rodas4_sample
  bool stiffness_test_ = false;     // Hairer's stiffness test in explicit_sample (options.stiffness_test)
  bool rosenbrock_failed_ = false;  // it gave up in this stretch of stiff samples: CVODE until it ends
  double h_rosenbrock_;             // the step rosenbrock_sample proposes next [s]
  // rosenbrock_sample's W = I - d h J (column-major, then its LU) and pivots: no allocation
  std::array<double, static_cast<std::size_t>(Sys::kCapacity) * Sys::kCapacity> W_{};
  std::array<int, Sys::kCapacity> piv_{};
  long steps_done_ = 0, rhs_done_ = 0, restarts_ = 0, stiff_samples_ = 0;
};

//! The single-actuator plant's default integrator.
using Dopri5Integrator = BasicDopri5Integrator<Dynamics>;

}  // namespace servohydraulics::detail
