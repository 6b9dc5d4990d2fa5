// The virtual real-time hybrid simulation loop of the RTHS benchmark (Silva et
// al. 2020, Fig 7; BENCHMARK.md Sec 5.4), with any experimental substructure,
// numerical substructure scheme and tracking controller.  Per sample k:
//   1. x_k = true specimen displacement; y1_k = numerical x_1(t_k)
//   2. w_k ~ N(0,1) (one draw, shared by both channels unless independent_noise)
//      x_m = x_k + sigma_x w_k
//   3. f_e = k_e x_k + c_e D(x)_k + m_e D(D(x))_k (backward differences, 0 at k = 0),
//      f_m = f_e + sigma_f w_k
//   4. f_in = f_m delayed one sample (0 at k = 0)
//   5. u_k = controller.command({y1, y1', y1'', x_m, f_m})
//   6. log row k
//   7. experimental substructure: one sample with u_k held; numerical substructure:
//      one sample with a_g at t_k, t_k + h/2, t_k + h and f_in held.
// Construction validates (throws Error); run() is noexcept and allocation-free
// (the caller provides the row buffers: RthsOutput rows described by kRthsChannels) and
// returns the RunSummary of every loop (record.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/record.hpp"
#include "servohydraulics/rths/benchmark_plant.hpp"
#include "servohydraulics/rths/converters.hpp"
#include "servohydraulics/rths/substructure.hpp"
#include "servohydraulics/rths/tracking.hpp"

namespace servohydraulics::rths {

struct RthsLoopConfig {
  double dt = 1.0 / 4096.0;               //!< [s]; must equal the substructures' sample times
  SensorNoise displacement_noise{1.6e-5};  //!< sigma = sqrt(6.25e-14 * 4096) m (F1 L169)
  SensorNoise force_noise{2.1797614548385793};  //!< sigma = sqrt(1.16e-3 * 4096) N (F1 L177)
  bool independent_noise = false;         //!< false: one w_k for both channels, as the official code
  std::uint64_t seed = 0;                 //!< of the noise generator(s)
  NoiseGenerator generator = NoiseGenerator::MersenneTwister;  //!< which generator draws w_k
  void validate() const;
};

//! Every channel of one RTHS sample (row k: the signals at t_k, before u_k is applied).
struct RthsOutput {
  double time = 0.0;                 //!< t_k [s]
  double ground_acceleration = 0.0;  //!< a_g(t_k), scaled [m/s^2]
  double measured = 0.0;             //!< X_m [m]
  double displacement = 0.0;         //!< true specimen displacement X_int [m]
  double actuator_force = 0.0;       //!< Force_act [N]
  double command = 0.0;              //!< y_gc [m]
  double feedback_force = 0.0;       //!< f_in into the numerical substructure [N]
};

//! The channels of RthsOutput (one table: the bindings' columns and rths.Trial's Response units).
inline constexpr ChannelInfoOf<RthsOutput> kRthsChannels[] = {
    {"time", "s", "time of the sample t_k", &RthsOutput::time},
    {"ground_acceleration", "m/s^2", "ground acceleration a_g(t_k), scaled", &RthsOutput::ground_acceleration},
    {"measured", "m", "measured specimen displacement X_m (with sensor noise)", &RthsOutput::measured},
    {"displacement", "m", "true specimen displacement X_int", &RthsOutput::displacement},
    {"actuator_force", "N", "actuator force Force_act", &RthsOutput::actuator_force},
    {"command", "m", "the controller's command y_gc", &RthsOutput::command},
    {"feedback_force", "N", "f_in into the numerical substructure (measured force, one sample late)",
     &RthsOutput::feedback_force},
};
static_assert(sizeof(RthsOutput) == sizeof(kRthsChannels) / sizeof(kRthsChannels[0]) * sizeof(double),
              "every RthsOutput member is a channel of kRthsChannels");

class RthsLoop {
 public:
  //! References are kept: the three parts must outlive the loop.
  RthsLoop(ExperimentalSubstructure& experimental, NumericalSubstructure& numerical, TrackingController& controller,
           const RthsLoopConfig& config = {});
  void reset() noexcept;
  //! n samples t_k = k dt, k = 0..n-1, ground acceleration from ag (already scaled).  Each
  //! buffer may be nullptr: rows (n), numerical (n x dofs, row-major: the numerical
  //! substructure's displacements [m]), step_seconds (n: each sample's wall time [s]).
  //! The summary (record.hpp, as every loop's): rows, the peaks (peak_force: the actuator force
  //! Force_act; peak_displacement, peak_velocity: the specimen's), the experimental substructure's
  //! work counts; at a failure, status (the experimental substructure's, NonFinite when the loop's
  //! own signals or the numerical substructure failed) with status.t = failure_time = t_k.
  RunSummary run(const GroundMotion& ag, std::size_t n, RthsOutput* rows, double* numerical = nullptr,
                  double* step_seconds = nullptr) noexcept;

  const RthsLoopConfig& config() const noexcept { return cfg_; }
  const ExperimentalSubstructure& experimental() const noexcept { return exp_; }
  const NumericalSubstructure& numerical() const noexcept { return num_; }
  const TrackingController& controller() const noexcept { return ctrl_; }

 private:
  ExperimentalSubstructure& exp_;
  NumericalSubstructure& num_;
  TrackingController& ctrl_;
  RthsLoopConfig cfg_;
  GaussianSequence wx_, wf_;
  BackwardDifference dx_, dv_;
  UnitDelay delay_;
};

}  // namespace servohydraulics::rths
