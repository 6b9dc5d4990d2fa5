#include "servohydraulics/loops.hpp"

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
// Summary bookkeeping shared by the runners.
void account(RunSummary& sum, const Output& o, double F_cap) noexcept {
  sum.flags_any |= o.flags;
  sum.peak_force = std::fmax(sum.peak_force, std::fabs(o.force));
  if (sum.first_capacity_time < 0.0 && std::fabs(o.force) > F_cap) sum.first_capacity_time = o.t;
}
}  // namespace

// ----------------------------------------------------------------------- EFT

void EftConfig::validate() const {
  require_dt(dt);
  require(std::isfinite(mass) && mass >= 0.0, "mass", mass, "EFT mass must be finite and >= 0 (0 = rig m) [kg]");
  require_lead(lead_T, "lead_T");
  require(std::isfinite(alpha) && alpha > 0.0 && alpha <= 1.0, "alpha", alpha, "must be in (0, 1]");
  require_delay(compute_delay);
  plant_options.validate();
}

EffectiveForceTest::EffectiveForceTest(const Rig& rig, const EftConfig& config, const Rig* model)
    : cfg_((config.validate(), config)),
      plant_(rig, ControlMode::Force, config.dt, config.plant_options),
      vfc_(model ? *model : rig, config.compensation, config.lead_T, config.alpha, config.dt),
      delay_(config.compute_delay),
      mass_(config.mass > 0.0 ? config.mass : rig.m) {
  reset();
}

void EffectiveForceTest::reset() noexcept {
  plant_.reset(0.0, 0.0);
  plant_.observe(last_);
  vfc_.reset();
  delay_.reset(0.0);
}

Status EffectiveForceTest::step(double ground_acceleration, EftOutput& out) noexcept {
  out.plant = last_;
  out.ground_acceleration = ground_acceleration;
  const double P = -mass_ * ground_acceleration;  // effective force
  out.effective_force = P;
  out.compensation = vfc_.step(last_.velocity, P - last_.force, last_.pressure);
  out.compensation_opening = vfc_.last_opening();
  out.command = delay_.step(P + out.compensation);
  return plant_.step(out.command, last_);
}

// ---------------------------------------------------------------------- RPsD

void RpsdConfig::validate() const {
  require_dt(dt);
  model.validate();
  require(std::isfinite(k_m) && k_m >= 0.0, "k_m", k_m, "must be finite and >= 0 (0 = rig k) [N/m]");
  require_lead(amplitude_T, "amplitude_T");
  require_lead(delay_T, "delay_T");
  require(std::isfinite(alpha) && alpha > 0.0 && alpha <= 1.0, "alpha", alpha, "must be in (0, 1]");
  require(std::isfinite(physical_mass_fraction) && physical_mass_fraction > 0.0, "physical_mass_fraction",
          physical_mass_fraction, "must be finite and > 0");
  require(std::isfinite(subtract_mass), "subtract_mass", subtract_mass, "must be finite (< 0 = physical) [kg]");
  require(std::isfinite(subtract_damping), "subtract_damping", subtract_damping,
          "must be finite (< 0 = rig c) [N s/m]");
  require_delay(compute_delay);
  plant_options.validate();
}

Rig RealTimePseudoDynamicTest::physical_rig(const Rig& rig, const RpsdConfig& cfg) {
  cfg.validate();
  Rig r = rig;
  r.m = cfg.physical_mass_fraction * cfg.model.m_m;
  r.validate();
  return r;
}

RealTimePseudoDynamicTest::RealTimePseudoDynamicTest(const Rig& rig, const RpsdConfig& config)
    : cfg_(config),
      plant_(physical_rig(rig, config), ControlMode::Displacement, config.dt, config.plant_options),
      cd_(config.model, config.dt),
      nm_(config.model, config.dt),
      amplitude_(config.amplitude_T, config.alpha, config.dt),
      delay_comp_(config.delay_T, config.alpha, config.dt),
      delay_(config.compute_delay) {
  const Rig& r = plant_.dynamics().rig();
  k_m_ = cfg_.k_m > 0.0 ? cfg_.k_m : r.k;
  // The mass behind the force measurement: the structure, plus the piston when
  // the measurement is the actuator force pA.
  const bool piston = cfg_.force_measurement == ForceMeasurement::ActuatorPressure && r.effects.piston_mass;
  m_sub_ = cfg_.subtract_mass >= 0.0 ? cfg_.subtract_mass : r.m + (piston ? r.m_p : 0.0);
  c_sub_ = cfg_.subtract_damping >= 0.0 ? cfg_.subtract_damping : r.c;
  A_ = r.A;
  reset();
}

const SolverState& RealTimePseudoDynamicTest::solver_state() const noexcept {
  return cfg_.solver == SolverKind::CentralDifference ? cd_.state() : nm_.state();
}

void RealTimePseudoDynamicTest::reset() noexcept {
  plant_.reset(0.0, 0.0);
  plant_.observe(last_);
  cd_.reset(0.0);
  nm_.reset(0.0);
  amplitude_.reset(0.0);
  delay_comp_.reset(0.0);
  delay_.reset(0.0);
}

Status RealTimePseudoDynamicTest::step(double ground_acceleration, double external_force,
                                       double restoring_force_error, RpsdOutput& out) noexcept {
  out.plant = last_;
  out.ground_acceleration = ground_acceleration;
  out.external_force = external_force;
  const double d_k = solver_state().next_displacement;  // the solver's displacement at t_k
  const double F = cfg_.force_measurement == ForceMeasurement::LoadCell ? last_.force : last_.pressure * A_;
  double f = 0.0;
  switch (cfg_.restoring_force) {
    case RestoringForce::CalculatedDisplacement: f = k_m_ * d_k; break;
    case RestoringForce::MeasuredDisplacement: f = k_m_ * last_.displacement; break;
    case RestoringForce::MeasuredForce: f = F; break;
    case RestoringForce::MeasuredForceCorrected:
      f = F - m_sub_ * last_.acceleration - c_sub_ * last_.velocity;
      break;
  }
  out.measured_restoring_force = f;
  out.restoring_force = delay_comp_.step(f) + restoring_force_error;  // delay compensation T_ld
  const double load = -cfg_.model.m_m * ground_acceleration + external_force;  // Eq (15)
  const double d_next = cfg_.solver == SolverKind::CentralDifference ? cd_.step(load, out.restoring_force)
                                                                     : nm_.step(load, out.restoring_force);
  const SolverState& s = solver_state();
  out.calc_displacement = s.displacement;
  out.calc_velocity = s.velocity;
  out.calc_acceleration = s.acceleration;
  out.target_displacement = d_next;
  out.command = delay_.step(amplitude_.step(d_next));  // amplitude compensation T_d
  return plant_.step(out.command, last_);
}

// -------------------------------------------------------------------- runners

namespace {
// The whole-record loop shared by both test methods: step_row(k) advances row k
// and returns its status; plant_row(k) is the plant's output in that row.
template <class StepRow, class PlantRow>
RunSummary run_rows(const Plant& p, std::size_t n, StepRow&& step_row, PlantRow&& plant_row) noexcept {
  RunSummary sum;
  const long ns0 = p.total_internal_steps(), nf0 = p.total_rhs_evals(), nr0 = p.total_restarts();
  const double F_cap = p.dynamics().rig().F_cap;
  for (std::size_t k = 0; k < n; ++k) {
    const Status st = step_row(k);
    account(sum, plant_row(k), F_cap);
    sum.rows = k + 1;
    if (st.internal_steps > sum.max_internal_steps) sum.max_internal_steps = st.internal_steps;
    if (!st.ok()) {
      sum.status = st;
      break;
    }
  }
  sum.internal_steps = p.total_internal_steps() - ns0;
  sum.rhs_evals = p.total_rhs_evals() - nf0;
  sum.restarts = p.total_restarts() - nr0;
  return sum;
}
}  // namespace

RunSummary run_eft(EffectiveForceTest& test, const double* ground_acceleration, std::size_t n,
                   EftOutput* rows) noexcept {
  return run_rows(
      test.plant(), n, [&](std::size_t k) { return test.step(ground_acceleration[k], rows[k]); },
      [&](std::size_t k) -> const Output& { return rows[k].plant; });
}

RunSummary run_rpsd(RealTimePseudoDynamicTest& test, const double* ground_acceleration,
                    const double* external_force, const double* restoring_force_error, std::size_t n,
                    RpsdOutput* rows) noexcept {
  return run_rows(
      test.plant(), n,
      [&](std::size_t k) {
        const double ag = ground_acceleration ? ground_acceleration[k] : 0.0;
        const double pe = external_force ? external_force[k] : 0.0;
        const double fe = restoring_force_error ? restoring_force_error[k] : 0.0;
        return test.step(ag, pe, fe, rows[k]);
      },
      [&](std::size_t k) -> const Output& { return rows[k].plant; });
}

}  // namespace servohydraulics
