// The one exception type of the library.  Setup and validation throw it; the
// real-time step path never throws and returns a Status instead.
#pragma once

#include <stdexcept>
#include <string>

namespace servohydraulics {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

//! Throws Error("invalid <field> = <value>: <requirement>") unless ok.
void require(bool ok, const char* field, double value, const char* requirement);

}  // namespace servohydraulics
