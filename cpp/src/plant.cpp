// The plant stepped at the controller rate: the zero-order hold of the command,
// the divergence guard and the lifecycle, over one of the integrators
// (detail/dopri5_integrator, cvode_integrator, rk4_integrator, arkode_integrator)
// held in a std::variant.
#include "servohydraulics/plant.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "detail/arkode_integrator.hpp"
#include "detail/cvode_integrator.hpp"
#include "detail/dopri5_integrator.hpp"
#include "detail/rk4_integrator.hpp"
#include "detail/ros2_integrator.hpp"

namespace servohydraulics {

namespace {
using detail::kMaxDisplacement;   // the divergence guard (detail/ode_system.hpp)
using detail::kMaxPressureRatio;

using Integrator = std::variant<detail::Dopri5Integrator, detail::CvodeIntegrator, detail::Rk4Integrator,
                                detail::ArkodeIntegrator, detail::Ros2Integrator>;

// The fixed-step integrators' substeps per sample (RK4, ROS2), 0 for the error-controlled ones.
int fixed_substeps(const Integrator& integ) noexcept {
  if (const auto* rk4 = std::get_if<detail::Rk4Integrator>(&integ)) return rk4->substeps();
  if (const auto* ros2 = std::get_if<detail::Ros2Integrator>(&integ)) return ros2->substeps();
  return 0;
}

SolverOptions checked(const SolverOptions& o, double dt) {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "controller sample time must be finite and > 0 [s]");
  o.validate();
  return o;
}

// A digital delay in whole samples plus a fraction in [0, 1) of dt.
struct SampleDelay {
  int whole = 0;
  double frac = 0.0;
  bool any() const noexcept { return whole > 0 || frac > 0.0; }
};

// delay [s] in samples of dt, at most kMaxDelaySamples; within 1e-9 of a whole sample is that sample.
SampleDelay sample_delay(const char* field, double delay, double dt) {
  const double q = delay / dt;
  const std::string why = "must be at most " + std::to_string(kMaxDelaySamples) + " samples of dt = " +
                          std::to_string(dt) + " s (" + std::to_string(q) + " samples) [s]";
  require(std::isfinite(q) && q <= kMaxDelaySamples + 1e-9, field, delay, why.c_str());
  SampleDelay d;
  d.whole = static_cast<int>(std::floor(q + 1e-9));
  d.frac = q - d.whole;
  if (d.frac < 1e-9) d.frac = 0.0;
  return d;
}

// The last values of a sampled signal, index j = samples since reset (fixed capacity: no allocation).
struct History {
  static constexpr int kSize = kMaxDelaySamples + 3;
  double v[kSize] = {};
  // Value j, or the first one for j < 0 (the signal held its first value before the reset).
  double at(long j) const noexcept { return v[(j < 0 ? 0 : j) % kSize]; }
  void put(long j, double x) noexcept { v[j % kSize] = x; }
  // The value delay d before sample j: linear interpolation between the neighbouring samples.
  double delayed(long j, const SampleDelay& d) const noexcept {
    const double a = at(j - d.whole);
    return d.frac == 0.0 ? a : (1.0 - d.frac) * a + d.frac * at(j - d.whole - 1);
  }
};

// Built in place (the SUNDIALS integrators are pinned: SUNDIALS holds their address).
Integrator make_integrator(const Dynamics& dyn, double dt, const SolverOptions& opt) {
  using M = SolverOptions::Method;
  const State y0 = dyn.equilibrium(0.0);
  switch (opt.method) {
    case M::CvodeBdf: return Integrator(std::in_place_type<detail::CvodeIntegrator>, dyn, dt, opt, y0);
    case M::Rk4: return Integrator(std::in_place_type<detail::Rk4Integrator>, dyn, dt, opt);
    case M::Ros2: return Integrator(std::in_place_type<detail::Ros2Integrator>, dyn, dt, opt);
    case M::ArkodeErk:
    case M::ArkodeDirk:
      return Integrator(std::in_place_type<detail::ArkodeIntegrator>, dyn, dt, opt, y0, opt.method == M::ArkodeDirk);
    case M::Dopri5: break;
  }
  return Integrator(std::in_place_type<detail::Dopri5Integrator>, dyn, dt, opt, y0, opt.stiff_check);
}
}  // namespace

struct Plant::Impl {
  Dynamics dyn;
  SolverOptions opt;
  double dt;
  double t = 0.0;   // local time since the last reset [s]: the integrators work in it
  double t0 = 0.0;  // time of the last reset [s]: only the time channel and statuses add it
  long k = 0;       // samples since then: sample times are t0 + k dt, never an accumulated sum
  State y{};
  Dynamics::Input input{};
  double prev_u = 0.0;
  bool have_prev_u = false;
  bool failed = false;
  Integrator integ;
  // Digital delays (docs/specimens.md): the command's, and the measured displacement's and force's.
  SampleDelay cmd_delay, disp_delay, force_delay;
  History commands, displacements, forces;

  Impl(const Rig& rig, ControlMode mode, double dt_, const SolverOptions& o)
      : dyn(rig, mode), opt(checked(o, dt_)), dt(dt_), integ(make_integrator(dyn, dt, opt)) {
    if (auto* rk4 = std::get_if<detail::Rk4Integrator>(&integ)) opt.rk4_substeps = rk4->substeps();
    const Rig& r = dyn.rig();
    cmd_delay = sample_delay("command_delay", r.command_delay, dt);
    disp_delay = sample_delay("measurement_delay_displacement", r.measurement_delay_displacement, dt);
    force_delay = sample_delay("measurement_delay_force", r.measurement_delay_force, dt);
  }

  // Integrate from t to t_end with input `in`; RK4 and ROS2 take `substeps` (0: their own count).
  // With the exact Coulomb law, stretch by stretch in one sliding mode (advance_sliding).
  Status advance(const Dynamics::Input& in, double t_end, int substeps) noexcept {
    return dyn.exact_coulomb() ? advance_sliding(in, t_end, substeps) : integrate(in, t_end, substeps);
  }
  Status advance_sliding(Dynamics::Input in, double t_end, int substeps) noexcept;
  // How far the stretch in mode in.sliding is from its end (>= 0 inside, < 0 past it): the velocity
  // sliding up, minus it sliding down, the static level less the held force stuck.
  double switch_margin(const Dynamics::Input& in) const noexcept {
    switch (in.sliding) {
      case Sliding::Up: return y[kV];
      case Sliding::Down: return -y[kV];
      default: return dyn.exact_coulomb()->static_level() - std::fabs(dyn.held_force(y.data(), in));
    }
  }
  // A stuck stretch's state has v = 0 exactly (the law's; an implicit solve leaves rounding there).
  void hold_stuck(const Dynamics::Input& in) noexcept {
    if (in.sliding == Sliding::Stuck) y[kV] = 0.0;
  }
  // The integrator goes on from y at t (set from outside), its counters running on.
  void restart() noexcept {
    std::visit([&](auto& integ) { integ.restart(y, t); }, integ);
  }
  Status integrate(const Dynamics::Input& in, double t_end, int substeps) noexcept {
    return std::visit(
        [&](auto& integ) {
          using T = std::decay_t<decltype(integ)>;
          if constexpr (std::is_same_v<T, detail::Rk4Integrator> || std::is_same_v<T, detail::Ros2Integrator>)
            return integ.advance(dyn, in, y, t, t_end, substeps);
          else
            return integ.advance(dyn, in, y, t, t_end);
        },
        integ);
  }

  // The held input that command j sets: its value and its rate (last increment / dt; 0 for the first).
  Dynamics::Input held(long j) const noexcept {
    const double rate = j <= 0 ? 0.0 : (commands.at(j) - commands.at(j - 1)) / dt;
    return {commands.at(j), rate};
  }
  Status advance_delayed(double t_next) noexcept;
  void record_measurements() noexcept {
    if (!disp_delay.any() && !force_delay.any()) return;
    Output o;
    dyn.outputs(y.data(), input, o);
    displacements.put(k, o.displacement);
    forces.put(k, o.force);
  }

  bool state_ok() const noexcept {
    for (double v : y)
      if (!std::isfinite(v)) return false;
    if (std::fabs(y[kX]) > kMaxDisplacement) return false;
    if (std::fabs(y[kP]) > kMaxPressureRatio * dyn.rig().p_s) return false;
    return true;
  }
};

Plant::Plant(const Rig& rig, ControlMode mode, double dt, const SolverOptions& options)
    : impl_(std::make_unique<Impl>(rig, mode, dt, options)) {
  reset(0.0, 0.0);
}
Plant::~Plant() = default;
Plant::Plant(Plant&&) noexcept = default;
Plant& Plant::operator=(Plant&&) noexcept = default;

void Plant::reset(double x0, double t0) {
  require(std::isfinite(t0), "t0", t0, "the start time must be finite [s]");
  reset_state(impl_->dyn.equilibrium(x0), t0);
}

// The integrators run in local time t - t0 from 0: at t0 = 1.7e9 s (a Unix time) a sample of 0.5 ms
// is 1e-13 of t, so absolute times would leave step sizes and CVODE's stop times a few bits.
void Plant::reset_state(const State& y0, double t0) {
  require(std::isfinite(t0), "t0", t0, "the start time must be finite [s]");
  Impl& m = *impl_;
  m.y = y0;
  m.t = 0.0;
  m.t0 = t0;
  m.k = 0;
  m.input = {};
  m.have_prev_u = false;
  m.failed = false;
  std::visit([&](auto& integ) { integ.reset(m.y, m.t); }, m.integ);
  m.record_measurements();
}

namespace {
// The work and the flags of `part`, a piece of the same sample, added to `st` (a failure's code kept).
void merge(Status& st, const Status& part) noexcept {
  st.internal_steps += part.internal_steps;
  st.rhs_evals += part.rhs_evals;
  st.restarted = st.restarted || part.restarted;
  st.stiff = st.stiff || part.stiff;
  st.inaccurate = st.inaccurate || part.inaccurate;
  st.error_estimate = std::max(st.error_estimate, part.error_estimate);
  st.run_error_estimate = std::max(st.run_error_estimate, part.run_error_estimate);
  if (!part.ok() && st.ok()) {
    st.code = part.code;
    st.cvode_flag = part.cvode_flag;
  }
  st.t = part.t;
}
}  // namespace

// The exact Coulomb law (ExactCoulomb): from t to t_end in stretches, each integrated in one mode,
// Sliding::Auto's rule at its start (so the right-hand side is smooth over it: no stiff slope, no
// jump for an error-controlled integrator to chase).  Where a stretch overshoots its end (the margin
// turns negative: the velocity crosses 0 sliding, the held force passes g(0) stuck), the switch is
// located by the Illinois variant of regula falsi on the fraction of the stretch, each trial
// re-integrated from the stretch's start (the error-controlled integrators to their tolerance, the
// fixed-step ones at their share of the substeps); the run goes on from the first trial past the
// switch, the velocity set to 0 there where it crossed.  A stuck stretch ends with v = 0 exactly
// (hold_stuck).  Status::Chatter past Status::kMaxSwitches switches in one call.
Status Plant::Impl::advance_sliding(Dynamics::Input in, double t_end, int substeps) noexcept {
  constexpr int kLocateTrials = 30;      // Illinois converges in a few; bisection's worst case is 30
  constexpr double kLocateMargin = 1e-6;  // of the overshoot's scale: where the switch counts as found
  const int n_all = substeps > 0 ? substeps : fixed_substeps(integ);  // 0: error-controlled
  const double t_begin = t;
  auto share = [&](double from, double to) {
    return n_all > 0 ? std::max(1, static_cast<int>(std::lround(n_all * (to - from) / (t_end - t_begin)))) : 0;
  };
  // The time the switches are located to, and a switch within it of t_end ends the call (a stretch
  // that short changes nothing the integrators resolve; CVODE refuses an output time at its start).
  const double t_min = 1e-9 * (t_end - t_begin);
  Status st;
  for (int switches = 0;; ++switches) {
    in.sliding = dyn.sliding(y.data(), in);
    const State y0 = y;
    const double t0s = t, e0 = std::max(0.0, switch_margin(in));
    merge(st, integrate(in, t_end, share(t0s, t_end)));
    if (!st.ok()) return st;
    hold_stuck(in);
    double e1 = switch_margin(in);
    if (!(e1 < 0.0)) return st;
    if (switches >= Status::kMaxSwitches) {
      st.code = Status::Chatter;
      st.t = t0s;
      return st;
    }
    // Illinois on the fraction th of [t0s, t_end]: the margin is e0 >= 0 at 0 and e1 < 0 at 1.
    double lo = 0.0, hi = 1.0, elo = e0, ehi = e1;
    State y_hi = y;
    double t_hi = t;
    const double scale = std::max(e0, -e1);
    int side = 0;
    for (int k = 0; k < kLocateTrials; ++k) {
      double th = (lo * ehi - hi * elo) / (ehi - elo);
      const double gap = t_min / (t_end - t0s);  // no trial closer than t_min to a bracket's end
      if (!(th > lo + gap && th < hi - gap)) th = 0.5 * (lo + hi);
      y = y0;
      t = t0s;
      restart();
      const double t_try = t0s + th * (t_end - t0s);
      merge(st, integrate(in, t_try, share(t0s, t_try)));
      if (!st.ok()) return st;
      hold_stuck(in);
      const double e = switch_margin(in);
      if (e < 0.0) {
        hi = th, ehi = e, y_hi = y, t_hi = t;
        if (side == -1) elo *= 0.5;
        side = -1;
      } else {
        lo = th, elo = e;
        if (side == 1) ehi *= 0.5;
        side = 1;
      }
      if (std::fabs(e) <= kLocateMargin * scale || (hi - lo) * (t_end - t0s) <= t_min) break;
    }
    y = y_hi;
    t = t_hi;
    if (in.sliding != Sliding::Stuck) y[kV] = 0.0;  // the velocity crossed 0: stuck or reversing from here
    restart();
    if (t_end - t <= t_min) {
      t = t_end;
      return st;
    }
  }
}

// With a command delay of (D + f) samples, command j holds over [t_j + (D + f) dt, t_(j+1) + (D + f) dt):
// over sample k the held value is command k-D-1 until t_k + f dt, then command k-D.  Both parts are
// integrated exactly as any sample (CVODE stops at the switch; RK4 and ROS2 share their substeps between them).
Status Plant::Impl::advance_delayed(double t_next) noexcept {
  const long j = k - cmd_delay.whole;
  if (cmd_delay.frac == 0.0) {
    input = held(j);
    return advance(input, t_next, 0);
  }
  const double t_switch = (static_cast<double>(k) + cmd_delay.frac) * dt;  // local time
  int n1 = 0, n2 = 0;
  if (const int n = fixed_substeps(integ); n > 0) {
    n1 = std::max(1, static_cast<int>(std::lround(cmd_delay.frac * n)));
    n2 = std::max(1, n - n1);
  }
  input = held(j - 1);
  Status st = advance(input, t_switch, n1);
  if (!st.ok()) return st;
  input = held(j);
  merge(st, advance(input, t_next, n2));
  return st;
}

Status Plant::step(double command, Output& out) noexcept {
  Impl& m = *impl_;
  if (m.failed) {
    Status st;
    st.code = Status::NotReady;
    st.t = m.t0 + m.t;
    observe(out);
    return st;
  }
  if (!std::isfinite(command)) {
    Status st;
    st.code = Status::NonFinite;
    st.t = m.t0 + m.t;
    m.failed = true;
    observe(out);
    return st;
  }
  const double t_next = static_cast<double>(m.k + 1) * m.dt;  // local time
  Status st;
  if (!m.cmd_delay.any()) {
    // Zero-order hold: the command is held over the sample, its rate is the last increment / dt.
    m.input.u = command;
    m.input.u_rate = m.have_prev_u ? (command - m.prev_u) / m.dt : 0.0;
    m.prev_u = command;
    m.have_prev_u = true;
    st = m.advance(m.input, t_next, 0);
  } else {
    m.commands.put(m.k, command);
    st = m.advance_delayed(t_next);
  }
  st.t += m.t0;
  if (st.ok() && !m.state_ok()) {
    st.code = Status::NonFinite;
  }
  if (st.ok()) {
    ++m.k;
    m.record_measurements();
  } else {
    m.failed = true;
  }
  observe(out);
  return st;
}

void Plant::observe(Output& out) const noexcept {
  const Impl& m = *impl_;
  out.time = m.t0 + m.t;
  m.dyn.outputs(m.y.data(), m.input, out);
  // Acquisition delays: the measured channels as the controller sees them (docs/specimens.md).
  if (m.disp_delay.any()) out.displacement = m.displacements.delayed(m.k, m.disp_delay);
  if (m.force_delay.any()) out.force = m.forces.delayed(m.k, m.force_delay);
}

double Plant::time() const noexcept { return impl_->t0 + impl_->t; }
double Plant::dt() const noexcept { return impl_->dt; }
const State& Plant::state() const noexcept { return impl_->y; }
const Dynamics& Plant::dynamics() const noexcept { return impl_->dyn; }
const SolverOptions& Plant::options() const noexcept { return impl_->opt; }
int Plant::rk4_substeps() const noexcept {
  const auto* rk4 = std::get_if<detail::Rk4Integrator>(&impl_->integ);
  return rk4 ? rk4->substeps() : 0;
}

long Plant::total_internal_steps() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_steps(); }, impl_->integ);
}
long Plant::total_rhs_evals() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_rhs_evals(); }, impl_->integ);
}
long Plant::total_restarts() const noexcept {
  return std::visit([](const auto& integ) { return integ.total_restarts(); }, impl_->integ);
}

}  // namespace servohydraulics
