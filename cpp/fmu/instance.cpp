#include "instance.hpp"

#include <cmath>
#include <cstdio>

#include "resources.hpp"
#include "servohydraulics/error.hpp"

namespace servohydraulics::fmu {

namespace {
double command(EftController& c, Values& v) noexcept {
  return c.command(v.sensors, v.ground_acceleration, &v.eft_out);
}
double command(RpsdController& c, Values& v) noexcept {
  return c.command(v.sensors, v.ground_acceleration, v.external_force, v.restoring_force_error, &v.rpsd_out);
}

std::string format(const char* fmt, double a, double b, double c = 0.0) {
  char buf[320];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}
}  // namespace

Instance::Instance(const std::string& resource_dir, const std::string& guid) {
  Loaded loaded = load_resources(resource_dir);
  if (loaded.guid != guid)
    throw Error("fmuGUID " + guid + " differs from the exporter's " + loaded.guid + " in " + resource_dir +
                "/fmu.toml: modelDescription.xml and resources/ are from different exports");
  initial_ = loaded.settings;
  vars_ = fmu::variables(initial_.kind, initial_.mode);
  reset();
}

void Instance::reset() {
  values_ = Values{};
  values_.settings = initial_;
  plant_.reset();
  for (auto* c : {&eft_.c[0], &eft_.c[1]}) c->reset();
  for (auto* c : {&rpsd_.c[0], &rpsd_.c[1]}) c->reset();
  t_start_ = 0.0;
  k_ = 0;
  initialized_ = false;
  failed_ = false;
}

template <class C>
void Instance::build(Slot<C>& slot, const C& controller) {
  slot.c[0].emplace(controller);
  slot.c[0]->reset();
  slot.c[1].emplace(*slot.c[0]);
  slot.cur = 0;
  slot.trial_valid = false;
}

void Instance::initialize(double start_time) {
  Settings& s = values_.settings;
  require(std::isfinite(start_time), "startTime", start_time, "the start time must be finite [s]");
  check_dt(s.dt);  // the host may have set dt
  s.rig.validate();
  s.eft.dt = s.rpsd.dt = s.dt;
  switch (s.kind) {
    case Kind::Plant:
      plant_.emplace(s.rig, s.mode, s.dt, s.solver);
      plant_->reset(s.x0, start_time);
      plant_->observe(values_.plant_out);
      break;
    case Kind::Eft: build(eft_, EftController(s.eft, s.rig)); break;
    case Kind::Rpsd: build(rpsd_, RpsdController(s.rpsd, s.rig)); break;
  }
  t_start_ = start_time;
  k_ = 0;
  initialized_ = true;
}

template <class C>
void Instance::evaluate(Slot<C>& slot) noexcept {
  auto& trial = slot.c[1 - slot.cur];
  *trial = *slot.c[slot.cur];  // same sizes: no allocation
  values_.sensors.time = time();
  command(*trial, values_);
  slot.trial_valid = true;
}

template <class C>
void Instance::advance(Slot<C>& slot, long samples) noexcept {
  if (!slot.trial_valid) evaluate(slot);
  slot.cur = 1 - slot.cur;  // commit the sample computed from the inputs at t_k
  const double t0 = time();
  for (long i = 1; i < samples; ++i) {  // the held inputs, sample by sample
    values_.sensors.time = t0 + static_cast<double>(i) * values_.settings.dt;
    command(*slot.c[slot.cur], values_);
  }
  slot.trial_valid = false;  // the outputs at the new time are computed when read
}

void Instance::invalidate_trial() noexcept {
  eft_.trial_valid = false;
  rpsd_.trial_valid = false;
}

double Instance::get(std::size_t vr) noexcept {
  const Variable& var = vars_[vr];
  if (initialized_ && var.causality == Causality::Output) {
    if (kind() == Kind::Eft && !eft_.trial_valid) evaluate(eft_);
    if (kind() == Kind::Rpsd && !rpsd_.trial_valid) evaluate(rpsd_);
  }
  return var.get(values_);
}

void Instance::set(std::size_t vr, double value) {
  const Variable& var = vars_[vr];
  if (var.causality == Causality::Output) throw Error(var.name + " is an output: it cannot be set");
  if (initialized_ && var.variability == Variability::Fixed)
    throw Error(var.name + " is a fixed parameter: set it before fmi2ExitInitializationMode");
  if (!std::isfinite(value)) throw Error("invalid " + var.name + " = " + std::to_string(value) + ": must be finite");
  const double old = var.get(values_);
  var.set(values_, value);
  if (var.causality == Causality::Input) {
    invalidate_trial();
  } else if (initialized_ && value != old) {  // a tunable parameter of the plant
    try {
      rebuild_plant();
    } catch (...) {
      var.set(values_, old);
      throw;
    }
  }
}

void Instance::rebuild_plant() {
  const Settings& s = values_.settings;
  s.rig.validate();
  Plant p(s.rig, s.mode, s.dt, s.solver);
  p.reset_state(plant_->state(), plant_->time());
  plant_.emplace(std::move(p));
}

std::string Instance::step_plant(long samples) noexcept {
  for (long i = 0; i < samples; ++i) {
    const Status st = plant_->step(values_.command, values_.plant_out);
    if (!st.ok()) {
      char buf[320];
      std::snprintf(buf, sizeof buf, "plant step failed at t = %.9g s: %s (code %d, CVODE flag %d)", st.t,
                    st.message(), static_cast<int>(st.code), st.cvode_flag);
      k_ += i;
      failed_ = true;
      return buf;
    }
  }
  return {};
}

std::string Instance::do_step(double t, double h) noexcept {
  if (!initialized_) return "fmi2DoStep before fmi2ExitInitializationMode";
  const double dt = values_.settings.dt;
  const double now = time();
  if (!(std::fabs(t - now) <= 1e-6 * dt + 1e-12 * std::fabs(now)))
    return format("fmi2DoStep at currentCommunicationPoint = %.17g s, but the FMU is at t = %.17g s", t, now);
  const double samples = h / dt;
  if (!(samples <= static_cast<double>(kMaxSamplesPerStep) + 0.5))  // also NaN; before lround overflows
    return format("invalid communicationStepSize = %.17g s: %.3g controller samples of dt = %.17g s, more than "
                  "the 10000000 one doStep may run (fmu::kMaxSamplesPerStep): split it into shorter steps",
                  h, samples, dt);
  const long n = std::lround(samples);
  if (!(n >= 1 && std::fabs(samples - static_cast<double>(n)) <= 1e-6))
    return format("invalid communicationStepSize = %.17g s: must be a whole number (>= 1) of controller samples "
                  "of dt = %.17g s",
                  h, dt);
  std::string error;
  switch (kind()) {
    case Kind::Plant: error = step_plant(n); break;
    case Kind::Eft: advance(eft_, n); break;
    case Kind::Rpsd: advance(rpsd_, n); break;
  }
  if (error.empty()) k_ += n;
  return error;
}

}  // namespace servohydraulics::fmu
