// The paper's rig (Zhao et al. 2003, Table I) as built-in presets.
#pragma once

#include "servohydraulics/rig.hpp"

namespace servohydraulics {

enum class Zhao2003Variant {
  Calibrated,  //!< Table I with K_a and C_l recalibrated so the model reproduces the paper's results
  Printed,     //!< Table I exactly as printed (its displacement loop is unstable: docs/calibration.md)
};

//! The rig of Table I.  actuator_attached selects the dissipation identified
//! with the actuator on (c = 2.1 kN s/m, 1.5 %, F_c = 31.6 N) or the free
//! structure (c = 1.1 kN s/m, 0.8 %, F_c = 95.7 N; Fig 2b).
Rig zhao2003(Zhao2003Variant variant = Zhao2003Variant::Calibrated, bool actuator_attached = true);

}  // namespace servohydraulics
