#include "servohydraulics/substructure.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

void LinearSubstructureModel::validate() const {
  const Eigen::Index n = M.rows();
  require(n >= 1 && M.cols() == n, "M.rows", static_cast<double>(n), "a square matrix of size >= 1");
  require(C.rows() == n && C.cols() == n, "C.rows", static_cast<double>(C.rows()), "the size of M");
  require(K.rows() == n && K.cols() == n, "K.rows", static_cast<double>(K.rows()), "the size of M");
  require(ground.size() == n, "ground.size", static_cast<double>(ground.size()), "the size of M");
  require(interface.size() == n, "interface.size", static_cast<double>(interface.size()), "the size of M");
  require(M.allFinite() && C.allFinite() && K.allFinite() && ground.allFinite() && interface.allFinite(),
          "matrices", 0.0, "finite entries");
  Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (M + M.transpose()));
  require(llt.info() == Eigen::Success, "M", M(0, 0), "symmetric positive definite");
}

LinearSubstructure::LinearSubstructure(const LinearSubstructureModel& model, double h, SubstructureScheme scheme)
    : model_(model), scheme_(scheme), h_(h) {
  model_.validate();
  require(std::isfinite(h) && h > 0.0, "h", h, "finite and > 0");
  const Eigen::Index n = model_.size();
  dof_ = n;
  for (Eigen::Index i = n - 1; i >= 0; --i)
    if (model_.interface(i) != 0.0) dof_ = i;
  require(dof_ < n, "interface", 0.0, "a nonzero entry (the DOF the specimen force acts on)");
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(model_.M);
  MiK_ = lu.solve(model_.K);
  MiC_ = lu.solve(model_.C);
  Mig_ = lu.solve(model_.ground);
  Migam_ = lu.solve(model_.interface);
  if (scheme_ == SubstructureScheme::CentralDifference) {
    S_inv_ = (model_.M / (h * h) + model_.C / (2.0 * h)).inverse();
    P1_ = model_.K - 2.0 * model_.M / (h * h);
    P2_ = model_.M / (h * h) - model_.C / (2.0 * h);
  } else if (scheme_ == SubstructureScheme::ExplicitNewmark) {
    S_inv_ = (model_.M + 0.5 * h * model_.C).inverse();
  } else if (scheme_ == SubstructureScheme::AverageAcceleration) {
    S_inv_ = (model_.M + 0.5 * h * model_.C + 0.25 * h * h * model_.K).inverse();
  }
  for (Eigen::VectorXd* v : {&x_, &v_, &a_, &x_prev_, &t1_, &t2_, &t3_, &k1x_, &k1v_, &k2x_, &k2v_, &k3x_, &k3v_,
                             &k4x_, &k4v_})
    v->setZero(n);
  reset();
}

void LinearSubstructure::reset() noexcept {
  x_.setZero();
  v_.setZero();
  a_.setZero();
  x_prev_.setZero();  // at rest: x_{-1} = x_0 - h v_0 + h^2/2 a_0 = 0
}

void LinearSubstructure::derivative(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double ag, double f_in,
                                    Eigen::VectorXd& dv) const noexcept {
  dv.noalias() = -MiK_ * x;
  dv.noalias() -= MiC_ * v;
  dv -= ag * Mig_ + f_in * Migam_;
}

double LinearSubstructure::acceleration(Eigen::Index dof, double ag, double f_in) const noexcept {
  return -MiK_.row(dof).dot(x_) - MiC_.row(dof).dot(v_) - ag * Mig_(dof) - f_in * Migam_(dof);
}

void LinearSubstructure::step(double ag0, double ag_mid, double ag1, double f_in) noexcept {
  const double h = h_;
  switch (scheme_) {
    case SubstructureScheme::RungeKutta4: {
      k1x_ = v_;
      derivative(x_, v_, ag0, f_in, k1v_);
      t1_ = x_ + 0.5 * h * k1x_;
      t2_ = v_ + 0.5 * h * k1v_;
      k2x_ = t2_;
      derivative(t1_, t2_, ag_mid, f_in, k2v_);
      t1_ = x_ + 0.5 * h * k2x_;
      t2_ = v_ + 0.5 * h * k2v_;
      k3x_ = t2_;
      derivative(t1_, t2_, ag_mid, f_in, k3v_);
      t1_ = x_ + h * k3x_;
      t2_ = v_ + h * k3v_;
      k4x_ = t2_;
      derivative(t1_, t2_, ag1, f_in, k4v_);
      x_ += (h / 6.0) * (k1x_ + 2.0 * k2x_ + 2.0 * k3x_ + k4x_);
      v_ += (h / 6.0) * (k1v_ + 2.0 * k2v_ + 2.0 * k3v_ + k4v_);
      break;
    }
    case SubstructureScheme::CentralDifference: {
      // (M/h^2 + C/2h) x_{k+1} = p_k - (K - 2M/h^2) x_k - (M/h^2 - C/2h) x_{k-1}
      t1_ = -ag0 * model_.ground - f_in * model_.interface;
      t1_.noalias() -= P1_ * x_;
      t1_.noalias() -= P2_ * x_prev_;
      t2_.noalias() = S_inv_ * t1_;
      x_prev_ = x_;
      x_ = t2_;
      v_ = (x_ - x_prev_) / h;
      break;
    }
    case SubstructureScheme::ExplicitNewmark: {
      // x_{k+1} = x_k + h v_k + h^2/2 a_k; (M + h/2 C) a_{k+1} = p_{k+1} - K x_{k+1} - C (v_k + h/2 a_k)
      derivative(x_, v_, ag0, f_in, a_);  // a_k from the current state and inputs
      x_ += h * v_ + 0.5 * h * h * a_;
      t3_ = v_ + 0.5 * h * a_;
      t1_ = -ag1 * model_.ground - f_in * model_.interface;
      t1_.noalias() -= model_.K * x_;
      t1_.noalias() -= model_.C * t3_;
      t2_.noalias() = S_inv_ * t1_;
      v_ = t3_ + 0.5 * h * t2_;
      break;
    }
    case SubstructureScheme::AverageAcceleration: {
      // (M + h/2 C + h^2/4 K) a_{k+1} = p_{k+1} - C (v_k + h/2 a_k) - K (x_k + h v_k + h^2/4 a_k)
      t3_ = v_ + 0.5 * h * a_;             // velocity predictor
      x_ += h * v_ + 0.25 * h * h * a_;  // displacement predictor
      t1_ = -ag1 * model_.ground - f_in * model_.interface;
      t1_.noalias() -= model_.C * t3_;
      t1_.noalias() -= model_.K * x_;
      t2_.noalias() = S_inv_ * t1_;  // a_{k+1}
      x_ += 0.25 * h * h * t2_;
      v_ = t3_ + 0.5 * h * t2_;
      a_ = t2_;
      break;
    }
  }
}

// ------------------------------------------------------------------ Eq (15)

namespace {
StructuralScheme eq15_scheme(StructuralScheme s) {
  require(s == StructuralScheme::CentralDifference || s == StructuralScheme::ExplicitNewmark, "scheme",
          static_cast<int>(s), "Eq (15)'s schemes are central_difference and explicit_newmark");
  return s;
}
}  // namespace

Eq15Substructure::Eq15Substructure(const ModelSDOF& model, double dt, StructuralScheme scheme)
    : mdl_(model), dt_(dt), scheme_(eq15_scheme(scheme)), cd_(model, dt), en_(model, dt) {
  reset();
}

void Eq15Substructure::reset() noexcept {
  cd_.reset(0.0);
  en_.reset(0.0);
}

double Eq15Substructure::step_load(double load, double f) noexcept {
  return scheme_ == StructuralScheme::CentralDifference ? cd_.step(load, f) : en_.step(load, f);
}

const IntegratorState& Eq15Substructure::state() const noexcept {
  return scheme_ == StructuralScheme::CentralDifference ? cd_.state() : en_.state();
}

bool Eq15Substructure::healthy() const noexcept {
  const IntegratorState& s = state();
  return std::isfinite(s.next_displacement) && std::isfinite(s.velocity) && std::isfinite(s.acceleration);
}

}  // namespace servohydraulics
