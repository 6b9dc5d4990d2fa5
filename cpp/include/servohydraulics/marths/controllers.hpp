// Multi-actuator tracking compensators of the maRTHS benchmark (MultiTrackingController,
// multi_actuator.hpp), all in SI at the seam:
//
// * RodeacController: the robust decentralized adaptive compensator of Quiroz, Galmez, Fermandois
//   (Front. Built Environ. 2024) as S3_Controller.m and the RLS-AC blocks define it (BENCHMARK.md
//   section 7), one independent channel per actuator: an FIR inverse model u = theta^T T_k on the last
//   taps of the target, its parameters identified online by recursive least squares from the 20 Hz
//   Butterworth-filtered measured displacement and command.  The model solves the algebraic loop
//   u -> B(z) -> uf -> theta+ -> u silently; it is linear, solved here in closed form.  With P0 = 0 it is
//   the fixed (non-adaptive) FIR compensator.
// * PassThrough: no compensation, u = target.
// * DecentralizedController: one single-actuator TrackingController (tracking.hpp: the sample PI + lead,
//   polynomial extrapolation, ATS, model-based, or a user's) per actuator, each seeing only its own target
//   and measurement.
// * MimoFeedforward: the low-frequency inverse of an identified transfer matrix, u = sum_m E_m r^(m) with
//   E(s) = sum_m E_m s^m the Taylor series of H(s)^-1 at s = 0 (coupled across actuators), plus an optional
//   PI per actuator on the tracking error.
//
// Construction validates (throws Error); reset() and command() are noexcept and allocation-free.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "servohydraulics/converters.hpp"
#include "servohydraulics/iir_filter.hpp"
#include "servohydraulics/marths/plant.hpp"
#include "servohydraulics/multi_actuator.hpp"
#include "servohydraulics/tracking.hpp"

namespace servohydraulics::marths {

//! Most FIR taps of a RoDeAC channel.
inline constexpr int kMaxTaps = 8;
using TapVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxTaps, 1>;
using TapMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxTaps, kMaxTaps>;

//! One actuator's initial FIR parameters and inverse correlation matrix (Initial_parameters.mat).
struct RodeacChannel {
  Eigen::VectorXd theta0;  //!< FIR coefficients on the target taps [-] (theta0_i)
  Eigen::MatrixXd P0;      //!< initial inverse correlation matrix [1/unit^2] (P0_i; 0 = non-adaptive)
};

struct RodeacConfig {
  std::vector<RodeacChannel> channels;  //!< one per actuator
  double forgetting = 1.0;              //!< lambda in (0, 1]
  //! The noise filter B(z) on the measured displacement and the command: butter(4, 20/(fs/2)) at 1024 Hz.
  IirCoefficients filter = butterworth_lowpass(4, 20.0, 1024.0);
  //! The unit of the signals the parameters were identified in [m]: the model's mm (1e-3).
  double unit = 1e-3;
  void validate() const;
};

class RodeacController final : public MultiTrackingController {
 public:
  explicit RodeacController(const RodeacConfig& config);
  std::size_t actuators() const noexcept override { return ch_.size(); }
  void reset() noexcept override;
  void command(const MultiTrackingInput& in, double* u) noexcept override;
  const RodeacConfig& config() const noexcept { return cfg_; }
  //! Actuator i's current FIR parameters (theta after the last command) [-].
  const TapVector& theta(std::size_t i) const noexcept { return ch_[i].theta; }
  const TapMatrix& P(std::size_t i) const noexcept { return ch_[i].P; }

 private:
  struct Channel {
    TapVector theta, X, T, PX, XtP, phi;
    TapMatrix P;
    IirFilter fx, fu;
  };
  RodeacConfig cfg_;
  std::vector<Channel> ch_;
};

//! No compensation: the command is the target (the benchmark's "none").
class PassThrough final : public MultiTrackingController {
 public:
  explicit PassThrough(std::size_t actuators);
  std::size_t actuators() const noexcept override { return n_; }
  void reset() noexcept override {}
  void command(const MultiTrackingInput& in, double* u) noexcept override {
    for (std::size_t i = 0; i < n_; ++i) u[i] = in.desired[i];
  }

 private:
  std::size_t n_;
};

//! One single-actuator compensator per actuator (not owned: they must outlive this object).  Each reads its
//! target, the target's rates and its measurement; no force is measured.  The rates: with dt > 0 the backward
//! differences of the target (first and second) at dt; with dt = 0 the loop's (0 when it gives none).
//! In the maRTHS loop the numerical substructure's own acceleration responds within the sample to the measured
//! noise (the feedback force's mass term is the second difference of the measurement), so a compensator that
//! multiplies it closes a loop of gain ~1/dt^2 and diverges; the differences of the target do not.
class DecentralizedController final : public MultiTrackingController {
 public:
  explicit DecentralizedController(std::vector<TrackingController*> channels, double dt = 0.0);
  std::size_t actuators() const noexcept override { return ch_.size(); }
  void reset() noexcept override;
  void command(const MultiTrackingInput& in, double* u) noexcept override;
  TrackingController& channel(std::size_t i) const noexcept { return *ch_[i]; }
  double dt() const noexcept { return dt_; }

 private:
  std::vector<TrackingController*> ch_;
  double dt_;
  std::vector<BackwardDifference> dv_, da_;
};

struct MimoFeedforwardConfig {
  double dt = 1.0 / 1024.0;  //!< [s]
  //! E_0 .. E_order (N x N): u = E_0 r + E_1 r' + E_2 r'' + E_3 r''' [s^m], the rates by backward differences
  std::vector<Eigen::MatrixXd> coefficients;
  PiGains pi{0.0, 0.0};  //!< feedback on each actuator's tracking error (0, 0: feedforward only)
  void validate() const;
  //! The series of H(s)^-1 from the plant's Taylor coefficients H_m (StateSpace::taylor_coefficients):
  //! E_0 = H_0^-1, E_m = -H_0^-1 sum_{j=1..m} H_j E_{m-j}; order 0 .. 3.  H(0) must be invertible.
  static MimoFeedforwardConfig from_plant(const StateSpace& plant, int order = 2, double dt = 1.0 / 1024.0);
};

//! u = sum_m E_m D^m r + PI(r - x_m), D the backward difference at dt: an FIR on the target's last taps (as
//! RoDeAC's), coupled across the actuators.  Not the loop's target rates: the numerical substructure's
//! acceleration carries the measured noise of the same sample with a gain ~1/dt^2 (DecentralizedController).
//! Order 2 is the default: order 3 (the jerk) destabilises the benchmark's loop (docs/marths-benchmark.md).
class MimoFeedforward final : public MultiTrackingController {
 public:
  explicit MimoFeedforward(const MimoFeedforwardConfig& config);
  std::size_t actuators() const noexcept override { return static_cast<std::size_t>(cfg_.coefficients[0].rows()); }
  void reset() noexcept override;
  void command(const MultiTrackingInput& in, double* u) noexcept override;
  const MimoFeedforwardConfig& config() const noexcept { return cfg_; }

 private:
  MimoFeedforwardConfig cfg_;
  std::vector<BackwardDifference> dr_, ddr_, dddr_;
  std::vector<TustinFirstOrder> pi_;
  Eigen::MatrixXd deriv_;  // N x 4: r, r', r'', r'''
  Eigen::VectorXd out_;
};

}  // namespace servohydraulics::marths
