// Whole-record runs: a command array in, every channel out, one controller
// sample per element.  Row k of the result is the state at t_k = t0 + k dt,
// measured before command[k] is applied (the convention of a lab record:
// the controller reads the sensors, then writes the command it holds for the
// next sample).  The last command is therefore held but not seen.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "servohydraulics/channels.hpp"
#include "servohydraulics/plant.hpp"

namespace servohydraulics {

//! Destination arrays of a run, each of length n (or nullptr to skip a channel).
//! channel[i] receives kPlantChannels[i] (channels.hpp); index it by Channel,
//! e.g. ch[Channel::Force] = force.data().
struct Channels {
  std::array<double*, kNumPlantChannels> channel{};
  std::uint32_t* flags = nullptr;
  int* internal_steps = nullptr;  //!< CVODE internal steps of the sample that starts at row k
  int* rhs_evals = nullptr;

  double*& operator[](Channel c) noexcept { return channel[static_cast<std::size_t>(c)]; }
  double* operator[](Channel c) const noexcept { return channel[static_cast<std::size_t>(c)]; }
};

//! What a run did: the summary of every whole-record run (run_record, run_eft, run_rpsd and
//! rths::RthsLoop::run), filled alike where a field means something for the loop.
struct RunSummary {
  //! Counts one sample's status: the largest work, the stiff and the inaccurate samples, and a
  //! failure (kept in status, its row's time t in failure_time).  Returns st.ok().
  bool count(const Status& st, double t) noexcept;
  //! Takes one row's peaks: |force|, |displacement|, |velocity|.
  void peaks(double force, double displacement, double velocity) noexcept;
  bool ok() const noexcept { return status.ok(); }  //!< ran every sample without a failure

  Status status;                  //!< the first failure, or Ok
  std::size_t rows = 0;           //!< rows written (n on success)
  long internal_steps = 0;        //!< CVODE internal steps in the run
  long rhs_evals = 0;             //!< right-hand-side evaluations in the run
  long restarts = 0;              //!< CVodeReInit calls in the run
  int max_internal_steps = 0;     //!< the largest number in one sample
  long stiff_samples = 0;         //!< samples the default pair found stiff and CVODE integrated (Status::stiff)
  long inaccurate_samples = 0;    //!< samples flagged Status::inaccurate (Rk4's companion, dopri5's stiff-run check)
  //! The run's accuracy check (Status::run_error_estimate of its last sample): the largest gap
  //! between the result and the method's check (Rk4's companion, dopri5's shadow of a run that
  //! turned stiff) relative to the run's peak displacement and force, over the check's bound.
  //! > 1 (or NaN): the run probably misses the method's stated accuracy; 0: nothing was checked.
  //! The gap scales with it, so a bound b' flags the run iff this x the configured bound > b'.
  double error_estimate = 0.0;
  //! The largest Status::error_estimate of a sample (> 1: a sample was flagged; a NaN sticks).
  double max_sample_error_estimate = 0.0;
  std::uint32_t flags_any = 0;    //!< OR of every row's OutputFlag bits
  //! max |force| [N]: the load cell (run_record, EFT, RPsD), the actuator force Force_act (RTHS)
  double peak_force = 0.0;
  double peak_displacement = 0.0;  //!< max |displacement| [m]: the plant's x (RTHS: the specimen's X_int)
  double peak_velocity = 0.0;      //!< max |velocity| [m/s]: the plant's v (RTHS: the specimen's x')
  double failure_time = -1.0;      //!< time of the row whose sample failed [s], -1 if none
  double first_capacity_time = -1.0;  //!< first time |force| > F_cap [s], -1 if never (the plant's loops)
};

//! Runs n samples from the plant's current state.  No allocation, no throw:
//! stops at the first failed sample and reports it.
RunSummary run_record(Plant& plant, const double* command, std::size_t n, const Channels& out) noexcept;

//! The default's check of a whole record.  Dopri5's shadow follows a run from its first stiff
//! sample, so an error made before it that the loop amplifies later is in the result and in the
//! shadow alike (a high-gain force loop ringing at the end of a record: 1.03e-3 off while the
//! shadow's gap read 0.39 of its bound; docs/benchmarks.md).  When the whole record is at hand,
//! a run that turned stiff is checked from its start: a second run of the same set-up at
//! rtol / 10 (its own check off), started where the run started, over the same commands.
//!
//! record_check_options: the second run's options, or nothing when the run needs no such check
//! (not Dopri5 with stiff_fallback and stiff_check, no stiff sample, or a failed run).
std::optional<SolverOptions> record_check_options(const SolverOptions& run, const RunSummary& summary) noexcept;

//! Runs `companion` (a plant set up as the run's with record_check_options, reset to the run's
//! start) over command[0..n) and compares its displacement and load-cell force with the run's
//! (x, F: the result's rows, `rows` of them, rows <= n) relative to the run's peaks (the floors
//! of the shadow's measure, detail/output_gap.hpp): summary.error_estimate becomes the larger of
//! its own and that gap over the shadow's bound (5e-4 of the peaks), so > 1 says the run may miss
//! the default's 1e-3.  A companion that fails is compared over the rows it ran.  Allocates (its
//! rows): not for a real-time step.
void check_record(Plant& companion, const double* command, std::size_t n, const double* x, const double* F,
                  std::size_t rows, RunSummary& summary);

//! Every channel as vectors, for C++ users who want a convenient result.
//! Row k holds the sensors at t_k, before command[k] (the convention above).
struct Trace {
  std::vector<double> command;
  std::array<std::vector<double>, kNumPlantChannels> channel;  //!< indexed like kPlantChannels
  std::vector<std::uint32_t> flags;
  RunSummary summary;

  const std::vector<double>& operator[](Channel c) const noexcept { return channel[static_cast<std::size_t>(c)]; }
};

//! Allocating convenience wrapper: validates the command (throws Error naming
//! the first non-finite element), then runs it.
Trace simulate(Plant& plant, const std::vector<double>& command);

}  // namespace servohydraulics
