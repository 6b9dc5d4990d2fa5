// Internal: the plant's default integrator, the Dormand-Prince 5(4) embedded
// Runge-Kutta pair with error control inside each controller sample (the
// sample is the maximum step; first-same-as-last within a sample and across
// samples while the held input and the state are unchanged), and an automatic
// switch to CVODE for a sample where the pair turns stiff, checked by a shadow
// CVODE at a tighter tolerance that flags the samples it cannot vouch for.
#pragma once

#include <memory>

#include "detail/cvode_integrator.hpp"
#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"
#include "servohydraulics/status.hpp"

namespace servohydraulics::detail {

//! The pair over a system of the OdeSystem interface (ode_system.hpp): the single-actuator plant
//! (Dopri5Integrator) or the coupled multi-actuator rig.
template <class System>
class BasicDopri5Integrator {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! Creates the CVODE fallback (if options.stiff_fallback) primed from y_prime; may throw Error.
  BasicDopri5Integrator(const System& sys, double dt, const SolverOptions& options, const State& y_prime);

  void reset(const State& y, double t) noexcept;
  //! Integrates from t to t_next with the input held.  Stiffness (more than stiff_steps steps in the
  //! sample, a step below 1e-12 of the sample, or a non-finite stage) redoes the sample from its start
  //! with CVODE (Status::stiff) and stays on CVODE for kImplicitHold samples; without the fallback it
  //! returns Status::Stiff.  More than max_steps_per_sample steps: TooMuchWork.
  //! With the fallback, a stiff sample is verified: a shadow state, started from the state at the
  //! first stiff sample, is integrated by a second CVODE at rtol / kShadowTighten over every sample
  //! up to kShadowFollow samples after the last stiff one; where its displacements or load-cell
  //! forces (Sys::checked_values) differ from the result's by more than kShadowGap x
  //! kVerifyTolerance of the run's peak so far, the sample is flagged (Status::inaccurate): the
  //! result is kept but may be off by more than kVerifyTolerance (on high-gain rigs with stiff oil
  //! the loop amplifies the integration error up to a million times).
  Status advance(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;

  long total_steps() const noexcept { return steps_done_; }
  long total_rhs_evals() const noexcept { return rhs_done_; }
  long total_restarts() const noexcept { return restarts_; }
  long total_stiff_samples() const noexcept { return stiff_samples_; }

  //! Samples that stay on CVODE after a stiff one before the pair is tried again.
  static constexpr int kImplicitHold = 16;
  //! The accuracy the default states (of the run's peak displacement and force), which the
  //! verification of stiff samples checks, and the factor by which the shadow's tolerance is looser.
  static constexpr double kVerifyTolerance = 1e-3;
  static constexpr double kShadowTighten = 10.0;
  //! The gap (in kVerifyTolerance) beyond which a sample is flagged.  The result's error e grows by
  //! 2x-40x per decade of rtol on the stiff random rigs (evaluation/accuracy_random_rigs.py), so the
  //! shadow is off by e/2 at most and the gap is between e/2 and 3e/2: a gap above half the
  //! tolerance says the result may miss it.  (A looser shadow cannot tell: with errors that grow
  //! 2x or 40x per decade its gap is 1x or 39x the result's error.)
  static constexpr double kShadowGap = 0.5;
  //! Samples after the last stiff one over which the shadow still follows the (explicit) result: an
  //! error made in a stiff stretch and amplified after it shows there.
  static constexpr int kShadowFollow = 32;

 private:
  enum class Outcome { Done, Stiff, TooMuchWork };
  Outcome explicit_sample(const System& sys, const Input& in, State& y, double& t, double t_next,
                          Status& st) noexcept;
  //! One trial step of size h from (y, k1): the 5th-order solution in y5, its slope in k7, and the
  //! weighted RMS norm of the embedded error estimate (returned).
  double trial_step(const System& sys, const Input& in, const State& y, double h, State& y5) noexcept;
  Status implicit_sample(const System& sys, const Input& in, State& y, double& t, double t_next) noexcept;
  //! Advances the shadow over the sample just done from t_start (starting it at y_start if it is not
  //! following the run) to t_next, compares it with the result y and flags st.
  void verify(const System& sys, const Input& in, const State& y_start, double t_start, const State& y,
              double t_next, Status& st) noexcept;
  //! Raises the run's peaks of the checked values to y's.
  void track_peaks(const System& sys, const Input& in, const State& y) noexcept;

  int n_;
  double rtol_;
  double atol_[Sys::kCapacity];
  long max_steps_;
  int stiff_steps_;
  double dt_;
  std::unique_ptr<BasicCvodeIntegrator<System>> implicit_;  // the stiff fallback, or null
  std::unique_ptr<BasicCvodeIntegrator<System>> shadow_;    // its check at rtol / kShadowTighten, or null
  State shadow_y_{};           // the shadow's state at the current time, while shadow_live_
  bool shadow_live_ = false;   // the shadow follows the run (from a stiff sample on)
  int since_stiff_ = 0;        // samples since the last stiff one
  int checked_ = 0;            // values the shadow compares (Sys::checked)
  double peak_[Sys::kMaxChecked] = {};   // the run's largest |value| of each so far
  double floor_[Sys::kMaxChecked] = {};  // their least values in the check (a run at rest)
  State k_[7];         // the stages; k_[0] is the slope at the current state
  bool fsal_ = false;  // k_[0] is f(y, in) of the state and input the next sample starts from
  Input fsal_in_{};
  double h_;           // the step the controller proposes next [s]
  int hold_ = 0;       // samples left on CVODE
  long steps_done_ = 0, rhs_done_ = 0, restarts_ = 0, stiff_samples_ = 0;
};

//! The single-actuator plant's default integrator.
using Dopri5Integrator = BasicDopri5Integrator<Dynamics>;

}  // namespace servohydraulics::detail
