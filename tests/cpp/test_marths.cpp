// The maRTHS blocks (servohydraulics/marths/*.hpp, iir_filter.hpp) against closed forms and their
// contracts: the Butterworth design (unit DC gain, -3 dB at the prewarped cutoff), the ode4 matrices
// against RK4 stages written out, the ode4 map's fixed point against the continuous DC gain, the modal
// realisation of a transfer matrix against its zero-pole-gain form, the perturbed draws (order and gain
// rescaling), the Newmark displacement form's invariants, RoDeAC's closed-form algebraic loop (the command
// equals the updated theta times the target taps), bad input named, and no allocation in any per-sample
// call nor in the whole loop.
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "servohydraulics/error.hpp"
#include "servohydraulics/marths/controllers.hpp"
#include "servohydraulics/marths/loop.hpp"
#include "servohydraulics/marths/plant.hpp"

#include "alloc_counter.hpp"  // after the headers that pull in mm_malloc.h
#include "check.hpp"

using namespace servohydraulics;
using namespace servohydraulics::marths;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDt = 1.0 / 1024.0;

template <class F>
bool throws_naming(F&& f, const std::string& field) {
  try {
    f();
  } catch (const Error& e) {
    const bool ok = std::string(e.what()).find(field) != std::string::npos;
    if (!ok) std::fprintf(stderr, "message without '%s': %s\n", field.c_str(), e.what());
    return ok;
  }
  return false;
}

void butterworth() {
  const IirCoefficients c = butterworth_lowpass(4, 20.0, 1024.0);
  CHECK(c.order == 4);
  CHECK_NEAR(c.dc_gain(), 1.0, 1e-12);
  CHECK_NEAR(c.b[0], 1.2134e-5, 5e-10);  // BENCHMARK.md 7: b0 = 1.2134e-5
  // the bilinear design with prewarping puts -3 dB exactly at the digital cutoff
  const std::complex<double> z = std::exp(std::complex<double>(0.0, 2.0 * kPi * 20.0 / 1024.0));
  std::complex<double> num = 0.0, den = 0.0;
  for (std::size_t i = 0; i <= 4; ++i) {
    num += c.b[i] * std::pow(z, -static_cast<double>(i));
    den += c.a[i] * std::pow(z, -static_cast<double>(i));
  }
  CHECK_NEAR(std::abs(num / den), 1.0 / std::sqrt(2.0), 1e-9);
  // the transposed direct form equals the difference equation written out
  IirFilter f(c);
  std::vector<double> u(200), y(200);
  std::mt19937 g(3);
  std::normal_distribution<double> n;
  for (double& v : u) v = n(g);
  for (std::size_t k = 0; k < u.size(); ++k) {
    double acc = 0.0;
    for (std::size_t i = 0; i <= 4; ++i) {
      if (k >= i) acc += c.b[i] * u[k - i];
      if (i > 0 && k >= i) acc -= c.a[i] * y[k - i];
    }
    y[k] = acc;
    const double pending = f.pending();
    const double out = f.step(u[k]);
    CHECK_NEAR(out, y[k], 1e-12);
    CHECK_NEAR(out, c.b[0] * u[k] + pending, 1e-15);
  }
  CHECK(throws_naming([] { butterworth_lowpass(4, 600.0, 1024.0); }, "butterworth.cutoff"));
  CHECK(throws_naming([] { butterworth_lowpass(9, 20.0, 1024.0); }, "butterworth.order"));
}

StateSpace random_plant(unsigned seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> n;
  StateSpace s;
  s.A = Eigen::MatrixXd::Zero(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.A(i, j) = 20.0 * n(g);
  s.A -= 80.0 * Eigen::MatrixXd::Identity(3, 3);
  s.B = Eigen::MatrixXd::Random(3, 2);
  s.C = Eigen::MatrixXd::Random(2, 3);
  s.D = Eigen::MatrixXd::Zero(2, 2);
  return s;
}

void ode4() {
  const StateSpace s = random_plant(7);
  Eigen::MatrixXd Phi, Gamma;
  ode4_matrices(s.A, s.B, kDt, Phi, Gamma);
  // classical RK4 with u held, stage by stage
  const Eigen::Vector3d x0(0.3, -1.2, 0.7);
  const Eigen::Vector2d u(0.5, -2.0);
  auto f = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return s.A * x + s.B * u; };
  const Eigen::Vector3d k1 = f(x0), k2 = f(x0 + 0.5 * kDt * k1), k3 = f(x0 + 0.5 * kDt * k2), k4 = f(x0 + kDt * k3);
  const Eigen::Vector3d rk4 = x0 + kDt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  CHECK_NEAR((Phi * x0 + Gamma * u - rk4).norm(), 0.0, 1e-14);
  // the ode4 map's fixed point under a held command is the continuous DC gain -C A^-1 B u
  IdentifiedPlant p(s, kDt, 1e-3);
  const double cmd[2] = {1e-3 * u(0), 1e-3 * u(1)};  // [m]: the model's unit is mm
  bool ok = true;
  for (int k = 0; k < 20000; ++k) ok = p.step(cmd).ok() && ok;
  CHECK(ok);
  double y[2];
  p.displacements(y);
  const Eigen::Vector2d dc = -s.C * s.A.partialPivLu().solve(s.B * u);
  CHECK_NEAR(y[0], 1e-3 * dc(0), 1e-15);
  CHECK_NEAR(y[1], 1e-3 * dc(1), 1e-15);
  // the Taylor series: H(s) - sum H_m s^m = O(s^4) at small s
  const auto H = s.taylor_coefficients(3);
  const std::complex<double> sm(0.0, 0.5);
  Eigen::MatrixXcd series = Eigen::MatrixXcd::Zero(2, 2);
  for (int m = 3; m >= 0; --m) series = series * sm + H[static_cast<std::size_t>(m)].cast<std::complex<double>>();
  CHECK((s.frequency_response(sm) - series).norm() < 1e-7 * H[0].norm());
  StateSpace bad = s;
  bad.D(1, 0) = 0.5;
  CHECK(throws_naming([&] { IdentifiedPlant q(bad, kDt); }, "D[1][0]"));
  bad = s;
  bad.A(2, 1) = std::nan("");
  CHECK(throws_naming([&] { IdentifiedPlant q(bad, kDt); }, "A[2][1]"));
}

void transfer_matrix() {
  const BenchmarkPlantModel nominal;
  const TransferMatrix H = nominal.transfer_matrix();
  const StateSpace ss = H.realize();
  CHECK(ss.states() == 8);
  for (double w : {0.0, 0.3, 5.0, 60.0, 400.0, 3000.0}) {
    const std::complex<double> s(0.0, w);
    CHECK((ss.frequency_response(s) - H.frequency_response(s)).norm() < 1e-11 * H.frequency_response(s).norm());
  }
  // BENCHMARK.md 4: the DC gains [[0.8638, 0.1311], [0.1396, 0.9258]]
  const Eigen::MatrixXd dc = H.dc_gain();
  CHECK_NEAR(dc(0, 0), 0.8638, 1e-4);
  CHECK_NEAR(dc(0, 1), 0.1311, 1e-4);
  CHECK_NEAR(dc(1, 0), 0.1396, 1e-4);
  CHECK_NEAR(dc(1, 1), 0.9258, 1e-4);
  // the nine draws in order: a unit draw k moves exactly the k-th value by (1 + c)
  const PlantUncertainty unc;
  const double c[9] = {0.055, 0.055, 0.06, 0.06, 0.05, 0.03, 0.03, 0.03, 0.03};
  for (int k = 0; k < 9; ++k) {
    double z[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    z[k] = 1.0;
    const BenchmarkPlantModel p = unc.perturb(nominal, z);
    const double f = 1.0 + c[k];
    const double got[9] = {p.h1_zero_1 / nominal.h1_zero_1, p.h1_zero_2 / nominal.h1_zero_2,
                           p.h1_pole_1 / nominal.h1_pole_1, p.h1_pole_2 / nominal.h1_pole_2,
                           (p.frame_pole / nominal.frame_pole).real(), p.h12_zero / nominal.h12_zero,
                           p.h2_pole_1 / nominal.h2_pole_1, p.h2_pole_2 / nominal.h2_pole_2,
                           p.h22_zero / nominal.h22_zero};
    for (int j = 0; j < 9; ++j) CHECK_NEAR(got[j], j == k ? f : 1.0, 1e-15);
    CHECK_NEAR((p.frame_pole / nominal.frame_pole).imag(), 0.0, 1e-15);  // both parts by one factor
  }
  // a draw: every element's magnitude at the match frequency is the nominal one; the columns share poles
  const TransferMatrix D = unc.draw(nominal, 42);
  const std::complex<double> s0(0.0, unc.match_frequency);
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j)
      CHECK_NEAR(std::abs(D.element(i, j, s0)), std::abs(H.element(i, j, s0)), 1e-12 * std::abs(H.element(i, j, s0)));
  CHECK(D.poles[0][2] == D.poles[1][2] && D.poles[0][3] == std::conj(D.poles[0][2]));
  CHECK(D.zeros[0][0] == D.zeros[1][0]);
  TransferMatrix bad = H;
  bad.poles[1][1] = bad.poles[1][0];
  CHECK(throws_naming([&] { bad.realize(); }, "transfer_matrix.poles[1][1]"));
}

//! A small structure with a massless DOF (the FE model's kind): 3 DOFs, DOF 2 massless.
StructureMatrices small_structure() {
  StructureMatrices s;
  s.K = Eigen::MatrixXd(3, 3);
  s.K << 4e6, -2e6, 0, -2e6, 5e6, -1e6, 0, -1e6, 3e6;
  s.M = Eigen::Vector3d(100.0, 0.0, 80.0).asDiagonal();
  s.C = 1e-3 * s.K;
  s.influence = Eigen::Vector3d(1.0, 0.0, 1.0);
  return s;
}

void newmark() {
  const StructureMatrices s = small_structure();
  NewmarkStructure n(s, kDt);
  std::mt19937 g(11);
  std::normal_distribution<double> d;
  Eigen::VectorXd U0 = n.displacement(), V0 = n.velocity(), A0 = n.acceleration();
  const NewmarkConstants c(0.5, 0.25, kDt);
  for (int k = 0; k < 400; ++k) {
    const double ag = d(g);
    const double F[3] = {d(g) * 1e3, d(g) * 1e2, 0.0};
    n.step(ag, F);
    const Eigen::VectorXd &U = n.displacement(), &V = n.velocity(), &A = n.acceleration();
    // the equation of motion holds at the new step (the displacement form's A is the EOM's)
    const Eigen::Vector3d Fv(F[0], F[1], F[2]);
    const Eigen::VectorXd r = s.M * A + s.C * V + s.K * U + s.M * s.influence * ag + Fv;
    CHECK(r.norm() < 1e-6 * (s.K * U).norm() + 1e-9);
    // average acceleration: V and U by the trapezoidal rule
    CHECK((V - V0 - 0.5 * kDt * (A0 + A)).norm() <= 1e-9 * (V.norm() + 1e-12));
    CHECK((U - U0 - 0.5 * kDt * (V0 + V)).norm() <= 1e-9 * (U.norm() + 1e-12));
    U0 = U;
    V0 = V;
    A0 = A;
  }
  StructureMatrices bad = s;
  bad.K(0, 1) *= 1.5;
  CHECK(throws_naming([&] { NewmarkStructure m(bad, kDt); }, "K[2,1]"));
  bad = s;
  bad.M(2, 2) = std::nan("");
  CHECK(throws_naming([&] { NewmarkStructure m(bad, kDt); }, "M[3,3]"));
}

void rodeac() {
  RodeacConfig cfg;
  for (int i = 0; i < 2; ++i) {
    RodeacChannel ch;
    ch.theta0 = Eigen::Vector4d(5.4, 1.96, -1.5, -4.96);
    ch.P0 = 1e4 * Eigen::Matrix4d::Identity();
    cfg.channels.push_back(ch);
  }
  RodeacController r(cfg);
  std::mt19937 g(5);
  std::normal_distribution<double> d;
  double T[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  for (int k = 0; k < 300; ++k) {
    double desired[2], measured[2], u[2];
    for (int i = 0; i < 2; ++i) {
      desired[i] = 1e-3 * std::sin(0.05 * k + i) + 1e-5 * d(g);
      measured[i] = 0.9 * desired[i] + 1e-5 * d(g);
      for (int j = 3; j > 0; --j) T[i][j] = T[i][j - 1];
      T[i][0] = desired[i] * 1e3;
    }
    r.command(MultiTrackingInput{2, desired, measured}, u);
    for (std::size_t i = 0; i < 2; ++i) {
      double dot = 0.0;
      for (int j = 0; j < 4; ++j) dot += r.theta(i)(j) * T[i][j];
      CHECK_NEAR(u[i] * 1e3, dot, 1e-9 * (1.0 + std::fabs(dot)));  // the model's u = theta+^T T
    }
  }
  RodeacConfig bad = cfg;
  bad.channels[1].P0(0, 3) += 1.0;
  CHECK(throws_naming([&] { RodeacController x(bad); }, "rodeac.P0[1]"));
  bad = cfg;
  bad.channels[0].P0 = -Eigen::Matrix4d::Identity();
  CHECK(throws_naming([&] { RodeacController x(bad); }, "rodeac.P0[0]"));
}

//! A synthetic 29-DOF model shaped like the benchmark's: a stiff chain, some DOFs massless.
MarthsStructures synthetic_structures() {
  const int n = 29;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n), M = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    K(i, i) = 3e8;
    if (i + 1 < n) K(i, i + 1) = K(i + 1, i) = -1e8;
    M(i, i) = (i % 3 == 1) ? 0.0 : 2000.0;
  }
  Eigen::VectorXd l = Eigen::VectorXd::Zero(n);
  l(12) = l(25) = l(26) = 1.0;
  return MarthsStructures::build(K, M, l);
}

void loop_and_allocations() {
  const MarthsStructures st = synthetic_structures();
  IdentifiedPlant plant(BenchmarkPlantModel().transfer_matrix().realize(), kDt);
  RodeacConfig cfg;
  for (int i = 0; i < 2; ++i) cfg.channels.push_back({Eigen::Vector4d(5.4, 1.96, -1.5, -4.96), 1e4 * Eigen::Matrix4d::Identity()});
  RodeacController rodeac(cfg);
  PassThrough none(2);
  SampleControllerConfig sc;
  sc.dt = kDt;
  SampleController s1(sc), s2(sc);
  DecentralizedController dec({&s1, &s2}, kDt);
  MimoFeedforward ff(MimoFeedforwardConfig::from_plant(BenchmarkPlantModel().transfer_matrix().realize(), 2, kDt));
  std::vector<double> t, a;
  for (int k = 0; k <= 400; ++k) {
    t.push_back(0.01 * k);
    a.push_back(k < 100 ? 0.0 : 3.0 * std::sin(0.3 * k) * std::exp(-0.01 * (k - 100)));
  }
  const GroundMotion gm(t, a, 0.4);
  const std::size_t n = 4096;
  std::vector<MarthsOutput> rows(n);
  std::vector<double> secs(n);
  for (MultiTrackingController* c : std::vector<MultiTrackingController*>{&rodeac, &none, &dec, &ff}) {
    MarthsLoop loop(plant, *c, st);
    {
      sh_test::AllocationCounter counter;
      const RunSummary sum = loop.run(gm, n, rows.data(), secs.data());
      if (sh_test::kCountingAllocations) CHECK(counter.count() == 0);
      CHECK(sum.ok() && sum.rows == n);
    }
    // rows: the targets are the strokes of the numerical interface; the estimate inverts the measured strokes
    const Coupler cp = Coupler::marths();
    for (std::size_t k = 0; k < n; k += 97) {
      double s[2];
      cp.strokes(rows[k].x_numerical, rows[k].theta_numerical, s);
      CHECK_NEAR(rows[k].target_1, s[0], 1e-15);
      CHECK_NEAR(rows[k].target_2, s[1], 1e-15);
      const double m[2] = {rows[k].measured_1, rows[k].measured_2};
      double x = 0, th = 0;
      cp.benchmark_estimate(m, &x, &th);
      CHECK(x == rows[k].x_estimate && th == rows[k].theta_estimate);
      CHECK_NEAR(rows[k].voltage_1, rows[k].command_1 * 1e3 / (1.053 * 7.4921) - 0.0092 / 7.4921, 1e-15);
    }
  }
  // the per-sample calls alone
  {
    double y[2], u[2] = {1e-3, -1e-3}, d[2] = {1e-3, 2e-3}, m[2] = {0.9e-3, 2.1e-3};
    sh_test::AllocationCounter counter;
    for (int k = 0; k < 100; ++k) {
      plant.displacements(y);
      (void)plant.step(u);
      rodeac.command(MultiTrackingInput{2, d, m}, u);
      ff.command(MultiTrackingInput{2, d, m}, u);
      dec.command(MultiTrackingInput{2, d, m}, u);
    }
    if (sh_test::kCountingAllocations) CHECK(counter.count() == 0);
  }
  // a diverging plant stops the loop at the failing sample, NonFinite
  StateSpace unstable = BenchmarkPlantModel().transfer_matrix().realize();
  unstable.A(0, 0) = 3000.0;
  IdentifiedPlant bad(unstable, kDt);
  MarthsLoop loop(bad, none, st);
  const RunSummary sum = loop.run(gm, 200000, nullptr);
  CHECK(!sum.ok() && sum.status.code == Status::NonFinite && sum.rows < 200000);
  CHECK_NEAR(sum.failure_time, static_cast<double>(sum.rows - 1) * kDt, 1e-12);
  // bad input named
  PassThrough three(3);
  CHECK(throws_naming([&] { MarthsLoop l(plant, three, st); }, "controller.actuators"));
  IdentifiedPlant slow(BenchmarkPlantModel().transfer_matrix().realize(), 2 * kDt);
  CHECK(throws_naming([&] { MarthsLoop l(slow, none, st); }, "plant.dt"));
  MarthsLoopConfig lc;
  lc.noise_power = -1.0;
  CHECK(throws_naming([&] { MarthsLoop l(plant, none, st, lc); }, "noise_power"));
}

void physical_frame() {
  const PhysicalFrame f = PhysicalFrame::from(PhysicalFrameParameters{});
  // K symmetric positive definite, G the condensation: K_oo G + K_ot = 0
  CHECK((f.K - f.K.transpose()).norm() <= 1e-12 * f.K.norm());
  CHECK((f.K.block<3, 3>(2, 2) * f.G + f.K.block<3, 2>(2, 0)).norm() <= 1e-9 * f.K.norm());
  // C is modal: each mode's damping ratio is 0.05 at its rounded frequency
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> es(f.K, f.M);
  for (int i = 0; i < 5; ++i) {
    const Eigen::Matrix<double, 5, 1> phi = es.eigenvectors().col(i);
    const double zeta = phi.dot(f.C * phi) / (2.0 * f.omegas[static_cast<std::size_t>(i)] * phi.dot(f.M * phi));
    CHECK_NEAR(zeta, 0.05, 1e-9);
    CHECK_NEAR(f.omegas[static_cast<std::size_t>(i)], std::sqrt(es.eigenvalues()(i)), 0.005 + 1e-12);
  }
  // the derivative blocks: 0 at k = 0, then backward differences
  FrameFeedback fb(f, kDt);
  double out[5];
  fb(0.0, 0.0, out);
  const double v = 0.01;  // m/s, a ramp in x
  fb(v * kDt, 0.0, out);  // k = 1: D1 = v, D2 = v / dt
  Eigen::Matrix<double, 5, 1> q, D1, D2;
  q << v * kDt, 0.0, f.G * Eigen::Vector2d(v * kDt, 0.0);
  D1 = q / kDt;
  D2 = D1 / kDt;
  const Eigen::Matrix<double, 5, 1> expect = f.K * q + f.C * D1 + f.M * D2;
  for (int i = 0; i < 5; ++i) CHECK_NEAR(out[i], expect(i), 1e-9 * expect.norm());
}
}  // namespace

int main() {
  butterworth();
  ode4();
  transfer_matrix();
  newmark();
  rodeac();
  physical_frame();
  loop_and_allocations();
  return sh_test::report("test_marths");
}
