// Internal: the one place every SUNDIALS setup call of the integrators goes
// through.  A failed call throws Error naming the call, what it was setting up
// and SUNDIALS' flag; the hot path never uses these (it returns a Status).
//
// Failure injection (tests only, tests/cpp/test_failure_injection.cpp): every
// checked call is counted, and when setup_fault().fail_at == k the k-th call
// (from 0) is not made and fails as SUNDIALS would (a negative flag, or NULL).
// The test fails each call in turn and requires an Error, no crash and no leak
// (allocation balance here, LeakSanitizer under scripts/run.sh sanitize).
// fail_at < 0, the default, is production: one relaxed atomic add per setup call.
#pragma once

#include <atomic>
#include <string>
#include <utility>

#include "servohydraulics/error.hpp"

namespace servohydraulics::detail {

struct SetupFault {
  std::atomic<long> calls{0};     //!< checked setup calls made so far
  std::atomic<long> fail_at{-1};  //!< index of the call to fail; < 0: none
};
inline SetupFault& setup_fault() noexcept {
  static SetupFault f;
  return f;
}

//! True if this call is the one to fail (counts the call).
inline bool inject_setup_fault() noexcept {
  SetupFault& f = setup_fault();
  const long k = f.calls.fetch_add(1, std::memory_order_relaxed);
  return k == f.fail_at.load(std::memory_order_relaxed);
}

//! Makes the call `make()` returning a SUNDIALS flag; throws Error if it is negative.
template <class Call>
int check_flag(const char* what, const char* call, Call&& make) {
  const int flag = inject_setup_fault() ? -1 : std::forward<Call>(make)();
  if (flag < 0)
    throw Error(std::string(what) + ": SUNDIALS call " + call + " failed with flag " + std::to_string(flag));
  return flag;
}

//! Makes the call `make()` returning a new SUNDIALS object; throws Error if it is NULL.
template <class Call>
auto check_ptr(const char* what, const char* call, Call&& make) {
  auto p = inject_setup_fault() ? nullptr : std::forward<Call>(make)();
  if (p == nullptr) throw Error(std::string(what) + ": SUNDIALS call " + call + " returned NULL (out of memory?)");
  return p;
}

}  // namespace servohydraulics::detail

// Every setup call through the checked helpers above, named by its function;
// the calling file defines `kSetup` (what is being set up, e.g. "CVODE setup").
#define SH_FLAG(fn, ...) ::servohydraulics::detail::check_flag(kSetup, #fn, [&] { return fn(__VA_ARGS__); })
#define SH_PTR(fn, ...) ::servohydraulics::detail::check_ptr(kSetup, #fn, [&] { return fn(__VA_ARGS__); })
