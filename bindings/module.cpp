// pybind11 module servohydraulics._core: one expose_<topic>.cpp per core header.
#include <pybind11/pybind11.h>

#include "protocol.hpp"
#include "servohydraulics/error.hpp"
#include "servohydraulics/plant.hpp"

namespace py = pybind11;

void expose_rig(py::module_& m);
void expose_plant(py::module_& m);
void expose_record(py::module_& m);
void expose_linearize(py::module_& m);
void expose_compensators(py::module_& m);
void expose_loops(py::module_& m);

PYBIND11_MODULE(_core, m) {
  m.doc() = "C++ core of servohydraulics (SUNDIALS CVODE, Eigen)";
  // Bad input is a ValueError that names the field and the value.
  py::register_exception<servohydraulics::Error>(m, "ServoHydraulicsError", PyExc_ValueError);
  expose_rig(m);
  expose_plant(m);
  // SolverOptions is bound in expose_plant.cpp (another owner); its protocol is
  // added here until that file calls add_protocol itself (lead: move it there).
  auto so = py::reinterpret_borrow<py::class_<servohydraulics::SolverOptions>>(
      py::type::of<servohydraulics::SolverOptions>());
  servohydraulics::bindings::add_protocol(so, {"method", "restart", "rtol", "atol_scale", "max_order",
                                               "max_steps_per_sample", "max_internal_step", "rk4_substeps",
                                               "rk4_h_rho"});
  expose_record(m);
  expose_linearize(m);
  expose_compensators(m);
  expose_loops(m);
}
