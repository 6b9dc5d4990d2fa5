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
  //! Rk4: the sample's embedded error estimate exceeded the tolerance (rk4_flag_rtol) after any
  //! refinement: the result is kept, the code stays Ok, the flag says it is not to be trusted.
  bool inaccurate = false;
  double error_estimate = 0.0;  //!< Rk4: the weighted RMS norm of the sample's estimated error (<= 1: within)

  bool ok() const noexcept { return code == Ok; }
  const char* message() const noexcept;  //!< static text for the code
};

}  // namespace servohydraulics
