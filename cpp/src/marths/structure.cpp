#include "servohydraulics/marths/structure.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics::marths {

namespace {
constexpr double kPi = 3.14159265358979323846;

void check_matrix(const Eigen::MatrixXd& A, const char* name, Eigen::Index n) {
  const std::string rows = std::string(name) + ".rows";
  require(A.rows() == n && A.cols() == n, rows.c_str(), static_cast<double>(A.rows()),
          "square, the size of K");
  double peak = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!std::isfinite(A(i, j))) {
        const std::string f = std::string(name) + "[" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "]";
        require(false, f.c_str(), A(i, j), "finite");
      }
      peak = std::max(peak, std::fabs(A(i, j)));
    }
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < i; ++j)
      if (std::fabs(A(i, j) - A(j, i)) > 1e-9 * peak) {
        const std::string f = std::string(name) + "[" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "]";
        require(false, f.c_str(), A(i, j), "symmetric (it differs from the transposed entry)");
      }
}

//! Local beam-column stiffness (6 x 6: x', y', theta at both ends) with the axial terms removed.
Eigen::Matrix<double, 6, 6> local_stiffness(double E, double I, double L) {
  Eigen::Matrix<double, 6, 6> k = Eigen::Matrix<double, 6, 6>::Zero();
  const double a = 12.0 * E * I / (L * L * L), b = 6.0 * E * I / (L * L), c = 4.0 * E * I / L, d = 2.0 * E * I / L;
  // rows/columns 0 and 3 (axial) are zero: "Neglecting axial deformations"
  k(1, 1) = a;  k(1, 2) = b;  k(1, 4) = -a; k(1, 5) = b;
  k(2, 1) = b;  k(2, 2) = c;  k(2, 4) = -b; k(2, 5) = d;
  k(4, 1) = -a; k(4, 2) = -b; k(4, 4) = a;  k(4, 5) = -b;
  k(5, 1) = b;  k(5, 2) = d;  k(5, 4) = -b; k(5, 5) = c;
  return k;
}

Eigen::Matrix<double, 6, 6> rotation(double theta) {
  Eigen::Matrix<double, 6, 6> T = Eigen::Matrix<double, 6, 6>::Zero();
  const double c = std::cos(theta), s = std::sin(theta);  // cos(pi/2) = 6.1e-17, as MATLAB's
  for (int e = 0; e < 2; ++e) {
    const int o = 3 * e;
    T(o, o) = c;
    T(o, o + 1) = s;
    T(o + 1, o) = -s;
    T(o + 1, o + 1) = c;
    T(o + 2, o + 2) = 1.0;
  }
  return T;
}
}  // namespace

void StructureMatrices::validate() const {
  const Eigen::Index n = K.rows();
  require(n >= 1 && K.cols() == n, "K.rows", static_cast<double>(n), "a square matrix of size >= 1");
  check_matrix(K, "K", n);
  check_matrix(M, "M", n);
  check_matrix(C, "C", n);
  require(influence.size() == n, "influence.size", static_cast<double>(influence.size()), "the size of K");
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(influence(i))) {
      const std::string f = "influence[" + std::to_string(i + 1) + "]";
      require(false, f.c_str(), influence(i), "finite");
    }
}

NewmarkConstants::NewmarkConstants(double delta, double alpha, double dt)
    : a0(1.0 / alpha / (dt * dt)),
      a1(delta / alpha / dt),
      a2(1.0 / alpha / dt),
      a3(1.0 / 2.0 / alpha - 1.0),
      a4(delta / alpha - 1.0),
      a5(dt / 2.0 * (delta / alpha - 2.0)),
      a6(dt * (1.0 - delta)),
      a7(delta * dt) {}

NewmarkStructure::NewmarkStructure(const StructureMatrices& s, double dt, double delta, double alpha)
    : s_(s), dt_(dt), c_(delta, alpha, dt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0 [s]");
  require(std::isfinite(delta) && delta >= 0.5, "newmark.delta", delta, ">= 1/2");
  require(std::isfinite(alpha) && alpha > 0.0, "newmark.alpha", alpha, "> 0");
  s_.validate();
  const Eigen::MatrixXd Kbar = s_.K + c_.a0 * s_.M + c_.a1 * s_.C;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(Kbar);
  require(lu.isInvertible(), "K + a0 M + a1 C", static_cast<double>(lu.rank()),
          "invertible (the dynamic stiffness): its rank");
  Kbar_inv_ = lu.inverse();
  ground_ = s_.M * s_.influence;
  const Eigen::Index n = s_.size();
  for (Eigen::VectorXd* v : {&U_, &V_, &A_, &w1_, &w2_, &R_, &U1_}) v->setZero(n);
}

void NewmarkStructure::reset() noexcept {
  U_.setZero();
  V_.setZero();
  A_.setZero();
}

void NewmarkStructure::step(double ag, const double* F) noexcept {
  const NewmarkConstants& c = c_;
  w1_ = c.a0 * U_ + c.a2 * V_ + c.a3 * A_;
  w2_ = c.a1 * U_ + c.a4 * V_ + c.a5 * A_;
  R_.noalias() = s_.M * w1_;
  R_.noalias() += s_.C * w2_;
  if (F)
    for (Eigen::Index i = 0; i < R_.size(); ++i) R_(i) -= F[i];
  R_ -= ag * ground_;
  U1_.noalias() = Kbar_inv_ * R_;
  // A1 = a0 (U1 - U0) - a2 V0 - a3 A0; V1 = V0 + a7 A1 + a6 A0 (w1_ reused for A1)
  w1_ = c.a0 * (U1_ - U_) - c.a2 * V_ - c.a3 * A_;
  V_ += c.a7 * w1_ + c.a6 * A_;
  A_ = w1_;
  U_.swap(U1_);
}

std::array<double, 2> rayleigh_coefficients(double wi, double wj, double zeta) {
  require(std::isfinite(wi) && wi > 0.0, "omega_i", wi, "finite and > 0 [rad/s]");
  require(std::isfinite(wj) && wj > 0.0 && wj != wi, "omega_j", wj, "finite, > 0 and != omega_i [rad/s]");
  require(std::isfinite(zeta) && zeta >= 0.0, "zeta", zeta, "finite and >= 0");
  Eigen::Matrix2d A;
  A << 0.5 / wi, 0.5 * wi, 0.5 / wj, 0.5 * wj;
  const Eigen::Vector2d x = A.partialPivLu().solve(Eigen::Vector2d(zeta, zeta));
  return {x(0), x(1)};
}

void MarthsDofs::validate(Eigen::Index size) const {
  const std::pair<const char*, int> all[] = {{"dofs.x", x}, {"dofs.theta", theta}, {"dofs.theta_b", theta_b},
                                             {"dofs.x_2nd", x_2nd}, {"dofs.theta_2nd", theta_2nd},
                                             {"dofs.x_3rd", x_3rd}, {"dofs.theta_3rd", theta_3rd}};
  for (const auto& d : all)
    require(d.second >= 1 && d.second <= size, d.first, d.second, "a DOF of the model (1-based)");
  require(x != theta && x != theta_b && theta != theta_b, "dofs.theta_b", theta_b,
          "distinct from dofs.x and dofs.theta");
}

void IdealFrameParameters::validate() const {
  const std::pair<const char*, double> all[] = {{"ideal_frame.Lb", Lb}, {"ideal_frame.Lc", Lc},
                                                {"ideal_frame.Ic", Ic}, {"ideal_frame.Ib", Ib},
                                                {"ideal_frame.Ac", Ac}, {"ideal_frame.Ab", Ab},
                                                {"ideal_frame.E", E},   {"ideal_frame.rho", rho}};
  for (const auto& f : all) require(std::isfinite(f.second) && f.second > 0.0, f.first, f.second, "finite and > 0");
  require(std::isfinite(zeta) && zeta >= 0.0, "ideal_frame.zeta", zeta, "finite and >= 0");
}

Eigen::Matrix3d IdealFrameParameters::K() const {
  const double c3 = 3.0 * E * Ic / (Lc * Lc), r = 3.0 * E * Ic / Lc + 4.0 * E * Ib / Lb, b = 2.0 * E * Ib / Lb;
  Eigen::Matrix3d KP;
  KP << 2.0 * (3.0 * Ic * E / (Lc * Lc * Lc)), -c3, -c3,  //
      -c3, r, -b,                                         //
      -c3, -b, r;
  return KP;
}

Eigen::Matrix3d IdealFrameParameters::M() const {
  const double mb = rho * Ab * Lb, mc = rho * Ac * Lc;
  const double m2 = (mb / 2.0) * (Lb * Lb) / 12.0 + (mc / 2.0) * (Lc * Lc) / 12.0;
  return Eigen::Vector3d(mb + mc, m2, m2).asDiagonal();
}

Eigen::Matrix3d IdealFrameParameters::C() const {
  const Eigen::Matrix3d KP = K(), MP = M();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> es(KP, MP, Eigen::EigenvaluesOnly);
  const auto ab = rayleigh_coefficients(std::sqrt(es.eigenvalues()(0)), std::sqrt(es.eigenvalues()(2)), zeta);
  return ab[0] * MP + ab[1] * KP;
}

void PhysicalFrameParameters::validate() const {
  const std::pair<const char*, double> all[] = {
      {"physical_frame.Lb", Lb}, {"physical_frame.Lc", Lc}, {"physical_frame.Ic", Ic},
      {"physical_frame.Ib", Ib}, {"physical_frame.Ac", Ac}, {"physical_frame.Ab", Ab},
      {"physical_frame.E", E},   {"physical_frame.rho", rho}, {"physical_frame.mass_factor", mass_factor}};
  for (const auto& f : all) require(std::isfinite(f.second) && f.second > 0.0, f.first, f.second, "finite and > 0");
  require(std::isfinite(zeta) && zeta >= 0.0, "physical_frame.zeta", zeta, "finite and >= 0");
}

PhysicalFrame PhysicalFrame::from(const PhysicalFrameParameters& p) {
  p.validate();
  const Eigen::Matrix<double, 6, 6> Tc = rotation(kPi / 2.0), Tb = rotation(0.0);
  const Eigen::Matrix<double, 6, 6> Kc = Tc.transpose() * local_stiffness(p.E, p.Ic, p.Lc) * Tc;
  const Eigen::Matrix<double, 6, 6> Kb = Tb.transpose() * local_stiffness(p.E, p.Ib, p.Lb) * Tb;
  auto c = [&](int i, int j) { return Kc(i - 1, j - 1); };  // the script's 1-based indices
  auto b = [&](int i, int j) { return Kb(i - 1, j - 1); };
  PhysicalFrame f;
  f.K << c(4, 4) * 2, c(4, 6), c(4, 6), c(4, 3), c(4, 3),  //
      c(6, 4), c(6, 6) + b(6, 6), b(6, 3), 0.0, c(6, 3),   //
      c(6, 4), b(3, 6), c(6, 6) + b(3, 3), c(6, 3), 0.0,   //
      c(3, 4), 0.0, c(3, 6), c(3, 3), 0.0,                 //
      c(3, 4), c(3, 6), 0.0, 0.0, c(3, 3);
  const double mb = p.rho * p.Ab * p.Lb, mc = p.rho * p.Ac * p.Lc;
  const double m1x = (mb + mc * 2.0) / 2.0 * p.mass_factor;
  const double m12z = (mb / 2.0 * p.Lb * p.Lb + mc / 2.0 * p.Lc * p.Lc) / 3.0 * p.mass_factor;
  const double m34z = mc / 2.0 * p.Lc * p.Lc / 3.0 * p.mass_factor;
  f.M = Eigen::Matrix<double, 5, 1>(m1x, m12z, m12z, m34z, m34z).asDiagonal();
  const Eigen::MatrixXd C = modal_damping(f.M, f.K, p.zeta, "physical_frame.K", f.omegas.data());
  f.C = C;
  const Eigen::Matrix3d Koo = f.K.block<3, 3>(2, 2);
  const Eigen::Matrix<double, 3, 2> Kot = f.K.block<3, 2>(2, 0);
  f.G = -Koo.partialPivLu().solve(Kot);
  return f;
}

Eigen::MatrixXd modal_damping(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double zeta, const char* field,
                              double* omegas) {
  require(K.rows() == K.cols() && M.rows() == K.rows() && M.cols() == K.rows(), field, static_cast<double>(K.rows()),
          "square, the size of M");
  // eig(M\K) has the eigenvalues and eigenvectors of the pair (K, M).
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), M);
  require(es.info() == Eigen::Success && es.eigenvalues().minCoeff() > 0.0, field,
          es.info() == Eigen::Success ? es.eigenvalues().minCoeff() : 0.0, "positive definite (the frame's modes)");
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(K.rows(), K.cols());
  for (Eigen::Index i = 0; i < K.rows(); ++i) {
    const double w = std::round(100.0 * std::sqrt(es.eigenvalues()(i))) / 100.0;
    if (omegas) omegas[i] = w;
    const Eigen::VectorXd phi = es.eigenvectors().col(i);
    const double m = phi.dot(M * phi);
    C += M * (2.0 * zeta * w * phi * phi.transpose() / m) * M;
  }
  return C;
}

CondensedFrame CondensedFrame::from(const PhysicalFrameParameters& p, FrameReduction reduction) {
  const PhysicalFrame f = PhysicalFrame::from(p);
  Eigen::Matrix<double, 5, 2> T;
  T.topRows<2>().setIdentity();
  T.bottomRows<3>() = f.G;
  CondensedFrame c;
  const Eigen::Matrix2d K = T.transpose() * f.K * T;
  c.K = 0.5 * (K + K.transpose());
  if (reduction == FrameReduction::Guyan) {
    c.M = T.transpose() * f.M * T;
    c.C = T.transpose() * f.C * T;
  } else {
    PhysicalFrameParameters unscaled = p;  // M_phys_2dof = diag(M1x, M12z): without the mass factor
    unscaled.mass_factor = 1.0;
    const PhysicalFrame u = PhysicalFrame::from(unscaled);
    c.M = Eigen::Vector2d(u.M(0, 0), u.M(1, 1)).asDiagonal();
    c.C = modal_damping(c.M, c.K, p.zeta, "physical_frame.K");
  }
  return c;
}

FrameFeedback::FrameFeedback(const PhysicalFrame& frame, double dt)
    : frame_(frame),
      d1_{BackwardDifference(dt), BackwardDifference(dt), BackwardDifference(dt), BackwardDifference(dt),
          BackwardDifference(dt)},
      d2_{BackwardDifference(dt), BackwardDifference(dt), BackwardDifference(dt), BackwardDifference(dt),
          BackwardDifference(dt)} {
  require(frame_.K.allFinite() && frame_.M.allFinite() && frame_.C.allFinite() && frame_.G.allFinite(),
          "physical_frame", 0.0, "finite matrices");
}

void FrameFeedback::reset() noexcept {
  for (auto& d : d1_) d.reset();
  for (auto& d : d2_) d.reset();
}

void FrameFeedback::operator()(double x, double theta, double* f) noexcept {
  Eigen::Matrix<double, 5, 1> q, v, a;
  q(0) = x;
  q(1) = theta;
  q.tail<3>() = frame_.G * Eigen::Vector2d(x, theta);
  for (int i = 0; i < 5; ++i) {
    v(i) = d1_[static_cast<std::size_t>(i)](q(i));
    a(i) = d2_[static_cast<std::size_t>(i)](v(i));
  }
  const Eigen::Matrix<double, 5, 1> r = frame_.K * q + frame_.C * v + frame_.M * a;
  for (int i = 0; i < 5; ++i) f[i] = r(i);
}

MarthsStructures MarthsStructures::build(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M,
                                         const Eigen::VectorXd& influence, const IdealFrameParameters& ideal,
                                         const PhysicalFrameParameters& physical, double omega_i, double omega_j,
                                         double zeta, const MarthsDofs& dofs) {
  MarthsStructures s;
  s.dofs = dofs;
  const auto ab = rayleigh_coefficients(omega_i, omega_j, zeta);
  s.reference.K = K;
  s.reference.M = M;
  s.reference.C = ab[0] * M + ab[1] * K;
  s.reference.influence = influence;
  s.reference.validate();
  dofs.validate(K.rows());
  ideal.validate();
  const Eigen::Matrix3d KP = ideal.K(), MP = ideal.M(), CP = ideal.C();
  const int idx[3] = {dofs.x - 1, dofs.theta_b - 1, dofs.theta - 1};  // KP index 1 <-> 27, 2 <-> 29, 3 <-> 21
  s.numerical = s.reference;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      s.numerical.K(idx[a], idx[b]) -= KP(a, b);
      s.numerical.C(idx[a], idx[b]) -= CP(a, b);
    }
  s.numerical.M(idx[0], idx[0]) -= MP(0, 0);  // the rotational masses are not removed (build_numerical.m)
  s.frame = PhysicalFrame::from(physical);
  return s;
}

}  // namespace servohydraulics::marths
