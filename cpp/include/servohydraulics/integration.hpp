// Integration schemes of real-time pseudodynamic testing (Zhao et al. 2003, Eq 15,
// Fig 7; Shing & Mahin's explicit schemes): the online solver of the modelled
// structure, not the ODE integrator of the plant (SolverOptions, plant.hpp).  The modelled SDOF system is
//   m_m a + c_m v + f = -m_m a_g + P_ext,
// with the modelled mass m_m and damping c_m kept apart from the physical ones
// in the rig; f is the restoring force fed back from the test (measured or
// calculated).  Each step takes f at the current displacement d_k and returns
// the displacement d_{k+1} to be reached one controller sample later.
#pragma once

#include <tuple>

#include "servohydraulics/config_fields.hpp"
#include "servohydraulics/enum_name.hpp"

namespace servohydraulics {

//! Modelled system of Eq (15).  No defaults here: Table I's values live in
//! Zhao2003TestMethods::model (zhao2003.hpp), which RpsdConfig starts from.
struct ModelSDOF {
  double m_m = 0.0;  //!< modelled mass [kg]
  double c_m = 0.0;  //!< modelled viscous damping [N s/m]
  void validate() const;
};
//! ModelSDOF's fields (config_fields.hpp): RpsdConfig::model's, for the FMU (rpsd.m_m, rpsd.c_m) and MODEL_SDOF_FIELDS.
inline constexpr auto kModelSdofFields =
    std::make_tuple(config_field("m_m", "kg", "modelled mass of Eq (15)", &ModelSDOF::m_m),
                    config_field("c_m", "N s/m", "modelled viscous damping of Eq (15)", &ModelSDOF::c_m));

//! The structural integration schemes of a numerical substructure (substructure.hpp), one
//! enum for every hybrid loop.  Eq (15) of RPsD takes CentralDifference or ExplicitNewmark
//! (its own 1-DOF forms below, Eq15Substructure); RungeKutta4 and AverageAcceleration (implicit
//! Newmark, gamma = 1/2, beta = 1/4, unconditionally stable) run on LinearSubstructure.
//! The values of CentralDifference and ExplicitNewmark are those of the RPsD enum before (the FMU
//! enumeration items, cpp/fmu/model.cpp, index them).
enum class StructuralScheme { CentralDifference, ExplicitNewmark, RungeKutta4, AverageAcceleration };
using IntegrationScheme = StructuralScheme;  //!< the RPsD name before issue 22
inline constexpr EnumName<StructuralScheme> kSchemeNames[] = {
    {StructuralScheme::CentralDifference, "central_difference", "CentralDifference"},
    {StructuralScheme::ExplicitNewmark, "explicit_newmark", "ExplicitNewmark"},
    {StructuralScheme::RungeKutta4, "runge_kutta4", "RungeKutta4"},
    {StructuralScheme::AverageAcceleration, "average_acceleration", "AverageAcceleration"},
};
static_assert(in_enum_order(kSchemeNames), "kSchemeNames: one row per enumerator, in order");
//! The schemes Eq (15) itself takes (RpsdConfig::scheme): the first two rows of kSchemeNames.
inline constexpr int kEq15Schemes = 2;

//! State of an integration scheme at time t_k.
struct IntegratorState {
  double displacement = 0.0;  //!< d_k [m]
  double velocity = 0.0;      //!< v_k [m/s]
  double acceleration = 0.0;  //!< a_k [m/s^2]
  double next_displacement = 0.0;  //!< d_{k+1}, the target of the next sample [m]
};

//! Explicit central difference:
//!   (m_m/dt^2 + c_m/(2 dt)) d_{k+1} = P_k - f_k + 2 m_m/dt^2 d_k - (m_m/dt^2 - c_m/(2 dt)) d_{k-1},
//! with v_k = (d_{k+1} - d_{k-1})/(2 dt) and a_k = (d_{k+1} - 2 d_k + d_{k-1})/dt^2.
//! Started from rest at d_0 with the textbook starter d_{-1} = d_0 + dt^2/2 a_0.
class CentralDifference {
 public:
  CentralDifference(const ModelSDOF& model, double dt);
  void reset(double d0 = 0.0) noexcept;
  //! load P_k = -m_m a_g + P_ext [N], restoring force f_k [N]; returns d_{k+1} [m].
  double step(double load, double restoring_force) noexcept;
  const IntegratorState& state() const noexcept { return s_; }

 private:
  ModelSDOF mdl_;
  double dt_;
  double d_prev_ = 0.0;
  bool started_ = false;
  IntegratorState s_;
};

//! Explicit Newmark (gamma = 1/2, Shing et al.).  At sample k, with f_k measured at d_k:
//!   a_k = (P_k - f_k - c_m (v_{k-1} + (1 - gamma) dt a_{k-1})) / (m_m + gamma dt c_m)
//!   v_k = v_{k-1} + dt ((1 - gamma) a_{k-1} + gamma a_k)
//!   d_{k+1} = d_k + dt v_k + dt^2/2 a_k            (predictor, the command)
class ExplicitNewmark {
 public:
  ExplicitNewmark(const ModelSDOF& model, double dt, double gamma = 0.5);
  void reset(double d0 = 0.0) noexcept;
  double step(double load, double restoring_force) noexcept;
  const IntegratorState& state() const noexcept { return s_; }

 private:
  ModelSDOF mdl_;
  double dt_, gamma_;
  bool first_ = true;
  IntegratorState s_;
};

}  // namespace servohydraulics
