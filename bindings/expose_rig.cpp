#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "servohydraulics/zhao2003.hpp"
#include "servohydraulics/rig.hpp"

namespace py = pybind11;
using namespace servohydraulics;

void expose_rig(py::module_& m) {
  py::class_<FlowCurve> fc(m, "FlowCurve", "Normalised flow-spool opening curve g(x_v) of Fig 4(a)");
  py::enum_<FlowCurve::Kind>(fc, "Kind").value("Rational", FlowCurve::Kind::Rational).value("Table", FlowCurve::Kind::Table);
  fc.def(py::init<>())
      .def_readwrite("kind", &FlowCurve::kind)
      .def_readwrite("b", &FlowCurve::b)
      .def_readwrite("opening", &FlowCurve::opening)
      .def_readwrite("flow", &FlowCurve::flow)
      .def("eval", &FlowCurve::eval, py::arg("x"))
      .def("slope", &FlowCurve::slope, py::arg("x"))
      .def("inverse", &FlowCurve::inverse, py::arg("q"))
      .def("validate", &FlowCurve::validate);

  py::class_<Effects>(m, "Effects", "Switches of the physical effects")
      .def(py::init<>())
      .def_readwrite("servovalve_dynamics", &Effects::servovalve_dynamics)
      .def_readwrite("load_pressure", &Effects::load_pressure)
      .def_readwrite("flow_nonlinearity", &Effects::flow_nonlinearity)
      .def_readwrite("coulomb_friction", &Effects::coulomb_friction)
      .def_readwrite("spring_softening", &Effects::spring_softening)
      .def_readwrite("piston_mass", &Effects::piston_mass)
      .def_readwrite("drive_saturation", &Effects::drive_saturation)
      .def_readwrite("spool_saturation", &Effects::spool_saturation)
      .def_readwrite("lugre_friction", &Effects::lugre_friction);

  py::class_<Rig>(m, "Rig", "Parameters of the rig, SI units, named after the paper's symbols")
      .def(py::init<>())
      .def_readwrite("m", &Rig::m)
      .def_readwrite("c", &Rig::c)
      .def_readwrite("k", &Rig::k)
      .def_readwrite("k_2", &Rig::k_2)
      .def_readwrite("x_contact", &Rig::x_contact)
      .def_readwrite("F_c", &Rig::F_c)
      .def_readwrite("v_stick", &Rig::v_stick)
      .def_readwrite("stribeck_ratio", &Rig::stribeck_ratio)
      .def_readwrite("v_s", &Rig::v_s)
      .def_readwrite("sigma_0", &Rig::sigma_0)
      .def_readwrite("sigma_1", &Rig::sigma_1)
      .def_readwrite("m_p", &Rig::m_p)
      .def_readwrite("A", &Rig::A)
      .def_readwrite("K_a", &Rig::K_a)
      .def_readwrite("C_l", &Rig::C_l)
      .def_readwrite("p_s", &Rig::p_s)
      .def_readwrite("F_cap", &Rig::F_cap)
      .def_readwrite("stroke", &Rig::stroke)
      .def_readwrite("K_v", &Rig::K_v)
      .def_readwrite("K_s", &Rig::K_s)
      .def_readwrite("f_v", &Rig::f_v)
      .def_readwrite("zeta_v", &Rig::zeta_v)
      .def_readwrite("x_v_max", &Rig::x_v_max)
      .def_readwrite("flow_curve", &Rig::flow_curve)
      .def_readwrite("C_F_disp", &Rig::C_F_disp)
      .def_readwrite("C_F_force", &Rig::C_F_force)
      .def_readwrite("G_p", &Rig::G_p)
      .def_readwrite("G_d", &Rig::G_d)
      .def_readwrite("v_max", &Rig::v_max)
      .def_readwrite("effects", &Rig::effects)
      .def("validate", &Rig::validate);

  py::enum_<Zhao2003Variant>(m, "Zhao2003Variant")
      .value("Calibrated", Zhao2003Variant::Calibrated)
      .value("Printed", Zhao2003Variant::Printed);
  py::class_<Zhao2003TestMethods>(m, "Zhao2003TestMethods",
                                  "Constants of the paper's test methods (Table I and text), SI")
      .def(py::init<>())
      .def_readonly("dt", &Zhao2003TestMethods::dt)
      .def_readonly("eft_lead_T", &Zhao2003TestMethods::eft_lead_T)
      .def_readonly("amplitude_T", &Zhao2003TestMethods::amplitude_T)
      .def_readonly("delay_T", &Zhao2003TestMethods::delay_T)
      .def_readonly("alpha", &Zhao2003TestMethods::alpha)
      .def_readonly("model", &Zhao2003TestMethods::model);
  m.attr("ZHAO2003_TEST_METHODS") = Zhao2003TestMethods{};
  m.def("zhao2003", &zhao2003, py::arg("variant") = Zhao2003Variant::Calibrated, py::arg("actuator_attached") = true);
}
