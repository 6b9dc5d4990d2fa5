// The FMU binary as a host tool uses it: dlopen, the fmi2* functions by name.
// - The plant FMU stepped sample by sample equals Plant::step on the same
//   commands, bit for bit (the same core inside).
// - After initialisation, fmi2SetReal / fmi2DoStep / fmi2GetReal allocate
//   nothing, for the plant and both controllers (the counter sees the binary's
//   malloc calls: its static C++ runtime calls glibc's malloc, which this
//   executable interposes).
// - A bad parameter is fmi2Error with a message naming it; two instances in one
//   process do not share state.
// - A hostile host (calls out of order, unknown value references, a NaN
//   command, null pointers, reset after a failure) gets fmi2Error and a
//   message, never a crash; scripts/run.sh sanitize runs this under ASan/UBSan.
#include <dlfcn.h>
#include <unistd.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "fmi2Functions.h"
#include "model.hpp"

#include "alloc_counter.hpp"  // after the headers that pull in mm_malloc.h (Eigen)
#include "check.hpp"

namespace fmu = servohydraulics::fmu;
using servohydraulics::ControlMode;

namespace {

std::string g_log;  // the last message the FMU logged
void logger(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String message, ...) {
  char buf[1024];
  va_list args;
  va_start(args, message);
  std::vsnprintf(buf, sizeof buf, message, args);
  va_end(args);
  g_log = buf;
}
const fmi2CallbackFunctions kCallbacks = {logger, nullptr, nullptr, nullptr, nullptr};

struct Api {
  void* lib = dlopen(SH_FMU_BINARY, RTLD_NOW | RTLD_LOCAL);
  template <class T>
  T* get(const char* name) const { return reinterpret_cast<T*>(dlsym(lib, name)); }
  fmi2InstantiateTYPE* instantiate = get<fmi2InstantiateTYPE>("fmi2Instantiate");
  fmi2SetupExperimentTYPE* setup = get<fmi2SetupExperimentTYPE>("fmi2SetupExperiment");
  fmi2EnterInitializationModeTYPE* enter = get<fmi2EnterInitializationModeTYPE>("fmi2EnterInitializationMode");
  fmi2ExitInitializationModeTYPE* exit = get<fmi2ExitInitializationModeTYPE>("fmi2ExitInitializationMode");
  fmi2SetRealTYPE* set_real = get<fmi2SetRealTYPE>("fmi2SetReal");
  fmi2GetRealTYPE* get_real = get<fmi2GetRealTYPE>("fmi2GetReal");
  fmi2DoStepTYPE* do_step = get<fmi2DoStepTYPE>("fmi2DoStep");
  fmi2FreeInstanceTYPE* free_instance = get<fmi2FreeInstanceTYPE>("fmi2FreeInstance");
  fmi2TerminateTYPE* terminate = get<fmi2TerminateTYPE>("fmi2Terminate");
  fmi2ResetTYPE* reset = get<fmi2ResetTYPE>("fmi2Reset");
  fmi2GetIntegerTYPE* get_integer = get<fmi2GetIntegerTYPE>("fmi2GetInteger");
  fmi2SetBooleanTYPE* set_boolean = get<fmi2SetBooleanTYPE>("fmi2SetBoolean");
  fmi2GetStringTYPE* get_string = get<fmi2GetStringTYPE>("fmi2GetString");
  fmi2GetRealStatusTYPE* get_real_status = get<fmi2GetRealStatusTYPE>("fmi2GetRealStatus");
  fmi2GetFMUstateTYPE* get_state = get<fmi2GetFMUstateTYPE>("fmi2GetFMUstate");
};

//! A resources directory for an FMU of this kind over the default rig.
std::string resources(const char* kind, const char* mode) {
  char tmpl[] = "/tmp/sh_fmu_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  std::ofstream(dir + "/fmu.toml") << "kind = \"" << kind << "\"\nmode = \"" << mode << "\"\nguid = \"{test}\"\n";
  std::ofstream(dir + "/rig.toml") << "# the core's default rig\n";
  return dir;
}

fmi2ValueReference vr(fmu::Kind kind, ControlMode mode, const char* name) {
  const int i = fmu::find(fmu::variables(kind, mode), name);
  CHECK(i >= 0);
  return static_cast<fmi2ValueReference>(i);
}

fmi2Component start(const Api& api, const std::string& dir, const char* name) {
  const std::string uri = "file://" + dir;
  sh_test::AllocationCounter counter;
  fmi2Component c = api.instantiate(name, fmi2CoSimulation, "{test}", uri.c_str(), &kCallbacks, fmi2False, fmi2False);
  // the counter sees the binary's allocations (none to see under ASan, which owns malloc)
  // The counter sees the binary's allocations (so its zeros below mean something); under ASan, which
  // owns malloc, it counts nothing.
  CHECK(!sh_test::kCountingAllocations || counter.count() > 10);
  CHECK(c != nullptr);
  CHECK(api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
  CHECK(api.enter(c) == fmi2OK);
  CHECK(api.exit(c) == fmi2OK);
  return c;
}

void plant_equals_core(const Api& api) {
  const double dt = 5e-4;
  const std::string dir = resources("plant", "displacement");
  fmi2Component a = start(api, dir, "a"), b = start(api, dir, "b");
  const fmi2ValueReference u_vr = vr(fmu::Kind::Plant, ControlMode::Displacement, "command");
  const fmi2ValueReference out_vr[2] = {vr(fmu::Kind::Plant, ControlMode::Displacement, "displacement"),
                                        vr(fmu::Kind::Plant, ControlMode::Displacement, "force")};
  servohydraulics::Plant plant(servohydraulics::Rig{}, ControlMode::Displacement, dt);
  plant.reset(0.0, 0.0);
  servohydraulics::Output out;
  long allocations = 0, mismatches = 0;
  for (int k = 0; k < 2000; ++k) {
    const double u = 0.01 * std::sin(2 * M_PI * 2.0 * k * dt), zero = 0.0;
    plant.step(u, out);
    double y[2], yb[2];
    sh_test::AllocationCounter counter;
    api.set_real(a, &u_vr, 1, &u);
    api.set_real(b, &u_vr, 1, &zero);  // the other instance holds 0
    const fmi2Status st = api.do_step(a, k * dt, dt, fmi2True);
    api.do_step(b, k * dt, dt, fmi2True);
    api.get_real(a, out_vr, 2, y);
    api.get_real(b, out_vr, 2, yb);
    allocations += counter.count();
    CHECK(st == fmi2OK);
    if (y[0] != out.displacement || y[1] != out.force || yb[0] != 0.0) ++mismatches;
  }
  CHECK(mismatches == 0);
  CHECK(allocations == 0);
  api.free_instance(a);
  api.free_instance(b);
}

//! A controller stepped with sensor inputs and a_g: no allocation, finite outputs.
void controller_allocates_nothing(const Api& api, fmu::Kind kind, const char* name, const char* mode) {
  const std::string dir = resources(name, mode);
  fmi2Component c = start(api, dir, name);
  const ControlMode m = fmu::parse_mode(mode);
  const fmi2ValueReference in[3] = {vr(kind, m, "ground_acceleration"), vr(kind, m, "sensors.velocity"),
                                    vr(kind, m, "sensors.displacement")};
  const fmi2ValueReference cmd = vr(kind, m, "command");
  long allocations = 0, bad = 0;
  for (int k = 0; k < 1000; ++k) {
    const double t = k * 5e-4, x[3] = {std::sin(10 * t), 0.01 * std::cos(10 * t), 0.001 * std::sin(10 * t)};
    double u = NAN;
    sh_test::AllocationCounter counter;
    api.set_real(c, in, 3, x);
    api.get_real(c, &cmd, 1, &u);
    const fmi2Status st = api.do_step(c, t, 5e-4, fmi2True);
    allocations += counter.count();
    if (st != fmi2OK || !std::isfinite(u)) ++bad;
  }
  CHECK(bad == 0);
  CHECK(allocations == 0);
  api.free_instance(c);
}

void bad_parameter_is_an_error(const Api& api) {
  const std::string dir = resources("plant", "force");
  fmi2Component c = api.instantiate("bad", fmi2CoSimulation, "{test}", ("file://" + dir).c_str(), &kCallbacks,
                                    fmi2False, fmi2False);
  const fmi2ValueReference k = vr(fmu::Kind::Plant, ControlMode::Force, "structure.k");
  const double minus = -5.0;
  CHECK(api.enter(c) == fmi2OK);
  CHECK(api.set_real(c, &k, 1, &minus) == fmi2OK);
  CHECK(api.exit(c) == fmi2Error);
  CHECK(g_log.find("k = -5") != std::string::npos);
  api.free_instance(c);
  // a wrong GUID and a missing resource directory: no instance, a message
  CHECK(api.instantiate("x", fmi2CoSimulation, "{other}", ("file://" + dir).c_str(), &kCallbacks, fmi2False,
                        fmi2False) == nullptr);
  CHECK(g_log.find("GUID") != std::string::npos);
  CHECK(api.instantiate("x", fmi2CoSimulation, "{test}", "file:///nonexistent/resources", &kCallbacks, fmi2False,
                        fmi2False) == nullptr);
  CHECK(g_log.find("cannot read") != std::string::npos);
}

//! Issue 26: a non-finite start time is refused; a doStep of more than kMaxSamplesPerStep samples
//! returns at once with fmi2Error and a message; dt below kMinDt is refused at initialisation; a
//! plant started at a Unix time (1.7e9 s) gives the outputs of one started at 0, bit for bit.
void timing_limits(const Api& api) {
  const std::string dir = resources("plant", "displacement");
  const std::string uri = "file://" + dir;
  fmi2Component c = api.instantiate("t", fmi2CoSimulation, "{test}", uri.c_str(), &kCallbacks, fmi2False, fmi2False);
  CHECK(api.setup(c, fmi2False, 0.0, NAN, fmi2False, 0.0) == fmi2Error);
  CHECK(g_log.find("invalid startTime = nan") != std::string::npos);
  CHECK(api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
  CHECK(api.enter(c) == fmi2OK);
  const fmi2ValueReference dt_vr = vr(fmu::Kind::Plant, ControlMode::Displacement, "dt");
  const double tiny = 5e-16, dt = 5e-4;
  CHECK(api.set_real(c, &dt_vr, 1, &tiny) == fmi2OK);
  CHECK(api.exit(c) == fmi2Error);
  CHECK(g_log.find("invalid dt = 5e-16") != std::string::npos);
  api.free_instance(c);

  fmi2Component a = start(api, dir, "a");
  const double huge = 2.0 * static_cast<double>(fmu::kMaxSamplesPerStep) * dt;
  CHECK(api.do_step(a, 0.0, huge, fmi2True) == fmi2Error);
  CHECK(g_log.find("more than the 10000000") != std::string::npos);
  CHECK(api.do_step(a, 0.0, INFINITY, fmi2True) == fmi2Error);
  CHECK(api.do_step(a, 0.0, dt, fmi2True) == fmi2OK);  // a bad step size can be retried

  // the same commands from t = 0 and t = 1.7e9 s: the same outputs
  fmi2Component b = api.instantiate("b", fmi2CoSimulation, "{test}", uri.c_str(), &kCallbacks, fmi2False, fmi2False);
  const double t0 = 1.7e9;
  CHECK(api.setup(b, fmi2False, 0.0, t0, fmi2False, 0.0) == fmi2OK);
  CHECK(api.enter(b) == fmi2OK);
  CHECK(api.exit(b) == fmi2OK);
  const fmi2ValueReference u_vr = vr(fmu::Kind::Plant, ControlMode::Displacement, "command");
  const fmi2ValueReference x_vr = vr(fmu::Kind::Plant, ControlMode::Displacement, "force");
  fmi2Component z = start(api, dir, "z");
  long differ = 0;
  for (int k = 0; k < 1000; ++k) {
    const double u = 0.002 * std::sin(2 * M_PI * 5.0 * k * dt);
    double yb = 0.0, yz = 0.0;
    api.set_real(b, &u_vr, 1, &u);
    api.set_real(z, &u_vr, 1, &u);
    CHECK(api.do_step(b, t0 + k * dt, dt, fmi2True) == fmi2OK);
    CHECK(api.do_step(z, k * dt, dt, fmi2True) == fmi2OK);
    api.get_real(b, &x_vr, 1, &yb);
    api.get_real(z, &x_vr, 1, &yz);
    if (yb != yz) ++differ;
  }
  CHECK(differ == 0);
  for (fmi2Component x : {a, b, z}) api.free_instance(x);
}

//! The calls of a careless or hostile host: each is fmi2Error (or a null instance) with a message,
//! nothing crashes or reads out of bounds, and fmi2Reset brings a failed plant back.
void hostile_host(const Api& api) {
  const std::string dir = resources("plant", "displacement");
  const std::string uri = "file://" + dir;
  const auto mode = ControlMode::Displacement;
  CHECK(api.instantiate("me", fmi2ModelExchange, "{test}", uri.c_str(), &kCallbacks, fmi2False, fmi2False) ==
        nullptr);
  CHECK(g_log.find("co-simulation only") != std::string::npos);
  CHECK(api.instantiate("x", fmi2CoSimulation, nullptr, uri.c_str(), &kCallbacks, fmi2False, fmi2False) == nullptr);
  CHECK(api.instantiate("x", fmi2CoSimulation, "{test}", nullptr, nullptr, fmi2False, fmi2False) == nullptr);
  // every entry point with a null instance
  double y = 0.0;
  const fmi2ValueReference x_vr = vr(fmu::Kind::Plant, mode, "displacement");
  CHECK(api.do_step(nullptr, 0.0, 5e-4, fmi2True) == fmi2Error);
  CHECK(api.get_real(nullptr, &x_vr, 1, &y) == fmi2Error);
  CHECK(api.setup(nullptr, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2Error);
  api.free_instance(nullptr);

  // a null instance name, and calls out of order
  fmi2Component c = api.instantiate(nullptr, fmi2CoSimulation, "{test}", uri.c_str(), &kCallbacks, fmi2False, fmi2False);
  CHECK(c != nullptr);
  CHECK(api.do_step(c, 0.0, 5e-4, fmi2True) == fmi2Error);
  CHECK(api.exit(c) == fmi2Error);
  CHECK(api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
  CHECK(api.enter(c) == fmi2OK);
  CHECK(api.enter(c) == fmi2Error);
  CHECK(api.exit(c) == fmi2OK);
  // unknown value references and wrong types: an error naming the reference, nothing read or written
  const fmi2ValueReference far[2] = {x_vr, 4000000000u};
  double two[2] = {1.0, 2.0};
  CHECK(api.get_real(c, far, 2, two) == fmi2Error);
  CHECK(g_log.find("unknown value reference 4000000000") != std::string::npos);
  CHECK(api.set_real(c, far, 2, two) == fmi2Error);
  fmi2Integer i = 0;
  CHECK(api.get_integer(c, &x_vr, 1, &i) == fmi2Error);
  CHECK(g_log.find("is of type") != std::string::npos);
  const fmi2Boolean on = fmi2True;
  CHECK(api.set_boolean(c, &x_vr, 1, &on) == fmi2Error);
  fmi2String str = nullptr;
  CHECK(api.get_string(c, &x_vr, 1, &str) == fmi2Error);
  CHECK(api.get_real(c, far, 0, nullptr) == fmi2OK);  // nothing asked, nothing read
  CHECK(api.get_real_status(c, fmi2LastSuccessfulTime, nullptr) == fmi2Error);
  fmi2FMUstate state = nullptr;
  CHECK(api.get_state(c, &state) == fmi2Error);
  // bad communication points and step sizes can be retried; a NaN command fails the plant
  CHECK(api.do_step(c, 1.0, 5e-4, fmi2True) == fmi2Error);
  CHECK(api.do_step(c, 0.0, -5e-4, fmi2True) == fmi2Error);
  CHECK(api.do_step(c, NAN, 5e-4, fmi2True) == fmi2Error);
  CHECK(api.do_step(c, 0.0, 1.5 * 5e-4, fmi2True) == fmi2Error);
  CHECK(api.do_step(c, 0.0, 5e-4, fmi2True) == fmi2OK);
  const fmi2ValueReference u_vr = vr(fmu::Kind::Plant, mode, "command");
  const double nan = NAN, huge = 1e300, fine = 1e-3;
  CHECK(api.set_real(c, &u_vr, 1, &nan) == fmi2Error);  // refused: the command keeps its value
  CHECK(g_log.find("command") != std::string::npos);
  CHECK(api.do_step(c, 5e-4, 5e-4, fmi2True) == fmi2OK);
  // a command beyond any stroke saturates or fails the plant, never crashes; after a failure only
  // fmi2Reset goes on
  CHECK(api.set_real(c, &u_vr, 1, &huge) == fmi2OK);
  const fmi2Status big = api.do_step(c, 1e-3, 200 * 5e-4, fmi2True);
  CHECK(big == fmi2OK || big == fmi2Error);
  CHECK(api.get_real(c, &x_vr, 1, &y) == fmi2OK);
  if (big == fmi2Error) {
    CHECK(api.do_step(c, 1e-3, 5e-4, fmi2True) == fmi2Error);
    CHECK(api.set_real(c, &u_vr, 1, &fine) == fmi2Error);
  }
  // fmi2Reset: a fresh start
  CHECK(api.reset(c) == fmi2OK);
  CHECK(api.setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK);
  CHECK(api.enter(c) == fmi2OK);
  CHECK(api.exit(c) == fmi2OK);
  CHECK(api.set_real(c, &u_vr, 1, &fine) == fmi2OK);
  CHECK(api.do_step(c, 0.0, 20 * 5e-4, fmi2True) == fmi2OK);
  CHECK(api.get_real(c, &x_vr, 1, &y) == fmi2OK && std::isfinite(y) && y > 0.0);
  CHECK(api.terminate(c) == fmi2OK);
  CHECK(api.do_step(c, 0.0, 5e-4, fmi2True) == fmi2Error);
  CHECK(api.set_real(c, &u_vr, 1, &fine) == fmi2Error);
  api.free_instance(c);
}

}  // namespace

int main() {
  Api api;
  CHECK(api.lib != nullptr);
  if (!api.lib) {
    std::fprintf(stderr, "dlopen %s: %s\n", SH_FMU_BINARY, dlerror());
    return sh_test::report("test_fmu_binary");
  }
  plant_equals_core(api);
  controller_allocates_nothing(api, fmu::Kind::Eft, "eft", "force");
  controller_allocates_nothing(api, fmu::Kind::Rpsd, "rpsd", "displacement");
  bad_parameter_is_an_error(api);
  timing_limits(api);
  hostile_host(api);
  return sh_test::report("test_fmu_binary");
}
