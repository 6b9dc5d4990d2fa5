// The maRTHS benchmark's control plant (BENCHMARK.md section 4): the identified 2 x 2 MIMO model of
// the two actuators and the specimen frame (ID_Control_plant_100Hz.mat, plantFRAME_SS), commands in,
// actuator displacements out, both in mm inside the model, as a MultiActuatorSystem in SI at the seam.
//
// Integration (section 1): one classical RK4 (Simulink ode4) step per sample with the command held,
// which for x' = A x + B u is exactly x+ = Phi x + Gamma u with
//   Phi   = sum_{j=0..4} (hA)^j / j!,   Gamma = h sum_{j=0..3} (hA)^j / (j+1)! B
// (not the exact exponential).  Phi and Gamma are polynomials in A, so every realisation of one
// transfer matrix gives the same samples: the perturbed plants are realised here from their
// zero-pole-gain form (TransferMatrix) in a real modal form of their own.
//
// Perturbed plants (fcn_build_uncert_plant.m): nine standard normals, in this order, each scaling one
// nominal value by (1 + c z): the two zeros of H11/H21 (c = 0.055 each), their poles at -2.65 Hz and
// -40 Hz (0.06 each), the frame pole 2 pi (-50 - 63j) (0.05, real and imaginary parts by the same
// factor, its conjugate following), the zero of H12 (0.03), the poles of H12/H22 at -3.5 and -18.5 Hz
// (0.03 each), the zero of H22 (0.03); each element's gain is then rescaled so that its magnitude at
// a low frequency equals the nominal element's.  The elements of a column share its poles.
//
// Construction validates (throws Error); reset(), displacements() and step() are noexcept and
// allocation-free.
#pragma once

#include <complex>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "servohydraulics/multi_actuator.hpp"

namespace servohydraulics::marths {

//! A continuous LTI model x' = A x + B u, y = C x + D u.
struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  //! Sizes agree (n x n, n x m, p x m... ), every entry finite; D must be zero when strictly_proper.
  void validate(bool strictly_proper = true) const;
  Eigen::Index states() const noexcept { return A.rows(); }
  Eigen::Index inputs() const noexcept { return B.cols(); }
  Eigen::Index outputs() const noexcept { return C.rows(); }
  //! H(s) = C (sI - A)^-1 B + D at one complex frequency s [rad/s].
  Eigen::MatrixXcd frequency_response(std::complex<double> s) const;
  //! The Taylor coefficients H_0 .. H_order of H(s) = sum_m H_m s^m at s = 0 (H_m = -C A^-(m+1) B, plus D in
  //! H_0); A must be invertible (Error otherwise).
  std::vector<Eigen::MatrixXd> taylor_coefficients(int order) const;
};

//! One ode4 step of x' = A x + B u with u held: x+ = Phi x + Gamma u (section 1).
void ode4_matrices(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h, Eigen::MatrixXd& Phi,
                   Eigen::MatrixXd& Gamma);

//! A square transfer matrix in zero-pole-gain form whose columns share their poles:
//! H_ij(s) = gain_ij prod_k (s - zeros_ij[k]) / prod_k (s - poles_j[k])  [rad/s].
struct TransferMatrix {
  std::size_t size = 0;                                        //!< N (inputs = outputs)
  std::vector<std::vector<std::complex<double>>> poles;        //!< poles[j]: column j's (conjugate pairs both given)
  std::vector<std::vector<std::vector<std::complex<double>>>> zeros;  //!< zeros[i][j] of H_ij
  std::vector<std::vector<double>> gains;                      //!< gains[i][j] of H_ij
  //! Proper, real (conjugate pairs), finite, distinct stable-or-not poles per column; throws Error naming the entry.
  void validate() const;
  std::complex<double> element(std::size_t i, std::size_t j, std::complex<double> s) const;
  Eigen::MatrixXcd frequency_response(std::complex<double> s) const;
  Eigen::MatrixXd dc_gain() const;  //!< H(0)
  //! A real state-space realisation: per column the modal form of its poles (one state per real pole, a 2 x 2
  //! block per conjugate pair), the outputs from the partial-fraction residues (distinct poles required).
  StateSpace realize() const;
};

//! The nominal values of fcn_build_uncert_plant.m [rad/s] (2 pi times the Hz values) and gains.
struct BenchmarkPlantModel {
  double h1_zero_1, h1_zero_2;            //!< zeros of H11 and H21 (-120, -90 Hz)
  double h1_pole_1, h1_pole_2;            //!< poles of column 1 (-2.65, -40 Hz)
  std::complex<double> frame_pole;        //!< 2 pi (-50 - 63j); its conjugate follows
  double h12_zero, h22_zero;              //!< (-3, -5 Hz)
  double h2_pole_1, h2_pole_2;            //!< poles of column 2 (-3.5, -18.5 Hz)
  double gain_11 = 2165.2, gain_21 = 349.95, gain_12 = 4.5394e6, gain_22 = 1.9238e7;
  BenchmarkPlantModel();
  TransferMatrix transfer_matrix() const;  //!< [[H11, H12], [H21, H22]], input/output mm
};

//! The relative standard deviations of the nine draws (fcn_build_uncert_plant.m).
struct PlantUncertainty {
  double h1_zeros = 0.055;   //!< the two zeros of H11/H21
  double h1_poles = 0.06;    //!< the poles -2.65 and -40 Hz
  double frame_pole = 0.05;  //!< the complex frame pole
  double h12_zero = 0.03;
  double h2_poles = 0.03;    //!< the poles -3.5 and -18.5 Hz
  double h22_zero = 0.03;
  //! Frequency at which each element's magnitude is kept at the nominal one [rad/s]: 2 pi 0.01 Hz, the script's
  //! for H11 (its H21, H12, H22 use the first point of MATLAB's automatic Bode grid; any frequency << 2 Hz gives
  //! the same gains to < 1e-4, BENCHMARK.md section 4).
  double match_frequency = 2.0 * 3.14159265358979323846 * 0.01;
  void validate() const;
  //! The nine values scaled by (1 + c z) with the standard normals z[0..8] in the script's order (gains unchanged).
  BenchmarkPlantModel perturb(const BenchmarkPlantModel& nominal, const double* z) const;
  //! A perturbed plant: the nine draws from a seeded standard-normal sequence (NoiseGenerator::MersenneTwister),
  //! then each element's gain rescaled to the nominal magnitude at match_frequency.
  TransferMatrix draw(const BenchmarkPlantModel& nominal, std::uint64_t seed) const;
  //! The gain rescaling alone, of any perturbed model (exposed for tests).
  TransferMatrix rescaled(const BenchmarkPlantModel& nominal, const BenchmarkPlantModel& perturbed) const;
};

//! The identified plant as N displacement-commanded actuators: commands [m] in, displacements [m] out; inside,
//! the model's own unit (the benchmark's: mm).
class IdentifiedPlant final : public MultiActuatorSystem {
 public:
  //! model: square (inputs = outputs = N), strictly proper; dt [s] > 0; unit: the model's signal unit [m] (1e-3).
  IdentifiedPlant(const StateSpace& model, double dt, double unit = 1e-3);
  std::size_t actuators() const noexcept override { return static_cast<std::size_t>(model_.outputs()); }
  double dt() const noexcept override { return dt_; }
  void reset() noexcept override;
  void displacements(double* y) const noexcept override;
  Status step(const double* u) noexcept override;  //!< NonFinite when the state diverged

  const StateSpace& model() const noexcept { return model_; }
  const Eigen::MatrixXd& phi() const noexcept { return phi_; }
  const Eigen::MatrixXd& gamma() const noexcept { return gamma_; }
  const Eigen::VectorXd& state() const noexcept { return x_; }
  double unit() const noexcept { return unit_; }

 private:
  StateSpace model_;
  double dt_, unit_;
  Eigen::MatrixXd phi_, gamma_;
  Eigen::VectorXd x_, next_, u_;
  double t_ = 0.0;
};

}  // namespace servohydraulics::marths
