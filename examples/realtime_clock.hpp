// The 2 kHz loop's clock for the C++ examples: absolute deadlines on
// CLOCK_MONOTONIC (clock_nanosleep with TIMER_ABSTIME), so a late sample does
// not shift the ones after it.
#pragma once

#include <time.h>

namespace examples {

constexpr long kNsPerS = 1000000000L;

inline void add_ns(timespec& t, long ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= kNsPerS) {
    t.tv_nsec -= kNsPerS;
    ++t.tv_sec;
  }
}

inline double seconds(const timespec& t) {
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace examples
