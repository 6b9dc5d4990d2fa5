// Pacing a loop to the wall clock, one sample per period, measured the way
// cyclictest measures it.
//
//   realtime::PacerOptions opt;           // what to ask the system for
//   opt.fifo_priority = 80;               // SCHED_FIFO 80 (0: do not ask)
//   opt.cpu = 1;                          // pin the loop's thread to CPU 1 (-1: do not pin)
//   opt.lock_memory = true;               // mlockall(MCL_CURRENT | MCL_FUTURE)
//   realtime::Pacer pacer(5e-4, opt);     // 2 kHz (setup: validates, may throw Error)
//   pacer.start();                        // applies the options; deadline 1 = now + period
//   for (...) { pacer.wait(); step(); }   // wait(): sleep to the next absolute deadline
//   pacer.stats();                        // latencies, compute times, misses, what was permitted
//   pacer.stop();                         // restores the thread's policy and affinity
//
// The schedule is absolute: deadline k = start + k * period on CLOCK_MONOTONIC
// (clock_nanosleep with TIMER_ABSTIME), so a late sample never shifts the ones
// after it.  A loop that falls behind is not skipped ahead: its samples run
// back to back until it has caught up (the simulated time of a sample is
// k * period; dropping samples would tear it from the wall clock), and every
// wait() entered after its deadline counts as a deadline miss.
//
// wait() returns the wake-up latency (the time from the deadline to the
// return, >= 0: clock_nanosleep never wakes early) and records it, and the
// compute time of the step before it (from the previous return to this call),
// in fixed-size histograms: wait() never allocates, never throws, and makes no
// system call but clock_gettime and clock_nanosleep.
//
// start() also sets the loop thread's timer slack to 1 ns (a SCHED_OTHER
// thread's default 50 us delays every wake-up; no privilege needed).
// SCHED_FIFO, mlockall and the CPU affinity are requests: when the system
// refuses one (no CAP_SYS_NICE or RLIMIT_RTPRIO, RLIMIT_MEMLOCK, a CPU outside
// the cpuset) the loop runs without it, and the Permission says why (errno).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <pthread.h>
#include <sched.h>

namespace servohydraulics::realtime {

//! Nanoseconds on CLOCK_MONOTONIC (the clock of the deadlines; Python's time.monotonic_ns()).
std::int64_t monotonic_ns() noexcept;

//! A histogram of durations [ns] in a fixed array: log-linear bins, 1 ns wide
//! below 64 ns, then 64 bins per octave (each bin at most 1/64 = 1.6 % of its
//! value wide) up to 2^40 ns (18 min); longer values land in the last bin.
//! add() is O(1), noexcept and allocation-free; the exact min, max and sum are
//! kept beside the bins.
class LatencyHistogram {
 public:
  static constexpr int kSubBits = 6;                                   //!< 2^6 = 64 bins per octave
  static constexpr int kSub = 1 << kSubBits;                           //!< 64
  static constexpr int kMaxOctave = 40;                                //!< values up to 2^40 ns
  static constexpr int kBins = (kMaxOctave - kSubBits + 1) * kSub;     //!< 2240

  void add(std::int64_t ns) noexcept;
  void clear() noexcept;

  std::int64_t count() const noexcept { return count_; }
  std::int64_t min() const noexcept { return count_ ? min_ : 0; }  //!< exact [ns]
  std::int64_t max() const noexcept { return count_ ? max_ : 0; }  //!< exact [ns]
  double mean() const noexcept;                                     //!< exact [ns]
  //! The q-quantile (0 <= q <= 1) [ns] by nearest rank: the value of the bin
  //! holding the ceil(q * count)-th smallest sample (numpy's "inverted_cdf"),
  //! reported as the bin's midpoint clamped to [min, max]; 0 when empty.
  double quantile(double q) const noexcept;

  static int bin(std::int64_t ns) noexcept;           //!< the bin of a value (negative -> 0)
  static std::int64_t bin_lower(int bin) noexcept;    //!< smallest value of a bin [ns]
  static std::int64_t bin_upper(int bin) noexcept;    //!< largest value of a bin [ns]
  std::int64_t bin_count(int bin) const noexcept { return counts_[static_cast<std::size_t>(bin)]; }

 private:
  std::array<std::int64_t, kBins> counts_{};
  std::int64_t count_ = 0, min_ = 0, max_ = 0;
  double sum_ = 0.0;
};

//! What the loop asks the system for (all off by default).
struct PacerOptions {
  int fifo_priority = 0;     //!< SCHED_FIFO priority 1 .. 99 for the calling thread; 0: leave the policy
  int cpu = -1;              //!< pin the calling thread to this CPU (0 .. CPUs-1); -1: leave the affinity
  bool lock_memory = false;  //!< mlockall(MCL_CURRENT | MCL_FUTURE) and prefault the stack
};

//! Whether the system granted one request, and why not.
struct Permission {
  bool requested = false;
  bool granted = false;
  int error = 0;       //!< errno of the refusal (0 when granted or not requested)
  std::string reason;  //!< "granted", "not requested", or the refusal: the call, errno name and what it needs
};

//! Percentiles of one histogram [us].
struct Percentiles {
  double min = 0.0, p50 = 0.0, p99 = 0.0, p999 = 0.0, max = 0.0, mean = 0.0;
};

struct PacerStats {
  double period_s = 0.0;
  std::int64_t samples = 0;  //!< wait() calls since start()
  std::int64_t misses = 0;   //!< wait() calls entered after their deadline (the step before overran)
  Percentiles latency_us;    //!< wake-up latency: return of wait() - its deadline
  Percentiles compute_us;    //!< the step between two waits: entry of wait() - return of the previous one
  Permission fifo, mlockall, cpu_affinity;
};

class Pacer {
 public:
  //! period_s in [1e-6, 60] s; options checked here (Error naming the field):
  //! fifo_priority 0 or within sched_get_priority_min/max(SCHED_FIFO), cpu -1
  //! or an existing CPU.
  explicit Pacer(double period_s, PacerOptions options = {});
  ~Pacer();
  Pacer(const Pacer&) = delete;
  Pacer& operator=(const Pacer&) = delete;

  //! Applies the options to the calling thread (the loop's thread) and sets its
  //! timer slack to 1 ns (prctl PR_SET_TIMERSLACK, no privilege needed; a
  //! SCHED_OTHER thread's default of 50 us would add up to 50 us to every wake-up), clears the
  //! statistics and sets the schedule: deadline k = now + k * period (k >= 1).
  //! Calling it again restarts the schedule.  Throws only if already started
  //! by another thread (stop() there first).
  void start();
  //! Sleeps until the next deadline (returns at once when it has passed: a
  //! miss), records the latency and the step's compute time, advances the
  //! deadline by one period.  Returns the wake-up latency [s] (>= 0).
  //! Before start() or after stop(): returns -1 and does nothing.  noexcept, allocation-free.
  double wait() noexcept;
  //! Restores the scheduling policy, CPU affinity and timer slack the calling
  //! thread had before start(), and munlockall() if start() locked memory.  Must run on the
  //! thread that called start(); a no-op when not started.  The statistics stay.
  void stop();

  bool started() const noexcept { return started_; }
  std::int64_t period_ns() const noexcept { return period_ns_; }  //!< rounded to 1 ns (exact schedule below)
  double period_s() const noexcept { return period_s_; }
  std::int64_t start_ns() const noexcept { return start_ns_; }  //!< CLOCK_MONOTONIC of start() [ns]
  //! Deadline k [ns] on CLOCK_MONOTONIC: start + round(k * period), exact
  //! (the period is held to 2^-20 ns, so no drift accumulates).
  std::int64_t deadline_ns(std::int64_t k) const noexcept;
  std::int64_t next_deadline_ns() const noexcept { return deadline_ns(index_); }
  std::int64_t samples() const noexcept { return samples_; }
  std::int64_t misses() const noexcept { return misses_; }
  const LatencyHistogram& latency() const noexcept { return latency_; }
  const LatencyHistogram& compute() const noexcept { return compute_; }
  PacerStats stats() const;

 private:
  double period_s_;
  std::int64_t period_ns_;      // round(period) [ns]
  std::int64_t period_whole_;   // floor(period) [ns]
  std::int64_t period_frac_;    // (period - floor) [2^-20 ns]
  PacerOptions options_;
  bool started_ = false;
  std::int64_t start_ns_ = 0;
  std::int64_t index_ = 1;      // the deadline the next wait() sleeps to
  std::int64_t last_wake_ns_ = 0;
  std::int64_t samples_ = 0, misses_ = 0;
  LatencyHistogram latency_, compute_;
  Permission fifo_, mlock_, affinity_;
  // What start() changed, to restore in stop().
  pthread_t thread_{};
  int old_policy_ = 0;
  sched_param old_param_{};
  bool policy_changed_ = false;
  cpu_set_t old_affinity_{};
  bool affinity_changed_ = false;
  bool memory_locked_ = false;
  int old_slack_ns_ = 0;
  bool slack_changed_ = false;
};

}  // namespace servohydraulics::realtime
