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

RunSummary run_record(Plant& plant, const double* command, std::size_t n, const Channels& out) noexcept {
  RunSummary sum;
  const long ns0 = plant.total_internal_steps(), nf0 = plant.total_rhs_evals(), nr0 = plant.total_restarts();
  Output o;
  plant.observe(o);
  const double F_cap = plant.dynamics().rig().F_cap;
  for (std::size_t k = 0; k < n; ++k) {
    put(out.time, k, o.t);
    put(out.displacement, k, o.displacement);
    put(out.velocity, k, o.velocity);
    put(out.acceleration, k, o.acceleration);
    put(out.force, k, o.force);
    put(out.pressure, k, o.pressure);
    put(out.spool, k, o.spool);
    put(out.drive, k, o.drive);
    put(out.flow, k, o.flow);
    put(out.flags, k, o.flags);
    sum.flags_any |= o.flags;
    sum.peak_force = std::fmax(sum.peak_force, std::fabs(o.force));
    if (sum.first_capacity_time < 0.0 && std::fabs(o.force) > F_cap) sum.first_capacity_time = o.t;
    sum.rows = k + 1;
    if (k + 1 == n) break;  // the last command is held but its effect is past the record
    const Status st = plant.step(command[k], o);
    put(out.internal_steps, k, st.internal_steps);
    put(out.rhs_evals, k, st.rhs_evals);
    if (st.internal_steps > sum.max_internal_steps) sum.max_internal_steps = st.internal_steps;
    if (!st.ok()) {
      sum.status = st;
      break;
    }
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
  for (auto* v : {&tr.time, &tr.displacement, &tr.velocity, &tr.acceleration, &tr.force, &tr.pressure, &tr.spool,
                  &tr.drive, &tr.flow})
    v->assign(n, 0.0);
  tr.flags.assign(n, 0u);
  Channels ch;
  ch.time = tr.time.data();
  ch.displacement = tr.displacement.data();
  ch.velocity = tr.velocity.data();
  ch.acceleration = tr.acceleration.data();
  ch.force = tr.force.data();
  ch.pressure = tr.pressure.data();
  ch.spool = tr.spool.data();
  ch.drive = tr.drive.data();
  ch.flow = tr.flow.data();
  ch.flags = tr.flags.data();
  tr.summary = run_record(plant, command.data(), n, ch);
  return tr;
}

}  // namespace servohydraulics
