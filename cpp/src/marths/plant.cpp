#include "servohydraulics/marths/plant.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "servohydraulics/converters.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics::marths {

namespace {
constexpr double kPi = 3.14159265358979323846;
using cd = std::complex<double>;

std::string at(const char* name, std::size_t i, std::size_t j) {
  return std::string(name) + "[" + std::to_string(i) + "][" + std::to_string(j) + "]";
}

void require_finite(const Eigen::MatrixXd& m, const char* name) {
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      if (!std::isfinite(m(i, j))) {
        const std::string f = at(name, static_cast<std::size_t>(i), static_cast<std::size_t>(j));
        require(false, f.c_str(), m(i, j), "finite");
      }
}

//! Roots that are real or come in conjugate pairs (within a relative tolerance).
bool conjugate_closed(const std::vector<cd>& r) {
  for (const cd& x : r) {
    const double tol = 1e-9 * std::max(1.0, std::abs(x));
    if (std::fabs(x.imag()) <= tol) continue;
    bool found = false;
    for (const cd& y : r)
      if (std::abs(y - std::conj(x)) <= tol) found = true;
    if (!found) return false;
  }
  return true;
}
}  // namespace

// ------------------------------------------------------------------------------------------- StateSpace

void StateSpace::validate(bool strictly_proper) const {
  const Eigen::Index n = A.rows();
  require(n >= 1 && A.cols() == n, "A.rows", static_cast<double>(n), "a square matrix of size >= 1");
  require(B.rows() == n && B.cols() >= 1, "B.rows", static_cast<double>(B.rows()), "the size of A (and >= 1 column)");
  require(C.cols() == n && C.rows() >= 1, "C.cols", static_cast<double>(C.cols()), "the size of A (and >= 1 row)");
  require(D.rows() == C.rows() && D.cols() == B.cols(), "D.rows", static_cast<double>(D.rows()),
          "outputs x inputs (the rows of C by the columns of B)");
  require_finite(A, "A");
  require_finite(B, "B");
  require_finite(C, "C");
  require_finite(D, "D");
  if (strictly_proper)
    for (Eigen::Index i = 0; i < D.rows(); ++i)
      for (Eigen::Index j = 0; j < D.cols(); ++j)
        if (D(i, j) != 0.0) {
          const std::string f = at("D", static_cast<std::size_t>(i), static_cast<std::size_t>(j));
          require(false, f.c_str(), D(i, j), "0: the sampled loop reads y(t_k) before it sets u(t_k)");
        }
}

Eigen::MatrixXcd StateSpace::frequency_response(cd s) const {
  const Eigen::Index n = A.rows();
  const Eigen::MatrixXcd M = s * Eigen::MatrixXcd::Identity(n, n) - A.cast<cd>();
  return C.cast<cd>() * M.partialPivLu().solve(B.cast<cd>()) + D.cast<cd>();
}

std::vector<Eigen::MatrixXd> StateSpace::taylor_coefficients(int order) const {
  validate(false);
  require(order >= 0 && order <= 16, "order", order, "0 to 16");
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
  require(lu.isInvertible(), "A", static_cast<double>(lu.rank()), "invertible (no pole at s = 0): its rank");
  std::vector<Eigen::MatrixXd> H;
  Eigen::MatrixXd Y = B;
  for (int m = 0; m <= order; ++m) {
    Y = lu.solve(Y);  // A^-(m+1) B
    H.push_back(-C * Y);
  }
  H[0] += D;
  return H;
}

void ode4_matrices(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h, Eigen::MatrixXd& Phi,
                   Eigen::MatrixXd& Gamma) {
  require(std::isfinite(h) && h > 0.0, "dt", h, "finite and > 0 [s]");
  const Eigen::Index n = A.rows();
  const Eigen::MatrixXd hA = h * A;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd hA2 = hA * hA, hA3 = hA2 * hA, hA4 = hA3 * hA;
  Phi = I + hA + hA2 / 2.0 + hA3 / 6.0 + hA4 / 24.0;
  Gamma = h * ((I + hA / 2.0 + hA2 / 6.0 + hA3 / 24.0) * B);
}

// ------------------------------------------------------------------------------------------- TransferMatrix

void TransferMatrix::validate() const {
  require(size >= 1 && size <= 16, "transfer_matrix.size", static_cast<double>(size), "1 to 16");
  require(poles.size() == size, "transfer_matrix.poles.size", static_cast<double>(poles.size()), "size columns");
  require(zeros.size() == size && gains.size() == size, "transfer_matrix.zeros.size",
          static_cast<double>(zeros.size()), "size rows (zeros and gains)");
  for (std::size_t j = 0; j < size; ++j) {
    const auto& p = poles[j];
    require(!p.empty(), "transfer_matrix.poles.size", 0.0, "at least one pole per column");
    for (std::size_t k = 0; k < p.size(); ++k) {
      const std::string f = at("transfer_matrix.poles", j, k);
      require(std::isfinite(p[k].real()) && std::isfinite(p[k].imag()), f.c_str(), p[k].real(), "finite");
      for (std::size_t l = 0; l < k; ++l)
        require(std::abs(p[k] - p[l]) > 1e-9 * std::max(1.0, std::abs(p[k])), f.c_str(), p[k].real(),
                "distinct from the column's other poles (the realisation is modal)");
    }
    const std::string pc = "transfer_matrix.poles[" + std::to_string(j) + "]";
    require(conjugate_closed(p), pc.c_str(), static_cast<double>(p.size()), "real or in conjugate pairs");
  }
  for (std::size_t i = 0; i < size; ++i) {
    require(zeros[i].size() == size && gains[i].size() == size, "transfer_matrix.zeros.size",
            static_cast<double>(zeros[i].size()), "size columns per row");
    for (std::size_t j = 0; j < size; ++j) {
      const std::string g = at("transfer_matrix.gains", i, j), z = at("transfer_matrix.zeros", i, j);
      require(std::isfinite(gains[i][j]), g.c_str(), gains[i][j], "finite");
      require(zeros[i][j].size() <= poles[j].size(), z.c_str(), static_cast<double>(zeros[i][j].size()),
              "no more zeros than the column's poles (proper)");
      for (const cd& x : zeros[i][j])
        require(std::isfinite(x.real()) && std::isfinite(x.imag()), z.c_str(), x.real(), "finite");
      require(conjugate_closed(zeros[i][j]), z.c_str(), static_cast<double>(zeros[i][j].size()),
              "real or in conjugate pairs");
    }
  }
}

cd TransferMatrix::element(std::size_t i, std::size_t j, cd s) const {
  cd v = gains[i][j];
  for (const cd& z : zeros[i][j]) v *= (s - z);
  for (const cd& p : poles[j]) v /= (s - p);
  return v;
}

Eigen::MatrixXcd TransferMatrix::frequency_response(cd s) const {
  Eigen::MatrixXcd H(size, size);
  for (std::size_t i = 0; i < size; ++i)
    for (std::size_t j = 0; j < size; ++j) H(i, j) = element(i, j, s);
  return H;
}

Eigen::MatrixXd TransferMatrix::dc_gain() const { return frequency_response(0.0).real(); }

StateSpace TransferMatrix::realize() const {
  validate();
  std::size_t n = 0;
  for (const auto& p : poles) n += p.size();
  StateSpace ss;
  ss.A = Eigen::MatrixXd::Zero(n, n);
  ss.B = Eigen::MatrixXd::Zero(n, size);
  ss.C = Eigen::MatrixXd::Zero(size, n);
  ss.D = Eigen::MatrixXd::Zero(size, size);
  std::size_t off = 0;
  for (std::size_t j = 0; j < size; ++j) {
    const auto& p = poles[j];
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double tol = 1e-9 * std::max(1.0, std::abs(p[k]));
      if (p[k].imag() < -tol) continue;  // the lower member of a pair: realised with its partner
      const bool pair = p[k].imag() > tol;
      // residue of H_ij at p_k: gain prod (p_k - z) / prod_{l != k} (p_k - p_l)
      auto residue = [&](std::size_t i) {
        cd r = gains[i][j];
        for (const cd& z : zeros[i][j]) r *= (p[k] - z);
        for (std::size_t l = 0; l < p.size(); ++l)
          if (l != k) r /= (p[k] - p[l]);
        return r;
      };
      if (!pair) {
        ss.A(off, off) = p[k].real();
        ss.B(off, j) = 1.0;
        for (std::size_t i = 0; i < size; ++i) ss.C(i, off) = residue(i).real();
        off += 1;
      } else {
        // z' = p z + u with z = x1 + j x2; y = r z + conj(r z) = 2 (Re r x1 - Im r x2)
        const double s = p[k].real(), w = p[k].imag();
        ss.A(off, off) = s;
        ss.A(off, off + 1) = -w;
        ss.A(off + 1, off) = w;
        ss.A(off + 1, off + 1) = s;
        ss.B(off, j) = 1.0;
        for (std::size_t i = 0; i < size; ++i) {
          const cd r = residue(i);
          ss.C(i, off) = 2.0 * r.real();
          ss.C(i, off + 1) = -2.0 * r.imag();
        }
        off += 2;
      }
    }
    for (std::size_t i = 0; i < size; ++i)
      if (zeros[i][j].size() == p.size()) ss.D(i, j) = gains[i][j];
  }
  return ss;
}

// ------------------------------------------------------------------------------------------- the benchmark plant

BenchmarkPlantModel::BenchmarkPlantModel()
    : h1_zero_1(-120.0 * 2.0 * kPi),
      h1_zero_2(-90.0 * 2.0 * kPi),
      h1_pole_1(-2.65 * 2.0 * kPi),
      h1_pole_2(-40.0 * 2.0 * kPi),
      frame_pole(cd(-50.0, -63.0) * (2.0 * kPi)),
      h12_zero(-3.0 * 2.0 * kPi),
      h22_zero(-5.0 * 2.0 * kPi),
      h2_pole_1(-3.5 * 2.0 * kPi),
      h2_pole_2(-18.5 * 2.0 * kPi) {}

TransferMatrix BenchmarkPlantModel::transfer_matrix() const {
  TransferMatrix H;
  H.size = 2;
  const cd f = frame_pole, fc = std::conj(frame_pole);
  H.poles = {{h1_pole_1, h1_pole_2, f, fc}, {h2_pole_1, h2_pole_2, f, fc}};
  H.zeros = {{{h1_zero_1, h1_zero_2}, {h12_zero}}, {{h1_zero_1, h1_zero_2}, {h22_zero}}};
  H.gains = {{gain_11, gain_12}, {gain_21, gain_22}};
  H.validate();
  return H;
}

void PlantUncertainty::validate() const {
  const std::pair<const char*, double> fields[] = {
      {"uncertainty.h1_zeros", h1_zeros}, {"uncertainty.h1_poles", h1_poles},
      {"uncertainty.frame_pole", frame_pole}, {"uncertainty.h12_zero", h12_zero},
      {"uncertainty.h2_poles", h2_poles}, {"uncertainty.h22_zero", h22_zero}};
  for (const auto& f : fields) require(std::isfinite(f.second) && f.second >= 0.0, f.first, f.second, "finite and >= 0");
  require(std::isfinite(match_frequency) && match_frequency >= 0.0, "uncertainty.match_frequency", match_frequency,
          "finite and >= 0 [rad/s]");
}

BenchmarkPlantModel PlantUncertainty::perturb(const BenchmarkPlantModel& nominal, const double* z) const {
  BenchmarkPlantModel p = nominal;  // the gains stay nominal here; rescaled() matches them
  p.h1_zero_1 = nominal.h1_zero_1 * (1.0 + h1_zeros * z[0]);
  p.h1_zero_2 = nominal.h1_zero_2 * (1.0 + h1_zeros * z[1]);
  p.h1_pole_1 = nominal.h1_pole_1 * (1.0 + h1_poles * z[2]);
  p.h1_pole_2 = nominal.h1_pole_2 * (1.0 + h1_poles * z[3]);
  p.frame_pole = nominal.frame_pole * (1.0 + frame_pole * z[4]);
  p.h12_zero = nominal.h12_zero * (1.0 + h12_zero * z[5]);
  p.h2_pole_1 = nominal.h2_pole_1 * (1.0 + h2_poles * z[6]);
  p.h2_pole_2 = nominal.h2_pole_2 * (1.0 + h2_poles * z[7]);
  p.h22_zero = nominal.h22_zero * (1.0 + h22_zero * z[8]);
  return p;
}

TransferMatrix PlantUncertainty::rescaled(const BenchmarkPlantModel& nominal,
                                          const BenchmarkPlantModel& perturbed) const {
  validate();
  const TransferMatrix Hn = nominal.transfer_matrix();
  TransferMatrix Hp = perturbed.transfer_matrix();
  const cd s(0.0, match_frequency);
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) {
      const double ref = std::abs(Hn.element(i, j, s)), now = std::abs(Hp.element(i, j, s));
      require(now > 0.0 && std::isfinite(now), "uncertainty.match_frequency", match_frequency,
              "a frequency where the perturbed element is finite and nonzero");
      Hp.gains[i][j] *= ref / now;
    }
  return Hp;
}

TransferMatrix PlantUncertainty::draw(const BenchmarkPlantModel& nominal, std::uint64_t seed) const {
  GaussianSequence g(seed, NoiseGenerator::MersenneTwister);
  double z[9];
  for (double& v : z) v = g.next();
  return rescaled(nominal, perturb(nominal, z));
}

// ------------------------------------------------------------------------------------------- IdentifiedPlant

IdentifiedPlant::IdentifiedPlant(const StateSpace& model, double dt, double unit)
    : model_(model), dt_(dt), unit_(unit) {
  model_.validate(true);
  require(model_.inputs() == model_.outputs(), "model.inputs", static_cast<double>(model_.inputs()),
          "the number of outputs (one command per actuator)");
  require(std::isfinite(unit) && unit > 0.0, "unit", unit, "finite and > 0 [m]");
  ode4_matrices(model_.A, model_.B, dt, phi_, gamma_);
  x_.setZero(model_.states());
  next_.setZero(model_.states());
  u_.setZero(model_.inputs());
  reset();
}

void IdentifiedPlant::reset() noexcept {
  x_.setZero();
  t_ = 0.0;
}

void IdentifiedPlant::displacements(double* y) const noexcept {
  for (Eigen::Index i = 0; i < model_.C.rows(); ++i) y[i] = unit_ * model_.C.row(i).dot(x_);
}

Status IdentifiedPlant::step(const double* u) noexcept {
  for (Eigen::Index i = 0; i < u_.size(); ++i) u_(i) = u[i] / unit_;
  next_.noalias() = phi_ * x_;
  next_.noalias() += gamma_ * u_;
  x_.swap(next_);
  t_ += dt_;
  Status st;
  st.t = t_;
  st.internal_steps = 1;
  st.rhs_evals = 4;
  if (!x_.allFinite()) st.code = Status::NonFinite;
  return st;
}

}  // namespace servohydraulics::marths
