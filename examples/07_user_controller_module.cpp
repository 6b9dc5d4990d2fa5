// PiLead (pi_lead.hpp), a user's C++ tracking controller, as a Python class: a
// pybind11 module of a few lines.  Its objects are rths.TrackingController objects,
// so run_trial, run_case and the CLI run them in the C++ loop at C++ speed (no Python
// call per sample):
//
//   c++ -O2 -shared -fPIC -std=c++17 $(python -m pybind11 --includes) -I<prefix>/include -I/usr/include/eigen3 \
//       -Iexamples examples/07_user_controller_module.cpp <prefix>/lib/libservohydraulics.a \
//       -o my_controllers$(python3-config --extension-suffix)
//   PYTHONPATH=. servohydraulics rths-benchmark --controller my_controllers:PiLead ...
//
// Build it with the same compiler and pybind11 as the servohydraulics package, so that
// both modules share pybind11's type registry (the base class TrackingController is
// registered by servohydraulics._core, imported first).
#include <pybind11/pybind11.h>

#include "pi_lead.hpp"

namespace py = pybind11;

PYBIND11_MODULE(my_controllers, m) {
  py::module_::import("servohydraulics._core");  // registers rths.TrackingController, the base class
  py::class_<PiLead, rths::TrackingController>(m, "PiLead", "PI + phase lead in C++ (examples/pi_lead.hpp)")
      .def(py::init<>());
}
