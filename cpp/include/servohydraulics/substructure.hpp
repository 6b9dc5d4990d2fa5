// The numerical substructure of a hybrid simulation (RPsD, controllers.hpp; the
// RTHS benchmark, rths/loop.hpp): one interface, NumericalSubstructure, and its
// implementations in the core.
//
// LinearSubstructure: a linear M, C, K model of any size, stepped once per controller sample,
//
//   M x'' + C x' + K x = -g a_g(t) - gamma f_in,
//
// where g is the ground-load vector (the benchmark's M_r iota, Silva et al. 2020
// Eq 6) and gamma the interface vector on which the (delayed, measured) specimen
// force f_in acts.  Schemes: classical RK4 on the state space [x; x'] with a_g
// evaluated at t_k, t_k + h/2, t_k + h (the benchmark's ode4), central
// difference, explicit Newmark (gamma = 1/2, beta = 0) and average acceleration.
//
// Eq15Substructure: the paper's modelled SDOF system of RPsD (Zhao et al. 2003,
// Eq 15), m_m a + c_m v + f = -m_m a_g + P_ext, integrated by its central
// difference or explicit Newmark (integration.hpp) -- the 1-DOF case M = m_m,
// C = c_m, K = 0, ground = m_m, interface = 1, with f the measured (or
// calculated) restoring force.  Its schemes are the pseudodynamic forms with f_k
// measured at d_k (Shing & Mahin).  For the central difference this is the same
// recursion as LinearSubstructure's (the two agree to round-off,
// tests/python/test_rpsd_substructure.py); LinearSubstructure's explicit Newmark
// holds f_in over the sample and evaluates the acceleration at both ends, so
// the two explicit Newmarks are different algorithms (first order in h apart in
// the velocity).
//
// Velocity convention of interface_velocity(): the velocity the scheme itself
// carries -- RK4, Newmark, average acceleration: the state at the new time;
// central difference: a difference quotient (LinearSubstructure: backward
// (x_{k+1} - x_k)/h; Eq15Substructure: central (d_{k+1} - d_{k-1})/(2 dt) at t_k,
// the paper's).
//
// Construction validates and factorises (allocates); reset() and step() are
// noexcept and allocation-free.
#pragma once

#include <Eigen/Dense>

#include "servohydraulics/integration.hpp"

namespace servohydraulics {

using SubstructureScheme = StructuralScheme;  //!< the RTHS benchmark's name (rths::SubstructureScheme)

//! A numerical substructure as the hybrid loops see it (RPsD, controllers.hpp; the RTHS loop,
//! rths/loop.hpp): stepped once per controller sample, its DOF displacements read back, one interface DOF.
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

//! Eq (15) of the paper as a 1-DOF numerical substructure: the RPsD default.
//! step_load() is the RPsD form (load P_k = -m_m a_g + P_ext and restoring force
//! f_k, returns d_{k+1}); step() is the interface form (load -m_m a_g0, f_in = f).
//! After a step, dof_displacement(0) is the target d_{k+1}; state() holds d_k, v_k, a_k.
class Eq15Substructure final : public NumericalSubstructure {
 public:
  //! scheme: CentralDifference or ExplicitNewmark (Error otherwise).
  Eq15Substructure(const ModelSDOF& model, double dt, StructuralScheme scheme);

  void reset() noexcept override;
  double step_load(double load, double restoring_force) noexcept;  //!< returns d_{k+1} [m]
  void step(double ag0, double, double, double f_in) noexcept override { step_load(-mdl_.m_m * ag0, f_in); }

  Eigen::Index dof_count() const noexcept override { return 1; }
  double dof_displacement(Eigen::Index) const noexcept override { return state().next_displacement; }
  Eigen::Index interface_dof() const noexcept override { return 0; }
  double interface_velocity() const noexcept override { return state().velocity; }
  double interface_acceleration(double, double) const noexcept override { return state().acceleration; }
  double sample_time() const noexcept override { return dt_; }
  bool healthy() const noexcept override;

  const IntegratorState& state() const noexcept;
  const ModelSDOF& model() const noexcept { return mdl_; }
  StructuralScheme scheme() const noexcept { return scheme_; }

 private:
  ModelSDOF mdl_;
  double dt_;
  StructuralScheme scheme_;
  CentralDifference cd_;
  ExplicitNewmark en_;
};

}  // namespace servohydraulics
