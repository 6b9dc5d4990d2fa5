// A tracking controller written in Python, in the C++ loops.
//
// Two ways in, one protocol (docs/rths-benchmark.md, "Bring your own controller"):
//   * a subclass of _core.rths.TrackingController (the pybind11 trampoline PyTrackingController);
//   * any object with reset() and command(...) (PythonTrackingController wraps it).
// Both call
//   reset() -> None
//   command(desired, desired_velocity, desired_acceleration, measured, measured_force,
//           [measured_velocity=..., measured_pressure=...]) -> float
// with the TrackingInput fields as floats in SI units (m, m/s, m/s^2, m, N; m/s, Pa) and take the
// returned command [m] (anything float() accepts).  The first five are positional; the last two
// are passed as keywords, each only if command() names it (or takes **kwargs), decided once from
// its signature (CommandSignature: when the object is wrapped, or at a subclass's reset()), so a
// five-argument command() keeps working and pays nothing for them.
//
// The loop runs without the GIL (bindings/busy.hpp): each call takes it.  reset() and
// command() are noexcept: a Python exception is stored (with the sample it happened at), the
// controller returns NaN from then on, so the loop stops at that sample (a non-finite command),
// and the binding that ran the loop re-raises it (raise_stored_error) as a RuntimeError naming
// the controller, the method, the sample and its time, caused by the original exception
// (KeyboardInterrupt and the other non-Exception errors are re-raised as they are).
#pragma once

#include <Python.h>

#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "servohydraulics/rths/tracking.hpp"

namespace servohydraulics::bindings {

namespace py = pybind11;

//! Which of TrackingInput's two optional inputs a Python command() takes as keywords: those it
//! names as keyword-accepting parameters, or both when it takes **kwargs (inspect.signature; a
//! callable whose signature cannot be read gets the five positional ones).  Read once (GIL held);
//! call() then passes them by vectorcall with the keyword names built here, no dict per sample.
struct CommandSignature {
  bool measured_velocity = false, measured_pressure = false;
  py::object keyword_names;  //!< tuple of the keywords passed, in that order (None: none)

  static CommandSignature of(const py::handle& command) {
    CommandSignature s;
    try {
      const py::module_ inspect = py::module_::import("inspect");
      const py::object kind = inspect.attr("Parameter");
      const py::object var_keyword = kind.attr("VAR_KEYWORD"), keyword_only = kind.attr("KEYWORD_ONLY"),
                       positional = kind.attr("POSITIONAL_OR_KEYWORD");
      for (const py::handle p : inspect.attr("signature")(command).attr("parameters").attr("values")()) {
        const py::object k = p.attr("kind");
        if (k.equal(var_keyword)) {
          s.measured_velocity = s.measured_pressure = true;
          break;
        }
        if (!k.equal(keyword_only) && !k.equal(positional)) continue;
        const std::string name = py::str(p.attr("name"));
        s.measured_velocity |= name == "measured_velocity";
        s.measured_pressure |= name == "measured_pressure";
      }
    } catch (const py::error_already_set&) {  // no signature (a builtin): the five positional inputs
      s.measured_velocity = s.measured_pressure = false;
    }
    py::list names;
    if (s.measured_velocity) names.append(py::str("measured_velocity"));
    if (s.measured_pressure) names.append(py::str("measured_pressure"));
    s.keyword_names = names.empty() ? py::object(py::none()) : py::object(py::tuple(names));
    return s;
  }

  //! f([self,] the five inputs, and the keywords it takes) (GIL held; throws error_already_set).
  py::object call(const py::handle& f, const rths::TrackingInput& in, const py::handle& self = py::handle()) const {
    const double values[7] = {in.desired,  in.desired_velocity, in.desired_acceleration, in.measured,
                              in.measured_force, in.measured_velocity, in.measured_pressure};
    PyObject* args[8];
    std::size_t n = 0;
    if (self) args[n++] = self.ptr();  // borrowed
    const std::size_t first = n, positional = first + 5;
    bool ok = true;
    auto push = [&](double v) {
      PyObject* x = ok ? PyFloat_FromDouble(v) : nullptr;
      if (x) args[n++] = x;
      else ok = false;
    };
    for (int i = 0; i < 5; ++i) push(values[i]);
    if (measured_velocity) push(values[5]);
    if (measured_pressure) push(values[6]);
    PyObject* r = ok ? PyObject_Vectorcall(f.ptr(), args, positional,
                                           keyword_names && !keyword_names.is_none() ? keyword_names.ptr() : nullptr)
                     : nullptr;
    for (std::size_t i = first; i < n; ++i) Py_DECREF(args[i]);
    if (r == nullptr) throw py::error_already_set();
    return py::reinterpret_steal<py::object>(r);
  }
};

//! The names of the callable methods (written "name()") and the attributes (written "name") that obj lacks,
//! comma-separated ("" when it has them all): the check of every Python object that stands in for a C++ one.
inline std::string missing_members(const py::handle& obj, std::initializer_list<const char*> methods,
                                   std::initializer_list<const char*> attributes = {}) {
  std::string missing;
  for (const char* name : methods)
    if (!py::hasattr(obj, name) || !PyCallable_Check(obj.attr(name).ptr()))
      missing += std::string(missing.empty() ? "" : ", ") + name + "()";
  for (const char* name : attributes)
    if (!py::hasattr(obj, name)) missing += std::string(missing.empty() ? "" : ", ") + name;
  return missing;
}

//! The call discipline shared by the two Python controllers: GIL, error capture, sample count.
class PythonControllerCalls {
 public:
  bool failed() const noexcept { return failed_; }
  long failed_sample() const noexcept { return failed_sample_; }
  const char* failed_method() const noexcept { return method_; }

  //! Re-raises the stored error (GIL held): RuntimeError("<who>.<method>() raised at sample k
  //! (t = k dt s): <Type>: <message>") from the original, with attributes sample and time.
  [[noreturn]] void raise_stored_error(const std::string& who, double dt) const {  // dt NaN: no time
    const py::object exc = error_;
    const bool plain = PyObject_IsInstance(exc.ptr(), PyExc_Exception) == 1;
    const double t = static_cast<double>(failed_sample_) * dt;
    std::string msg;
    if (plain) {  // every Python call before the error indicator is set
      const std::string text = py::str(exc).cast<std::string>();
      const std::string when = std::isfinite(t) ? " (t = " + py::str(py::float_(t)).cast<std::string>() + " s)" : "";
      msg = who + "." + method_ + "() raised at sample " + std::to_string(failed_sample_) + when + ": " +
            py::str(py::type::handle_of(exc).attr("__name__")).cast<std::string>() +
            (text.empty() ? "" : ": " + text);
    }
    PyObject* value = exc.ptr();
    PyObject* type = reinterpret_cast<PyObject*>(Py_TYPE(value));
    Py_INCREF(type);
    Py_INCREF(value);
    PyErr_Restore(type, value, PyException_GetTraceback(value));
    if (!plain) throw py::error_already_set();  // KeyboardInterrupt, SystemExit: as they are
    py::raise_from(PyExc_RuntimeError, msg.c_str());
    py::error_already_set err;
    err.value().attr("sample") = failed_sample_;
    err.value().attr("time") = t;
    throw err;
  }

 protected:
  //! reset() through f (GIL taken here); clears a stored error.
  template <class F>
  void reset_call(F&& f) noexcept {
    py::gil_scoped_acquire gil;
    error_ = py::object();
    failed_ = false;
    failed_sample_ = -1;
    samples_ = 0;
    guarded("reset", f);
  }
  //! command() through f, which returns the Python result; NaN once anything failed.
  template <class F>
  double command_call(F&& f) noexcept {
    if (failed_) return std::numeric_limits<double>::quiet_NaN();
    py::gil_scoped_acquire gil;
    double u = std::numeric_limits<double>::quiet_NaN();
    guarded("command", [&] { u = to_command(f()); });
    ++samples_;
    return failed_ ? std::numeric_limits<double>::quiet_NaN() : u;
  }
  //! A multi-actuator command() through f, which returns the Python result: n floats written to u; NaN in
  //! every u[i] once anything failed (multi_trampoline.hpp).
  template <class F>
  void command_into(F&& f, double* u, std::size_t n) noexcept {
    for (std::size_t i = 0; i < n; ++i) u[i] = std::numeric_limits<double>::quiet_NaN();
    if (failed_) return;
    py::gil_scoped_acquire gil;
    guarded("command", [&] { to_commands(f(), u, n); });
    ++samples_;
    if (failed_)
      for (std::size_t i = 0; i < n; ++i) u[i] = std::numeric_limits<double>::quiet_NaN();
  }

 private:
  static void to_commands(const py::handle& r, double* u, std::size_t n) {
    using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;
    const bool numeric = py::isinstance<py::sequence>(r) || py::isinstance<py::array>(r);
    Arr a = numeric ? Arr::ensure(r) : Arr();
    if (!a || a.ndim() != 1 || static_cast<std::size_t>(a.size()) != n) {
      PyErr_Clear();
      throw py::type_error("command() returned " + py::repr(r).cast<std::string>().substr(0, 200) + ": expected " +
                           std::to_string(n) + " floats, the actuator commands [m]");
    }
    for (std::size_t i = 0; i < n; ++i) u[i] = a.data()[i];
  }
  static double to_command(const py::handle& r) {
    const double u = PyFloat_AsDouble(r.ptr());
    if (u == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw py::type_error("command() returned " + py::repr(r).cast<std::string>() +
                           ": expected a float, the actuator command [m]");
    }
    return u;
  }
  template <class F>
  void guarded(const char* method, F&& f) noexcept {
    try {
      try {
        f();
      } catch (py::error_already_set& e) {
        store(method, e.value());
      } catch (py::builtin_exception& e) {
        e.set_error();
        store(method, py::error_already_set().value());
      } catch (const std::exception& e) {
        PyErr_SetString(PyExc_RuntimeError, e.what());
        store(method, py::error_already_set().value());
      }
    } catch (...) {  // storing failed (out of memory): still stop the run
      PyErr_Clear();
      failed_ = true;
      method_ = method;
      failed_sample_ = samples_;
    }
  }
  void store(const char* method, py::object exc) {
    error_ = std::move(exc);
    failed_ = true;
    method_ = method;
    failed_sample_ = samples_;
  }
  py::object error_;
  bool failed_ = false;
  const char* method_ = "command";
  long samples_ = 0, failed_sample_ = -1;
};

//! Trampoline: a Python subclass of TrackingController overrides reset() and command(...).
//! reset() also caches the class's command function and reads its signature (CommandSignature);
//! command() then calls it with the instance (borrowed: the instance owns this object), skipping
//! pybind11's per-call override lookup.  An override that is not a plain method of the class is
//! looked up on every call.
class PyTrackingController : public rths::TrackingController, public PythonControllerCalls {
 public:
  using rths::TrackingController::TrackingController;
  void reset() noexcept override {
    reset_call([&] {
      command_ = py::object();
      self_ = py::handle();
      override_of("reset")();
      const py::function f = override_of("command");
      signature_ = CommandSignature::of(f);
      if (py::hasattr(f, "__func__") && py::hasattr(f, "__self__")) {
        const py::object self = f.attr("__self__"), func = f.attr("__func__");
        if (py::getattr(py::type::handle_of(self), "command", py::none()).is(func)) {
          command_ = func;
          self_ = self;  // borrowed: it owns this C++ object, so it outlives every call
        }
      }
    });
  }
  double command(const rths::TrackingInput& in) noexcept override {
    return command_call([&] {
      if (command_) return signature_.call(command_, in, self_);  // the class's function, self first
      return signature_.call(override_of("command"), in);
    });
  }

 private:
  py::function override_of(const char* name) const {
    py::function f = py::get_override(static_cast<const rths::TrackingController*>(this), name);
    if (!f) throw py::type_error(std::string("a TrackingController subclass must define ") + name + "()");
    return f;
  }
  py::object command_;
  py::handle self_;
  CommandSignature signature_;
};

//! Any Python object with reset() and command(...) as a TrackingController.
class PythonTrackingController final : public rths::TrackingController, public PythonControllerCalls {
 public:
  explicit PythonTrackingController(py::object obj) : obj_(std::move(obj)) {
    const std::string missing = missing_members(obj_, {"reset", "command"});
    if (!missing.empty())
      throw py::type_error("invalid controller = " + py::repr(obj_).cast<std::string>() +
                           ": not a tracking controller, it lacks " + missing +
                           " (expected reset() and command(desired, desired_velocity, desired_acceleration, "
                           "measured, measured_force, [measured_velocity=..., measured_pressure=...]) -> float)");
    reset_ = obj_.attr("reset");
    command_ = obj_.attr("command");
    signature_ = CommandSignature::of(command_);
  }
  void reset() noexcept override {
    reset_call([&] { reset_(); });
  }
  double command(const rths::TrackingInput& in) noexcept override {
    return command_call([&] { return signature_.call(command_, in); });
  }
  const py::object& object() const noexcept { return obj_; }
  const CommandSignature& signature() const noexcept { return signature_; }

 private:
  py::object obj_, reset_, command_;
  CommandSignature signature_;
};

//! After a run (GIL held): re-raises what a Python controller raised during it, if anything
//! (dt: the loop's sample time [s]; NaN outside a loop: the message then gives no time).
inline void raise_controller_error(const rths::TrackingController& c, double dt) {
  py::object self;
  const PythonControllerCalls* calls = nullptr;
  if (const auto* p = dynamic_cast<const PythonTrackingController*>(&c)) {
    calls = p;
    self = p->object();
  } else if (const auto* q = dynamic_cast<const PyTrackingController*>(&c)) {
    calls = q;
    self = py::cast(static_cast<const rths::TrackingController*>(q), py::return_value_policy::reference);
  }
  if (calls == nullptr || !calls->failed()) return;
  calls->raise_stored_error(py::str(py::type::handle_of(self).attr("__qualname__")).cast<std::string>(), dt);
}

}  // namespace servohydraulics::bindings
