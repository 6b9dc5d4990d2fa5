// Digital compensators of the two real-time test methods (Zhao et al. 2003,
// Figs 1 and 7), run at the controller rate.  Each is a small stateful object:
// construction validates (throws Error) and allocates; reset() and step() are
// noexcept and allocation-free.
#pragma once

#include <cstddef>
#include <vector>

#include "servohydraulics/enum_name.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/rig.hpp"

namespace servohydraulics {

//! First-order phase-lead network H(s) = (T s + 1)/(alpha T s + 1) (Fig 1, Table I),
//! discretised with the bilinear (Tustin) transform prewarped at w_p:
//!   s <- c (z - 1)/(z + 1),  c = w_p / tan(w_p dt / 2),
//! so that the discrete response equals H(j w_p) exactly and the DC gain is 1.
//! The default prewarping frequency is the frequency of maximum phase lead,
//! w_m = 1/(T sqrt(alpha)) (clamped below Nyquist).  T = 0 is the identity.
class PhaseLead {
 public:
  //! T [s] >= 0, 0 < alpha <= 1, dt [s] > 0, prewarp [rad/s]: 0 = w_m, < 0 = plain Tustin (c = 2/dt).
  PhaseLead(double T, double alpha, double dt, double prewarp = 0.0);
  PhaseLead() noexcept = default;  //!< identity

  //! Restart at steady state with constant input u0 (output u0).
  void reset(double u0 = 0.0) noexcept;
  //! y_k = (b0 u_k + b1 u_{k-1} - a1 y_{k-1}) (direct feedthrough).
  double step(double u) noexcept;
  //! Steps over a whole array from the current state (y may alias u).
  void filter(const double* u, double* y, std::size_t n) noexcept;

  double T() const noexcept { return T_; }
  double alpha() const noexcept { return alpha_; }
  double prewarp() const noexcept { return wp_; }  //!< prewarping frequency used [rad/s] (0: plain Tustin)
  //! Coefficients of y_k + a1 y_{k-1} = b0 u_k + b1 u_{k-1}.
  double b0() const noexcept { return b0_; }
  double b1() const noexcept { return b1_; }
  double a1() const noexcept { return a1_; }

 private:
  double T_ = 0.0, alpha_ = 1.0, wp_ = 0.0;
  double b0_ = 1.0, b1_ = 0.0, a1_ = 0.0;
  double u1_ = 0.0, y1_ = 0.0;
};

//! Pure delay of N controller samples (ring buffer allocated at construction).
//! N = 0 passes through; N = 1 is the optional one-sample compute delay.
class SampleDelay {
 public:
  explicit SampleDelay(int samples = 0);
  void reset(double u0 = 0.0) noexcept;  //!< fill the buffer with u0
  double step(double u) noexcept;        //!< returns u from N samples ago
  int samples() const noexcept { return static_cast<int>(buf_.size()); }

 private:
  std::vector<double> buf_;
  std::size_t head_ = 0;
};

//! Velocity feedback compensation of effective force testing (Fig 1a, Eqs 9-10).
//! The natural velocity feedback takes the flow A v out of the actuator (Eq 4);
//! the compensator adds a command du that puts it back.
//!
//! Linear: through the inverse of the linearised forward path (Eqs 6, 7, 1):
//!   du = A v / (K_v K_s C_F G_p)                                      [N]
//! Nonlinear (Fig 4c): the servo controller turns the force error e = u - F into
//! the spool opening x_e = K_s C_F G_p e.  The linear design (Eq 10) wants the
//! total valve flow Q_d = K_v x_e + A v.  Inverting Eq (3) for the total opening,
//!   x_t = g^-1( Q_d / (K_v sqrt(1 - sgn(Q_d) p / p_s)) ),  clamped to +-x_v_max,
//! and removing the force-error part gives du = (x_t - x_e) / (K_s C_F G_p).
//! The flow-gain curve g and the pressure factor come from the *model* rig given
//! at construction (the controller's knowledge, which may differ from the
//! plant's), through Dynamics::flow_gain / FlowCurve::inverse /
//! Dynamics::pressure_factor, so the model's Effects switches apply.
//! The phase lead (T = 5 ms, alpha = 0.1; Table I's T_d-hat) acts on the
//! measured velocity before the map, which for the linear map is the same as
//! leading the compensation signal (Fig 1a): the velocity is predicted by the
//! valve's delay and converted at the current force error and pressure.
class VelocityFeedbackCompensator {
 public:
  enum class Kind { None, Linear, Nonlinear };

  //! model: the controller's rig model (force-control C_F is used); lead_T [s], alpha, dt [s].
  VelocityFeedbackCompensator(const Rig& model, Kind kind, double lead_T, double alpha, double dt);

  void reset() noexcept;
  //! velocity [m/s], force_error e = command - load-cell force [N], pressure [Pa];
  //! returns the compensation du to add to the force command [N].
  double step(double velocity, double force_error, double pressure) noexcept;

  Kind kind() const noexcept { return kind_; }
  double forward_gain() const noexcept { return Kf_; }  //!< K_v K_s C_F G_p [m^3/(s N)]
  const PhaseLead& lead() const noexcept { return lead_; }
  double last_opening() const noexcept { return x_total_; }  //!< nonlinear: last total opening x_t [-]

 private:
  Dynamics model_;
  Kind kind_;
  PhaseLead lead_;
  double A_, K_v_, Kx_, Kf_, x_v_max_;  // Kx_ = K_s C_F G_p [1/N]
  double x_total_ = 0.0;
};
//! Velocity feedback compensation by name ("none" is None_ in Python, where None is a keyword).
inline constexpr EnumName<VelocityFeedbackCompensator::Kind> kCompensationNames[] = {
    {VelocityFeedbackCompensator::Kind::None, "none", "None_"},
    {VelocityFeedbackCompensator::Kind::Linear, "linear", "Linear"},
    {VelocityFeedbackCompensator::Kind::Nonlinear, "nonlinear", "Nonlinear"},
};
static_assert(in_enum_order(kCompensationNames), "kCompensationNames: one row per enumerator, in order");

}  // namespace servohydraulics
