#include "servohydraulics/solver_options.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

void SolverOptions::validate() const {
  require(std::isfinite(rtol) && rtol > 0.0 && rtol < 1.0, "rtol", rtol, "must be in (0, 1)");
  for (double s : atol_scale) require(std::isfinite(s) && s > 0.0, "atol_scale", s, "must be finite and > 0");
  require(max_order >= 1 && max_order <= 5, "max_order", max_order, "BDF order must be 1..5");
  require(max_steps_per_sample >= 1, "max_steps_per_sample", static_cast<double>(max_steps_per_sample), "must be >= 1");
  require(std::isfinite(max_internal_step) && max_internal_step >= 0.0, "max_internal_step", max_internal_step,
          "must be finite and >= 0 (0 = no limit)");
  require(rk4_substeps >= 0, "rk4_substeps", rk4_substeps, "must be >= 1, or 0 for automatic");
  require(std::isfinite(rk4_h_rho) && rk4_h_rho > 0.0 && rk4_h_rho <= 2.5, "rk4_h_rho", rk4_h_rho,
          "must be in (0, 2.5] (RK4 is unstable past |h lambda| ~ 2.8)");
  require(std::isfinite(rk4_v_ref) && rk4_v_ref >= 0.0, "rk4_v_ref", rk4_v_ref,
          "must be finite and >= 0 [m/s] (0 = the no-load actuator speed)");
}

}  // namespace servohydraulics
