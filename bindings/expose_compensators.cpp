#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "busy.hpp"
#include "enums_py.hpp"
#include "servohydraulics/compensators.hpp"

namespace py = pybind11;
using namespace servohydraulics;

void expose_compensators(py::module_& m) {
  py::class_<PhaseLead>(m, "PhaseLead",
                        "Phase lead (T s + 1)/(alpha T s + 1), Tustin prewarped at w_p (default 1/(T sqrt(alpha)))")
      .def(py::init<double, double, double, double>(), py::arg("T"), py::arg("alpha"), py::arg("dt"),
           py::arg("prewarp") = 0.0)
      .def("reset", bindings::guarded(&PhaseLead::reset, "PhaseLead.reset"), py::arg("u0") = 0.0)
      .def("step", bindings::guarded(&PhaseLead::step, "PhaseLead.step"), py::arg("u"))
      .def(
          "filter",
          [](PhaseLead& f, py::array_t<double, py::array::c_style | py::array::forcecast> u) {
            if (u.ndim() != 1) throw Error("phase-lead input must be a 1-D array");
            py::array_t<double> y(u.shape(0));
            const double* src = u.data();
            double* dst = y.mutable_data();
            const auto n = static_cast<std::size_t>(u.shape(0));
            {
              bindings::BusyGuard busy({&f}, "PhaseLead.filter");
              py::gil_scoped_release release;
              f.filter(src, dst, n);
            }
            return y;
          },
          py::arg("u"), "Steps over a whole array from the current state; releases the GIL.")
      .def_property_readonly("T", &PhaseLead::T)
      .def_property_readonly("alpha", &PhaseLead::alpha)
      .def_property_readonly("prewarp", &PhaseLead::prewarp)
      .def_property_readonly("b0", &PhaseLead::b0)
      .def_property_readonly("b1", &PhaseLead::b1)
      .def_property_readonly("a1", &PhaseLead::a1);

  py::class_<SampleDelay>(m, "SampleDelay", "Pure delay of N controller samples")
      .def(py::init<int>(), py::arg("samples") = 0)
      .def("reset", &SampleDelay::reset, py::arg("u0") = 0.0)
      .def("step", &SampleDelay::step, py::arg("u"))
      .def_property_readonly("samples", &SampleDelay::samples);

  py::class_<VelocityFeedbackCompensator> vfc(m, "VelocityFeedbackCompensator",
                                              "EFT velocity feedback compensation (linear or nonlinear)");
  sh_py::bind_enum(vfc, "Kind", kCompensationNames);
  m.attr("COMPENSATION_NAMES") = sh_py::enum_names(kCompensationNames);
  vfc.def(py::init<const Rig&, VelocityFeedbackCompensator::Kind, double, double, double>(), py::arg("model"),
          py::arg("kind"), py::arg("lead_T"), py::arg("alpha"), py::arg("dt"))
      .def("reset", bindings::guarded(&VelocityFeedbackCompensator::reset, "VelocityFeedbackCompensator.reset"))
      .def("step", bindings::guarded(&VelocityFeedbackCompensator::step, "VelocityFeedbackCompensator.step"),
           py::arg("velocity"), py::arg("force_error"),
           py::arg("pressure"))
      .def_property_readonly("kind", &VelocityFeedbackCompensator::kind)
      .def_property_readonly("forward_gain", &VelocityFeedbackCompensator::forward_gain)
      .def_property_readonly("last_opening", &VelocityFeedbackCompensator::last_opening);
}
