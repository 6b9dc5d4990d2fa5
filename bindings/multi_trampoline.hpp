// The multi-actuator seam (servohydraulics/multi_actuator.hpp) written in Python, in the C++ loop.
//
// A multi-actuator controller, two ways in, one protocol (docs/marths-benchmark.md, "Bring your own"):
//   * a subclass of _core.MultiTrackingController (constructed with its number of actuators,
//     super().__init__(2)), the trampoline PyMultiTrackingController;
//   * any object with reset() and command(...) (PythonMultiController wraps it).
// Both call
//   reset() -> None
//   command(desired, measured, [desired_velocity=..., desired_acceleration=...]) -> N floats [m]
// with NumPy arrays of N floats (SI: m, m/s, m/s^2); the two rates are passed as keywords only when
// command() names them (or takes **kwargs).  Errors are stored with their sample and re-raised after the run
// (tracking_trampoline.hpp's PythonControllerCalls), the loop stopping at that sample (NaN commands).
//
// A plant written in Python (PythonMultiActuatorSystem): any object with attributes actuators (int) and dt
// [s], and methods reset(), displacements() -> N floats [m] and step(u) (u: N commands [m] as a NumPy array,
// held over one dt; its return value is ignored).  An exception stops the loop (step() returns NonFinite) and is re-raised
// by the binding that ran it.  A C++ MultiActuatorSystem (e.g. a rig of nonlinear actuators) bound as a
// subclass of _core.MultiActuatorSystem runs without the GIL.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "servohydraulics/multi_actuator.hpp"
#include "tracking_trampoline.hpp"

namespace servohydraulics::bindings {

namespace py = pybind11;

//! Whether a Python command() takes the target rates as keywords (names them, or **kwargs).
inline bool takes_rates(const py::handle& command) {
  try {
    const py::module_ inspect = py::module_::import("inspect");
    const py::object kind = inspect.attr("Parameter");
    bool v = false, a = false;
    for (const py::handle p : inspect.attr("signature")(command).attr("parameters").attr("values")()) {
      if (p.attr("kind").equal(kind.attr("VAR_KEYWORD"))) return true;
      const std::string name = py::str(p.attr("name"));
      v |= name == "desired_velocity";
      a |= name == "desired_acceleration";
    }
    return v && a;
  } catch (const py::error_already_set&) {
    return false;
  }
}

inline py::array_t<double> copy_array(const double* p, std::size_t n) {
  py::array_t<double> a(static_cast<py::ssize_t>(n));
  for (std::size_t i = 0; i < n; ++i) a.mutable_data()[i] = p ? p[i] : 0.0;
  return a;
}

//! command(...) of a Python controller with the loop's input (GIL held; throws error_already_set).
inline py::object call_multi(const py::handle& f, const MultiTrackingInput& in, bool rates) {
  const py::array_t<double> d = copy_array(in.desired, in.n), m = copy_array(in.measured, in.n);
  if (!rates) return f(d, m);
  return f(d, m, py::arg("desired_velocity") = copy_array(in.desired_velocity, in.n),
           py::arg("desired_acceleration") = copy_array(in.desired_acceleration, in.n));
}

//! Trampoline: a Python subclass of MultiTrackingController overrides reset() and command(...).
class PyMultiTrackingController : public MultiTrackingController, public PythonControllerCalls {
 public:
  explicit PyMultiTrackingController(std::size_t actuators) : n_(actuators) {
    if (actuators < 1 || actuators > 8)
      throw py::value_error("invalid actuators = " + std::to_string(actuators) + ": 1 to 8");
  }
  std::size_t actuators() const noexcept override { return n_; }
  void reset() noexcept override {
    reset_call([&] {
      override_of("reset")();
      rates_ = takes_rates(override_of("command"));
    });
  }
  void command(const MultiTrackingInput& in, double* u) noexcept override {
    command_into([&] { return call_multi(override_of("command"), in, rates_); }, u, n_);
  }

 private:
  py::function override_of(const char* name) const {
    py::function f = py::get_override(static_cast<const MultiTrackingController*>(this), name);
    if (!f) throw py::type_error(std::string("a MultiTrackingController subclass must define ") + name + "()");
    return f;
  }
  std::size_t n_;
  bool rates_ = false;
};

//! Any Python object with reset() and command(...) as a MultiTrackingController of n actuators.
class PythonMultiController final : public MultiTrackingController, public PythonControllerCalls {
 public:
  PythonMultiController(py::object obj, std::size_t actuators) : obj_(std::move(obj)), n_(actuators) {
    if (actuators < 1 || actuators > 8)
      throw py::value_error("invalid actuators = " + std::to_string(actuators) + ": 1 to 8");
    const std::string missing = missing_members(obj_, {"reset", "command"});
    if (!missing.empty())
      throw py::type_error("invalid controller = " + py::repr(obj_).cast<std::string>() +
                           ": not a multi-actuator controller, it lacks " + missing +
                           " (expected reset() and command(desired, measured, [desired_velocity=..., "
                           "desired_acceleration=...]) -> N commands [m])");
    reset_ = obj_.attr("reset");
    command_ = obj_.attr("command");
    rates_ = takes_rates(command_);
  }
  std::size_t actuators() const noexcept override { return n_; }
  void reset() noexcept override {
    reset_call([&] { reset_(); });
  }
  void command(const MultiTrackingInput& in, double* u) noexcept override {
    command_into([&] { return call_multi(command_, in, rates_); }, u, n_);
  }
  const py::object& object() const noexcept { return obj_; }

 private:
  py::object obj_, reset_, command_;
  std::size_t n_;
  bool rates_ = false;
};

//! After a run (GIL held): re-raises what a Python multi-actuator controller raised during it.
inline void raise_multi_controller_error(const MultiTrackingController& c, double dt) {
  if (const auto* p = dynamic_cast<const PythonMultiController*>(&c); p && p->failed())
    p->raise_stored_error(py::str(py::type::handle_of(p->object()).attr("__qualname__")).cast<std::string>(), dt);
  if (const auto* q = dynamic_cast<const PyMultiTrackingController*>(&c); q && q->failed()) {
    const py::object self =
        py::cast(static_cast<const MultiTrackingController*>(q), py::return_value_policy::reference);
    q->raise_stored_error(py::str(py::type::handle_of(self).attr("__qualname__")).cast<std::string>(), dt);
  }
}

//! A Python object as the loop's MultiActuatorSystem (each call takes the GIL).
class PythonMultiActuatorSystem final : public MultiActuatorSystem {
 public:
  explicit PythonMultiActuatorSystem(py::object obj) : obj_(std::move(obj)) {
    const std::string missing = missing_members(obj_, {"reset", "displacements", "step"}, {"actuators", "dt"});
    if (!missing.empty())
      throw py::type_error("invalid plant = " + py::repr(obj_).cast<std::string>() +
                           ": not a multi-actuator system, it lacks " + missing);
    n_ = obj_.attr("actuators").cast<std::size_t>();
    dt_ = obj_.attr("dt").cast<double>();
    if (n_ < 1 || n_ > 8) throw py::value_error("invalid plant.actuators = " + std::to_string(n_) + ": 1 to 8");
    if (!(std::isfinite(dt_) && dt_ > 0.0))
      throw py::value_error("invalid plant.dt = " + std::to_string(dt_) + ": finite and > 0 [s]");
  }
  std::size_t actuators() const noexcept override { return n_; }
  double dt() const noexcept override { return dt_; }
  void reset() noexcept override {
    error_.clear();
    call([&] {
      obj_.attr("reset")();
      pull();
    });
  }
  void displacements(double* y) const noexcept override {
    for (std::size_t i = 0; i < n_; ++i) y[i] = y_[i];
  }
  Status step(const double* u) noexcept override {
    Status s;
    call([&] {
      obj_.attr("step")(copy_array(u, n_));  // its return value is not read: an exception is a failure
      pull();
    });
    if (!error_.empty()) s.code = Status::NonFinite;
    return s;
  }
  const std::string& error() const noexcept { return error_; }
  const py::object& object() const noexcept { return obj_; }

 private:
  template <class F>
  void call(F&& f) noexcept {
    if (!error_.empty()) return;
    py::gil_scoped_acquire gil;
    try {
      f();
    } catch (py::error_already_set& e) {
      try {
        error_ = py::str(e.type().attr("__name__")).cast<std::string>() + ": " + py::str(e.value()).cast<std::string>();
      } catch (...) {
        error_ = "a Python exception";
      }
    } catch (const std::exception& e) {
      error_ = e.what();
    }
    if (!error_.empty())
      for (double& v : y_) v = std::nan("");
  }
  void pull() {
    using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;
    const Arr a = Arr::ensure(obj_.attr("displacements")());
    if (!a || a.ndim() != 1 || static_cast<std::size_t>(a.size()) != n_) {
      PyErr_Clear();
      throw py::type_error("displacements() must return " + std::to_string(n_) + " floats [m]");
    }
    for (std::size_t i = 0; i < n_; ++i) y_[i] = a.data()[i];
  }
  py::object obj_;
  std::size_t n_ = 0;
  double dt_ = 0.0;
  double y_[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  std::string error_;
};

}  // namespace servohydraulics::bindings
