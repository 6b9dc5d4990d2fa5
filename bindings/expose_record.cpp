#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>

#include "busy.hpp"
#include "channels_py.hpp"
#include "servohydraulics/record.hpp"

namespace py = pybind11;
using namespace servohydraulics;

void expose_record(py::module_& m) {
  py::class_<RunSummary>(m, "RunSummary", "What a run did (record.hpp): every loop's summary (run_record, EFT, "
                                          "RPsD, rths.RthsLoop)")
      .def("ok", &RunSummary::ok, "ran every sample without a failure (status.ok())")
      .def_readonly("status", &RunSummary::status)
      .def_readonly("rows", &RunSummary::rows)
      .def_readonly("internal_steps", &RunSummary::internal_steps)
      .def_readonly("rhs_evals", &RunSummary::rhs_evals)
      .def_readonly("restarts", &RunSummary::restarts)
      .def_readonly("max_internal_steps", &RunSummary::max_internal_steps)
      .def_readonly("flags_any", &RunSummary::flags_any)
      .def_readonly("peak_force", &RunSummary::peak_force)
      .def_readonly("peak_displacement", &RunSummary::peak_displacement)
      .def_readonly("peak_velocity", &RunSummary::peak_velocity)
      .def_readonly("failure_time", &RunSummary::failure_time)
      .def_readonly("first_capacity_time", &RunSummary::first_capacity_time)
      .def_readonly("stiff_samples", &RunSummary::stiff_samples)
      .def_readonly("inaccurate_samples", &RunSummary::inaccurate_samples)
      .def_readonly("error_estimate", &RunSummary::error_estimate)
      .def_readonly("max_sample_error_estimate", &RunSummary::max_sample_error_estimate);

  m.def(
      "run_record",
      [](Plant& plant, py::array_t<double, py::array::c_style | py::array::forcecast> command) {
        if (command.ndim() != 1) throw Error("command must be a 1-D array");
        const std::size_t n = static_cast<std::size_t>(command.shape(0));
        py::dict out;
        Channels ch;
        sh_py::add_columns(out, kPlantChannels, n, ch.channel.data());
        ch.flags = sh_py::add_column<std::uint32_t>(out, "flags", n);
        ch.internal_steps = sh_py::add_column<int>(out, "internal_steps", n);
        ch.rhs_evals = sh_py::add_column<int>(out, "rhs_evals", n);
        const double* u = command.data();
        RunSummary sum;
        {
          bindings::BusyGuard busy({&plant}, "run_record");
          py::gil_scoped_release release;
          sum = run_record(plant, u, n, ch);
        }
        return py::make_tuple(out, sum);
      },
      py::arg("plant"), py::arg("command"),
      "Runs the plant over the command: returns (channels dict, RunSummary) with one row per command\n"
      "element, row k the state before command[k] is applied (row 0: the plant's current state). The\n"
      "last command is not applied (its effect is past the record): n commands make n - 1 steps.\n"
      "Chunks of one record therefore overlap by one element: pass each chunk with the next chunk's\n"
      "first command appended and drop the first row of every chunk after the first. Releases the GIL.");

  m.def("record_check_options", &record_check_options, py::arg("options"), py::arg("summary"),
        "The options of the default's whole-record check of a run (record.hpp): rtol / 10, its own\n"
        "check off; None when the run needs none (not dopri5 with its stiff fallback and check, never\n"
        "stiff, or failed).");
  m.def(
      "check_record",
      [](Plant& companion, py::array_t<double, py::array::c_style | py::array::forcecast> command,
         py::array_t<double, py::array::c_style | py::array::forcecast> displacement,
         py::array_t<double, py::array::c_style | py::array::forcecast> force, RunSummary summary) {
        if (command.ndim() != 1 || displacement.ndim() != 1 || force.ndim() != 1)
          throw Error("command, displacement and force must be 1-D arrays");
        const std::size_t rows = static_cast<std::size_t>(std::min(displacement.shape(0), force.shape(0)));
        const std::size_t n = static_cast<std::size_t>(command.shape(0));
        {
          bindings::BusyGuard busy({&companion}, "check_record");
          py::gil_scoped_release release;
          check_record(companion, command.data(), n, displacement.data(), force.data(), rows, summary);
        }
        return summary;
      },
      py::arg("companion"), py::arg("command"), py::arg("displacement"), py::arg("force"), py::arg("summary"),
      "The default's whole-record check (record.hpp): runs the companion plant (set up as the run's with\n"
      "record_check_options, at the run's start) over the command and returns the summary with\n"
      "error_estimate raised to the gap between the run's displacement and force and the companion's\n"
      "over the check's bound (> 1: the run may miss 1e-3 of its peaks). Releases the GIL.");
}
