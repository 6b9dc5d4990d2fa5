// The maRTHS benchmark's structures (BENCHMARK.md sections 3 and 6): the 29-DOF reference frame and the
// numerical substructure, each integrated by Newmark's average acceleration in the displacement form of
// the benchmark's MATLAB Function blocks, and the physical frame's model that turns the measured
// interface motion into the feedback force.
//
// Why not the core's LinearSubstructure (substructure.hpp, whose AverageAcceleration is the same
// scheme): the FE models' mass matrix is singular (the SAP2000 export lumps no mass on 16 of the 29
// DOFs), which the displacement form needs only through K + a0 M + a1 C but LinearSubstructure needs
// inverted (M^-1 K, M^-1 C, its interface acceleration); and the benchmark feeds back three load
// components (a force at DOF 27, moments at DOFs 21 and 29), not one scalar on one vector.  Nor does
// the benchmark step advance "from t_k to t_k + h" with the load at the end: step k takes the ground
// acceleration and the feedback of step k and returns the displacements that step k's targets use.
//
// FE DOF numbers are 1-based in comments and in MarthsDofs (DOF 27 = element 26 of a 29-vector).
// Construction validates (throws Error naming the field and the value); reset(), step() and the frame
// feedback's operator() are noexcept and allocation-free.
#pragma once

#include <array>

#include <Eigen/Dense>

#include "servohydraulics/converters.hpp"

namespace servohydraulics::marths {

//! A linear structure M x'' + C x' + K x = -M l a_g - F (N, m, kg; rotations in rad, moments in N m).
struct StructureMatrices {
  Eigen::MatrixXd M, C, K;
  Eigen::VectorXd influence;  //!< l: 1 on the DOFs the ground acceleration drives
  //! Square, one size, finite, symmetric (|A - A^T| <= 1e-9 max|A|); throws Error naming the matrix and entry.
  void validate() const;
  Eigen::Index size() const noexcept { return K.rows(); }
};

//! Newmark's constants a0 .. a7 (fcn_newmark_beta_const.m) for delta, alpha and dt.
struct NewmarkConstants {
  double a0, a1, a2, a3, a4, a5, a6, a7;
  NewmarkConstants(double delta, double alpha, double dt);
};

//! Newmark's method in the benchmark's displacement form, one step per sample (delta = 1/2, alpha = 1/4:
//! average acceleration, unconditionally stable):
//!   R  = M (a0 U0 + a2 V0 + a3 A0) + C (a1 U0 + a4 V0 + a5 A0) - F - M l a_g
//!   U1 = (K + a0 M + a1 C)^-1 R;  A1 = a0 (U1 - U0) - a2 V0 - a3 A0;  V1 = V0 + a7 A1 + a6 A0
//! with (K + a0 M + a1 C)^-1 formed once (the model's Kbar_inv).  M may be singular.
class NewmarkStructure {
 public:
  NewmarkStructure(const StructureMatrices& s, double dt, double delta = 0.5, double alpha = 0.25);
  void reset() noexcept;  //!< U = V = A = 0
  //! One step with the ground acceleration a_g [m/s^2] and the load F (size(), or nullptr for none).
  void step(double ag, const double* F) noexcept;
  const Eigen::VectorXd& displacement() const noexcept { return U_; }
  const Eigen::VectorXd& velocity() const noexcept { return V_; }
  const Eigen::VectorXd& acceleration() const noexcept { return A_; }
  bool healthy() const noexcept { return U_.allFinite() && V_.allFinite() && A_.allFinite(); }
  const StructureMatrices& matrices() const noexcept { return s_; }
  const Eigen::MatrixXd& dynamic_stiffness_inverse() const noexcept { return Kbar_inv_; }
  double dt() const noexcept { return dt_; }

 private:
  StructureMatrices s_;
  double dt_;
  NewmarkConstants c_;
  Eigen::MatrixXd Kbar_inv_;
  Eigen::VectorXd ground_;  // M l
  Eigen::VectorXd U_, V_, A_, w1_, w2_, R_, U1_;
};

//! Rayleigh coefficients (alpha, beta) with damping ratio zeta at omega_i and omega_j [rad/s]:
//! solve(1/2 [[1/wi, wi], [1/wj, wj]], [zeta, zeta]) (build_reference.m).
std::array<double, 2> rayleigh_coefficients(double omega_i, double omega_j, double zeta);

//! The FE DOFs the benchmark reads and loads (1-based, BENCHMARK.md section 3).
struct MarthsDofs {
  int x = 27;        //!< the interface node's translation (xRef, xNum; F(27) = f1)
  int theta = 21;    //!< its rotation, sign reversed (rRef = -U(21); F(21) = -f2)
  int theta_b = 29;  //!< the other interface node's rotation (F(29) = -f3)
  int x_2nd = 26, theta_2nd = 22;  //!< 2nd story (node 12)
  int x_3rd = 13, theta_3rd = 3;   //!< 3rd story (node 16)
  void validate(Eigen::Index size) const;
};

//! The ideal physical frame removed from the reference to make the numerical substructure
//! (build_physical_ideal.m), on DOFs (x, theta_b, theta) = (27, 29, 21).
struct IdealFrameParameters {
  double Lb = 0.762;                        //!< beam length [m]
  double Lc = 0.635;                        //!< column length [m]
  double Ic = 2.520 * 0.0254 * 0.0254 * 0.0254 * 0.0254;   //!< column 2nd moment of area [m^4] (2.520 in^4)
  double Ib = 0.6132 * 0.0254 * 0.0254 * 0.0254 * 0.0254;  //!< beam [m^4] (0.6132 in^4)
  double Ac = 1.670 * 0.0254 * 0.0254;      //!< column area [m^2] (1.670 in^2)
  double Ab = 0.947 * 0.0254 * 0.0254;      //!< beam area [m^2] (0.947 in^2)
  double E = 200e9;                         //!< [Pa]
  double rho = 785e3;                       //!< [kg/m^3]: as coded (100 x steel)
  double zeta = 0.05;                       //!< Rayleigh, at the smallest and largest mode
  void validate() const;
  Eigen::Matrix3d K() const;  //!< KP
  Eigen::Matrix3d M() const;  //!< MP = diag(mb + mc, mb/2 Lb^2/12 + mc/2 Lc^2/12, same)
  Eigen::Matrix3d C() const;  //!< CP = alpha MP + beta KP, Rayleigh at sqrt of the extreme eigenvalues of (KP, MP)
};

//! The physical frame of physicalFrame_feedbackForce.m: a 5-DOF frame (X1, theta1 .. theta4), axial
//! deformation neglected, columns transformed with theta = pi/2.
struct PhysicalFrameParameters {
  double Lb = 0.762;                                               //!< beam length [m]
  double Lc = 0.64135;                                             //!< column length [m]
  double Ic = 0.7 * 2.520 * 0.0254 * 0.0254 * 0.0254 * 0.0254;    //!< column [m^4] (tuning factor 0.7)
  double Ib = 4.21372e-7;                                          //!< beam [m^4]
  double Ac = 1.670 * 0.0254 * 0.0254;                             //!< column area [m^2]
  double Ab = 7.56e-4;                                             //!< beam area [m^2]
  double E = 200e9;                                                //!< [Pa]
  double rho = 7850.0;                                             //!< [kg/m^3]
  double mass_factor = 1.1;                                        //!< on the lumped masses
  double zeta = 0.05;                                              //!< modal damping of every mode
  void validate() const;
};

//! K5, M5, C5 (modal, omegas rounded to 0.01 rad/s) and the condensation G = -Koo^-1 Kot.
struct PhysicalFrame {
  Eigen::Matrix<double, 5, 5> K, M, C;
  Eigen::Matrix<double, 3, 2> G;
  std::array<double, 5> omegas{};  //!< its natural frequencies, rounded to 0.01 rad/s, ascending [rad/s]
  static PhysicalFrame from(const PhysicalFrameParameters& p);
};

//! Modal damping with the ratio zeta on every mode of (K, M) (symmetric; M positive definite):
//! C = sum_i M (2 zeta w_i phi_i phi_i^T / (phi_i^T M phi_i)) M, w_i the natural frequencies rounded to 0.01 rad/s
//! (physicalFrame_feedbackForce.m; the scaling of phi_i cancels).  omegas (K.rows() values, or nullptr) gets the
//! rounded w_i, ascending [rad/s].  Throws Error naming `field` when K is not positive definite.
Eigen::MatrixXd modal_damping(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, double zeta, const char* field,
                              double* omegas = nullptr);

//! How the physical frame is condensed to the interface node's (x, theta) (CondensedFrame).
enum class FrameReduction {
  Guyan,   //!< T^T K5 T, T^T M5 T, T^T C5 T with T = [I; G]: consistent, the slaves' inertia follows the node
  Static,  //!< the scripts' simplified 2-DOF model: the same stiffness, M = diag(M1x, M12z), its own modal damping
};

//! The physical frame condensed to the node's q = (x [m], theta [rad]): the specimen of the nonlinear
//! multi-actuator rig (multi_rig.hpp) on the benchmark's frame.  The stiffness is the benchmark's condensed
//! one, K5tt + K5to G, in both reductions.  Static: M = diag(M1x, M12z) without mass_factor (K_phys_2dof,
//! M_phys_2dof of the scripts) and modal_damping(M, K, zeta).
struct CondensedFrame {
  Eigen::Matrix2d M, C, K;  //!< [[kg, kg m], [kg m, kg m^2]], [[N s/m, N s], [N s, N m s]], [[N/m, N], [N, N m]]
  static CondensedFrame from(const PhysicalFrameParameters& p = {}, FrameReduction reduction = FrameReduction::Guyan);
};

//! Section 6's feedback: q = [x, theta, G [x; theta]], D1 = (q_k - q_{k-1})/dt, D2 = (D1_k - D1_{k-1})/dt
//! (Simulink Derivative blocks: 0 at k = 0), f = K q + C D1 + M D2.
class FrameFeedback {
 public:
  FrameFeedback(const PhysicalFrame& frame, double dt);
  void reset() noexcept;
  //! The 5 generalised forces f [N, N m] at the interface motion (x [m], theta [rad]) of this sample.
  void operator()(double x, double theta, double* f) noexcept;
  const PhysicalFrame& frame() const noexcept { return frame_; }

 private:
  PhysicalFrame frame_;
  std::array<BackwardDifference, 5> d1_, d2_;  // Simulink Derivative blocks on q and on D1
};

//! The benchmark's two structures and the physical frame, from the reference FE model.
struct MarthsStructures {
  StructureMatrices reference, numerical;
  PhysicalFrame frame;
  MarthsDofs dofs;
  //! K_R, M_R [N/m.., kg..] and the influence vector l of the SAP2000 model: C_R Rayleigh (5 % at 13.493 and
  //! 165.125 rad/s); the numerical substructure = the reference minus the ideal frame on DOFs (27, 29, 21)
  //! (K and C; the mass MP(1,1) on DOF 27 only).
  static MarthsStructures build(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, const Eigen::VectorXd& influence,
                                const IdealFrameParameters& ideal = {}, const PhysicalFrameParameters& physical = {},
                                double omega_i = 13.493, double omega_j = 165.125, double zeta = 0.05,
                                const MarthsDofs& dofs = {});
};

}  // namespace servohydraulics::marths
