// The RTHS blocks (servohydraulics/rths/*.hpp) and the loops' converter blocks
// (loop_converters.hpp) against closed forms and their contracts: Tustin
// coefficients and frequency response, quantizer/saturation/converter order,
// noise statistics, unit delay, backward difference, a substructure step
// against the SDOF step response, and no allocation in any controller's
// command(), the plants' and substructures' steps, the RTHS loop and a
// closed loop with its converter blocks on.
#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

#include "servohydraulics/loop_converters.hpp"
#include "servohydraulics/loops.hpp"
#include "servohydraulics/rths/loop.hpp"
#include "servohydraulics/zhao2003.hpp"

#include "alloc_counter.hpp"  // after the headers that pull in mm_malloc.h
#include "check.hpp"

using namespace servohydraulics;
using namespace servohydraulics::rths;

namespace {
constexpr double kH = 1.0 / 4096.0;
constexpr double kPi = 3.14159265358979323846;

void tustin_coefficients() {
  // BENCHMARK.md 7: the published difference equations at h = 1/4096.
  SampleController c;
  CHECK_NEAR(c.lead().n0(), 25.353362720558675, 1e-12);
  CHECK_NEAR(c.lead().n1(), -24.330788542666237, 1e-12);
  CHECK_NEAR(c.lead().d1(), 0.022574177892434395, 1e-15);
  CHECK(c.pi().n0() == 2.0115966796875 && c.pi().n1() == -1.9884033203125 && c.pi().d1() == -1.0);
  // Any first-order section: H(e^{jwh}) = G(j (2/h) tan(wh/2)) (the bilinear map), at several w.
  const double b1 = 0.3, b0 = 7.0, a1 = 0.02, a0 = 5.0, h = 1e-3;
  const TustinFirstOrder t(b1, b0, a1, a0, h);
  for (double w : {1.0, 50.0, 700.0, 2500.0}) {
    const std::complex<double> zi = std::exp(std::complex<double>(0.0, -w * h));
    const std::complex<double> H = (t.n0() + t.n1() * zi) / (1.0 + t.d1() * zi);
    const std::complex<double> s(0.0, 2.0 / h * std::tan(w * h / 2.0));
    const std::complex<double> G = (b1 * s + b0) / (a1 * s + a0);
    CHECK_NEAR(std::abs(H - G), 0.0, 1e-12 * std::abs(G));
  }
  TustinFirstOrder step(b1, b0, a1, a0, h);  // DC gain b0/a0 after the transient
  double y = 0.0;
  for (int k = 0; k < 20000; ++k) y = step(1.0);
  CHECK_NEAR(y, b0 / a0, 1e-12);
}

//! 200,000 draws of a generator: mean 0, sd 1, no lag-1 correlation (4.5 sigma bounds), and
//! the same sequence from a second generator with the same seed.
void check_standard_normal(NoiseGenerator generator, std::uint64_t seed) {
  GaussianSequence g(seed, generator), g2(seed, generator);
  const int n = 200000;
  double s = 0.0, s2 = 0.0, s11 = 0.0, prev = 0.0;
  bool same = true;
  for (int k = 0; k < n; ++k) {
    const double w = g.next();
    same = same && (w == g2.next());
    s += w;
    s2 += w * w;
    s11 += w * prev;
    prev = w;
  }
  CHECK(same);
  CHECK_NEAR(s / n, 0.0, 4.5 / std::sqrt(n));
  CHECK_NEAR(std::sqrt(s2 / n), 1.0, 4.5 / std::sqrt(2.0 * n));
  CHECK_NEAR(s11 / n, 0.0, 4.5 / std::sqrt(n));
}

void converters() {
  const Quantizer q{0.25};
  CHECK(q(0.125) == 0.25 && q(-0.125) == -0.25 && q(0.375) == 0.5 && q(0.12) == 0.0);  // half away from zero
  double worst = 0.0;
  for (int i = -4000; i <= 4000; ++i) {
    const double u = 1.2345e-3 * i;
    worst = std::fmax(worst, std::fabs(q(u) - u));
    CHECK(std::fabs(q(u) / 0.25 - std::round(q(u) / 0.25)) == 0.0);
  }
  CHECK(worst <= 0.125);
  Converter ad, da;
  ad.kind = Converter::Kind::AnalogToDigital;
  da.kind = Converter::Kind::DigitalToAnalog;
  ad.saturation = da.saturation = {-2.4, 2.4};
  ad.quantizer.step = da.quantizer.step = 1.0;
  CHECK(ad(5.0) == 2.0 && da(5.0) == 2.4);  // A/D: saturate then quantize; D/A: quantize then saturate
  CHECK(ad(-5.0) == -2.0 && da(-5.0) == -2.4);
  const Converter b = benchmark_converter(Converter::Kind::AnalogToDigital);
  CHECK(b.quantizer.step == std::ldexp(1.0, -18) && b.saturation.upper == 3.8);
  CHECK(ideal_converter()(1e300) == 1e300);
  // Noise: mean 0, sd 1, white; the same sequence for the same seed.
  check_standard_normal(NoiseGenerator::MersenneTwister, 42);
  CHECK_NEAR(SensorNoise::band_limited_sigma(6.25e-14, kH), 1.6e-5, 1e-20);  // BENCHMARK.md 3.2
  // The Simulink generator.  Seed scrambling: 0 maps to the block's replacement
  // state, 65536 (high half 1) to state 1.  From state 1 the minimal standard
  // generator is at 1043618065 after 10000 draws (Park and Miller 1988, CACM 31(10),
  // the check value of a correct implementation).
  CHECK(GaussianSequence::simulink_state(0) == 1144108930U);
  CHECK(GaussianSequence::simulink_state(65536) == 1U);
  GaussianSequence pm(65536, NoiseGenerator::SimulinkRandomNumber);
  CHECK(pm.simulink_generator_state() == 1U);
  double last = 0.0;
  for (int k = 0; k < 10000; ++k) last = pm.simulink_uniform();
  CHECK(pm.simulink_generator_state() == 1043618065U);
  CHECK_NEAR(last, 1043618065.0 / 2147483647.0, 1e-16);
  // Its normals: mean 0, sd 1, white, and the same for the same seed.
  check_standard_normal(NoiseGenerator::SimulinkRandomNumber, 0);
  UnitDelay d(0.5);
  CHECK(d(1.0) == 0.5 && d(2.0) == 1.0 && d(3.0) == 2.0);
  d.reset();
  CHECK(d(7.0) == 0.5);
  BackwardDifference D(0.01);
  CHECK(D(3.0) == 0.0);  // the first step
  CHECK_NEAR(D(3.02), 2.0, 1e-12);
  CHECK_NEAR(D(3.04), 2.0, 1e-12);
}

void loop_io() {
  LoopConverters c;
  CHECK(!c.active() && !LoopIo(c).active());
  c.force.converter.enabled = true;
  c.force.converter.quantizer.step = 10.0;
  c.displacement.unit_delay = true;
  c.command.enabled = true;
  c.command.quantizer.step = 0.5;
  c.command_unit_delay = true;
  LoopIo io(c);
  CHECK(io.active());
  Output t, m;
  t.displacement = 1.0;
  t.velocity = 0.3;
  t.force = 14.9;
  io.measure(t, m);
  CHECK(m.displacement == 0.0 && m.velocity == 0.3 && m.force == 10.0);
  t.displacement = 2.0;
  t.force = 15.0;
  io.measure(t, m);
  CHECK(m.displacement == 1.0 && m.force == 20.0);
  CHECK(io.actuate(0.3) == 0.0 && io.actuate(0.8) == 0.5 && io.actuate(0.0) == 1.0);
  LoopConverters bad;
  bad.velocity.noise.sigma = -1.0;
  bool threw = false;
  try {
    LoopIo x(bad);
  } catch (const Error& e) {
    threw = std::string(e.what()).find("converters.velocity.noise.sigma") != std::string::npos;
  }
  CHECK(threw);
}

// SDOF m x'' + c x' + k x = -m a_g - f from rest, a_g and f constant: the closed-form step response.
double sdof_step(double m, double c, double k, double load, double t) {
  const double wn = std::sqrt(k / m), z = c / (2.0 * std::sqrt(k * m)), wd = wn * std::sqrt(1.0 - z * z);
  return load / k * (1.0 - std::exp(-z * wn * t) * (std::cos(wd * t) + z / std::sqrt(1.0 - z * z) * std::sin(wd * t)));
}

void substructure_step() {
  const double m = 100.0, k = 4.0e5, c = 2.0 * 0.03 * std::sqrt(k * m), ag = 1.5, f = 40.0;
  LinearSubstructureModel model;
  model.M = Eigen::MatrixXd::Constant(1, 1, m);
  model.C = Eigen::MatrixXd::Constant(1, 1, c);
  model.K = Eigen::MatrixXd::Constant(1, 1, k);
  model.ground = Eigen::VectorXd::Constant(1, m);
  model.interface = Eigen::VectorXd::Constant(1, 1.0);
  const double load = -m * ag - f, xs = std::fabs(load / k);
  const int n = 4096;  // 1 s; the structure at 10 Hz
  // Tolerances (of the static displacement), wh = 0.0153: RK4 n (wh)^5 / 120 = 3e-8; Newmark's
  // period error n (wh)^3 / 24 ~ 4e-4; central difference starts from rest with x_{-1} = 0 instead of
  // h^2/2 a_0 under the step load: an initial-velocity error h a_0 / 2, i.e. an amplitude h w / 2 = 7.7e-3;
  // the average acceleration scheme starts with a_0 = 0 (at rest) under the step load: the same 7.4e-3.
  const struct {
    SubstructureScheme scheme;
    double tol;
  } cases[] = {{SubstructureScheme::RungeKutta4, 5e-8}, {SubstructureScheme::CentralDifference, 1e-2},
               {SubstructureScheme::ExplicitNewmark, 5e-4}, {SubstructureScheme::AverageAcceleration, 1e-2}};
  for (const auto& cs : cases) {
    LinearSubstructure s(model, kH, cs.scheme);
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
      s.step(ag, ag, ag, f);
      worst = std::fmax(worst, std::fabs(s.displacement()(0) - sdof_step(m, c, k, load, (i + 1) * kH)));
    }
    std::printf("substructure step, scheme %d: worst error %.3g of the static displacement\n",
                static_cast<int>(cs.scheme), worst / xs);
    CHECK(worst <= cs.tol * xs);
  }
  // No interface DOF: a setup error naming the field.
  LinearSubstructureModel none = model;
  none.interface.setZero();
  bool named = false;
  try {
    LinearSubstructure bad(none, kH);
  } catch (const Error& e) {
    named = std::string(e.what()).find("interface") != std::string::npos;
  }
  CHECK(named);
  // One RK4 step against its own closed form: x1 = h^2/2 a0 (1 - h^2 wn^2/12) ... checked via the Taylor series.
  LinearSubstructure s(model, kH);
  s.step(ag, ag, ag, f);
  const double a0 = load / m, w2 = k / m, z2 = c / m, h = kH;
  // RK4 is exact through h^4 for x' = A x + b: x1 = sum_{j=1..4} h^j/j! A^{j-1} b (first component).
  const double b2 = a0, b3 = -z2 * a0, b4 = (z2 * z2 - w2) * a0;  // (A^{j-1} b)_x for j = 2, 3, 4
  const double x1 = h * h / 2.0 * b2 + h * h * h / 6.0 * b3 + h * h * h * h / 24.0 * b4;
  CHECK_NEAR(s.displacement()(0), x1, 1e-14 * std::fabs(x1));
}

LinearSubstructureModel three_storey() {
  LinearSubstructureModel mdl;
  const double k = 2.0e6;
  mdl.M = 1000.0 * Eigen::Matrix3d::Identity();
  mdl.M(0, 0) -= 29.13;
  mdl.K.resize(3, 3);
  mdl.K << 2 * k, -k, 0, -k, 2 * k, -k, 0, -k, k;
  mdl.K(0, 0) -= 1190e3;
  mdl.C = 1e-3 * mdl.K + 0.1 * mdl.M;
  mdl.ground = Eigen::Vector3d::Constant(1000.0);
  mdl.interface = Eigen::Vector3d(1.0, 0.0, 0.0);
  return mdl;
}

void no_allocation() {
  if (!sh_test::kCountingAllocations) {
    std::printf("allocation checks skipped (sanitizer build)\n");
    return;
  }
  const BenchmarkPlantParameters par;
  SampleController sample;
  PolynomialConfig pc;
  pc.tau = plant_delay(par);
  PolynomialExtrapolation poly(pc);
  AdaptiveTimeSeries ats(AtsConfig{});
  ModelBasedCompensator model(model_based_config(par, 3));
  TrackingController* ctrls[] = {&sample, &poly, &ats, &model};
  BenchmarkPlant plant(par, kH);
  LinearSubstructure subs[] = {{three_storey(), kH, SubstructureScheme::RungeKutta4},
                               {three_storey(), kH, SubstructureScheme::CentralDifference},
                               {three_storey(), kH, SubstructureScheme::ExplicitNewmark},
                               {three_storey(), kH, SubstructureScheme::AverageAcceleration}};
  std::vector<double> t(400), a(400);
  for (int i = 0; i < 400; ++i) {
    t[i] = 0.01 * i;
    a[i] = std::sin(2.0 * kPi * 2.0 * t[i]);
  }
  GroundMotion gm(t, a, 0.4);
  LinearSubstructure num(three_storey(), kH);
  RthsLoop loop(plant, num, sample);
  const std::size_t n = 8192;
  std::vector<RthsOutput> rec(n);
  std::vector<double> nd(3 * n);
  LoopConverters lc;
  lc.force.noise.sigma = 5.0;
  lc.displacement.converter = benchmark_converter(Converter::Kind::AnalogToDigital);
  lc.displacement.unit_delay = true;
  lc.command = benchmark_converter(Converter::Kind::DigitalToAnalog);
  RpsdConfig rc;
  SolverOptions rk4;
  rk4.method = SolverOptions::Method::Rk4;
  RealTimePseudoDynamicTest rpsd(zhao2003(), rc, lc, nullptr, nullptr, RpsdLoopOptions{rk4});
  std::vector<RpsdOutput> rows(2000);
  std::vector<double> ag(2000);
  for (std::size_t i = 0; i < ag.size(); ++i) ag[i] = std::sin(0.01 * static_cast<double>(i));
  long counts[4] = {0, 0, 0, 0};
  RunSummary sum;
  RunSummary rs;
  {
    sh_test::AllocationCounter counter;
    for (int c = 0; c < 4; ++c) {
      for (int k = 0; k < 5000; ++k) {
        const double s = std::sin(1e-3 * k);
        ctrls[c]->command(TrackingInput{1e-3 * s, 1e-3 * std::cos(1e-3 * k), -1e-3 * s, 0.9e-3 * s, 10.0 * s});
      }
      ctrls[c]->reset();
    }
    counts[0] = counter.count();
    counter.restart();
    for (int k = 0; k < 5000; ++k) {
      plant.step(1e-4);
      for (auto& s : subs) s.step(0.1, 0.2, 0.3, 5.0);
    }
    counts[1] = counter.count();
    counter.restart();
    sum = loop.run(gm, n, rec.data(), nd.data());
    counts[2] = counter.count();
    counter.restart();
    rs = run_rpsd(rpsd, ag.data(), nullptr, nullptr, ag.size(), rows.data());
    counts[3] = counter.count();
  }
  std::printf("allocations: controllers %ld, plant+substructures %ld, RthsLoop.run %ld, RPsD with converters %ld\n",
              counts[0], counts[1], counts[2], counts[3]);
  CHECK(counts[0] == 0 && counts[1] == 0 && counts[2] == 0 && counts[3] == 0);
  CHECK(sum.ok() && sum.rows == n);
  CHECK(rs.status.ok() && rs.rows == ag.size());
}
}  // namespace

// The experimental substructure's step returns a Status: Ok on a normal sample,
// NonFinite when the benchmark plant's state diverges, and the loop's summary
// carries it at the failure.
static void experimental_status() {
  BenchmarkPlant plant(BenchmarkPlantParameters{}, 1.0 / 4096.0);
  CHECK(plant.step(1e-3).ok());
  const Status bad = plant.step(std::nan(""));
  CHECK(bad.code == Status::NonFinite);
  plant.reset();
  CHECK(plant.step(1e-3).ok());
}

int main() {
  tustin_coefficients();
  converters();
  loop_io();
  substructure_step();
  no_allocation();
  experimental_status();
  return sh_test::report("test_rths");
}
