#include "servohydraulics/error.hpp"

#include <sstream>

namespace servohydraulics {

void require(bool ok, const char* field, double value, const char* requirement) {
  if (ok) return;
  std::ostringstream s;
  s.precision(10);
  s << "invalid " << field << " = " << value << ": " << requirement;
  throw Error(s.str());
}

}  // namespace servohydraulics
