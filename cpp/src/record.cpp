#include "servohydraulics/record.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "detail/dopri5_integrator.hpp"
#include "detail/output_gap.hpp"

namespace servohydraulics {

namespace {
template <class T>
void put(T* dst, std::size_t k, T v) noexcept {
  if (dst) dst[k] = v;
}
}  // namespace

bool RunSummary::count(const Status& st, double t) noexcept {
  if (st.internal_steps > max_internal_steps) max_internal_steps = st.internal_steps;
  stiff_samples += st.stiff ? 1 : 0;
  inaccurate_samples += st.inaccurate ? 1 : 0;
  if (!std::isnan(max_sample_error_estimate) && !(st.error_estimate <= max_sample_error_estimate))
    max_sample_error_estimate = st.error_estimate;  // a NaN estimate sticks
  error_estimate = st.run_error_estimate;
  if (!st.ok()) {
    status = st;
    failure_time = t;
  }
  return st.ok();
}

void RunSummary::peaks(double force, double displacement, double velocity) noexcept {
  peak_force = std::fmax(peak_force, std::fabs(force));
  peak_displacement = std::fmax(peak_displacement, std::fabs(displacement));
  peak_velocity = std::fmax(peak_velocity, std::fabs(velocity));
}

RunSummary run_record(Plant& plant, const double* command, std::size_t n, const Channels& out) noexcept {
  RunSummary sum;
  const long ns0 = plant.total_internal_steps(), nf0 = plant.total_rhs_evals(), nr0 = plant.total_restarts();
  Output o;
  plant.observe(o);
  const double F_cap = plant.dynamics().rig().F_cap;
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < kNumPlantChannels; ++i) put(out.channel[i], k, o.*kPlantChannels[i].member);
    put(out.flags, k, o.flags);
    sum.flags_any |= o.flags;
    sum.peaks(o.force, o.displacement, o.velocity);
    if (sum.first_capacity_time < 0.0 && std::fabs(o.force) > F_cap) sum.first_capacity_time = o.time;
    sum.rows = k + 1;
    if (k + 1 == n) break;  // the last command is held but its effect is past the record
    const double t = o.time;  // the row's (o becomes the next sample's)
    const Status st = plant.step(command[k], o);
    put(out.internal_steps, k, st.internal_steps);
    put(out.rhs_evals, k, st.rhs_evals);
    if (!sum.count(st, t)) break;
  }
  sum.internal_steps = plant.total_internal_steps() - ns0;
  sum.rhs_evals = plant.total_rhs_evals() - nf0;
  sum.restarts = plant.total_restarts() - nr0;
  return sum;
}

std::optional<SolverOptions> record_check_options(const SolverOptions& run, const RunSummary& summary) noexcept {
  if (run.method != SolverOptions::Method::Dopri5 || !run.stiff_fallback || !run.stiff_check) return std::nullopt;
  if (summary.stiff_samples == 0 || !summary.ok()) return std::nullopt;
  SolverOptions tight = run;
  tight.rtol = run.rtol / detail::Dopri5Integrator::kShadowTighten;  // the absolute tolerances follow rtol
  tight.stiff_check = false;
  return tight;
}

void check_record(Plant& companion, const double* command, std::size_t n, const double* x, const double* F,
                  std::size_t rows, RunSummary& summary) {
  using Integrator = detail::Dopri5Integrator;
  rows = std::min(rows, n);
  std::vector<double> xc(rows), Fc(rows);
  Channels ch;
  ch[Channel::Displacement] = xc.data();
  ch[Channel::Force] = Fc.data();
  const RunSummary second = run_record(companion, command, rows, ch);
  detail::OutputGap<Dynamics> gap(companion.dynamics());
  for (std::size_t k = 0; k < second.rows; ++k) {
    const double v[2] = {x[k], F[k]}, vc[2] = {xc[k], Fc[k]};
    gap.gap_values(v, vc);
  }
  const double estimate = gap.run_gap() / (Integrator::kShadowGap * Integrator::kVerifyTolerance);
  if (!(estimate <= summary.error_estimate) && !std::isnan(summary.error_estimate))
    summary.error_estimate = estimate;  // a NaN sticks
}

Trace simulate(Plant& plant, const std::vector<double>& command) {
  for (std::size_t k = 0; k < command.size(); ++k) {
    if (!std::isfinite(command[k])) {
      std::ostringstream s;
      s << "invalid command[" << k << "] = " << command[k] << ": commands must be finite";
      throw Error(s.str());
    }
  }
  const std::size_t n = command.size();
  Trace tr;
  tr.command = command;
  Channels ch;
  for (std::size_t i = 0; i < kNumPlantChannels; ++i) {
    tr.channel[i].assign(n, 0.0);
    ch.channel[i] = tr.channel[i].data();
  }
  tr.flags.assign(n, 0u);
  ch.flags = tr.flags.data();
  tr.summary = run_record(plant, command.data(), n, ch);
  return tr;
}

}  // namespace servohydraulics
