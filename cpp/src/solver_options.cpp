#include "servohydraulics/solver_options.hpp"

#include <algorithm>
#include <cmath>

#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/error.hpp"
#include "detail/math.hpp"

namespace servohydraulics {

void SolverOptions::validate() const {
  const int m = static_cast<int>(method), r = static_cast<int>(restart);
  require(m >= static_cast<int>(Method::Dopri5) && m <= static_cast<int>(Method::Ros2), "method", m,
          "is not a SolverOptions::Method (0 dopri5, 1 cvode, 2 rk4, 3 arkode_erk, 4 arkode_dirk, 5 ros2)");
  require(r >= static_cast<int>(Restart::OnInputChange) && r <= static_cast<int>(Restart::Never), "restart", r,
          "is not a SolverOptions::Restart (0 on_input_change, 1 never)");
  require(std::isfinite(rtol) && rtol > 0.0 && rtol < 1.0, "rtol", rtol, "must be in (0, 1)");
  require(std::isfinite(atol_fraction) && atol_fraction > 0.0 && atol_fraction <= 1.0, "atol_fraction",
          atol_fraction, "must be in (0, 1] (a fraction of each state's scale)");
  require(max_order >= 1 && max_order <= 5, "max_order", max_order, "BDF order must be 1..5");
  require(max_steps_per_sample >= 1 && max_steps_per_sample <= 10000000, "max_steps_per_sample",
          static_cast<double>(max_steps_per_sample), "must be in 1..10000000");
  require(std::isfinite(max_internal_step) && max_internal_step >= 0.0, "max_internal_step", max_internal_step,
          "must be finite and >= 0 (0 = no limit)");
  require(stiff_steps >= 2 && stiff_steps <= 100000, "stiff_steps", stiff_steps, "must be in 2..100000");
  require(rk4_substeps >= 0 && rk4_substeps <= kMaxSubsteps, "rk4_substeps", rk4_substeps,
          "must be in 1..100000, or 0 for automatic");
  require(std::isfinite(rk4_h_rho) && rk4_h_rho > 0.0 && rk4_h_rho <= 2.5, "rk4_h_rho", rk4_h_rho,
          "must be in (0, 2.5] (RK4 is unstable past |h lambda| ~ 2.8)");
  require(std::isfinite(rk4_v_ref) && rk4_v_ref >= 0.0, "rk4_v_ref", rk4_v_ref,
          "must be finite and >= 0 [m/s] (0 = the no-load actuator speed)");
  require(std::isfinite(rk4_flag_rtol) && rk4_flag_rtol >= 0.0 && rk4_flag_rtol < 1.0, "rk4_flag_rtol",
          rk4_flag_rtol, "must be in [0, 1) (a fraction of the run's peaks; 0 = no check)");
  require(rk4_max_refinements >= 0 && rk4_max_refinements <= 16, "rk4_max_refinements", rk4_max_refinements,
          "must be in 0..16 (each doubles the substeps of the rest of the run)");
  require(rosenbrock_order == 2 || rosenbrock_order == 4, "rosenbrock_order", rosenbrock_order,
          "must be 2 (Shampine & Reichelt's formula) or 4 (RODAS4)");
  require(ros2_substeps >= 1 && ros2_substeps <= kMaxSubsteps, "ros2_substeps", ros2_substeps,
          "must be in 1..100000");
}

double state_scale(const Dynamics& dyn, int i) noexcept {
  const Rig& r = dyn.rig();
  const bool free = dyn.mode() == ControlMode::Free;
  switch (i) {
    case kX: return r.stroke;
    case kV: {
      if (!free) return dyn.no_load_speed();
      const double w = std::sqrt(r.k / dyn.moving_mass());
      return w > 0.0 ? r.stroke * w : 1.0;
    }
    case kP: {
      const double force = std::max(r.k * r.stroke, r.F_c);
      return force > 0.0 ? std::min(r.p_s, force / r.A) : r.p_s;
    }
    case kXv: return r.x_v_max;
    case kXvDot: return 2.0 * detail::kPi * r.f_v * r.x_v_max;
    case kZ: return r.F_c > 0.0 ? r.F_c / r.sigma_0 : 1e-6;
    default: return dyn.state_scale(i);  // the specimen and in-loop delay states (Dynamics::state_scale)
  }
}

void absolute_tolerances(const Dynamics& dyn, const SolverOptions& opt, double* atol) noexcept {
  for (int i = 0; i < dyn.num_states(); ++i) atol[i] = opt.rtol * opt.atol_fraction * state_scale(dyn, i);
}

}  // namespace servohydraulics
