// Fixed-seed random draws for property tests (after ruckig's test/randomizer.hpp):
// the same sequence on every platform (std::mt19937_64 is specified exactly; the
// conversion to double is done here, not by a library distribution).
#pragma once

#include <cstdint>
#include <random>

namespace sh_test {

class Randomizer {
 public:
  explicit Randomizer(std::uint64_t seed) : gen_(seed) {}
  //! Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen_() >> 11) * 0x1p-53; }
  //! Uniform in [lo, hi) with a random sign.
  double signed_uniform(double lo, double hi) { return (gen_() & 1u ? 1.0 : -1.0) * uniform(lo, hi); }
  bool coin() { return (gen_() & 1u) != 0; }
  std::uint64_t bits() { return gen_(); }

 private:
  std::mt19937_64 gen_;
};

}  // namespace sh_test
