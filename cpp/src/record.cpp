#include "servohydraulics/record.hpp"

#include <cmath>
#include <sstream>

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
