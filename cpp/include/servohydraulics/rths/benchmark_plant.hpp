// The experimental substructure of a real-time hybrid simulation behind one
// interface, so that either the RTHS benchmark's linear control plant or our
// nonlinear servo-hydraulic Plant can sit in the same loop (loop.hpp).
//
// The benchmark's control plant (Silva, Gomez, Maghareh, Dyke, Spencer 2020,
// Sec 4.2, Eqs 21-22, Fig 11; the official F1_input_file.m values, not the
// rounded Table 2): servovalve a1b0/(s^2 + b1 s + b2), actuator 1/(s + a3) with
// the control-structure interaction a2 s, specimen 1/(me s^2 + ce s + ke), and
// the gain 1.0261 on the command only.  With state p = [q, q', f, x, x']:
//   q'' = -b1 q' - b2 q + a1b0 (gain u - x)
//   f'  = -a3 f + q - a2 x'
//   me x'' = f - ce x' - ke x
// integrated with classical RK4 over the sample with u held (ode4).
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "servohydraulics/plant.hpp"

namespace servohydraulics::rths {

//! The specimen's model used by the loop's feedback-force blocks: f_e = ke x + ce x' + me x''.
struct SpecimenModel {
  double m = 0.0;  //!< [kg]
  double c = 0.0;  //!< [N s/m]
  double k = 0.0;  //!< [N/m]
};

//! The benchmark plant's parameters (F1_input_file.m L61-L121, SI; BENCHMARK.md 2.2).
struct BenchmarkPlantParameters {
  double a1_beta0 = 2.1283e13;  //!< servovalve gain [N/(m s^3)]
  double a2 = 4.2297e6;         //!< control-structure interaction [N/m]
  double a3 = 3.3;              //!< actuator pole [1/s] (may be negative in perturbed draws)
  double beta1 = 425.0;         //!< servovalve [1/s]
  double beta2 = 9.9976e4;      //!< servovalve [1/s^2]
  double m_e = 29.13;           //!< specimen mass [kg]
  double k_e = 1190e3;          //!< specimen stiffness [N/m]
  double zeta_e = 0.0097;       //!< specimen damping ratio: c_e = 2 zeta_e sqrt(k_e m_e)
  double gain = 1.0261;         //!< gain on the command only (F1 L106)
  //! CSI as the code's Simulink Derivative block on a2 x (major step: backward
  //! difference, 0 at the first step; RK4 stages: difference from the last major
  //! step) instead of the exact a2 x' of the paper's Eq 21.
  bool csi_derivative_block = false;
  void validate() const;
  double c_e() const noexcept;  //!< [N s/m]
  SpecimenModel specimen() const noexcept { return {m_e, c_e(), k_e}; }
  //! G_P(s) = numerator / (A5 s^5 + ... + A0): {A5, A4, A3, A2, A1, A0} (descending powers).
  std::array<double, 6> denominator() const noexcept;
  double numerator() const noexcept { return gain * a1_beta0; }
};

//! Standard deviations of the benchmark's uncertainty draws (F1 L67, L119-L121).
struct BenchmarkPlantUncertainty {
  double k_e = 50e3;
  double beta1 = 3.3;
  double beta2 = 3.3e3;
  double a3 = 1.3;
  //! One perturbed plant: ke, b1, b2, a3 = nominal + sigma z with independent
  //! standard normals z (not truncated, as the official code); c_e follows k_e.
  BenchmarkPlantParameters draw(const BenchmarkPlantParameters& nominal, std::uint64_t seed) const;
};

//! An experimental substructure: held command in, true displacement and force out.
class ExperimentalSubstructure {
 public:
  virtual ~ExperimentalSubstructure() = default;
  virtual void reset() noexcept = 0;  //!< at rest at t = 0
  //! Hold command [m] over one sample; the status of the step (not ok: the loop stops).
  virtual Status step(double command) noexcept = 0;
  virtual double displacement() const noexcept = 0;    //!< true specimen displacement [m]
  virtual double velocity() const noexcept = 0;        //!< [m/s]
  virtual double actuator_force() const noexcept = 0;  //!< actuator force (benchmark: f; Plant: load cell) [N]
  virtual SpecimenModel specimen() const noexcept = 0;  //!< for the feedback-force blocks and the partitioning
  virtual double dt() const noexcept = 0;               //!< sample time [s]
};

//! The benchmark's linear control plant.
class BenchmarkPlant final : public ExperimentalSubstructure {
 public:
  BenchmarkPlant(const BenchmarkPlantParameters& parameters, double dt);
  void reset() noexcept override {
    p_.fill(0.0);
    x_prev_ = 0.0;
    first_ = true;
  }
  Status step(double command) noexcept override;  //!< NonFinite when the state diverged
  double displacement() const noexcept override { return p_[3]; }
  double velocity() const noexcept override { return p_[4]; }
  double actuator_force() const noexcept override { return p_[2]; }
  SpecimenModel specimen() const noexcept override { return par_.specimen(); }
  double dt() const noexcept override { return dt_; }
  const BenchmarkPlantParameters& parameters() const noexcept { return par_; }
  const std::array<double, 5>& state() const noexcept { return p_; }  //!< [q, q', f, x, x']

 private:
  void rhs(const std::array<double, 5>& p, double u, double csi_rate, std::array<double, 5>& dp) const noexcept;
  double csi_rate(const std::array<double, 5>& p, double since) const noexcept;
  BenchmarkPlantParameters par_;
  double dt_, c_e_, x_prev_ = 0.0, x_major_ = 0.0, d_major_ = 0.0;
  bool first_ = true;
  std::array<double, 5> p_{};
};

//! Our nonlinear servo-hydraulic Plant (displacement control) as the experimental substructure.
class ServoHydraulicSubstructure final : public ExperimentalSubstructure {
 public:
  //! The specimen is the rig's structure (m, c, k); dt the sample time.
  ServoHydraulicSubstructure(const Rig& rig, double dt, const SolverOptions& options = {});
  void reset() noexcept override;
  Status step(double command) noexcept override;  //!< the Plant's own Status
  double displacement() const noexcept override { return out_.displacement; }
  double velocity() const noexcept override { return out_.velocity; }
  double actuator_force() const noexcept override { return out_.force; }
  SpecimenModel specimen() const noexcept override { return specimen_; }
  double dt() const noexcept override { return plant_.dt(); }
  const Plant& plant() const noexcept { return plant_; }
  const Output& output() const noexcept { return out_; }

 private:
  Plant plant_;
  Output out_;
  SpecimenModel specimen_;
};

}  // namespace servohydraulics::rths
