// The wall-clock Pacer (realtime.hpp) against oracles that hold on any machine,
// loaded or not (no timing assertion): the histogram's bins tile the line and
// its quantiles are the nearest-rank sample's bin; wait() never returns before
// its deadline (checked on the clock itself); the deadlines are start + k * period
// exactly, at 1 ms and at 4096 Hz (a period of 244140.625 ns: no drift); an
// injected overrun is counted as misses; wait() allocates nothing; bad input
// is an Error naming the field; SCHED_FIFO refused (in a child without
// CAP_SYS_NICE and RLIMIT_RTPRIO 0) is reported with its errno, and the loop runs.
#include <linux/capability.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "check.hpp"
#include "servohydraulics/error.hpp"
#include "servohydraulics/realtime.hpp"

using namespace servohydraulics;
using realtime::LatencyHistogram;
using realtime::Pacer;
using realtime::PacerOptions;

namespace {

void sleep_ns(std::int64_t ns) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / 1000000000LL);
  t.tv_nsec = static_cast<long>(ns % 1000000000LL);
  while (nanosleep(&t, &t) != 0) {
  }
}

// The Error's text when f throws one, "" otherwise.
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void histogram_bins_tile_the_line() {
  for (int b = 0; b < LatencyHistogram::kBins; ++b) {
    const std::int64_t lo = LatencyHistogram::bin_lower(b), hi = LatencyHistogram::bin_upper(b);
    CHECK(lo <= hi);
    CHECK(LatencyHistogram::bin(lo) == b);
    CHECK(LatencyHistogram::bin(hi) == b);
    if (b + 1 < LatencyHistogram::kBins) CHECK(LatencyHistogram::bin_lower(b + 1) == hi + 1);
    if (lo >= LatencyHistogram::kSub) CHECK(64 * (hi - lo + 1) <= lo);  // at most 1/64 of the value wide
  }
  CHECK(LatencyHistogram::bin_lower(0) == 0);
  CHECK(LatencyHistogram::bin(-5) == 0);
  CHECK(LatencyHistogram::bin(std::int64_t{1} << 50) == LatencyHistogram::kBins - 1);
}

// Quantiles against the sorted samples: the nearest-rank sample's bin.
void histogram_quantiles_are_nearest_rank() {
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> log_ns(0.0, 8.0);  // 1 ns .. 100 ms, log-uniform
  for (int draw = 0; draw < 40; ++draw) {
    const int n = 1 + static_cast<int>(rng() % 5000);
    LatencyHistogram h;
    std::vector<std::int64_t> v(static_cast<std::size_t>(n));
    for (auto& x : v) {
      x = static_cast<std::int64_t>(std::pow(10.0, log_ns(rng)));
      h.add(x);
    }
    std::sort(v.begin(), v.end());
    CHECK(h.count() == n);
    CHECK(h.min() == v.front());
    CHECK(h.max() == v.back());
    for (std::int64_t per_mille : {0, 100, 500, 900, 990, 999, 1000}) {
      const double q = 1e-3 * static_cast<double>(per_mille);
      const std::int64_t rank = std::max<std::int64_t>(1, (per_mille * n + 999) / 1000);  // ceil(q n), exactly
      const std::int64_t exact = v[static_cast<std::size_t>(rank - 1)];
      const int b = LatencyHistogram::bin(exact);
      const double got = h.quantile(q);
      CHECK(got >= static_cast<double>(LatencyHistogram::bin_lower(b)));
      CHECK(got <= static_cast<double>(LatencyHistogram::bin_upper(b)));
    }
  }
}

void wait_never_early_and_schedule_is_absolute() {
  for (double period : {1e-3, 1.0 / 4096.0}) {
    Pacer pacer(period);
    CHECK(pacer.wait() == -1.0);  // before start(): nothing
    pacer.start();
    const std::int64_t start = pacer.start_ns();
    // deadline k = start + round(k * period): exact integer oracles for both periods
    for (std::int64_t k : {1LL, 2LL, 3LL, 4LL, 1000LL, 4096LL, 123457LL, 4096LL * 3600 * 24}) {
      const std::int64_t expect = period == 1e-3 ? start + k * 1000000
                                                 : start + (k * 244140625 + 500) / 1000;  // 244140.625 ns
      CHECK(pacer.deadline_ns(k) == expect);
    }
    for (int k = 1; k <= 200; ++k) {
      CHECK(pacer.next_deadline_ns() == pacer.deadline_ns(k));
      const double late = pacer.wait();
      const std::int64_t now = realtime::monotonic_ns();
      CHECK(late >= 0.0);
      CHECK(now >= pacer.deadline_ns(k));  // the clock itself: not before the deadline
    }
    CHECK(pacer.samples() == 200);
    CHECK(pacer.latency().count() == 200);
    CHECK(pacer.compute().count() == 199);
    CHECK(pacer.latency().min() >= 0);
    pacer.stop();
  }
}

void overruns_are_misses() {
  const std::int64_t period = 20000000;  // 20 ms
  Pacer pacer(1e-9 * static_cast<double>(period));
  pacer.start();
  pacer.wait();
  pacer.wait();
  const std::int64_t before = pacer.misses();
  // The step after wait 2 overruns by 2.5 periods: deadlines 3 and 4 have passed
  // when waits 3 and 4 are entered (wait 2 returned at or after deadline 2).
  sleep_ns(5 * period / 2);
  const double late3 = pacer.wait();
  pacer.wait();
  CHECK(pacer.misses() - before >= 2);
  CHECK(late3 >= 1.5e-9 * static_cast<double>(period));  // woke >= deadline 2 + 2.5 periods, deadline 3 + 1.5
  // Catching up, not skipping: the schedule is unchanged.
  CHECK(pacer.next_deadline_ns() == pacer.start_ns() + 5 * period);
  CHECK(pacer.samples() == 4);
  CHECK(pacer.compute().max() >= 5 * period / 2);
}

void wait_allocates_nothing() {
  PacerOptions o;
  o.lock_memory = false;
  Pacer pacer(2e-4, o);
  pacer.start();
  pacer.wait();
  sh_test::AllocationCounter counter;
  for (int k = 0; k < 500; ++k) pacer.wait();
  const long allocations = counter.count();
  if (sh_test::kCountingAllocations) CHECK(allocations == 0);
}

void bad_input_names_the_field() {
  CHECK(error_of([] { Pacer p(0.0); }).find("period_s") != std::string::npos);
  CHECK(error_of([] { Pacer p(-1e-3); }).find("period_s") != std::string::npos);
  CHECK(error_of([] { Pacer p(std::nan("")); }).find("period_s") != std::string::npos);
  CHECK(error_of([] { Pacer p(1e9); }).find("period_s") != std::string::npos);
  for (int prio : {-1, 100, 1000}) {
    PacerOptions o;
    o.fifo_priority = prio;
    CHECK(error_of([&] { Pacer p(1e-3, o); }).find("fifo_priority") != std::string::npos);
  }
  for (int cpu : {-2, 4096, static_cast<int>(sysconf(_SC_NPROCESSORS_CONF))}) {
    PacerOptions o;
    o.cpu = cpu;
    CHECK(error_of([&] { Pacer p(1e-3, o); }).find("invalid cpu") != std::string::npos);
  }
  CHECK(error_of([] { Pacer p(5e-4); }).empty());
}

// What was asked and what was granted; stop() restores the thread.
void permissions_reported_and_restored() {
  {
    Pacer pacer(1e-3);
    pacer.start();
    const auto s = pacer.stats();
    CHECK(!s.fifo.requested && !s.fifo.granted && s.fifo.reason == "not requested");
    CHECK(!s.mlockall.requested && !s.cpu_affinity.requested);
  }
  PacerOptions o;
  o.fifo_priority = 10;
  o.cpu = 0;
  Pacer pacer(1e-3, o);
  const int policy_before = sched_getscheduler(0);
  const int slack_before = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
  pacer.start();
  const int slack_during = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
  CHECK(slack_during >= 0 && slack_during <= slack_before);  // 1 ns asked (a kernel may keep its own; RT: 0)
  for (int k = 0; k < 20; ++k) pacer.wait();
  const auto s = pacer.stats();
  CHECK(s.fifo.requested && s.cpu_affinity.requested);
  CHECK(s.fifo.granted == (sched_getscheduler(0) == SCHED_FIFO));
  CHECK(s.fifo.granted ? s.fifo.error == 0 : (s.fifo.error != 0 && s.fifo.reason.find("failed") != std::string::npos));
  if (s.cpu_affinity.granted) CHECK(sched_getcpu() == 0);
  std::printf("here: fifo %s; cpu_affinity %s; timer slack %d ns -> %d ns\n", s.fifo.reason.c_str(),
              s.cpu_affinity.reason.c_str(), slack_before, slack_during);
  pacer.stop();
  CHECK(sched_getscheduler(0) == policy_before);
  CHECK(prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0) == slack_before);
  CHECK(pacer.stats().samples == 20);  // the statistics survive stop()
}

// In a child without CAP_SYS_NICE and with RLIMIT_RTPRIO 0, SCHED_FIFO is
// refused: the Permission says EPERM and the loop runs all the same.
void fifo_refused_is_reported() {
  const pid_t pid = fork();
  if (pid == 0) {
    rlimit none{0, 0};
    setrlimit(RLIMIT_RTPRIO, &none);
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    __user_cap_data_struct data[2]{};
    if (syscall(SYS_capget, &header, data) == 0) {
      data[0].effective &= ~(1u << CAP_SYS_NICE);
      data[0].permitted &= ~(1u << CAP_SYS_NICE);
      data[0].inheritable &= ~(1u << CAP_SYS_NICE);
      syscall(SYS_capset, &header, data);
    }
    PacerOptions o;
    o.fifo_priority = 50;
    Pacer pacer(1e-3, o);
    pacer.start();
    for (int k = 0; k < 5; ++k) pacer.wait();
    const auto s = pacer.stats();
    if (s.fifo.granted) _exit(3);  // could not take the privilege away: nothing to test here
    const bool ok = s.fifo.requested && s.fifo.error == EPERM && s.fifo.reason.find("EPERM") != std::string::npos &&
                    s.samples == 5 && sched_getscheduler(0) != SCHED_FIFO;
    if (!ok) std::fprintf(stderr, "child: fifo reason \"%s\", error %d\n", s.fifo.reason.c_str(), s.fifo.error);
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
  CHECK(WIFEXITED(status));
  if (WEXITSTATUS(status) == 3) {
    std::puts("fifo_refused_is_reported: SCHED_FIFO could not be taken away in the child; skipped");
    return;
  }
  CHECK(WEXITSTATUS(status) == 0);
}

}  // namespace

int main() {
  histogram_bins_tile_the_line();
  histogram_quantiles_are_nearest_rank();
  wait_never_early_and_schedule_is_absolute();
  overruns_are_misses();
  wait_allocates_nothing();
  bad_input_names_the_field();
  permissions_reported_and_restored();
  fifo_refused_is_reported();
  return sh_test::report("test_realtime");
}
