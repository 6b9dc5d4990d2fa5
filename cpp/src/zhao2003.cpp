#include "servohydraulics/zhao2003.hpp"

namespace servohydraulics {

FlowCurve zhao2003_flow_curve() {
  FlowCurve fc;
  fc.kind = FlowCurve::Kind::Table;
  fc.opening = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0};
  fc.flow = {0.0, 0.1, 0.19, 0.265, 0.33, 0.385, 0.47, 0.56};
  return fc;
}

Rig zhao2003(Zhao2003Variant variant, bool actuator_attached) {
  Rig r;  // the defaults of Rig are the calibrated preset, actuator attached
  if (!actuator_attached) {
    r.c = 1.1e3;   // Table I, free structure (0.8 % of critical, p. 1777)
    r.F_c = 95.7;  // Table I, free structure
  }
  if (variant == Zhao2003Variant::Printed) {
    r.K_a = 0.3e-8 * 1e-3;  // Table I: 0.3e-8 m^5/kN -> m^5/N
    r.C_l = 0.1e-8 * 1e-3;  // Table I: 0.1e-8 m^5/(kN s) -> m^3/(s Pa)
  }
  return r;
}

}  // namespace servohydraulics
