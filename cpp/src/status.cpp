#include "servohydraulics/status.hpp"

namespace servohydraulics {

const char* Status::message() const noexcept {
  switch (code) {
    case Ok: return "ok";
    case SolverFailure: return "the SUNDIALS integrator failed (see cvode_flag)";
    case TooMuchWork: return "overrun: more internal steps than max_steps_per_sample in one sample";
    case NonFinite: return "the state became NaN or infinite (the run diverged)";
    case NotReady: return "step() called after a failure without reset()";
    case Stiff: return "the sample is stiff for the explicit Dormand-Prince pair (stiff_fallback off): use CVODE";
    case Chatter:
      return "the exact Coulomb law (v_stick = 0) switched between stick and slip more than 64 times in one "
             "sample (chatter): use a smaller dt or the regularised law (v_stick > 0)";
  }
  return "?";
}

}  // namespace servohydraulics
