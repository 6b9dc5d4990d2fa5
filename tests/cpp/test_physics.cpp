// Physics against closed forms, in the core's own language (the Python suite
// has more: energy balance, Coulomb decay, sampled-data tracking).
//
// 1. Free vibration (Free mode, linear spring, viscous damping only): the
//    plant released from x0 at rest follows the damped oscillator
//    x(t) = x0 e^{-zeta w t} (cos w_d t + zeta / sqrt(1 - zeta^2) sin w_d t),
//    w = sqrt(k/m), zeta = c / (2 sqrt(k m)), w_d = w sqrt(1 - zeta^2), with
//    CVODE and with RK4; its zero crossings are w_d apart.
// 2. The closed displacement loop of Eq (12) with the linear-analysis effect
//    set (static valve, Eq 7 flow, no friction or saturation):
//    G_xu(s) = A L / ((C_l + K_a s)(M s^2 + c s + k) + A^2 s + A L),
//    L = K_v C_F K_s G_p.  The linear model from the analytic Jacobian matches
//    it across frequency; the simulated step response settles on its DC gain
//    A L / (C_l k + A L), and its -3 dB roll-off is near w_cRPD = L / A (Eq 13).
#include <cmath>
#include <complex>
#include <cstdio>
#include <vector>

#include "check.hpp"
#include "servohydraulics/linearize.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/presets.hpp"

using namespace servohydraulics;
using cd = std::complex<double>;

namespace {
constexpr double kDt = 5e-4;
constexpr double kPi = 3.14159265358979323846;

void check_free_vibration(const SolverOptions& opt, double tol, const char* name) {
  Rig rig = zhao2003();
  rig.effects.coulomb_friction = false;
  rig.effects.spring_softening = false;
  Plant plant(rig, ControlMode::Free, kDt, opt);
  const double x0 = 0.01, m = plant.dynamics().moving_mass();
  CHECK(m == rig.m);  // no piston in free mode
  const double w = std::sqrt(rig.k / m), zeta = rig.c / (2.0 * std::sqrt(rig.k * m));
  const double wd = w * std::sqrt(1.0 - zeta * zeta);
  plant.reset(x0);
  const int n = static_cast<int>(std::ceil(6.0 * 2.0 * kPi / wd / kDt));  // six periods
  double worst = 0.0, prev = x0;
  std::vector<double> crossings;
  Output o;
  for (int k = 1; k <= n; ++k) {
    CHECK(plant.step(0.0, o).ok());
    const double t = o.time;
    const double exact =
        x0 * std::exp(-zeta * w * t) * (std::cos(wd * t) + zeta / std::sqrt(1.0 - zeta * zeta) * std::sin(wd * t));
    worst = std::fmax(worst, std::fabs(o.displacement - exact));
    if ((prev > 0.0) != (o.displacement > 0.0))  // linear interpolation of the crossing
      crossings.push_back(t - kDt * o.displacement / (o.displacement - prev));
    prev = o.displacement;
  }
  std::printf("free vibration (%s): f_d = %.4f Hz, zeta = %.4f, max |x - exact| = %.3g m\n", name,
              wd / (2.0 * kPi), zeta, worst);
  CHECK(worst <= tol * x0);
  CHECK(crossings.size() >= 10);
  const double half_period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  CHECK_NEAR(half_period, kPi / wd, 1e-4 * kPi / wd);
}

Rig linear_rig() {
  Rig rig = zhao2003();
  Effects& e = rig.effects;
  e.servovalve_dynamics = e.load_pressure = e.flow_nonlinearity = e.coulomb_friction = false;
  e.spring_softening = e.drive_saturation = e.spool_saturation = false;
  return rig;
}

cd eq12(const Rig& r, double M, cd s) {
  const double L = r.K_v * r.C_F_disp * r.K_s * r.G_p;
  return r.A * L / ((r.C_l + r.K_a * s) * (M * s * s + r.c * s + r.k) + r.A * r.A * s + r.A * L);
}

void check_eq12() {
  const Rig rig = linear_rig();
  const Dynamics dyn(rig, ControlMode::Displacement);
  const auto op = dyn.operating_point(0.0);
  const LinearModel lm = linearize(dyn, op.y0, op.u0);
  const double M = dyn.moving_mass();
  const double L = rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p, w_c = L / rig.A;
  // Frequency response of the linear model (active states only) against Eq (12).
  std::vector<int> act;
  for (int i = 0; i < kNumStates; ++i)
    if (lm.active[i]) act.push_back(i);
  const int na = static_cast<int>(act.size());
  CHECK(na == 3);  // x, v, p
  double worst = 0.0;
  for (double w : {0.1, 1.0, 10.0, 0.5 * w_c, w_c, 2.0 * w_c, 10.0 * w_c, 1e3, 1e4}) {
    Eigen::MatrixXcd sIA(na, na);
    Eigen::VectorXcd b(na), c(na);
    for (int i = 0; i < na; ++i) {
      b(i) = lm.B(act[i]);
      c(i) = lm.C(0, act[i]);
      for (int j = 0; j < na; ++j) sIA(i, j) = (i == j ? cd(0.0, w) : cd(0.0)) - lm.A(act[i], act[j]);
    }
    const cd H = c.dot(sIA.partialPivLu().solve(b)) + lm.D(0);  // dot conjugates c, which is real
    const cd G = eq12(rig, M, cd(0.0, w));
    worst = std::fmax(worst, std::abs(H - G) / std::abs(G));
  }
  CHECK(worst < 1e-8);
  // -3 dB near w_cRPD (Eq 13's first-order view of Eq 12).
  const double mag_c = std::abs(eq12(rig, M, cd(0.0, w_c))) / std::abs(eq12(rig, M, cd(0.0, 0.0)));
  std::printf("Eq (12): max |H - G| / |G| = %.3g; |G(j w_cRPD)| / G(0) = %.4f (w_cRPD = %.1f rad/s)\n", worst, mag_c,
              w_c);
  CHECK(mag_c > 0.6 && mag_c < 0.8);

  // The nonlinear plant's step response (linear effect set) settles on the DC gain.
  const double dc = rig.A * L / (rig.C_l * rig.k + rig.A * L);
  Plant plant(rig, ControlMode::Displacement, kDt, {});
  const double u = 0.01;
  Output o;
  const int n = static_cast<int>(std::ceil(40.0 / w_c / kDt));  // forty loop time constants
  for (int k = 0; k < n; ++k) CHECK(plant.step(u, o).ok());
  std::printf("Eq (12) DC gain: simulated %.9f, closed form %.9f\n", o.displacement / u, dc);
  CHECK_NEAR(o.displacement / u, dc, 1e-6);
  CHECK(dc < 1.0);  // leakage needs a standing error
}
}  // namespace

int main() {
  SolverOptions tight;
  tight.rtol = 1e-9;
  check_free_vibration(tight, 1e-5, "CVODE rtol 1e-9");
  SolverOptions rk4;
  rk4.method = SolverOptions::Method::Rk4;
  check_free_vibration(rk4, 1e-4, "RK4 automatic");
  check_eq12();
  return sh_test::report("test_physics");
}
