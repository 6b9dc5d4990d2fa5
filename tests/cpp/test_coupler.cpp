// The fixture kinematics (coupler.hpp) against closed forms: strokes at rest, derivatives against
// central differences, the node load by virtual work, the exact inverse, and the maRTHS model's
// estimate (theta exact for the symmetric coupler, x off by the model's s-for-asin(s) substitution).
#include <cmath>
#include <cstdio>
#include <string>

#include "check.hpp"
#include "servohydraulics/coupler.hpp"
#include "servohydraulics/error.hpp"

using servohydraulics::Coupler;

int main() {
  const Coupler c = Coupler::marths();
  CHECK(c.actuators() == 2);
  CHECK_NEAR(c.arm(0), 0.2953945, 1e-7);  // BENCHMARK.md 6: 0.2953945 m
  CHECK_NEAR(c.arm(0) * std::sin(c.angle(1)), 0.127, 2e-6);  // the arms' vertical offset

  double s[2];
  c.strokes(0.0, 0.0, s);
  CHECK(s[0] == 0.0 && s[1] == 0.0);
  c.strokes(0.01, 0.0, s);
  CHECK_NEAR(s[0], 0.01, 1e-16);
  CHECK_NEAR(s[1], 0.01, 1e-16);
  // A small rotation moves the lower arm (alpha < 0) forward, the upper one back: ds/dtheta = -/+0.127 m.
  CHECK_NEAR(c.dstroke_dtheta(0, 0.0), 0.127, 2e-6);
  CHECK_NEAR(c.dstroke_dtheta(1, 0.0), -0.127, 2e-6);

  for (double th : {-0.3, -0.05, 0.0, 0.02, 0.4}) {
    const double h = 1e-6;
    double sp[2], sm[2], s0[2];
    c.strokes(0.003, th + h, sp);
    c.strokes(0.003, th - h, sm);
    c.strokes(0.003, th, s0);
    for (std::size_t i = 0; i < 2; ++i) {
      CHECK_NEAR(c.dstroke_dtheta(i, th), (sp[i] - sm[i]) / (2 * h), 1e-9);
      CHECK_NEAR(c.d2stroke_dtheta2(i, th), (sp[i] - 2 * s0[i] + sm[i]) / (h * h), 1e-3);
      CHECK_NEAR(c.d3stroke_dtheta3(i, th), (c.d2stroke_dtheta2(i, th + h) - c.d2stroke_dtheta2(i, th - h)) / (2 * h),
                 1e-8);
    }
    // Virtual work: F . ds = Fx dx + M dtheta for any small motion.
    const double F[2] = {1234.5, -987.0};
    double Fx = 0, M = 0;
    c.node_load(th, F, &Fx, &M);
    const double dx = 1e-7, dth = 3e-7;
    double s1[2];
    c.strokes(0.003 + dx, th + dth, s1);
    c.strokes(0.003 - dx, th - dth, sm);
    const double work = F[0] * (s1[0] - sm[0]) + F[1] * (s1[1] - sm[1]);
    CHECK_NEAR(work, Fx * 2 * dx + M * 2 * dth, 1e-9);
    // The exact inverse returns the node.
    double x = 0, t = 0;
    CHECK(c.node_from_strokes(s0, &x, &t));
    CHECK_NEAR(x, 0.003, 1e-14);
    CHECK_NEAR(t, th, 1e-13);
    // The benchmark's estimate: theta = asin(sin theta) exactly; x uses sin(theta) for theta.
    double bx = 0, bt = 0;
    c.benchmark_estimate(s0, &bx, &bt);
    CHECK_NEAR(bt, th, 1e-12);
    const double a0 = c.angle(0);
    const double expect_x = 0.003 + c.arm(0) * (std::cos(th + a0) - std::cos(std::sin(th) + a0));
    CHECK_NEAR(bx, expect_x, 1e-14);
  }

  // Out of reach: no node.
  double far[2] = {0.0, 5.0}, x = 0, t = 0;
  CHECK(!c.node_from_strokes(far, &x, &t));

  // Bad input names the field and the value.
  const double d_bad[2] = {0.3, -1.0};
  const double a_ok[2] = {0.1, -0.1};
  bool threw = false;
  try {
    Coupler(2, d_bad, a_ok);
  } catch (const servohydraulics::Error& e) {
    threw = std::string(e.what()).find("coupler.d[1] = -1") != std::string::npos;
    if (!threw) std::fprintf(stderr, "message: %s\n", e.what());
  }
  CHECK(threw);
  threw = false;
  try {
    Coupler(0, d_bad, a_ok);
  } catch (const servohydraulics::Error& e) {
    threw = std::string(e.what()).find("coupler.actuators = 0") != std::string::npos;
  }
  CHECK(threw);
  return sh_test::report("test_coupler");
}
