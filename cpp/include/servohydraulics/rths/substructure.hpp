// The numerical substructure of a real-time hybrid simulation: a linear
// M, C, K model of any size, stepped once per controller sample,
//
//   M x'' + C x' + K x = -g a_g(t) - gamma f_in,
//
// where g is the ground-load vector (the benchmark's M_r iota, Silva et al. 2020
// Eq 6: the whole reference mass, because the specimen has a fixed base) and
// gamma the interface vector on which the (delayed, measured) specimen force
// f_in acts.  Schemes: classical RK4 on the state space [x; x'] with a_g
// evaluated at t_k, t_k + h/2, t_k + h (the benchmark's ode4), central
// difference and explicit Newmark (gamma = 1/2, beta = 0), the explicit
// schemes of the field.  Construction validates and factorises (allocates);
// reset() and step() are noexcept and allocation-free.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

namespace servohydraulics::rths {

//! AverageAcceleration: implicit Newmark (gamma = 1/2, beta = 1/4), unconditionally stable,
//! the acceleration carried from step to step (0 at rest), loads at t_k + h.
enum class SubstructureScheme { RungeKutta4, CentralDifference, ExplicitNewmark, AverageAcceleration };

//! A numerical substructure as the RTHS loop sees it (loop.hpp): stepped once
//! per controller sample, its DOF displacements read back, one interface DOF.
//! LinearSubstructure is the C++ one; the Python bindings let a Python object
//! (e.g. the OpenSeesPy adapter) be one.  All calls are noexcept: a failure is
//! reported by healthy() == false (the loop then stops).
class NumericalSubstructure {
 public:
  virtual ~NumericalSubstructure() = default;
  virtual void reset() noexcept = 0;  //!< at rest at t = 0
  //! One sample: ground acceleration at t_k, t_k + h/2, t_k + h [m/s^2]; f_in held [N].
  virtual void step(double ag0, double ag_mid, double ag1, double f_in) noexcept = 0;
  virtual Eigen::Index dof_count() const noexcept = 0;                 //!< DOFs read back
  virtual double dof_displacement(Eigen::Index i) const noexcept = 0;  //!< x_i(t_k) [m]
  virtual Eigen::Index interface_dof() const noexcept = 0;            //!< the DOF the specimen force acts on
  virtual double interface_velocity() const noexcept = 0;             //!< [m/s]
  //! Relative acceleration of the interface DOF at t_k with a_g and f_in at t_k [m/s^2].
  virtual double interface_acceleration(double ag, double f_in) const noexcept = 0;
  virtual double sample_time() const noexcept = 0;  //!< h [s]
  virtual bool healthy() const noexcept = 0;        //!< finite state, no failure
};

//! M, C, K [kg, N s/m, N/m], ground-load vector g [kg] and interface vector gamma [-].
struct LinearSubstructureModel {
  Eigen::MatrixXd M, C, K;
  Eigen::VectorXd ground;     //!< load = -ground a_g
  Eigen::VectorXd interface;  //!< load -= interface f_in
  void validate() const;
  Eigen::Index size() const noexcept { return M.rows(); }
};

class LinearSubstructure final : public NumericalSubstructure {
 public:
  //! The interface DOF is the first one whose interface entry is nonzero (Error if none).
  LinearSubstructure(const LinearSubstructureModel& model, double h,
                     SubstructureScheme scheme = SubstructureScheme::RungeKutta4);

  void reset() noexcept override;  //!< at rest at t = 0
  //! Advance one sample from t_k to t_k + h: ground acceleration [m/s^2] at t_k,
  //! t_k + h/2 and t_k + h; interface force f_in [N] held over the sample.
  void step(double ag0, double ag_mid, double ag1, double f_in) noexcept override;

  Eigen::Index dof_count() const noexcept override { return model_.size(); }
  double dof_displacement(Eigen::Index i) const noexcept override { return x_(i); }
  Eigen::Index interface_dof() const noexcept override { return dof_; }
  double interface_velocity() const noexcept override { return v_(dof_); }
  double interface_acceleration(double ag, double f_in) const noexcept override {
    return acceleration(dof_, ag, f_in);
  }
  double sample_time() const noexcept override { return h_; }
  bool healthy() const noexcept override { return x_.allFinite() && v_.allFinite(); }

  const Eigen::VectorXd& displacement() const noexcept { return x_; }  //!< x(t_k) [m]
  //! x'(t_k) [m/s]: the state (RK4, Newmark) or the backward difference (central difference).
  const Eigen::VectorXd& velocity() const noexcept { return v_; }
  //! Relative acceleration x''(t_k) [m/s^2] from the equation of motion with a_g and f_in at t_k.
  double acceleration(Eigen::Index dof, double ag, double f_in) const noexcept;

  const LinearSubstructureModel& model() const noexcept { return model_; }
  SubstructureScheme scheme() const noexcept { return scheme_; }
  double h() const noexcept { return h_; }

 private:
  void derivative(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double ag, double f_in,
                  Eigen::VectorXd& dv) const noexcept;
  LinearSubstructureModel model_;
  SubstructureScheme scheme_;
  double h_;
  Eigen::Index dof_ = 0;
  Eigen::MatrixXd MiK_, MiC_;       // M^-1 K, M^-1 C
  Eigen::VectorXd Mig_, Migam_;     // M^-1 g, M^-1 gamma
  Eigen::MatrixXd S_inv_;  // central difference: (M/h^2 + C/2h)^-1; Newmark: (M + h/2 C)^-1; average: (M + h/2 C + h^2/4 K)^-1
  Eigen::MatrixXd P1_, P2_;         // central difference: K - 2M/h^2, M/h^2 - C/2h
  Eigen::VectorXd x_, v_, a_, x_prev_;
  mutable Eigen::VectorXd t1_, t2_, t3_;
  Eigen::VectorXd k1x_, k1v_, k2x_, k2v_, k3x_, k3v_, k4x_, k4v_;
};

//! A ground-motion record evaluated by linear interpolation on its stored time
//! row (Simulink From File), scaled; holds the end values outside the record.
class GroundMotion {
 public:
  GroundMotion(std::vector<double> time, std::vector<double> acceleration, double scale = 1.0);
  //! scale * a(t); a cursor makes monotone queries O(1).  noexcept, no allocation.
  double operator()(double t) const noexcept;
  double end_time() const noexcept { return t_.back(); }
  double scale() const noexcept { return scale_; }

 private:
  std::vector<double> t_, a_;
  double scale_;
  mutable std::size_t cursor_ = 0;
};

}  // namespace servohydraulics::rths
