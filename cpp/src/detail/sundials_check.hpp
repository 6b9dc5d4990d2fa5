// Internal: the one place where a SUNDIALS setup call's result is checked
// (CVODE and ARKODE integrators): a negative flag or a NULL object throws
// Error naming the call.  Every SUNDIALS object is owned by an RAII holder
// before the next call, so a throw part-way frees what was made.
#pragma once

#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics::detail {

inline int check_flag(int flag, const char* call) {
  if (flag < 0) throw Error(std::string("SUNDIALS setup call ") + call + " failed with flag " + std::to_string(flag));
  return flag;
}

template <class P>
P check_ptr(P p, const char* call) {
  if (p == nullptr) throw Error(std::string("SUNDIALS setup call ") + call + " returned NULL");
  return p;
}

}  // namespace servohydraulics::detail
