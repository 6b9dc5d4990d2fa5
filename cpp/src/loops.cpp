#include "servohydraulics/loops.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
// Summary bookkeeping shared by the runners.
void account(RunSummary& sum, const Output& o, double F_cap) noexcept {
  sum.flags_any |= o.flags;
  sum.peaks(o.force, o.displacement, o.velocity);
  if (sum.first_capacity_time < 0.0 && std::fabs(o.force) > F_cap) sum.first_capacity_time = o.time;
}

EftConfig with_mass(const EftConfig& config, const Rig& rig) {
  config.validate();
  EftConfig c = config;
  if (!c.mass) c.mass = rig.m;  // P_eff = -m a_g with the plant's mass, whatever the model
  return c;
}
}  // namespace

void RpsdLoopOptions::validate() const {
  plant_options.validate();
  require(std::isfinite(physical_mass_fraction) && physical_mass_fraction > 0.0, "physical_mass_fraction",
          physical_mass_fraction, "must be finite and > 0");
}

EffectiveForceTest::EffectiveForceTest(const Rig& rig, const EftConfig& config, const std::optional<Rig>& model,
                                       const LoopConverters& converters, TrackingController* tracking,
                                       const EftLoopOptions& options)
    : ClosedLoop(Plant(rig, ControlMode::Force, config.dt, (options.validate(), options.plant_options)),
                 EftController(with_mass(config, rig), model.value_or(rig), tracking), converters) {}

Rig RealTimePseudoDynamicTest::physical_rig(const Rig& rig, const RpsdConfig& cfg, const RpsdLoopOptions& options) {
  cfg.validate();
  options.validate();
  Rig r = rig;
  r.m = options.physical_mass_fraction * cfg.model.m_m;
  r.validate();
  return r;
}

RealTimePseudoDynamicTest::RealTimePseudoDynamicTest(const Rig& rig, const RpsdConfig& config,
                                                     const LoopConverters& converters,
                                                     TrackingController* tracking,
                                                     NumericalSubstructure* substructure,
                                                     const RpsdLoopOptions& options)
    : ClosedLoop(Plant(physical_rig(rig, config, options), ControlMode::Displacement, config.dt,
                       options.plant_options),
                 RpsdController(config, physical_rig(rig, config, options), tracking, substructure), converters) {}

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
    const Output& row = plant_row(k);
    account(sum, row, F_cap);
    sum.rows = k + 1;
    if (!sum.count(st, row.time)) break;
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
