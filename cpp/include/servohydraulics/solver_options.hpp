// How the plant is integrated across one controller sample (the ODE integrator,
// not the structural integration scheme of Eq 15).
#pragma once

#include <array>

#include "servohydraulics/state.hpp"

namespace servohydraulics {

struct SolverOptions {
  enum class Method {
    CvodeBdf,  //!< CVODE, BDF, Newton with the analytic dense Jacobian (reference, default)
    Rk4,       //!< classical fixed-step Runge-Kutta, rk4_substeps per sample (real-time option)
  };
  enum class Restart {
    OnInputChange,  //!< CVodeReInit when the held command changes (ZOH jump): safest
    Never,          //!< keep the BDF history across samples (the sample end is a stop time, never straddled)
  };
  Method method = Method::CvodeBdf;
  Restart restart = Restart::OnInputChange;
  double rtol = 1e-6;                 //!< CVODE relative tolerance [-]
  //! CVODE absolute tolerance = rtol * atol_scale[i]: [m, m/s, Pa, -, 1/s, m]
  std::array<double, kNumStates> atol_scale{1e-3, 1e-2, 1e5, 1e-2, 1.0, 1e-6};
  int max_order = 5;                  //!< BDF maximum order
  long max_steps_per_sample = 2000;   //!< cap on CVODE internal steps in one step(); then TooMuchWork
  double max_internal_step = 0.0;     //!< CVODE hmax [s], 0 = no limit
  //! Rk4: substeps per controller sample; 0 = automatic (rk4_automatic_substeps in
  //! plant.hpp): the fewest with h * rho(J) <= rk4_h_rho, rho the spectral radius
  //! of the Jacobian at the equilibrium (where friction is steepest), chosen at
  //! construction; with LuGre friction also h sigma_0 v_ref / F_c <= rk4_h_rho.
  int rk4_substeps = 0;
  double rk4_h_rho = 1.0;             //!< Rk4 automatic substeps: bound on h * rho(J) (stability limit ~2.8)
  //! Rk4 automatic substeps with LuGre: the sliding speed v_ref [m/s] that bounds the
  //! bristle rate; 0 = the no-load actuator speed K_v g(x_v_max) / A (1 m/s in free mode).
  double rk4_v_ref = 0.0;

  //! Throws Error naming the first invalid field.
  void validate() const;
};

}  // namespace servohydraulics
