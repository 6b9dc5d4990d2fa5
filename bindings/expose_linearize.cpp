#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "servohydraulics/linearize.hpp"

namespace py = pybind11;
using namespace servohydraulics;

void expose_linearize(py::module_& m) {
  py::class_<LinearModel>(m, "LinearModel")
      .def_readonly("A", &LinearModel::A)
      .def_readonly("B", &LinearModel::B)
      .def_readonly("C", &LinearModel::C)
      .def_readonly("D", &LinearModel::D)
      .def_readonly("active", &LinearModel::active);
  m.def("linearize_dynamics",
        [](const Dynamics& d, const std::vector<double>& y0, double u0) {
          if (static_cast<int>(y0.size()) != d.num_states())
            throw py::value_error("invalid y0 (length) = " + std::to_string(y0.size()) + ": this plant has " +
                                  std::to_string(d.num_states()) + " states (Dynamics.states)");
          State y{};
          for (std::size_t i = 0; i < y0.size(); ++i) y[i] = y0[i];
          return linearize(d, y, u0);
        },
        py::arg("dynamics"), py::arg("y0"), py::arg("u0") = 0.0,
        "LinearModel of the plant about state y0 with the command held at u0 (the C++ linearize)");
}
