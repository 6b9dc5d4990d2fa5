#include "servohydraulics/realtime.hpp"

#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics::realtime {

namespace {

constexpr std::int64_t kNsPerS = 1000000000LL;
constexpr int kFracBits = 20;  // the period's fraction of a nanosecond, in 2^-20 ns

std::int64_t to_ns(const timespec& t) noexcept { return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + t.tv_nsec; }

timespec to_timespec(std::int64_t ns) noexcept {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / kNsPerS);
  t.tv_nsec = static_cast<long>(ns % kNsPerS);
  return t;
}

int floor_log2(std::uint64_t v) noexcept { return 63 - __builtin_clzll(v); }

// "EPERM (Operation not permitted)": the errno's name and its text.
std::string errno_text(int e) {
  const char* name = nullptr;
  switch (e) {
    case EPERM: name = "EPERM"; break;
    case EINVAL: name = "EINVAL"; break;
    case ENOMEM: name = "ENOMEM"; break;
    case EAGAIN: name = "EAGAIN"; break;
    case ESRCH: name = "ESRCH"; break;
    case EFAULT: name = "EFAULT"; break;
    default: break;
  }
  const std::string text = std::strerror(e);
  return name ? std::string(name) + " (" + text + ")" : "errno " + std::to_string(e) + " (" + text + ")";
}

Permission refused(int e, const std::string& call, const std::string& needs) {
  Permission p;
  p.requested = true;
  p.error = e;
  p.reason = call + " failed: " + errno_text(e) + "; " + needs;
  return p;
}

Permission granted(const std::string& what) {
  Permission p;
  p.requested = true;
  p.granted = true;
  p.reason = "granted: " + what;
  return p;
}

Permission not_requested() {
  Permission p;
  p.reason = "not requested";
  return p;
}

// Touches a stack buffer so its pages are resident (and locked under mlockall):
// the loop's first deep call does not page-fault.
void prefault_stack() noexcept {
  constexpr std::size_t kBytes = 64 * 1024;
  unsigned char buffer[kBytes];
  std::memset(buffer, 0, kBytes);
  asm volatile("" : : "r"(buffer) : "memory");  // keep the stores
}

Percentiles percentiles(const LatencyHistogram& h) {
  Percentiles p;
  p.min = 1e-3 * static_cast<double>(h.min());
  p.p50 = 1e-3 * h.quantile(0.5);
  p.p99 = 1e-3 * h.quantile(0.99);
  p.p999 = 1e-3 * h.quantile(0.999);
  p.max = 1e-3 * static_cast<double>(h.max());
  p.mean = 1e-3 * h.mean();
  return p;
}

}  // namespace

std::int64_t monotonic_ns() noexcept {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return to_ns(t);
}

// ---- LatencyHistogram --------------------------------------------------------

int LatencyHistogram::bin(std::int64_t ns) noexcept {
  if (ns < kSub) return ns < 0 ? 0 : static_cast<int>(ns);
  const int e = floor_log2(static_cast<std::uint64_t>(ns));
  if (e > kMaxOctave) return kBins - 1;
  // Octave e (>= kSubBits) holds [2^e, 2^(e+1)) in kSub bins of width 2^(e - kSubBits).
  return (e - kSubBits + 1) * kSub + static_cast<int>((ns >> (e - kSubBits)) - kSub);
}

std::int64_t LatencyHistogram::bin_lower(int b) noexcept {
  if (b < kSub) return b;
  const int octave = b / kSub - 1;  // e - kSubBits
  return static_cast<std::int64_t>(kSub + b % kSub) << octave;
}

std::int64_t LatencyHistogram::bin_upper(int b) noexcept {
  if (b < kSub) return b;
  const int octave = b / kSub - 1;
  return bin_lower(b) + (std::int64_t{1} << octave) - 1;
}

void LatencyHistogram::add(std::int64_t ns) noexcept {
  if (ns < 0) ns = 0;
  ++counts_[static_cast<std::size_t>(bin(ns))];
  if (count_ == 0 || ns < min_) min_ = ns;
  if (count_ == 0 || ns > max_) max_ = ns;
  ++count_;
  sum_ += static_cast<double>(ns);
}

void LatencyHistogram::clear() noexcept {
  counts_.fill(0);
  count_ = min_ = max_ = 0;
  sum_ = 0.0;
}

double LatencyHistogram::mean() const noexcept { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }

double LatencyHistogram::quantile(double q) const noexcept {
  if (count_ == 0 || !(q >= 0.0)) return 0.0;
  q = std::min(q, 1.0);
  // Nearest rank: the ceil(q n)-th smallest sample (rank 1 for q = 0); the 1e-9 keeps
  // q n = 999.0000000000001 (q = 0.999, n = 1000) at rank 999.
  std::int64_t rank = static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_) - 1e-9));
  rank = std::max<std::int64_t>(1, std::min(rank, count_));
  std::int64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += counts_[static_cast<std::size_t>(b)];
    if (seen >= rank) {
      const double mid = 0.5 * (static_cast<double>(bin_lower(b)) + static_cast<double>(bin_upper(b)));
      return std::min(std::max(mid, static_cast<double>(min_)), static_cast<double>(max_));
    }
  }
  return static_cast<double>(max_);
}

// ---- Pacer --------------------------------------------------------------------

Pacer::Pacer(double period_s, PacerOptions options) : period_s_(period_s), options_(options) {
  require(std::isfinite(period_s) && period_s >= 1e-6 && period_s <= 60.0, "period_s", period_s,
          "the pacing period must be within [1e-6, 60] s");
  if (options.fifo_priority != 0) {
    const int lo = sched_get_priority_min(SCHED_FIFO), hi = sched_get_priority_max(SCHED_FIFO);
    require(options.fifo_priority >= lo && options.fifo_priority <= hi, "fifo_priority", options.fifo_priority,
            ("SCHED_FIFO priorities are " + std::to_string(lo) + " .. " + std::to_string(hi) +
             " (0: leave the policy)").c_str());
  }
  if (options.cpu != -1) {
    const long cpus = sysconf(_SC_NPROCESSORS_CONF);
    require(options.cpu >= 0 && options.cpu < CPU_SETSIZE && (cpus <= 0 || options.cpu < cpus), "cpu",
            options.cpu,
            ("this machine's CPUs are 0 .. " + std::to_string(cpus - 1) + " (-1: leave the affinity)").c_str());
  }
  const double ns = period_s * 1e9;
  period_ns_ = std::llround(ns);
  period_whole_ = static_cast<std::int64_t>(std::floor(ns));
  period_frac_ = std::llround((ns - static_cast<double>(period_whole_)) * static_cast<double>(1LL << kFracBits));
  if (period_frac_ == (1LL << kFracBits)) {
    ++period_whole_;
    period_frac_ = 0;
  }
  fifo_ = mlock_ = affinity_ = not_requested();
}

Pacer::~Pacer() {
  // Only memory is restored here: the thread that started the pacer may be gone
  // (its policy and affinity died with it) or may not be this one.
  if (memory_locked_) munlockall();
}

std::int64_t Pacer::deadline_ns(std::int64_t k) const noexcept {
  // start + k * (whole + frac 2^-20), rounded to the nearest ns; k * frac < 2^63 for k < 2^43.
  return start_ns_ + k * period_whole_ + ((k * period_frac_ + (1LL << (kFracBits - 1))) >> kFracBits);
}

void Pacer::start() {
  const pthread_t self = pthread_self();
  if (started_ && !pthread_equal(self, thread_)) {
    throw Error("Pacer.start: already started by another thread (call stop() on that thread first)");
  }
  if (!started_) {
    thread_ = self;
    if (options_.lock_memory) {
      if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
        memory_locked_ = true;
        mlock_ = granted("mlockall(MCL_CURRENT | MCL_FUTURE)");
        prefault_stack();
      } else {
        mlock_ = refused(errno, "mlockall(MCL_CURRENT | MCL_FUTURE)",
                         "needs CAP_IPC_LOCK or an RLIMIT_MEMLOCK above the process's mapped memory "
                         "(ulimit -l unlimited); memory may page out");
      }
    }
    if (options_.cpu >= 0) {
      cpu_set_t want;
      CPU_ZERO(&want);
      CPU_SET(options_.cpu, &want);
      const int got_old = pthread_getaffinity_np(self, sizeof old_affinity_, &old_affinity_);
      const int rc = pthread_setaffinity_np(self, sizeof want, &want);
      if (rc == 0) {
        affinity_changed_ = got_old == 0;
        affinity_ = granted("pinned to CPU " + std::to_string(options_.cpu));
      } else {
        affinity_ = refused(rc, "pthread_setaffinity_np(CPU " + std::to_string(options_.cpu) + ")",
                            "the CPU must be online and in the process's cpuset (taskset/cgroup)");
      }
    }
    {
      // A SCHED_OTHER thread's timers may fire up to its timer slack late (50 us by
      // default); 1 ns needs no privilege (SCHED_FIFO threads have none anyway).
      const int old = prctl(PR_GET_TIMERSLACK, 0UL, 0UL, 0UL, 0UL);
      if (old >= 0 && prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0) {
        old_slack_ns_ = old;
        slack_changed_ = true;
      }
    }
    if (options_.fifo_priority > 0) {
      const int got_old = pthread_getschedparam(self, &old_policy_, &old_param_);
      sched_param want{};
      want.sched_priority = options_.fifo_priority;
      const int rc = pthread_setschedparam(self, SCHED_FIFO, &want);
      if (rc == 0) {
        policy_changed_ = got_old == 0;
        fifo_ = granted("SCHED_FIFO priority " + std::to_string(options_.fifo_priority));
      } else {
        fifo_ = refused(rc, "pthread_setschedparam(SCHED_FIFO, " + std::to_string(options_.fifo_priority) + ")",
                        "needs CAP_SYS_NICE (root) or an RLIMIT_RTPRIO >= the priority (ulimit -r; "
                        "/etc/security/limits.conf rtprio), and an RT budget in the cgroup; runs SCHED_OTHER");
      }
    }
  }
  latency_.clear();
  compute_.clear();
  samples_ = misses_ = 0;
  index_ = 1;
  start_ns_ = monotonic_ns();
  last_wake_ns_ = start_ns_;
  started_ = true;
}

double Pacer::wait() noexcept {
  if (!started_) return -1.0;
  const std::int64_t deadline = deadline_ns(index_);
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  const std::int64_t entry = to_ns(now);
  if (samples_ > 0) compute_.add(entry - last_wake_ns_);
  if (entry > deadline) {
    ++misses_;
  } else {
    const timespec until = to_timespec(deadline);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
    }
  }
  clock_gettime(CLOCK_MONOTONIC, &now);
  const std::int64_t wake = to_ns(now);
  const std::int64_t late = wake - deadline;  // >= 0: TIMER_ABSTIME never wakes early
  latency_.add(late);
  last_wake_ns_ = wake;
  ++samples_;
  ++index_;
  return 1e-9 * static_cast<double>(late);
}

void Pacer::stop() {
  if (!started_) return;
  const pthread_t self = pthread_self();
  if (!pthread_equal(self, thread_)) throw Error("Pacer.stop: must run on the thread that called start()");
  if (policy_changed_) pthread_setschedparam(self, old_policy_, &old_param_);
  if (affinity_changed_) pthread_setaffinity_np(self, sizeof old_affinity_, &old_affinity_);
  if (memory_locked_) munlockall();
  if (slack_changed_) prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(old_slack_ns_), 0UL, 0UL, 0UL);
  policy_changed_ = affinity_changed_ = memory_locked_ = slack_changed_ = false;
  started_ = false;
}

PacerStats Pacer::stats() const {
  PacerStats s;
  s.period_s = period_s_;
  s.samples = samples_;
  s.misses = misses_;
  s.latency_us = percentiles(latency_);
  s.compute_us = percentiles(compute_);
  s.fifo = fifo_;
  s.mlockall = mlock_;
  s.cpu_affinity = affinity_;
  return s;
}

}  // namespace servohydraulics::realtime
