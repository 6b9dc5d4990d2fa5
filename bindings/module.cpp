// pybind11 module servohydraulics._core: one expose_<topic>.cpp per core header.
#include <pybind11/pybind11.h>

#include "busy.hpp"
#include "servohydraulics/error.hpp"

namespace py = pybind11;

void expose_rig(py::module_& m);
void expose_plant(py::module_& m);
void expose_record(py::module_& m);
void expose_linearize(py::module_& m);
void expose_compensators(py::module_& m);
void expose_loops(py::module_& m);
void expose_rths(py::module_& m);
void expose_marths(py::module_& m);
void expose_fmu(py::module_& m);
void expose_realtime(py::module_& m);
void expose_multi_rig(py::module_& m);

PYBIND11_MODULE(_core, m) {
  m.doc() = "C++ core of servohydraulics (SUNDIALS CVODE, Eigen)";
  // Bad input is a ValueError that names the field and the value.
  py::register_exception<servohydraulics::Error>(m, "ServoHydraulicsError", PyExc_ValueError);
  // One object used from two threads at once (bindings/busy.hpp).
  py::register_exception<servohydraulics::bindings::ConcurrentUse>(m, "ConcurrentUseError", PyExc_RuntimeError);
  expose_rig(m);
  expose_plant(m);
  expose_record(m);
  expose_linearize(m);
  expose_compensators(m);
  expose_loops(m);
  expose_rths(m);
  expose_marths(m);  // registers the MultiActuatorSystem seam, before expose_multi_rig binds a subclass
  expose_fmu(m);
  expose_realtime(m);
  expose_multi_rig(m);
}
