// Exact equality of two plant samples, channel by channel from the one table
// (kPlantChannels) plus the flags: "the same arithmetic in the same order".
#pragma once

#include "servohydraulics/channels.hpp"

namespace sh_test {

inline bool same(const servohydraulics::Output& a, const servohydraulics::Output& b) {
  for (const auto& c : servohydraulics::kPlantChannels)
    if (!(a.*c.member == b.*c.member)) return false;
  return a.flags == b.flags;
}

}  // namespace sh_test
