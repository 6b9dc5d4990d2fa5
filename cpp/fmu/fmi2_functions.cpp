// The FMI 2.0 co-simulation interface over fmu::Instance.  The declarations
// are the standard's own headers (fmi2Functions.h, found at build time in the
// fmpy package, or SH_FMI2_INCLUDE_DIR); the shared library exports these
// fmi2* functions and nothing else (fmi2.map).
//
// Every entry point catches every exception: an error is an fmi2 status with a
// message through the logger callback, never a crash.
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>

#include "fmi2Functions.h"
#include "instance.hpp"
#include "resources.hpp"

namespace {

using servohydraulics::fmu::Causality;
using servohydraulics::fmu::Instance;
using servohydraulics::fmu::Type;

enum class Phase { Instantiated, Initialization, Step, Terminated, Error };

struct Component {
  std::string name;
  fmi2CallbackFunctions callbacks{};
  bool logging = false;
  Phase phase = Phase::Instantiated;
  double start_time = 0.0;
  std::unique_ptr<Instance> instance;
};

// The logger takes a printf format: pass the message with every '%' doubled.
void log_to(const fmi2CallbackFunctions* cb, fmi2String instance, fmi2Status status, const char* category,
            const std::string& message) {
  if (!cb || !cb->logger) return;
  std::string text;
  for (char ch : message) text += ch == '%' ? std::string("%%") : std::string(1, ch);
  cb->logger(cb->componentEnvironment, instance ? instance : "", status, category, text.c_str());
}

fmi2Status fail(Component* c, const char* function, const std::string& why, fmi2Status status = fmi2Error) {
  log_to(&c->callbacks, c->name.c_str(), status, "logStatusError", std::string(function) + ": " + why);
  return status;
}

//! Runs f, turning any exception into a logged fmi2Error (fmi2Fatal when out of memory).
template <class F>
fmi2Status guarded(fmi2Component comp, const char* function, F&& f) {
  if (!comp) return fmi2Error;
  Component* c = static_cast<Component*>(comp);
  try {
    return f(*c);
  } catch (const std::bad_alloc&) {
    c->phase = Phase::Error;
    return fail(c, function, "out of memory", fmi2Fatal);
  } catch (const std::exception& e) {
    return fail(c, function, e.what());
  } catch (...) {
    return fail(c, function, "unknown error");
  }
}

//! Checks each value reference and its type; returns the first problem, or "".
std::string check_refs(const Instance& in, const fmi2ValueReference vr[], size_t n, Type t1, Type t2) {
  const auto& vars = in.variables();
  for (size_t i = 0; i < n; ++i) {
    if (vr[i] >= vars.size()) return "unknown value reference " + std::to_string(vr[i]);
    const Type t = vars[vr[i]].type;
    if (t != t1 && t != t2)
      return vars[vr[i]].name + " (value reference " + std::to_string(vr[i]) + ") is of type " +
             servohydraulics::fmu::to_string(t);
  }
  return {};
}

template <class T>
fmi2Status get_values(fmi2Component comp, const char* fn, const fmi2ValueReference vr[], size_t n, T value[],
                      Type t1, Type t2) {
  return guarded(comp, fn, [&](Component& c) {
    const std::string bad = check_refs(*c.instance, vr, n, t1, t2);
    if (!bad.empty()) return fail(&c, fn, bad);
    for (size_t i = 0; i < n; ++i) value[i] = static_cast<T>(c.instance->get(vr[i]));
    return fmi2OK;
  });
}

template <class T>
fmi2Status set_values(fmi2Component comp, const char* fn, const fmi2ValueReference vr[], size_t n, const T value[],
                      Type t1, Type t2) {
  return guarded(comp, fn, [&](Component& c) {
    if (c.phase == Phase::Terminated || c.phase == Phase::Error)
      return fail(&c, fn, "not allowed after fmi2Terminate or an error (call fmi2Reset)");
    const std::string bad = check_refs(*c.instance, vr, n, t1, t2);
    if (!bad.empty()) return fail(&c, fn, bad);
    for (size_t i = 0; i < n; ++i) c.instance->set(vr[i], static_cast<double>(value[i]));
    return fmi2OK;
  });
}

fmi2Status unsupported(fmi2Component comp, const char* fn) {
  return guarded(comp, fn, [&](Component& c) { return fail(&c, fn, "not supported by this FMU"); });
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t, const fmi2String[]) {
  return guarded(comp, "fmi2SetDebugLogging", [&](Component& c) {
    c.logging = on != fmi2False;
    return fmi2OK;
  });
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions* callbacks, fmi2Boolean, fmi2Boolean logging) {
  try {
    if (type != fmi2CoSimulation) throw servohydraulics::Error("this FMU is for co-simulation only");
    if (!guid || !resources) throw servohydraulics::Error("fmuGUID and fmuResourceLocation are required");
    auto c = std::make_unique<Component>();
    c->name = name ? name : "";
    if (callbacks) c->callbacks = *callbacks;
    c->logging = logging != fmi2False;
    c->instance = std::make_unique<Instance>(servohydraulics::fmu::path_from_uri(resources), guid);
    return c.release();
  } catch (const std::exception& e) {
    log_to(callbacks, name, fmi2Error, "logStatusError", std::string("fmi2Instantiate: ") + e.what());
  } catch (...) {
    log_to(callbacks, name, fmi2Error, "logStatusError", "fmi2Instantiate: unknown error");
  }
  return nullptr;
}

void fmi2FreeInstance(fmi2Component comp) { delete static_cast<Component*>(comp); }

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean, fmi2Real, fmi2Real start, fmi2Boolean, fmi2Real) {
  return guarded(comp, "fmi2SetupExperiment", [&](Component& c) {
    if (c.phase != Phase::Instantiated) return fail(&c, "fmi2SetupExperiment", "only after fmi2Instantiate");
    if (!std::isfinite(start))
      return fail(&c, "fmi2SetupExperiment", "invalid startTime = " + std::to_string(start) + ": must be finite [s]");
    c.start_time = start;
    return fmi2OK;
  });
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
  return guarded(comp, "fmi2EnterInitializationMode", [&](Component& c) {
    if (c.phase != Phase::Instantiated) return fail(&c, "fmi2EnterInitializationMode", "only after fmi2Instantiate");
    c.phase = Phase::Initialization;
    return fmi2OK;
  });
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
  return guarded(comp, "fmi2ExitInitializationMode", [&](Component& c) {
    if (c.phase != Phase::Initialization)
      return fail(&c, "fmi2ExitInitializationMode", "only after fmi2EnterInitializationMode");
    c.instance->initialize(c.start_time);  // throws Error naming a bad parameter
    c.phase = Phase::Step;
    return fmi2OK;
  });
}

fmi2Status fmi2Terminate(fmi2Component comp) {
  return guarded(comp, "fmi2Terminate", [&](Component& c) {
    c.phase = Phase::Terminated;
    return fmi2OK;
  });
}

fmi2Status fmi2Reset(fmi2Component comp) {
  return guarded(comp, "fmi2Reset", [&](Component& c) {
    c.instance->reset();
    c.phase = Phase::Instantiated;
    c.start_time = 0.0;
    return fmi2OK;
  });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
  return get_values(c, "fmi2GetReal", vr, n, value, Type::Real, Type::Real);
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
  return get_values(c, "fmi2GetInteger", vr, n, value, Type::Integer, Type::Enumeration);
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
  return get_values(c, "fmi2GetBoolean", vr, n, value, Type::Boolean, Type::Boolean);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference[], size_t n, fmi2String[]) {
  return n == 0 ? fmi2OK : unsupported(c, "fmi2GetString (this FMU has no String variables)");
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
  return set_values(c, "fmi2SetReal", vr, n, value, Type::Real, Type::Real);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
  return set_values(c, "fmi2SetInteger", vr, n, value, Type::Integer, Type::Enumeration);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
  return set_values(c, "fmi2SetBoolean", vr, n, value, Type::Boolean, Type::Boolean);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference[], size_t n, const fmi2String[]) {
  return n == 0 ? fmi2OK : unsupported(c, "fmi2SetString (this FMU has no String variables)");
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate*) { return unsupported(c, "fmi2GetFMUstate"); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate) { return unsupported(c, "fmi2SetFMUstate"); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate*) { return unsupported(c, "fmi2FreeFMUstate"); }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate, size_t*) {
  return unsupported(c, "fmi2SerializedFMUstateSize");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate, fmi2Byte[], size_t) {
  return unsupported(c, "fmi2SerializeFMUstate");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte[], size_t, fmi2FMUstate*) {
  return unsupported(c, "fmi2DeSerializeFMUstate");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference[], size_t,
                                        const fmi2ValueReference[], size_t, const fmi2Real[], fmi2Real[]) {
  return unsupported(c, "fmi2GetDirectionalDerivative");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                       const fmi2Real[]) {
  return unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                        fmi2Real[]) {
  return unsupported(c, "fmi2GetRealOutputDerivatives");
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean) {
  return guarded(comp, "fmi2DoStep", [&](Component& c) {
    if (c.phase != Phase::Step) return fail(&c, "fmi2DoStep", "only after fmi2ExitInitializationMode and before "
                                                              "fmi2Terminate, and not after an error (fmi2Reset)");
    const std::string error = c.instance->do_step(t, h);
    if (error.empty()) return fmi2OK;
    if (c.instance->failed()) c.phase = Phase::Error;  // the plant cannot go on; a bad t or h can be retried
    return fail(&c, "fmi2DoStep", error);
  });
}
fmi2Status fmi2CancelStep(fmi2Component c) { return unsupported(c, "fmi2CancelStep (doStep never returns pending)"); }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind, fmi2Status*) {
  return unsupported(c, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2Real* value) {
  return guarded(comp, "fmi2GetRealStatus", [&](Component& c) {
    if (kind != fmi2LastSuccessfulTime || !value) return fail(&c, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime");
    *value = c.instance->time();
    return fmi2OK;
  });
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind, fmi2Integer*) {
  return unsupported(c, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind, fmi2Boolean*) {
  return unsupported(c, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind, fmi2String*) {
  return unsupported(c, "fmi2GetStringStatus");
}

}  // extern "C"
