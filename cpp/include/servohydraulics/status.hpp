// The result of one controller sample: the hot path returns it and never throws.
#pragma once

namespace servohydraulics {

struct Status {
  enum Code : int {
    Ok = 0,
    SolverFailure = 1,  //!< CVODE returned an error flag (see cvode_flag)
    TooMuchWork = 2,    //!< more than max_steps_per_sample internal steps: an overrun
    NonFinite = 3,      //!< the state became NaN or infinite (diverged)
    NotReady = 4,       //!< step() after a failure without reset()
    Stiff = 5,          //!< Dopri5 without stiff_fallback: the sample is stiff for the explicit pair
    Chatter = 6,        //!< the exact Coulomb law switched more than Status::kMaxSwitches times in one sample
  };
  //! Most switches of the exact Coulomb law (stick, slip, reversal) in one sample (in each part of a
  //! sample that a command delay splits).
  static constexpr int kMaxSwitches = 64;
  Code code = Ok;
  int cvode_flag = 0;      //!< CVODE/ARKODE return flag when code != Ok
  double t = 0.0;          //!< time reached [s] (where the failure happened)
  int internal_steps = 0;  //!< CVODE internal steps taken in this sample (or RK4 substeps)
  int rhs_evals = 0;       //!< right-hand-side evaluations in this sample
  bool restarted = false;  //!< CVodeReInit was called at the start of this sample
  bool stiff = false;      //!< Dopri5: the sample was stiff for the explicit pair and CVODE integrated it
  //! The result is kept, the code stays Ok, the flag says it is not to be trusted.  Rk4: the result's
  //! displacement or force departs from a companion run at twice the substeps by more than
  //! rk4_flag_rtol of the run's peak.  Dopri5: a sample of a run that has turned stiff where a
  //! tighter shadow run does not confirm the result to the default's stated accuracy
  //! (dopri5_integrator.hpp, kVerifyTolerance of the run's peak displacement and force).
  bool inaccurate = false;
  //! The check's gap over its bound (<= 1: within; 0 where nothing was checked): Rk4 against its
  //! companion, Dopri5 against its shadow, relative to the run's peak up to this sample
  double error_estimate = 0.0;
  //! The run's verdict so far: the largest gap since the reset relative to the peaks so far, over
  //! the same bound (0 while nothing was checked).  The last sample's is the run's
  //! (RunSummary::error_estimate): measured against the run's peaks, as the stated accuracy is;
  //! a sample's flag, against the peak up to that sample, fires also where a later, larger signal
  //! makes an early error small (the start of a run, the onset of a step).
  double run_error_estimate = 0.0;

  bool ok() const noexcept { return code == Ok; }
  const char* message() const noexcept;  //!< static text for the code
};

}  // namespace servohydraulics
