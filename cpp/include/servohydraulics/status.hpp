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

}  // namespace servohydraulics
