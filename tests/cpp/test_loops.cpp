// Compensators, solvers and the two test-method loops: oracles and the
// real-time promise (no heap allocation in step()).
#include <cmath>
#include <complex>
#include <cstdio>
#include <vector>

#include "servohydraulics/loops.hpp"
#include "servohydraulics/rths/tracking.hpp"
#include "servohydraulics/zhao2003.hpp"

#include "alloc_counter.hpp"  // after the headers that pull in mm_malloc.h (Eigen)
#include "check.hpp"

using namespace servohydraulics;
constexpr double kPi = 3.14159265358979323846;

// PhaseLead: the discrete response at z = e^{j w dt} against the continuous
// (T j w + 1)/(alpha T j w + 1), exact at the prewarping frequency, and the
// measured steady-state sine response of step() against the discrete one.
static void phase_lead() {
  const double dt = 5e-4;
  for (double T : {5e-3, 11.2e-3, 68e-3}) {
    PhaseLead L(T, 0.1, dt);
    auto Hd = [&](double w) {
      const std::complex<double> z = std::exp(std::complex<double>(0.0, w * dt));
      return (L.b0() * z + L.b1()) / (z + L.a1());
    };
    auto Hc = [&](double w) {
      return std::complex<double>(1.0, T * w) / std::complex<double>(1.0, 0.1 * T * w);
    };
    CHECK_NEAR(std::abs(Hd(L.prewarp()) - Hc(L.prewarp())), 0.0, 1e-12);
    CHECK_NEAR(std::abs(Hd(0.0)), 1.0, 1e-12);
    for (double f = 0.1; f <= 10.0; f += 0.1) {  // the band of interest: 0-10 Hz
      const double w = 2 * kPi * f;
      CHECK(std::abs(Hd(w) / Hc(w) - 1.0) < 2.5e-3);  // 0.22 % at 10 Hz for T = 5 ms
    }
    // step() on a sine: least-squares amplitude/phase after the transient.
    const double f = 3.0, w = 2 * kPi * f;
    L.reset(0.0);
    double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0;
    for (int k = 0; k < 40000; ++k) {
      const double t = k * dt, y = L.step(std::sin(w * t));
      if (k < 20000) continue;
      const double s = std::sin(w * t), c = std::cos(w * t);
      ss += s * s, sc += s * c, cc += c * c, ys += y * s, yc += y * c;
    }
    const double det = ss * cc - sc * sc;
    const std::complex<double> H((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
    CHECK_NEAR(std::abs(H - Hd(w)), 0.0, 1e-6);
  }
}

static void sample_delay() {
  SampleDelay d(3);
  d.reset(0.0);
  for (int k = 0; k < 10; ++k) {
    const double y = d.step(k + 1.0);
    CHECK_NEAR(y, k < 3 ? 0.0 : k - 2.0, 0.0);
  }
  SampleDelay none(0);
  CHECK_NEAR(none.step(4.2), 4.2, 0.0);
}

// Solvers on a linear SDOF with f = k d (no test rig): the free vibration from
// d0 against the exact damped response, second-order accuracy.
static void solvers() {
  const ModelSDOF m{7084.0, 3.5e3};
  const double k = 700.8e3, dt = 5e-4, d0 = 0.016;
  const double wn = std::sqrt(k / m.m_m), z = m.c_m / (2 * std::sqrt(k * m.m_m)), wd = wn * std::sqrt(1 - z * z);
  auto exact = [&](double t) { return d0 * std::exp(-z * wn * t) * (std::cos(wd * t) + z * wn / wd * std::sin(wd * t)); };
  CentralDifference cd(m, dt);
  ExplicitNewmark nm(m, dt);
  cd.reset(d0);
  nm.reset(d0);
  double err_cd = 0, err_nm = 0;
  for (int k_ = 0; k_ < 10000; ++k_) {  // 5 s
    const double t = k_ * dt;
    cd.step(0.0, k * cd.state().next_displacement);
    nm.step(0.0, k * nm.state().next_displacement);
    err_cd = std::fmax(err_cd, std::fabs(cd.state().displacement - exact(t)));
    err_nm = std::fmax(err_nm, std::fabs(nm.state().displacement - exact(t)));
  }
  // Second order: the phase error after 5 s is ~ wn^3 dt^2 t / 24 ~ 5e-6 rad.
  std::printf("solver max error over 5 s: CD %.3g, Newmark %.3g (of d0 = %.3g m)\n", err_cd, err_nm, d0);
  CHECK(err_cd < 1e-4 * d0);
  CHECK(err_nm < 1e-4 * d0);
}

template <class F>
static long count_allocations(F&& f) {
  sh_test::AllocationCounter counter;
  f();
  return counter.count();
}

static void loops_do_not_allocate() {
  const Rig rig = zhao2003();
  for (auto method : {SolverOptions::Method::CvodeBdf, SolverOptions::Method::Rk4}) {
    EftConfig ec;
    EftLoopOptions eo_options;
    eo_options.plant_options.method = method;
    ec.compensation = VelocityFeedbackCompensator::Kind::Nonlinear;
    ec.compute_delay = 1;
    EffectiveForceTest eft(rig, ec, std::nullopt, {}, nullptr, eo_options);
    EftOutput eo;
    std::vector<EftOutput> rows(2000);
    std::vector<double> ag(2000);
    for (std::size_t i = 0; i < ag.size(); ++i) ag[i] = 0.3 * std::sin(2 * kPi * 1.5 * i * ec.dt);
    eft.step(0.1, eo);  // warm-up (first-use lazies, if any)
    const long n_eft = count_allocations([&] {
      for (int i = 0; i < 500; ++i) eft.step(0.3 * std::sin(0.01 * i), eo);
      run_eft(eft, ag.data(), ag.size(), rows.data());
      eft.reset();
      eft.step(0.0, eo);
    });
    CHECK(n_eft == 0);

    for (auto rf : {RestoringForce::CalculatedDisplacement, RestoringForce::MeasuredDisplacement,
                    RestoringForce::MeasuredForce, RestoringForce::MeasuredForceCorrected}) {
      RpsdConfig rc;
      RpsdLoopOptions ro_options;
      ro_options.plant_options.method = method;
      rc.restoring_force = rf;
      rc.scheme = rf == RestoringForce::MeasuredForce ? IntegrationScheme::ExplicitNewmark : IntegrationScheme::CentralDifference;
      rc.compute_delay = 1;
      RealTimePseudoDynamicTest rp(rig, rc, {}, nullptr, nullptr, ro_options);
      RpsdOutput ro;
      std::vector<RpsdOutput> rrows(2000);
      rp.step(0.0, 100.0, 0.0, ro);
      const long n_rp = count_allocations([&] {
        for (int i = 0; i < 500; ++i) rp.step(0.0, 5e3, 0.0, ro);
        run_rpsd(rp, ag.data(), nullptr, nullptr, ag.size(), rrows.data());
        rp.reset();
      });
      CHECK(n_rp == 0);
    }
  }
}

// The EFT loop with exact linear compensation on the linear-analysis plant
// (Eqs 6-8, no valve dynamics) follows Eq (10): a first-order lag of roll-off
// w_cEFT (Eq 11) from P_eff to the applied force, independent of the structure.
static void eft_follows_eq10() {
  Rig rig = zhao2003();
  rig.effects.servovalve_dynamics = false;
  rig.effects.flow_nonlinearity = false;
  rig.effects.load_pressure = false;
  rig.effects.coulomb_friction = false;
  rig.effects.spring_softening = false;
  rig.effects.piston_mass = false;
  EftConfig ec;
  ec.lead_T = 0.0;  // no valve lag to compensate
  EffectiveForceTest eft(rig, ec);
  const double K = rig.A * rig.K_v * rig.C_F_force * rig.K_s * rig.G_p;
  const double wc = (rig.C_l + K) / rig.K_a;  // Eq (11)
  const double gain = K / (rig.C_l + K);      // Eq (10) at DC
  const double f = 1.58, w = 2 * kPi * f;     // at the structure's natural frequency
  EftOutput o;
  double ss = 0, sc = 0, cc = 0, ys = 0, yc = 0;
  for (int k = 0; k < 16000; ++k) {
    const double t = k * ec.dt;
    eft.step(-1e3 * std::sin(w * t) / rig.m, o);  // P_eff = 1 kN sin(w t)
    if (k < 8000) continue;
    const double s = std::sin(w * o.plant.time), c = std::cos(w * o.plant.time);
    ss += s * s, sc += s * c, cc += c * c, ys += o.plant.force * s, yc += o.plant.force * c;
  }
  const double det = ss * cc - sc * sc;
  const std::complex<double> H((ys * cc - yc * sc) / det / 1e3, (yc * ss - ys * sc) / det / 1e3);
  // Eq (10) with the digital loop's half-sample ZOH on the velocity compensation: loose tolerance.
  const std::complex<double> H10 = gain / std::complex<double>(1.0, w / wc);
  CHECK(std::abs(std::abs(H) - std::abs(H10)) < 0.05);
}

// Sensors of a smooth motion, the same for every controller (open loop: the
// controllers' commands compare sample for sample).
static Output sensors_at(int k, double dt) {
  // x = X sin^3(w t): at rest at t_0 (x, v, a and the forces 0), as a loop starts.
  const double t = k * dt, w = 2 * kPi * 1.3, sn = std::sin(w * t), cs = std::cos(w * t), X = 2e-3;
  Output s;
  s.time = t;
  s.displacement = X * sn * sn * sn;
  s.velocity = 3 * X * w * sn * sn * cs;
  s.acceleration = X * w * w * (6 * sn * cs * cs - 3 * sn * sn * sn);
  s.force = 3e3 * sn * sn * sn + 500.0 * sn * sn;
  s.pressure = s.force / 8.21e-3;
  return s;
}

// Eq (15)'s central difference is the 1-DOF case of LinearSubstructure (M = m_m,
// C = c_m, K = 0, ground = m_m, interface = 1): the RPsD commands agree to round-off
// for every restoring-force option, and the loop runs it without allocating.
static void eq15_is_the_one_dof_linear_substructure() {
  const Rig rig = zhao2003();
  for (auto rf : {RestoringForce::CalculatedDisplacement, RestoringForce::MeasuredDisplacement,
                  RestoringForce::MeasuredForce, RestoringForce::MeasuredForceCorrected}) {
    RpsdConfig rc;
    rc.restoring_force = rf;
    LinearSubstructureModel m1;
    m1.M = Eigen::MatrixXd::Constant(1, 1, rc.model.m_m);
    m1.C = Eigen::MatrixXd::Constant(1, 1, rc.model.c_m);
    m1.K = Eigen::MatrixXd::Zero(1, 1);
    m1.ground = Eigen::VectorXd::Constant(1, rc.model.m_m);
    m1.interface = Eigen::VectorXd::Ones(1);
    LinearSubstructure lin(m1, rc.dt, StructuralScheme::CentralDifference);
    RpsdController eq15(rc, rig), one(rc, rig, nullptr, &lin);
    double peak = 0.0, worst = 0.0;
    for (int k = 0; k < 4000; ++k) {
      const Output s = sensors_at(k, rc.dt);
      const double ag = k == 0 ? 0.0 : 2.0 * std::sin(2 * kPi * 2.1 * k * rc.dt);  // at rest at t_0
      const double pe = 500.0 * std::sin(2 * kPi * 0.7 * k * rc.dt);
      const double u1 = eq15.command(s, ag, pe), u2 = one.command(s, ag, pe);
      peak = std::fmax(peak, std::fabs(u1));
      worst = std::fmax(worst, std::fabs(u1 - u2));
      CHECK_NEAR(eq15.integrator_state().displacement, one.integrator_state().displacement, 1e-9 * (peak + 1e-6));
    }
    CHECK(peak > 1e-4);
    CHECK(worst <= 1e-9 * peak);
    std::printf("  1-DOF linear vs Eq (15) central difference, option %d: max |du| = %.3g of peak %.3g m\n",
                static_cast<int>(rf), worst, peak);
  }
}

// RPsD on a 3-DOF linear substructure with ATS as the tracking compensator: runs,
// finite, and neither step nor run allocates.
static void rpsd_mdof_with_ats_does_not_allocate() {
  const Rig rig = zhao2003();
  RpsdConfig rc;
  rc.restoring_force = RestoringForce::MeasuredDisplacement;
  LinearSubstructureModel m3;
  m3.M = 2000.0 * Eigen::MatrixXd::Identity(3, 3);
  m3.K.setZero(3, 3);
  const double k = 4e6;
  m3.K << k, -k, 0, -k, 2 * k, -k, 0, -k, k;
  m3.C = 1e-3 * m3.K;
  m3.ground = m3.M * Eigen::VectorXd::Ones(3);
  m3.interface = Eigen::VectorXd::Unit(3, 0);
  LinearSubstructure lin(m3, rc.dt, StructuralScheme::CentralDifference);
  rths::AtsConfig ac;
  ac.dt = rc.dt;
  ac.converters.ad = ideal_converter();
  ac.converters.da = ideal_converter(Converter::Kind::DigitalToAnalog);
  rths::AdaptiveTimeSeries ats(ac);
  RealTimePseudoDynamicTest rp(rig, rc, {}, &ats, &lin);
  std::vector<RpsdOutput> rows(3000);
  std::vector<double> ag(rows.size());
  for (std::size_t i = 0; i < ag.size(); ++i) ag[i] = 0.3 * std::sin(2 * kPi * 2.0 * i * rc.dt);
  RpsdOutput ro;
  rp.step(0.0, 0.0, 0.0, ro);
  RunSummary sum;
  const long n = count_allocations([&] {
    rp.reset();
    sum = run_rpsd(rp, ag.data(), nullptr, nullptr, ag.size(), rows.data());
  });
  CHECK(n == 0);
  CHECK(sum.rows == rows.size());
  double peak = 0.0;
  for (const RpsdOutput& r : rows) peak = std::fmax(peak, std::fabs(r.plant.displacement));
  CHECK(std::isfinite(peak) && peak > 1e-5 && peak < 0.1);
}

int main() {
  phase_lead();
  sample_delay();
  solvers();
  loops_do_not_allocate();
  eft_follows_eq10();
  eq15_is_the_one_dof_linear_substructure();
  rpsd_mdof_with_ats_does_not_allocate();
  return sh_test::report("test_loops");
}
