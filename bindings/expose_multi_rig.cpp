// The coupled multi-actuator rig (multi_rig.hpp): NodeSpecimen, MultiRig, MultiRigPlant and
// run_multi_record.  Conversions only; the channel names come from kNodeChannels and
// kActuatorChannels ("node.<name>", "actuator<i>.<name>").
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "busy.hpp"
#include "channels_py.hpp"
#include "servohydraulics/multi_rig.hpp"

namespace py = pybind11;
using namespace servohydraulics;

namespace {
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string actuator_channel(std::size_t i, const char* name) {
  return "actuator" + std::to_string(i + 1) + "." + name;
}

MultiRig::State to_state(const MultiRig& r, const Array& y) {
  if (y.ndim() != 1 || y.shape(0) != r.num_states())
    throw py::value_error("invalid y (length) = " + std::to_string(y.size()) + ": this rig has " +
                          std::to_string(r.num_states()) + " states (MultiRig.states)");
  MultiRig::State s{};
  for (int i = 0; i < r.num_states(); ++i) s[static_cast<std::size_t>(i)] = y.data()[i];
  return s;
}

py::array_t<double> from_state(const MultiRig& r, const MultiRig::State& y) {
  py::array_t<double> out(r.num_states());
  for (int i = 0; i < r.num_states(); ++i) out.mutable_data()[i] = y[static_cast<std::size_t>(i)];
  return out;
}

// N commands (and optionally their rates) as the held input.
MultiRig::Input to_input(const MultiRig& r, const Array& u, const py::object& u_rate) {
  const auto N = static_cast<py::ssize_t>(r.actuators());
  if (u.ndim() != 1 || u.shape(0) != N)
    throw py::value_error("invalid u (length) = " + std::to_string(u.size()) + ": one command per actuator (" +
                          std::to_string(N) + ") [m]");
  MultiRig::Input in;
  for (py::ssize_t i = 0; i < N; ++i) in.u[static_cast<std::size_t>(i)] = u.data()[i];
  if (!u_rate.is_none()) {
    const Array ur = u_rate.cast<Array>();
    if (ur.ndim() != 1 || ur.shape(0) != N)
      throw py::value_error("invalid u_rate (length) = " + std::to_string(ur.size()) + ": one rate per actuator");
    for (py::ssize_t i = 0; i < N; ++i) in.u_rate[static_cast<std::size_t>(i)] = ur.data()[i];
  }
  return in;
}

py::array_t<double> matrix(const std::vector<double>& a, int rows, int cols) {
  py::array_t<double> out({rows, cols});
  std::copy(a.begin(), a.end(), out.mutable_data());
  return out;
}

// One sample's channels by name (scalars), as a run's columns are named.
py::dict output_dict(const MultiRig& r, const MultiRigOutput& o) {
  py::dict d;
  d["time"] = o.time;
  for (const auto& c : kNodeChannels) d[(std::string("node.") + c.name).c_str()] = o.node.*c.member;
  for (std::size_t i = 0; i < static_cast<std::size_t>(r.actuators()); ++i) {
    for (const auto& c : kActuatorChannels) d[actuator_channel(i, c.name).c_str()] = o.actuator[i].*c.member;
    d[actuator_channel(i, "flags").c_str()] = o.actuator[i].flags;
  }
  return d;
}
}  // namespace

void expose_multi_rig(py::module_& m) {
  m.attr("ACTUATOR_CHANNELS") = sh_py::channel_units(kActuatorChannels);
  m.attr("NODE_CHANNELS") = sh_py::channel_units(kNodeChannels);
  m.attr("MAX_ACTUATORS") = static_cast<int>(MultiRig::kMaxActuators);

  py::class_<NodeSpecimen>(m, "NodeSpecimen",
                           "The specimen and fixture at the frame node in (x [m], theta [rad]): M, C, K as "
                           "row-major 2 x 2 lists of 4 (multi_rig.hpp)")
      .def(py::init<>())
      .def_readwrite("rotation", &NodeSpecimen::rotation, "theta free (False: locked at 0, the node translates)")
      .def_readwrite("M", &NodeSpecimen::M, "mass [[kg, kg m], [kg m, kg m^2]], row-major")
      .def_readwrite("C", &NodeSpecimen::C, "damping [[N s/m, N s], [N s, N m s]], row-major")
      .def_readwrite("K", &NodeSpecimen::K, "stiffness [[N/m, N], [N, N m]], row-major")
      .def_readwrite("fixture_mass", &NodeSpecimen::fixture_mass, "[kg]")
      .def_readwrite("fixture_inertia", &NodeSpecimen::fixture_inertia, "[kg m^2]")
      .def("validate", &NodeSpecimen::validate);

  py::class_<MultiRig>(m, "MultiRig",
                       "N servo-hydraulic actuators (one Rig each) on rigid arms to one frame node with a linear "
                       "specimen: right-hand side, analytic Jacobian, outputs (multi_rig.hpp)")
      .def(py::init([](const std::vector<Rig>& rigs, const std::vector<double>& arms,
                       const std::vector<double>& angles, const NodeSpecimen& specimen) {
             if (arms.size() != angles.size())
               throw Error("invalid angles (length) = " + std::to_string(angles.size()) + ": one angle per arm (" +
                           std::to_string(arms.size()) + ")");
             return MultiRig(rigs, Coupler(arms.size(), arms.data(), angles.data()), specimen);
           }),
           py::arg("rigs"), py::arg("arms"), py::arg("angles"), py::arg("specimen"),
           "rigs[i] on arm i of length arms[i] [m] at angles[i] [rad] from the actuator axis")
      .def_property_readonly("actuators", &MultiRig::actuators)
      .def_property_readonly("dofs", &MultiRig::dofs, "the node's coordinates: 2 (x, theta) or 1 (x)")
      .def_property_readonly("num_states", &MultiRig::num_states)
      .def_property_readonly("states",
                             [](const MultiRig& r) {
                               py::tuple t(static_cast<std::size_t>(r.num_states()));
                               for (int k = 0; k < r.num_states(); ++k)
                                 t[static_cast<std::size_t>(k)] = py::make_tuple(r.state_name(k), r.state_unit(k));
                               return t;
                             },
                             "((name, unit), ...) of the states, in order")
      .def_property_readonly("state_scales",
                             [](const MultiRig& r) {
                               py::array_t<double> a(r.num_states());
                               for (int k = 0; k < r.num_states(); ++k) a.mutable_data()[k] = r.state_scale(k);
                               return a;
                             },
                             "each state's magnitude, the unit of its absolute tolerance")
      .def("offset", &MultiRig::offset, py::arg("i"), "index of actuator i's first state (its load pressure)")
      .def("rig", [](const MultiRig& r, int i) { return r.actuator(i).rig(); }, py::arg("i"))
      .def_property_readonly("arms",
                             [](const MultiRig& r) {
                               std::vector<double> d;
                               for (std::size_t i = 0; i < r.coupler().actuators(); ++i) d.push_back(r.coupler().arm(i));
                               return d;
                             })
      .def_property_readonly("angles",
                             [](const MultiRig& r) {
                               std::vector<double> a;
                               for (std::size_t i = 0; i < r.coupler().actuators(); ++i)
                                 a.push_back(r.coupler().angle(i));
                               return a;
                             })
      .def_property_readonly("specimen", &MultiRig::specimen)
      .def("rest", [](const MultiRig& r) { return from_state(r, r.rest()); }, "the state at rest, commands 0")
      .def("rhs",
           [](const MultiRig& r, const Array& y, const Array& u, const py::object& u_rate) {
             const MultiRig::State s = to_state(r, y);
             MultiRig::State yd{};
             r.rhs(s.data(), to_input(r, u, u_rate), yd.data());
             return from_state(r, yd);
           },
           py::arg("y"), py::arg("u"), py::arg("u_rate") = py::none())
      .def("jacobian",
           [](const MultiRig& r, const Array& y, const Array& u, const py::object& u_rate) {
             const MultiRig::State s = to_state(r, y);
             const int n = r.num_states(), N = r.actuators();
             std::vector<double> J(static_cast<std::size_t>(n) * n), B(static_cast<std::size_t>(n) * N);
             r.jacobian(s.data(), to_input(r, u, u_rate), J.data(), n, 1, B.data());
             return py::make_tuple(matrix(J, n, n), matrix(B, n, N));
           },
           py::arg("y"), py::arg("u"), py::arg("u_rate") = py::none(), "(J, B): df/dy (n x n) and df/du (n x N)")
      .def("outputs",
           [](const MultiRig& r, const Array& y, const Array& u) {
             MultiRigOutput o;
             r.outputs(to_state(r, y).data(), to_input(r, u, py::none()), o);
             return output_dict(r, o);
           },
           py::arg("y"), py::arg("u"), "every channel at state y with the commands u held (dict of scalars)")
      .def("strokes",
           [](const MultiRig& r, const Array& y) {
             py::array_t<double> s(r.actuators());
             r.strokes(to_state(r, y).data(), s.mutable_data());
             return s;
           },
           py::arg("y"))
      .def("linearize",
           [](const MultiRig& r, const Array& y0, const Array& u0) {
             const MultiRig::Input in = to_input(r, u0, py::none());
             const MultiRigLinearModel lm = linearize(r, to_state(r, y0), in.u.data());
             return py::make_tuple(matrix(lm.A, lm.n, lm.n), matrix(lm.B, lm.n, lm.inputs),
                                   matrix(lm.C, lm.inputs, lm.n));
           },
           py::arg("y0"), py::arg("u0"),
           "(A, B, C): dy/dt = A dy + B du, strokes = C dy, about state y0 with the commands u0 [m] held");

  m.def("multi_rig_rk4_substeps",
        [](const MultiRig& r, double dt, const SolverOptions& o) { return rk4_automatic_substeps(r, dt, o); },
        py::arg("rig"), py::arg("dt"), py::arg("options") = SolverOptions{},
        "RK4 substeps per sample of dt [s] the coupled rig's automatic rule chooses");

  // The seam (multi_actuator.hpp) is registered once, by expose_marths (called first in module.cpp),
  // so the maRTHS loop takes this plant as its MultiActuatorSystem.
  py::class_<MultiRigPlant, MultiActuatorSystem>(m, "MultiRigPlant",
                                                 "The coupled rig stepped at the loop's rate, the N commands [m] "
                                                 "held over each sample (a MultiActuatorSystem)")
      .def(py::init<const MultiRig&, double, const SolverOptions&>(), py::arg("rig"), py::arg("dt"),
           py::arg("options") = SolverOptions{})
      .def_property_readonly("actuators", &MultiRigPlant::actuators)
      .def_property_readonly("dt", &MultiRigPlant::dt)
      .def_property_readonly("time", &MultiRigPlant::time)
      .def_property_readonly("rig", &MultiRigPlant::rig)
      .def_property_readonly("options", &MultiRigPlant::options)
      .def_property_readonly("rk4_substeps", &MultiRigPlant::rk4_substeps)
      .def_property_readonly("state", [](const MultiRigPlant& p) { return from_state(p.rig(), p.state()); })
      .def_property_readonly("total_internal_steps", &MultiRigPlant::total_internal_steps)
      .def_property_readonly("total_rhs_evals", &MultiRigPlant::total_rhs_evals)
      .def_property_readonly("total_restarts", &MultiRigPlant::total_restarts)
      .def("reset", bindings::guarded(&MultiRigPlant::reset, "MultiRigPlant.reset"))
      .def("reset_state",
           [](MultiRigPlant& p, const Array& y) {
             bindings::require_idle(&p, "MultiRigPlant.reset_state");
             p.reset_state(to_state(p.rig(), y));
           },
           py::arg("y"))
      .def("displacements",
           [](const MultiRigPlant& p) {
             py::array_t<double> y(static_cast<py::ssize_t>(p.actuators()));
             p.displacements(y.mutable_data());
             return y;
           },
           "the N strokes [m]")
      .def("step",
           [](MultiRigPlant& p, const Array& u) {
             bindings::require_idle(&p, "MultiRigPlant.step");
             to_input(p.rig(), u, py::none());  // checks the length
             return p.step(u.data());
           },
           py::arg("u"), "holds the N commands u [m] over one sample; returns the Status")
      .def("observe",
           [](const MultiRigPlant& p) {
             MultiRigOutput o;
             p.observe(o);
             return output_dict(p.rig(), o);
           },
           "every channel now (dict of scalars)");

  m.def(
      "run_multi_record",
      [](MultiRigPlant& plant, const Array& commands) {
        const auto N = static_cast<py::ssize_t>(plant.actuators());
        if (commands.ndim() != 2 || commands.shape(1) != N)
          throw py::value_error("invalid commands (shape): expected (n, " + std::to_string(N) +
                                ") [m], one column per actuator");
        const auto n = static_cast<std::size_t>(commands.shape(0));
        py::dict out;
        MultiRigChannels ch;
        ch.time = sh_py::add_column<double>(out, "time", n);
        for (std::size_t c = 0; c < kNumNodeChannels; ++c)
          ch.node[c] = sh_py::add_column<double>(out, (std::string("node.") + kNodeChannels[c].name).c_str(), n);
        for (std::size_t i = 0; i < static_cast<std::size_t>(N); ++i) {
          for (std::size_t c = 0; c < kNumActuatorChannels; ++c)
            ch.actuator[i][c] = sh_py::add_column<double>(out, actuator_channel(i, kActuatorChannels[c].name).c_str(), n);
          ch.flags[i] = sh_py::add_column<std::uint32_t>(out, actuator_channel(i, "flags").c_str(), n);
        }
        ch.internal_steps = sh_py::add_column<int>(out, "internal_steps", n);
        ch.rhs_evals = sh_py::add_column<int>(out, "rhs_evals", n);
        const double* u = commands.data();
        RunSummary sum;
        {
          bindings::BusyGuard busy({&plant}, "run_multi_record");
          py::gil_scoped_release release;
          sum = run_multi_record(plant, u, n, ch);
        }
        return py::make_tuple(out, sum);
      },
      py::arg("plant"), py::arg("commands"),
      "Runs the plant over commands (n, N) [m]: returns (channels dict, RunSummary), row k measured before command\n"
      "row k is applied (the record convention of run_record; the last row's commands are held but not seen).\n"
      "Releases the GIL.");
}
