#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "servohydraulics/record.hpp"

namespace py = pybind11;
using namespace servohydraulics;

void expose_record(py::module_& m) {
  py::class_<RunSummary>(m, "RunSummary")
      .def_readonly("status", &RunSummary::status)
      .def_readonly("rows", &RunSummary::rows)
      .def_readonly("internal_steps", &RunSummary::internal_steps)
      .def_readonly("rhs_evals", &RunSummary::rhs_evals)
      .def_readonly("restarts", &RunSummary::restarts)
      .def_readonly("max_internal_steps", &RunSummary::max_internal_steps)
      .def_readonly("flags_any", &RunSummary::flags_any)
      .def_readonly("peak_force", &RunSummary::peak_force)
      .def_readonly("first_capacity_time", &RunSummary::first_capacity_time);

  m.def(
      "run_record",
      [](Plant& plant, py::array_t<double, py::array::c_style | py::array::forcecast> command) {
        if (command.ndim() != 1) throw Error("command must be a 1-D array");
        const std::size_t n = static_cast<std::size_t>(command.shape(0));
        py::dict out;
        const char* names[] = {"time", "displacement", "velocity", "acceleration", "force",
                               "pressure", "spool", "drive", "flow"};
        std::vector<py::array_t<double>> arrs;
        for (const char* nm : names) {
          arrs.emplace_back(static_cast<py::ssize_t>(n));
          out[nm] = arrs.back();
        }
        py::array_t<std::uint32_t> flags(static_cast<py::ssize_t>(n));
        py::array_t<int> nsteps(static_cast<py::ssize_t>(n)), nrhs(static_cast<py::ssize_t>(n));
        std::fill(nsteps.mutable_data(), nsteps.mutable_data() + n, 0);
        std::fill(nrhs.mutable_data(), nrhs.mutable_data() + n, 0);
        Channels ch;
        double** dst[] = {&ch.time, &ch.displacement, &ch.velocity, &ch.acceleration, &ch.force,
                          &ch.pressure, &ch.spool, &ch.drive, &ch.flow};
        for (std::size_t i = 0; i < arrs.size(); ++i) *dst[i] = arrs[i].mutable_data();
        ch.flags = flags.mutable_data();
        ch.internal_steps = nsteps.mutable_data();
        ch.rhs_evals = nrhs.mutable_data();
        const double* u = command.data();
        RunSummary sum;
        {
          py::gil_scoped_release release;
          sum = run_record(plant, u, n, ch);
        }
        out["flags"] = flags;
        out["internal_steps"] = nsteps;
        out["rhs_evals"] = nrhs;
        return py::make_tuple(out, sum);
      },
      py::arg("plant"), py::arg("command"),
      "Run one sample per command element; returns (channels dict, RunSummary). Releases the GIL.");
}
