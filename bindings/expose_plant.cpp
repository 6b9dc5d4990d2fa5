#include <string>
#include <variant>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "busy.hpp"
#include "channels_py.hpp"
#include "enums_py.hpp"
#include "protocol.hpp"
#include "servohydraulics/plant.hpp"

namespace py = pybind11;
using namespace servohydraulics;

namespace {
// The active part of a state vector (Dynamics::num_states entries) to and from NumPy.
State to_state(const Dynamics& d, const std::vector<double>& y) {
  if (static_cast<int>(y.size()) != d.num_states())
    throw py::value_error("invalid y (length) = " + std::to_string(y.size()) + ": this plant has " +
                          std::to_string(d.num_states()) + " states (Dynamics.states)");
  State s{};
  for (std::size_t i = 0; i < y.size(); ++i) s[i] = y[i];
  return s;
}
py::array_t<double> from_state(const Dynamics& d, const State& y) {
  py::array_t<double> out(d.num_states());
  for (int i = 0; i < d.num_states(); ++i) out.mutable_data()[i] = y[i];
  return out;
}
py::tuple state_table(const Dynamics& d) {
  py::tuple t(static_cast<std::size_t>(d.num_states()));
  for (int i = 0; i < d.num_states(); ++i) {
    const StateInfo& s = d.state_info(i);
    t[i] = py::make_tuple(s.name, s.unit, s.doc);
  }
  return t;
}
// num_states, each element's first state index (by its switch's name, -1: off) and each active
// appended state's index (by its name).
py::dict layout_dict(const Dynamics& d) {
  const StateLayout& L = d.layout();
  py::dict out;
  out["num_states"] = L.num_states;
  for (std::size_t e = 0; e < kNumElements; ++e) out[kElementNames[e]] = L.offset[e];
  for (int i = kNumStates; i < L.num_states; ++i) out[d.state_info(i).name] = i;
  return out;
}

// The kinematic driver: the specimen force along a measured motion (Dynamics::specimen_forces).
py::array_t<double> specimen_forces(const Dynamics& d, const py::array_t<double, py::array::c_style | py::array::forcecast>& x,
                                    const py::array_t<double, py::array::c_style | py::array::forcecast>& v, double dt,
                                    int substeps) {
  if (x.ndim() != 1 || v.ndim() != 1 || x.size() != v.size())
    throw py::value_error("invalid x, v (shape): two 1-D arrays of one length expected, got " +
                          std::to_string(x.size()) + " and " + std::to_string(v.size()) + " samples");
  py::array_t<double> F(x.size());
  d.specimen_forces(x.data(), v.data(), static_cast<std::size_t>(x.size()), dt, substeps, F.mutable_data());
  return F;
}
}  // namespace

void expose_plant(py::module_& m) {
  sh_py::bind_enum(m, "ControlMode", kControlModeNames);
  m.attr("CONTROL_MODE_NAMES") = sh_py::enum_names(kControlModeNames);

  // The state vector: StateIndex values named after kStates, and _core.STATES = ((name, unit), ...).
  py::enum_<StateIndex> si(m, "StateIndex", "Indices of the plant's state vector");
  py::tuple states(static_cast<std::size_t>(kNumStates));
  for (int i = 0; i < kNumStates; ++i) {
    si.value(kStates[i].name, static_cast<StateIndex>(i), kStates[i].doc);
    states[i] = py::make_tuple(kStates[i].name, kStates[i].unit);
  }
  m.attr("STATES") = states;  // the base states; Dynamics.states adds the switched-on elements'
  m.attr("NUM_STATES") = static_cast<int>(kNumStates);
  m.attr("MAX_STATES") = static_cast<int>(kMaxStates);
  m.attr("MAX_PADE_ORDER") = static_cast<int>(kMaxPadeOrder);
  m.attr("MAX_DELAY_SAMPLES") = static_cast<int>(kMaxDelaySamples);

  // Output: one read-only attribute per channel of kPlantChannels, and the flags.
  py::class_<Output> output(m, "Output");
  output.def(py::init<>()).def_readonly("flags", &Output::flags);
  for (const ChannelInfo& c : kPlantChannels) output.def_readonly(c.name, c.member, c.doc);
  output.def_static(
      "from_channels",
      [](const py::kwargs& channels) {
        Output o;
        for (const auto& item : channels) {
          const auto name = item.first.cast<std::string>();
          const ChannelInfo* c = nullptr;
          for (const ChannelInfo& ch : kPlantChannels)
            if (name == ch.name) c = &ch;
          if (c == nullptr) {
            std::string names;
            for (const ChannelInfo& ch : kPlantChannels) names += std::string(names.empty() ? "" : ", ") + ch.name;
            throw py::value_error("unknown plant channel " + name + ": expected one of " + names);
          }
          o.*(c->member) = item.second.cast<double>();
        }
        return o;
      },
      "An Output holding the given channels by name (the others 0): sensors read from a real or remote rig, for a "
      "controller's command()");
  m.attr("PLANT_CHANNELS") = sh_py::channel_units(kPlantChannels);

  m.attr("FLAG_CAPACITY_EXCEEDED") = static_cast<unsigned>(kCapacityExceeded);
  m.attr("FLAG_SUPPLY_LIMITED") = static_cast<unsigned>(kSupplyLimited);
  m.attr("FLAG_SPOOL_SATURATED") = static_cast<unsigned>(kSpoolSaturated);
  m.attr("FLAG_DRIVE_SATURATED") = static_cast<unsigned>(kDriveSaturated);
  m.attr("FLAG_STROKE_EXCEEDED") = static_cast<unsigned>(kStrokeExceeded);

  py::class_<SolverOptions> so(m, "SolverOptions");
  sh_py::bind_enum(so, "Method", kMethodNames);
  sh_py::bind_enum(so, "Restart", kRestartNames);
  m.attr("METHOD_NAMES") = sh_py::enum_names(kMethodNames);
  m.attr("RESTART_NAMES") = sh_py::enum_names(kRestartNames);
  so.def(py::init<>())
      .def_readonly_static("MAX_SUBSTEPS", &SolverOptions::kMaxSubsteps)
      .def("validate", &SolverOptions::validate);
  // The fields from kSolverOptionFields: one attribute each, the object protocol over all of them.
  std::vector<std::string> fields;
  py::list field_info;
  for (const SolverOptionField& f : kSolverOptionFields) {
    std::visit([&](auto member) { so.def_readwrite(f.name, member, f.doc); }, f.member);
    fields.emplace_back(f.name);
    field_info.append(py::dict(py::arg("name") = f.name, py::arg("unit") = f.unit, py::arg("doc") = f.doc));
  }
  bindings::add_protocol(so, fields);
  m.attr("SOLVER_OPTION_FIELDS") = py::tuple(field_info);

  py::class_<Status> st(m, "Status");
  py::enum_<Status::Code>(st, "Code")
      .value("Ok", Status::Ok)
      .value("SolverFailure", Status::SolverFailure)
      .value("TooMuchWork", Status::TooMuchWork)
      .value("NonFinite", Status::NonFinite)
      .value("NotReady", Status::NotReady)
      .value("Stiff", Status::Stiff)
      .value("Chatter", Status::Chatter);
  st.def_readonly("code", &Status::code)
      .def_readonly("cvode_flag", &Status::cvode_flag)
      .def_readonly("t", &Status::t)
      .def_readonly("internal_steps", &Status::internal_steps)
      .def_readonly("rhs_evals", &Status::rhs_evals)
      .def_readonly("restarted", &Status::restarted)
      .def_readonly("stiff", &Status::stiff)
      .def_readonly("inaccurate", &Status::inaccurate)
      .def_readonly("error_estimate", &Status::error_estimate)
      .def_readonly("run_error_estimate", &Status::run_error_estimate)
      .def("ok", &Status::ok)
      .def_property_readonly("message", &Status::message);

  py::class_<Dynamics>(m, "Dynamics", "Right-hand side, analytic Jacobian and outputs of the plant")
      .def(py::init<const Rig&, ControlMode>(), py::arg("rig"), py::arg("mode"))
      .def("rhs",
           [](const Dynamics& d, const std::vector<double>& yv, double u, double u_rate) {
             const State y = to_state(d, yv);
             State yd{};
             d.rhs(y.data(), {u, u_rate}, yd.data());
             return from_state(d, yd);
           },
           py::arg("y"), py::arg("u"), py::arg("u_rate") = 0.0)
      .def("jacobian",
           [](const Dynamics& d, const std::vector<double>& yv, double u, double u_rate) {
             const State y = to_state(d, yv);
             Jacobian J;
             d.jacobian(y.data(), {u, u_rate}, J);
             const int n = d.num_states();
             py::array_t<double> out({n, n});
             auto a = out.mutable_unchecked<2>();
             for (int i = 0; i < n; ++i)
               for (int j = 0; j < n; ++j) a(i, j) = J[i][j];
             return out;
           },
           py::arg("y"), py::arg("u"), py::arg("u_rate") = 0.0)
      .def("outputs",
           [](const Dynamics& d, const std::vector<double>& yv, double u) {
             const State y = to_state(d, yv);
             Output o;
             d.outputs(y.data(), {u, 0.0}, o);
             return o;
           },
           py::arg("y"), py::arg("u"))
      .def("specimen_force",
           [](const Dynamics& d, const std::vector<double>& yv) {
             const State y = to_state(d, yv);
             return d.specimen_force(y.data());
           },
           py::arg("y"), "Force of the switched-on specimen elements at state y [N] (0 when none is on)")
      .def("specimen_forces", &specimen_forces, py::arg("x"), py::arg("v"), py::arg("dt"), py::arg("substeps") = 0,
           "The kinematic driver: the specimen elements' force [N] along a given motion x(t) [m], v(t) [m/s] "
           "sampled at dt [s], their states starting at rest at x[0] and integrated by RK4 with `substeps` per "
           "sample (0: from their rate bound), the motion interpolated linearly between samples")
      .def("equilibrium", [](const Dynamics& d, double x0) { return from_state(d, d.equilibrium(x0)); },
           py::arg("x0"))
      .def("operating_point",
           [](const Dynamics& d, double x0) {
             const Dynamics::OperatingPoint op = d.operating_point(x0);
             return py::make_tuple(from_state(d, op.y0), op.u0);
           },
           py::arg("x0"),
           "(y0, u0): the equilibrium state at displacement x0 [m] and the held command that keeps it at rest")
      .def_property_readonly("num_states", &Dynamics::num_states,
                             "active length of the state vector (base states and the switched-on elements')")
      .def_property_readonly("states", &state_table, "((name, unit, doc), ...) of the active states, in order")
      .def_property_readonly("layout", &layout_dict,
                             "num_states, each element's first state (by its effects switch; -1: off) and each "
                             "appended state's index (by its name: bw_z, mr_y, mr_z, delay_1, ...)")
      .def_property_readonly("pade",
                             [](const Dynamics& d) {
                               const Dynamics::Pade& P = d.pade();
                               py::dict out;
                               out["order"] = P.order;
                               out["tau"] = P.tau;
                               out["a"] = std::vector<double>(P.a, P.a + P.order);
                               out["c"] = std::vector<double>(P.c, P.c + P.order);
                               out["d"] = P.d;
                               return out;
                             },
                             "the Pade loop delay's realisation q' = (A' q + e_N w) / tau, out = c q + d w")
      .def("structure_forces", py::vectorize(&Dynamics::structure_force), py::arg("x"), py::arg("v"),
           py::arg("z") = 0.0,
           "The structure's force against the applied one in Eq (5), f_s(x) + c v + F_f(v, z) [N]: "
           "spring, damping and friction (Stribeck, LuGre with bristle deflection z [m]); vectorised")
      .def("spring_force", &Dynamics::spring_force)
      .def("friction_force", &Dynamics::friction_force)
      .def("friction_level", &Dynamics::friction_level)
      .def("flow_gain", &Dynamics::flow_gain)
      .def("pressure_factor", &Dynamics::pressure_factor)
      .def_property_readonly("moving_mass", &Dynamics::moving_mass)
      .def_property_readonly("mode", &Dynamics::mode);

  m.def("state_scale", &state_scale, py::arg("dynamics"), py::arg("i"),
        "The magnitude of state i of this rig, the unit of its absolute tolerance (solver_options.hpp)");
  m.def("absolute_tolerances",
        [](const Dynamics& d, const SolverOptions& o) {
          py::array_t<double> a(d.num_states());
          absolute_tolerances(d, o, a.mutable_data());
          return a;
        },
        py::arg("dynamics"), py::arg("options") = SolverOptions{},
        "Absolute tolerance of each state [its unit]: rtol * atol_fraction * state_scale (one home, C++)");
  m.def("rk4_automatic_substeps", &rk4_automatic_substeps, py::arg("dynamics"), py::arg("dt"),
        py::arg("options") = SolverOptions{},
        "RK4 substeps per sample of dt [s] that SolverOptions(rk4_substeps=0) would choose (the C++ rule)");

  py::class_<Plant>(m, "Plant", "The plant stepped at the controller rate (the ODE integrator of SolverOptions between samples)")
      .def(py::init<const Rig&, ControlMode, double, const SolverOptions&>(), py::arg("rig"), py::arg("mode"),
           py::arg("dt"), py::arg("options") = SolverOptions{})
      .def("reset", bindings::guarded(&Plant::reset, "Plant.reset"), py::arg("x0") = 0.0, py::arg("t0") = 0.0)
      .def("reset_state",
           [](Plant& p, const std::vector<double>& y0, double t0) {
             bindings::require_idle(&p, "Plant.reset_state");
             p.reset_state(to_state(p.dynamics(), y0), t0);
           },
           py::arg("y0"), py::arg("t0") = 0.0)
      .def("step",
           [](Plant& p, double u) {
             bindings::require_idle(&p, "Plant.step");
             Output o;
             Status s = p.step(u, o);
             return py::make_tuple(s, o);
           },
           py::arg("command"))
      .def("observe",
           [](const Plant& p) {
             bindings::require_idle(&p, "Plant.observe");
             Output o;
             p.observe(o);
             return o;
           })
      .def_property_readonly("time", &Plant::time)
      .def_property_readonly("rk4_substeps", &Plant::rk4_substeps)
      .def_property_readonly("dt", &Plant::dt)
      .def_property_readonly("state", [](const Plant& p) { return from_state(p.dynamics(), p.state()); })
      .def_property_readonly("states", [](const Plant& p) { return state_table(p.dynamics()); },
                             "((name, unit, doc), ...) of the active states, in order")
      .def_property_readonly("dynamics", &Plant::dynamics, py::return_value_policy::reference_internal)
      .def_property_readonly("total_internal_steps", &Plant::total_internal_steps)
      .def_property_readonly("total_rhs_evals", &Plant::total_rhs_evals)
      .def_property_readonly("total_restarts", &Plant::total_restarts);
}
