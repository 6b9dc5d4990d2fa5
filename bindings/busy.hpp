// One object, one thread at a time.  The long calls (Plant run_record, the
// loops' run, PhaseLead.filter) release the GIL, so without a guard two Python
// threads could step one Plant at once and corrupt it silently.  BusyGuard marks
// the C++ objects a call works on as busy for its duration; another call that
// touches any of them meanwhile (a second run, or step/reset/observe of the
// same object) raises _core.ConcurrentUseError (a RuntimeError) instead.
// Separate objects never conflict, so one object per thread still runs in
// parallel.  The registry is a set of addresses under a mutex: no state in the
// core types, no cost on their hot path.
//
//   { bindings::BusyGuard busy({&plant}, "Plant.run_record");
//     py::gil_scoped_release release; ... }
//   bindings::require_idle(&plant, "Plant.step");
#pragma once

#include <initializer_list>
#include <mutex>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace servohydraulics::bindings {

//! Raised (as _core.ConcurrentUseError) when an object is used while another thread runs it.
class ConcurrentUse : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace busy_detail {
struct Registry {
  std::mutex mutex;
  std::unordered_map<const void*, const char*> running;  // object -> the call running on it
};
inline Registry& registry() {
  static Registry r;
  return r;
}
[[noreturn]] inline void refuse(const char* call, const char* running) {
  throw ConcurrentUse(std::string(call) + ": the object is in use by another thread (" + running +
                      " is running on it). Plants, test loops and filters are not thread-safe: "
                      "give each thread its own object (build one per thread from the same Rig).");
}
}  // namespace busy_detail

//! Throws ConcurrentUse if another thread is running a call on obj.
inline void require_idle(const void* obj, const char* call) {
  auto& r = busy_detail::registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.running.find(obj);
  if (it != r.running.end()) busy_detail::refuse(call, it->second);
}

//! Marks objects busy for its lifetime; throws ConcurrentUse if any already is.
class BusyGuard {
 public:
  BusyGuard(std::initializer_list<const void*> objects, const char* call) {
    auto& r = busy_detail::registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    for (const void* o : objects) {
      const auto it = r.running.find(o);
      if (it != r.running.end()) busy_detail::refuse(call, it->second);
    }
    for (const void* o : objects) r.running.emplace(o, call);
    objects_.assign(objects.begin(), objects.end());
  }
  ~BusyGuard() {
    auto& r = busy_detail::registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    for (const void* o : objects_) r.running.erase(o);
  }
  BusyGuard(const BusyGuard&) = delete;
  BusyGuard& operator=(const BusyGuard&) = delete;

 private:
  std::vector<const void*> objects_;
};

//! A member function as a binding that first checks require_idle(&self, call).
template <class C, class R, class... A>
auto guarded(R (C::*f)(A...), const char* call) {
  return [f, call](C& self, A... a) -> R {
    require_idle(&self, call);
    return (self.*f)(a...);
  };
}
template <class C, class R, class... A>
auto guarded(R (C::*f)(A...) noexcept, const char* call) {
  return [f, call](C& self, A... a) -> R {
    require_idle(&self, call);
    return (self.*f)(a...);
  };
}

}  // namespace servohydraulics::bindings
