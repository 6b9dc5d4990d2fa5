#include "servohydraulics/controllers.hpp"

#include <cmath>

namespace servohydraulics {

namespace {
void require_dt(double dt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
}
void require_delay(int n) {
  require(n >= 0 && n <= 1000, "compute_delay", n, "must be 0..1000 samples");
}
void require_lead(double T, const char* field) {
  require(std::isfinite(T) && T >= 0.0, field, T, "phase-lead time constant must be finite and >= 0 [s]");
}
void require_alpha(double alpha) {
  require(std::isfinite(alpha) && alpha > 0.0 && alpha <= 1.0, "alpha", alpha, "must be in (0, 1]");
}
// The tracking compensator's input: the target and the measured channels of the sensors.
TrackingInput tracking_input(const Output& s, double desired) noexcept {
  TrackingInput in;
  in.desired = desired;
  in.measured = s.displacement;
  in.measured_force = s.force;
  in.measured_velocity = s.velocity;
  in.measured_pressure = s.pressure;
  return in;
}
// An optional value, when given, must be finite and >= 0 (> 0 if positive).
void require_given(const std::optional<double>& v, const char* field, bool positive, const char* requirement) {
  if (v) require(std::isfinite(*v) && (positive ? *v > 0.0 : *v >= 0.0), field, *v, requirement);
}
}  // namespace

// ----------------------------------------------------------------------- EFT

void EftConfig::validate() const {
  require_dt(dt);
  require_given(mass, "mass", true, "EFT mass must be finite and > 0 when given (none = rig m) [kg]");
  require_lead(lead_T, "lead_T");
  require_alpha(alpha);
  require_delay(compute_delay);
}

EftController::EftController(const EftConfig& config, const Rig& model, TrackingController* tracking)
    : cfg_((config.validate(), config)),
      paper_(model, config.compensation, config.lead_T, config.alpha, config.dt),
      user_(tracking),
      delay_(config.compute_delay),
      mass_(config.mass.value_or(model.m)) {
  reset();
}

void EftController::reset() noexcept {
  tracking().reset();
  delay_.reset(0.0);
}

double EftController::command(const Output& s, double ground_acceleration, EftOutput* out) noexcept {
  const double P = -mass_ * ground_acceleration;  // effective force
  const double c = tracking().command(tracking_input(s, P));  // paper: P + du (Eqs 9-10)
  const double u = delay_.step(c);
  if (out) {
    out->plant = s;
    out->ground_acceleration = ground_acceleration;
    out->effective_force = P;
    out->compensation = user_ ? c - P : paper_.last_compensation();
    out->compensation_opening = user_ ? 0.0 : paper_.compensator().last_opening();
    out->command = u;
  }
  return u;
}

// ---------------------------------------------------------------------- RPsD

void RpsdConfig::validate() const {
  require_dt(dt);
  model.validate();
  require_given(k_m, "k_m", false, "must be finite and >= 0 when given (none = rig k) [N/m]");
  require_lead(amplitude_T, "amplitude_T");
  require_lead(delay_T, "delay_T");
  require_alpha(alpha);
  require_given(subtract_mass, "subtract_mass", false,
                "must be finite and >= 0 when given (none = the physical mass) [kg]");
  require_given(subtract_damping, "subtract_damping", false,
                "must be finite and >= 0 when given (none = rig c) [N s/m]");
  require_delay(compute_delay);
}

namespace {
const RpsdConfig& validated(const RpsdConfig& cfg, const NumericalSubstructure* sub) {
  cfg.validate();
  if (sub)
    require(std::fabs(sub->sample_time() - cfg.dt) <= 1e-12 * cfg.dt, "substructure.sample_time",
            sub->sample_time(), "the controller's dt");
  return cfg;
}
}  // namespace

RpsdController::RpsdController(const RpsdConfig& config, const Rig& r, TrackingController* tracking,
                               NumericalSubstructure* substructure)
    : cfg_(validated(config, substructure)),
      eq15_(config.model, config.dt,
            substructure ? StructuralScheme::CentralDifference : config.scheme),
      user_sub_(substructure),
      amplitude_(config.amplitude_T, config.alpha, config.dt),
      user_(tracking),
      delay_comp_(config.delay_T, config.alpha, config.dt),
      delay_(config.compute_delay) {
  r.validate();
  k_m_ = cfg_.k_m.value_or(r.k);
  // The mass behind the force measurement: the structure, plus the piston when
  // the measurement is the actuator force pA.
  const bool piston = cfg_.force_measurement == ForceMeasurement::ActuatorPressure && r.effects.piston_mass;
  m_sub_ = cfg_.subtract_mass.value_or(r.m + (piston ? r.m_p : 0.0));
  c_sub_ = cfg_.subtract_damping.value_or(r.c);
  A_ = r.A;
  reset();
}

void RpsdController::reset() noexcept {
  substructure().reset();
  st_ = IntegratorState{};
  tracking().reset();
  delay_comp_.reset(0.0);
  delay_.reset(0.0);
}

double RpsdController::restoring_force(const Output& s) const noexcept {
  const double F = cfg_.force_measurement == ForceMeasurement::LoadCell ? s.force : s.pressure * A_;
  switch (cfg_.restoring_force) {
    case RestoringForce::CalculatedDisplacement: return k_m_ * integrator_state().next_displacement;  // d_k
    case RestoringForce::MeasuredDisplacement: return k_m_ * s.displacement;
    case RestoringForce::MeasuredForce: return F;
    case RestoringForce::MeasuredForceCorrected: return F - m_sub_ * s.acceleration - c_sub_ * s.velocity;
  }
  return 0.0;
}

double RpsdController::command(const Output& s, double ground_acceleration, double external_force,
                               double restoring_force_error, RpsdOutput* out) noexcept {
  const double f = restoring_force(s);
  const double f_used = delay_comp_.step(f) + restoring_force_error;  // delay compensation T_ld
  const double load = -cfg_.model.m_m * ground_acceleration + external_force;  // Eq (15)
  double d_next;
  if (!user_sub_) {
    d_next = eq15_.step_load(load, f_used);
    st_ = eq15_.state();
  } else {  // P_ext acts on the interface DOF; a_g held over the sample
    NumericalSubstructure& sub = *user_sub_;
    const Eigen::Index i = sub.interface_dof();
    const double fin = f_used - external_force;
    st_.displacement = sub.dof_displacement(i);
    sub.step(ground_acceleration, ground_acceleration, ground_acceleration, fin);
    d_next = sub.dof_displacement(i);
    st_.velocity = sub.interface_velocity();
    st_.acceleration = sub.interface_acceleration(ground_acceleration, fin);
    st_.next_displacement = d_next;
  }
  const IntegratorState& st = st_;
  TrackingInput in = tracking_input(s, d_next);
  in.desired_velocity = st.velocity;
  in.desired_acceleration = st.acceleration;
  const double u = delay_.step(tracking().command(in));  // paper: amplitude compensation T_d
  if (out) {
    out->plant = s;
    out->ground_acceleration = ground_acceleration;
    out->external_force = external_force;
    out->measured_restoring_force = f;
    out->restoring_force = f_used;
    out->calc_displacement = st.displacement;
    out->calc_velocity = st.velocity;
    out->calc_acceleration = st.acceleration;
    out->target_displacement = d_next;
    out->command = u;
  }
  return u;
}

}  // namespace servohydraulics
