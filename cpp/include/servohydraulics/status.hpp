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
  };
  Code code = Ok;
  int cvode_flag = 0;      //!< CVODE/ARKODE return flag when code != Ok
  double t = 0.0;          //!< time reached [s] (where the failure happened)
  int internal_steps = 0;  //!< CVODE internal steps taken in this sample (or RK4 substeps)
  int rhs_evals = 0;       //!< right-hand-side evaluations in this sample
  bool restarted = false;  //!< CVodeReInit was called at the start of this sample
  bool stiff = false;      //!< Dopri5: the sample was stiff for the explicit pair and CVODE integrated it
  //! The result is kept, the code stays Ok, the flag says it is not to be trusted.  Rk4: the sample's
  //! embedded error estimate exceeded the tolerance (rk4_flag_rtol) after any refinement.  Dopri5:
  //! a stiff sample whose CVODE result a looser shadow run does not confirm to the default's stated
  //! accuracy (dopri5_integrator.hpp, kVerifyTolerance of the run's peak displacement and force).
  bool inaccurate = false;
  //! Rk4: the weighted RMS norm of the sample's estimated error; Dopri5 on a stiff sample: the
  //! shadow's gap over its bound (<= 1: within)
  double error_estimate = 0.0;

  bool ok() const noexcept { return code == Ok; }
  const char* message() const noexcept;  //!< static text for the code
};

}  // namespace servohydraulics
