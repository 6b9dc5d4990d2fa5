// FlowCurve tables that cannot be indexed (0 or 1 point, flow and opening of
// different lengths), as a caller can assign them field by field: eval, slope
// and inverse return NaN (a NonFinite status in a run) and never read out of
// bounds (scripts/run.sh sanitize runs this under AddressSanitizer); validate()
// names the field; a Plant refuses such a rig.  A valid table still interpolates.
#include <cmath>
#include <string>
#include <vector>

#include "check.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;

int main() {
  struct Case {
    std::vector<double> opening, flow;
    const char* field;
  };
  const Case cases[] = {{{}, {}, "flow_curve.opening (length)"},
                        {{0.0}, {0.0}, "flow_curve.opening (length)"},
                        {{0.0, 0.5, 1.0}, {0.0, 0.5}, "flow_curve.flow (length)"},
                        {{0.0, 1.0}, {0.0, 0.5, 0.7}, "flow_curve.flow (length)"}};
  for (const Case& c : cases) {
    FlowCurve fc;
    fc.kind = FlowCurve::Kind::Table;
    fc.opening = c.opening;
    fc.flow = c.flow;
    for (double x : {-2.0, -0.3, 0.0, 0.3, 0.99, 5.0}) {
      CHECK(std::isnan(fc.eval(x)));
      CHECK(std::isnan(fc.slope(x)));
      CHECK(std::isnan(fc.inverse(x)));
    }
    std::string what;
    try {
      fc.validate();
    } catch (const Error& e) {
      what = e.what();
    }
    CHECK(what.find(c.field) != std::string::npos);
    Rig rig = zhao2003();
    rig.flow_curve = fc;
    bool refused = false;
    try {
      Plant p(rig, ControlMode::Displacement, 5e-4);
    } catch (const Error&) {
      refused = true;
    }
    CHECK(refused);
  }
  // A valid two-point table: g(x) = 0.8 x on [0, 1], mirrored.
  FlowCurve fc;
  fc.kind = FlowCurve::Kind::Table;
  fc.opening = {0.0, 1.0};
  fc.flow = {0.0, 0.8};
  fc.validate();
  CHECK_NEAR(fc.eval(0.5), 0.4, 1e-15);
  CHECK_NEAR(fc.eval(-0.5), -0.4, 1e-15);
  CHECK_NEAR(fc.slope(0.2), 0.8, 1e-15);
  CHECK_NEAR(fc.inverse(0.4), 0.5, 1e-15);
  // validate() names the index of a point that breaks monotonicity.
  fc.opening = {0.0, 0.5, 0.4};
  fc.flow = {0.0, 0.3, 0.5};
  std::string what;
  try {
    fc.validate();
  } catch (const Error& e) {
    what = e.what();
  }
  CHECK(what.find("flow_curve.opening[2] = 0.4") != std::string::npos);
  return sh_test::report("test_flow_curve_bounds");
}
