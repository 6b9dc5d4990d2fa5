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
  m.def("linearize_dynamics", &linearize, py::arg("dynamics"), py::arg("y0"), py::arg("u0") = 0.0,
        "LinearModel of the plant about state y0 with the command held at u0 (the C++ linearize)");
}
