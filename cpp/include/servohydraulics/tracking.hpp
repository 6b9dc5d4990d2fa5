// The tracking compensator of a hybrid simulation: the block between what the
// loop wants the actuator to do (the target) and the command it sends.  One
// interface for every loop of the project (EFT, RPsD, the RTHS benchmark) and
// for a user's own controller:
//
//   TrackingInput in;               // filled by the loop at t_k
//   in.desired = target; in.measured = x_meas; in.measured_force = f_meas; ...
//   double u = controller.command(in);   // hold u over [t_k, t_k + dt]
//
// What "desired" is depends on the loop's control mode: a displacement [m] in
// displacement control (RPsD: the solver's d_{k+1}; the RTHS benchmark: the
// numerical substructure's interface displacement y_n(1)), a force [N] in force
// control (EFT: the effective force P_eff = -m a_g).  The loop fills every field
// it has; a compensator reads what it needs.
//
// Implementations: the paper's amplitude compensation (AmplitudeLead, the RPsD
// default) and velocity feedback compensation (VelocityFeedbackTracking, the EFT
// default), and the predictive compensators of the RTHS field (the benchmark's
// sample controller, polynomial extrapolation, ATS, model-based feedforward; their
// rths:: names are aliases, rths/tracking.hpp).  Those read the desired and
// measured displacements through their A/D converters and write the command
// through their D/A converter (converters.hpp; the benchmark's 18-bit converters
// by default).
//
// Construct once (validates, throws Error); reset() and command() are noexcept
// and allocation-free.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Dense>

#include "servohydraulics/compensators.hpp"
#include "servohydraulics/converters.hpp"

namespace servohydraulics {

//! What a tracking compensator reads at t_k.
struct TrackingInput {
  double desired = 0.0;               //!< target: displacement [m] (displacement control) or force [N] (force control)
  double desired_velocity = 0.0;      //!< rate of the target displacement (numerical substructure's interface) [m/s]
  double desired_acceleration = 0.0;  //!< its acceleration (relative) [m/s^2]
  double measured = 0.0;              //!< x_m, measured specimen displacement [m]
  double measured_force = 0.0;        //!< measured specimen force (load cell) [N]
  double measured_velocity = 0.0;     //!< measured actuator velocity [m/s]
  double measured_pressure = 0.0;     //!< measured load pressure p = p_1 - p_2 [Pa]
};

//! The interface: reset() to rest, command() once per sample.
class TrackingController {
 public:
  virtual ~TrackingController() = default;
  virtual void reset() noexcept = 0;
  //! The command to hold over [t_k, t_k + dt]: displacement [m] or force [N], the target's unit.
  virtual double command(const TrackingInput& in) noexcept = 0;
};

//! The paper's amplitude compensation of RPsD (Fig 1b): the phase lead
//! (T_d s + 1)/(alpha T_d s + 1) on the target displacement, u = H(desired)
//! (compensators.hpp PhaseLead; T_d = 68 ms, alpha = 0.1 by default; T = 0 passes through).
class AmplitudeLead final : public TrackingController {
 public:
  AmplitudeLead(double T, double alpha, double dt) : lead_(T, alpha, dt) {}
  void reset() noexcept override { lead_.reset(0.0); }
  double command(const TrackingInput& in) noexcept override { return lead_.step(in.desired); }
  const PhaseLead& lead() const noexcept { return lead_; }

 private:
  PhaseLead lead_;
};

//! The paper's velocity feedback compensation of EFT (Fig 1a, Eqs 9-10): the
//! force command plus the compensation du of the measured velocity, at the
//! force error desired - measured_force and the measured pressure:
//! u = desired + du (compensators.hpp VelocityFeedbackCompensator).
class VelocityFeedbackTracking final : public TrackingController {
 public:
  //! model: the controller's rig model; lead_T [s], alpha, dt [s] (Table I: 5 ms, 0.1, 0.5 ms).
  VelocityFeedbackTracking(const Rig& model, VelocityFeedbackCompensator::Kind kind, double lead_T, double alpha,
                           double dt)
      : vfc_(model, kind, lead_T, alpha, dt) {}
  void reset() noexcept override { vfc_.reset(); }
  double command(const TrackingInput& in) noexcept override {
    du_ = vfc_.step(in.measured_velocity, in.desired - in.measured_force, in.measured_pressure);
    return in.desired + du_;
  }
  const VelocityFeedbackCompensator& compensator() const noexcept { return vfc_; }
  double last_compensation() const noexcept { return du_; }  //!< du of the last command [N]

 private:
  VelocityFeedbackCompensator vfc_;
  double du_ = 0.0;
};

//! (b1 s + b0) / (a1 s + a0) discretised with Tustin (no prewarping) at h:
//! y_k = -d1 y_{k-1} + n0 u_k + n1 u_{k-1}, zero initial state.
class TustinFirstOrder {
 public:
  TustinFirstOrder() = default;
  TustinFirstOrder(double b1, double b0, double a1, double a0, double h);
  void reset() noexcept { u1_ = y1_ = 0.0; }
  double operator()(double u) noexcept {
    const double y = -d1_ * y1_ + n0_ * u + n1_ * u1_;
    u1_ = u;
    y1_ = y;
    return y;
  }
  double n0() const noexcept { return n0_; }
  double n1() const noexcept { return n1_; }
  double d1() const noexcept { return d1_; }

 private:
  double n0_ = 1.0, n1_ = 0.0, d1_ = 0.0, u1_ = 0.0, y1_ = 0.0;
};

//! The converters around a controller: A/D on each input, D/A on the command.
struct ControllerConverters {
  Converter ad = benchmark_converter(Converter::Kind::AnalogToDigital);
  Converter da = benchmark_converter(Converter::Kind::DigitalToAnalog);
  void validate() const;
};

//! PI on the tracking error, G_C(s) = Kp + Ki / s (paper Eq 23).
struct PiGains {
  double Kp = 2.0;   //!< [-]
  double Ki = 95.0;  //!< [1/s]
  void validate() const;
};

// ---------------------------------------------------------------------------
// The benchmark's sample controller (Silva et al. 2020, Sec 5.2-5.3, Fig 15)
// ---------------------------------------------------------------------------

struct SampleControllerConfig {
  double dt = 1.0 / 4096.0;  //!< [s]
  PiGains pi;
  //! Phase lead on the reference path, G_T(s) = (lead_b1 s + lead_b0) / (s + lead_a0)
  //! (Eq 24 to full precision, BENCHMARK.md Sec 7; DC gain lead_b0 / lead_a0 = 1).
  double lead_b1 = 50.83163360273612;
  double lead_b0 = 8570.397339444286;
  double lead_a0 = 8570.397339444286;
  ControllerConverters converters;
  void validate() const;
};

//! r = AD(y_n1); y_p = DA(G_T r); e = AD(y_p - x_m); u = DA(PI e).
class SampleController final : public TrackingController {
 public:
  explicit SampleController(const SampleControllerConfig& config = {});
  void reset() noexcept override;
  double command(const TrackingInput& in) noexcept override;
  const SampleControllerConfig& config() const noexcept { return cfg_; }
  const TustinFirstOrder& lead() const noexcept { return lead_; }
  const TustinFirstOrder& pi() const noexcept { return pi_; }

 private:
  SampleControllerConfig cfg_;
  TustinFirstOrder lead_, pi_;
};

// ---------------------------------------------------------------------------
// Predictive compensators: u = DA(feedforward prediction + PI(AD(y_n1) - AD(x_m)))
// ---------------------------------------------------------------------------

//! Polynomial extrapolation (Horiuchi, Inoue, Konno, Namita 1999, Earthquake
//! Eng. Struct. Dyn. 28:1121-1141): the command is the desired displacement
//! tau ahead, from the polynomial of the given order through the last order + 1
//! desired values spaced stride samples apart (Lagrange extrapolation), divided
//! by the plant's static gain; plus the PI on the tracking error.
struct PolynomialConfig {
  double dt = 1.0 / 4096.0;  //!< [s]
  double tau = 0.0;          //!< lead time [s] (e.g. the plant's delay, plant_delay())
  //! polynomial order, 1..5.  First order by default: the gain at Nyquist is the sum of the
  //! weights' magnitudes, 1 + 2 tau / (stride dt) = 13.8 for the benchmark's 25.1 ms lead;
  //! order 2 gives 109, order 3 at stride 32 gives 128, and both lose perturbed benchmark
  //! plants (benchmarks/rths_polynomial_study.py).
  int order = 1;
  int stride = 16;           //!< samples between the points of the fit (>= 1)
  double static_gain = 1.0;  //!< the plant's DC gain (the command is divided by it)
  PiGains pi;                //!< feedback (Kp = Ki = 0: feedforward only)
  ControllerConverters converters;
  void validate() const;
};

class PolynomialExtrapolation final : public TrackingController {
 public:
  explicit PolynomialExtrapolation(const PolynomialConfig& config);
  void reset() noexcept override;
  double command(const TrackingInput& in) noexcept override;
  const std::vector<double>& weights() const noexcept { return w_; }  //!< on y(t_k - i stride dt), i = 0..order

 private:
  PolynomialConfig cfg_;
  std::vector<double> w_, hist_;  // hist_: ring buffer of order*stride + 1 desired values
  std::size_t head_ = 0;
  TustinFirstOrder pi_;
};

//! Adaptive time series compensation (Chae, Kazemibidokhti, Ricles 2013,
//! Earthquake Eng. Struct. Dyn. 42:1697-1715): u_k = a0 x_d + a1 x_d' + a2 x_d''
//! with (a0, a1, a2) identified online by least squares from the command and
//! the measured displacement and its derivatives (u ~ a0 x_m + a1 x_m' + a2 x_m'',
//! exponentially weighted window, both signals through the same low-pass
//! filter, central differences), within bounds; plus the PI on the tracking error.
struct AtsConfig {
  double dt = 1.0 / 4096.0;  //!< [s]
  std::array<double, 3> initial{1.0, 0.0, 0.0};  //!< a0 [-], a1 [s], a2 [s^2] at the start
  std::array<double, 3> lower{0.5, 0.0, -1e-3};  //!< bounds of the coefficients
  std::array<double, 3> upper{2.0, 0.1, 1e-3};
  double window = 2.0;         //!< time constant of the exponential window [s]
  double filter_hz = 20.0;     //!< critically damped 2nd-order low-pass on u and x_m before the fit [Hz]
  int update_every = 64;       //!< samples between coefficient updates
  double min_amplitude = 1e-4; //!< no update until the filtered RMS of x_m over the window exceeds this [m]
  PiGains pi;
  ControllerConverters converters;
  void validate() const;
};

class AdaptiveTimeSeries final : public TrackingController {
 public:
  explicit AdaptiveTimeSeries(const AtsConfig& config);
  void reset() noexcept override;
  double command(const TrackingInput& in) noexcept override;
  const std::array<double, 3>& coefficients() const noexcept { return a_; }

 private:
  void learn(double u, double xm) noexcept;
  AtsConfig cfg_;
  std::array<double, 3> a_;
  TustinFirstOrder pi_, lpu1_, lpu2_, lpx1_, lpx2_;
  Eigen::Matrix3d R_;
  Eigen::Vector3d r_;
  double xf_[3] = {0, 0, 0}, uf_[2] = {0, 0}, lambda_ = 1.0, energy_ = 0.0, weight_ = 0.0;
  long k_ = 0;
  double u_prev_ = 0.0;
};

//! Model-based feedforward-feedback (Phillips and Spencer 2013, J. Struct. Eng.
//! 139(7):1205-1214): the feedforward is the inverse of the plant model's
//! low-frequency part, u_ff = (A0 x_d + A1 x_d' + A2 x_d'' + A3 x_d''') / b0
//! (x_d' and x_d'' from the numerical substructure, x_d''' their backward
//! difference), the feedback a PI on the tracking error (their LQG is replaced by
//! the benchmark's PI).
struct ModelBasedConfig {
  double dt = 1.0 / 4096.0;          //!< [s]
  std::array<double, 4> coefficients{1.0, 0.0, 0.0, 0.0};  //!< A0/b0 [-], A1/b0 [s], A2/b0 [s^2], A3/b0 [s^3]
  PiGains pi;
  ControllerConverters converters;
  void validate() const;
  //! The coefficients from a plant model G_P = b0 / (A5 s^5 + ... + A0) (denominator A5 .. A0),
  //! up to the given order (0..3): A_i / b0.  rths::model_based_config(plant) for the benchmark plant.
  static ModelBasedConfig from_denominator(const std::array<double, 6>& A, double b0, int order = 2);
};

class ModelBasedCompensator final : public TrackingController {
 public:
  explicit ModelBasedCompensator(const ModelBasedConfig& config);
  void reset() noexcept override;
  double command(const TrackingInput& in) noexcept override;

 private:
  ModelBasedConfig cfg_;
  TustinFirstOrder pi_;
  double a_prev_ = 0.0;
  bool first_ = true;
};

}  // namespace servohydraulics
