#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "busy.hpp"
#include "enums_py.hpp"
#include "channels_py.hpp"
#include "protocol.hpp"
#include "servohydraulics/controllers.hpp"
#include "servohydraulics/loops.hpp"

namespace py = pybind11;
using namespace servohydraulics;
using servohydraulics::bindings::add_protocol;

namespace {
using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;

//! Every channel of the loop's rows: the plant's (kPlantChannels of row.plant), flags, then the loop's own table.
template <class Row, std::size_t N>
py::dict to_dict(const std::vector<Row>& rows, std::size_t n, const ChannelInfoOf<Row> (&table)[N]) {
  py::dict out;
  sh_py::rows_to_dict(out, kPlantChannels, rows, n, [](const Row& r) -> const Output& { return r.plant; });
  std::uint32_t* flags = sh_py::add_column<std::uint32_t>(out, "flags", n);
  for (std::size_t k = 0; k < n; ++k) flags[k] = rows[k].plant.flags;
  sh_py::rows_to_dict(out, table, rows, n);
  return out;
}

//! A loop's per-sample struct in Python: .plant, then one read-only attribute per entry of its table.
template <class Row, std::size_t N>
void expose_row(py::module_& m, const char* name, const ChannelInfoOf<Row> (&table)[N]) {
  py::class_<Row> cls(m, name);
  cls.def_readonly("plant", &Row::plant, "the plant's sensors at t_k (Output)");
  for (const auto& c : table) cls.def_readonly(c.name, c.member, c.doc);
}

const double* optional_input(const std::optional<Arr>& a, std::size_t n, const char* name) {
  if (!a) return nullptr;
  if (a->ndim() != 1 || static_cast<std::size_t>(a->shape(0)) != n)
    throw Error(std::string("invalid ") + name + ": expected a 1-D array as long as ground_acceleration");
  return a->data();
}
}  // namespace

// The optional sensor and converter blocks of the loops (loop_converters.hpp).
// A config's field table (config_fields.hpp): def_readwrite of every field (its meaning as the doc);
// returns the field names in table order for add_protocol.
template <class Cls, class Table>
std::vector<std::string> def_fields(Cls& cls, const Table& table) {
  std::vector<std::string> names;
  std::apply([&](const auto&... f) { ((cls.def_readwrite(f.name, f.member, f.meaning), names.push_back(f.name)), ...); },
             table);
  return names;
}

//! [(name, unit, meaning), ...] of a config's field table.
template <class Table>
py::list field_table(const Table& table) {
  py::list out;
  std::apply([&](const auto&... f) { (out.append(py::make_tuple(f.name, f.unit, f.meaning)), ...); }, table);
  return out;
}

void expose_loop_converters(py::module_& m) {
  py::class_<SensorChannel>(m, "SensorChannel", "noise, A/D converter and unit delay of one measured channel")
      .def(py::init<>())
      .def_readwrite("noise", &SensorChannel::noise)
      .def_readwrite("converter", &SensorChannel::converter)
      .def_readwrite("unit_delay", &SensorChannel::unit_delay)
      .def_property_readonly("active", &SensorChannel::active);
  py::class_<LoopConverters>(m, "LoopConverters", "the optional sensor and converter blocks of a loop (off by default)")
      .def(py::init<>())
      .def_readwrite("displacement", &LoopConverters::displacement)
      .def_readwrite("velocity", &LoopConverters::velocity)
      .def_readwrite("force", &LoopConverters::force)
      .def_readwrite("command", &LoopConverters::command)
      .def_readwrite("command_unit_delay", &LoopConverters::command_unit_delay)
      .def_readwrite("seed", &LoopConverters::seed)
      .def_readwrite("generator", &LoopConverters::generator)
      .def_property_readonly("active", &LoopConverters::active)
      .def("validate", &LoopConverters::validate);
  py::class_<LoopIo>(m, "LoopIo", "the blocks' state: measure(truth) -> measured Output, actuate(command)")
      .def(py::init<const LoopConverters&>(), py::arg("config") = LoopConverters{})
      .def("reset", [](LoopIo& io) { bindings::require_idle(&io, "LoopIo.reset"); io.reset(); })
      .def("measure", [](LoopIo& io, double x, double v, double f) {
        bindings::require_idle(&io, "LoopIo.measure");
        Output truth, y;
        truth.displacement = x;
        truth.velocity = v;
        truth.force = f;
        io.measure(truth, y);
        return py::make_tuple(y.displacement, y.velocity, y.force);
      }, py::arg("displacement"), py::arg("velocity"), py::arg("force"),
      "One sample: the true (displacement, velocity, force) -> the measured ones")
      .def("actuate", [](LoopIo& io, double u) {
        bindings::require_idle(&io, "LoopIo.actuate");
        return io.actuate(u);
      }, py::arg("command"))
      .def_property_readonly("active", &LoopIo::active)
      .def_property_readonly("config", &LoopIo::config);
}

void expose_loops(py::module_& m) {
  // --- integration schemes of Eq (15) ---------------------------------------------------------------
  py::class_<ModelSDOF> model(m, "ModelSDOF", "Modelled SDOF system of Eq (15): m_m [kg], c_m [N s/m]");
  model.def(py::init<>())
      .def(py::init([](double m_m, double c_m) { return ModelSDOF{m_m, c_m}; }), py::arg("m_m"), py::arg("c_m"))
      .def("validate", &ModelSDOF::validate);
  add_protocol(model, def_fields(model, kModelSdofFields));
  m.attr("MODEL_SDOF_FIELDS") = field_table(kModelSdofFields);
  py::class_<IntegratorState>(m, "IntegratorState")
      .def_readonly("displacement", &IntegratorState::displacement)
      .def_readonly("velocity", &IntegratorState::velocity)
      .def_readonly("acceleration", &IntegratorState::acceleration)
      .def_readonly("next_displacement", &IntegratorState::next_displacement);
  m.attr("SolverState") = m.attr("IntegratorState");  // the name before issue 11
  sh_py::bind_enum(m, "StructuralScheme", kSchemeNames);
  m.attr("SCHEME_NAMES") = sh_py::enum_names(kSchemeNames);
  m.attr("IntegrationScheme") = m.attr("StructuralScheme");  // the RPsD name before issue 22
  m.attr("SolverKind") = m.attr("StructuralScheme");  // the name before issue 11
  py::class_<CentralDifference>(m, "CentralDifference", "Explicit central-difference solver of Eq (15)")
      .def(py::init<const ModelSDOF&, double>(), py::arg("model"), py::arg("dt"))
      .def("reset", &CentralDifference::reset, py::arg("d0") = 0.0)
      .def("step", &CentralDifference::step, py::arg("load"), py::arg("restoring_force"))
      .def_property_readonly("state", &CentralDifference::state);
  py::class_<ExplicitNewmark>(m, "ExplicitNewmark", "Explicit Newmark solver of Eq (15) (gamma = 1/2)")
      .def(py::init<const ModelSDOF&, double, double>(), py::arg("model"), py::arg("dt"), py::arg("gamma") = 0.5)
      .def("reset", &ExplicitNewmark::reset, py::arg("d0") = 0.0)
      .def("step", &ExplicitNewmark::step, py::arg("load"), py::arg("restoring_force"))
      .def_property_readonly("state", &ExplicitNewmark::state);

  // --- EFT -------------------------------------------------------------------
  py::class_<EftConfig> eft_config(m, "EftConfig");
  eft_config.def(py::init<>()).def("validate", &EftConfig::validate);
  add_protocol(eft_config, def_fields(eft_config, kEftConfigFields));
  m.attr("EFT_CONFIG_FIELDS") = field_table(kEftConfigFields);
  py::class_<EftLoopOptions> eft_options(m, "EftLoopOptions", "How the EFT loop simulates the plant (loops.hpp)");
  eft_options.def(py::init<>()).def("validate", &EftLoopOptions::validate);
  add_protocol(eft_options, def_fields(eft_options, kEftLoopOptionFields));
  m.attr("EFT_LOOP_OPTION_FIELDS") = field_table(kEftLoopOptionFields);
  expose_row(m, "EftOutput", kEftChannels);
  m.attr("EFT_CHANNELS") = sh_py::channel_units(kEftChannels);
  py::class_<EftController>(m, "EftController",
                            "EFT controller (Fig 1a): sensors at t_k and a_g -> force command [N]")
      .def(py::init<const EftConfig&, const Rig&, TrackingController*>(), py::arg("config"), py::arg("model"),
           py::arg("tracking") = py::none(), py::keep_alive<1, 4>())
      .def("reset", bindings::guarded(&EftController::reset, "EftController.reset"))
      .def("command",
           [](EftController& c, const Output& s, double ag) {
             bindings::require_idle(&c, "EftController.command");
             return c.command(s, ag);
           },
           py::arg("sensors"), py::arg("ground_acceleration"))
      .def(
          "command_output",
          [](EftController& c, const Output& s, double ag) {
            bindings::require_idle(&c, "EftController.command_output");
            EftOutput o;
            c.command(s, ag, &o);
            return o;
          },
          py::arg("sensors"), py::arg("ground_acceleration"), "As command(), returning every channel (EftOutput)")
      .def_property_readonly("config", &EftController::config)
      .def_property_readonly("mass", &EftController::mass)
      .def_property_readonly("compensator", &EftController::compensator, py::return_value_policy::reference_internal);
  expose_loop_converters(m);
  py::class_<EffectiveForceTest>(m, "EffectiveForceTest", "Effective force testing loop (force control, Fig 1a)")
      .def(py::init<const Rig&, const EftConfig&, const std::optional<Rig>&, const LoopConverters&,
                    TrackingController*, const EftLoopOptions&>(),
           py::arg("rig"), py::arg("config"), py::arg("model") = py::none(), py::arg("converters") = LoopConverters{},
           py::arg("tracking") = py::none(), py::arg("options") = EftLoopOptions{}, py::keep_alive<1, 6>())
      .def_property_readonly("converters", [](const EffectiveForceTest& t) { return t.converters().config(); })
      .def("reset",
           [](EffectiveForceTest& t) {
             bindings::require_idle(&t, "EffectiveForceTest.reset");
             t.reset();
           })
      .def(
          "step",
          [](EffectiveForceTest& t, double ag) {
            bindings::require_idle(&t, "EffectiveForceTest.step");
            EftOutput o;
            Status s = t.step(ag, o);
            return py::make_tuple(s, o);
          },
          py::arg("ground_acceleration"))
      .def(
          "run",
          [](EffectiveForceTest& t, Arr ag) {
            if (ag.ndim() != 1) throw Error("ground_acceleration must be a 1-D array");
            const auto n = static_cast<std::size_t>(ag.shape(0));
            std::vector<EftOutput> rows(n);
            RunSummary sum;
            const double* a = ag.data();
            {
              bindings::BusyGuard busy({&t, &t.plant(), &t.controller(), &t.compensator()},
                                       "EffectiveForceTest.run");
              py::gil_scoped_release release;
              sum = run_eft(t, a, n, rows.data());
            }
            return py::make_tuple(to_dict(rows, sum.rows, kEftChannels), sum);
          },
          py::arg("ground_acceleration"),
          "Runs one sample per element from the current state; returns (channels dict, RunSummary). Releases the GIL.")
      .def_property_readonly("plant", &EffectiveForceTest::plant, py::return_value_policy::reference_internal)
      .def_property_readonly("compensator", &EffectiveForceTest::compensator,
                             py::return_value_policy::reference_internal)
      .def_property_readonly("controller", &EffectiveForceTest::controller,
                             py::return_value_policy::reference_internal);

  // --- RPsD ------------------------------------------------------------------
  sh_py::bind_enum(m, "RestoringForce", kRestoringForceNames);
  sh_py::bind_enum(m, "ForceMeasurement", kForceMeasurementNames);
  m.attr("RESTORING_FORCE_NAMES") = sh_py::enum_names(kRestoringForceNames);
  m.attr("FORCE_MEASUREMENT_NAMES") = sh_py::enum_names(kForceMeasurementNames);
  py::class_<RpsdConfig> rpsd_config(m, "RpsdConfig");
  rpsd_config.def(py::init<>()).def("validate", &RpsdConfig::validate);
  add_protocol(rpsd_config, def_fields(rpsd_config, kRpsdConfigFields));
  m.attr("RPSD_CONFIG_FIELDS") = field_table(kRpsdConfigFields);
  py::class_<RpsdLoopOptions> rpsd_options(m, "RpsdLoopOptions", "How the RPsD loop simulates the plant (loops.hpp)");
  rpsd_options.def(py::init<>()).def("validate", &RpsdLoopOptions::validate);
  add_protocol(rpsd_options, def_fields(rpsd_options, kRpsdLoopOptionFields));
  m.attr("RPSD_LOOP_OPTION_FIELDS") = field_table(kRpsdLoopOptionFields);
  expose_row(m, "RpsdOutput", kRpsdChannels);
  m.attr("RPSD_CHANNELS") = sh_py::channel_units(kRpsdChannels);
  py::class_<RpsdController>(m, "RpsdController",
                             "RPsD controller (Figs 1b, 7): sensors at t_k, a_g, P_ext -> displacement command [m]")
      .def(py::init<const RpsdConfig&, const Rig&, TrackingController*, NumericalSubstructure*>(), py::arg("config"),
           py::arg("physical"), py::arg("tracking") = py::none(), py::arg("substructure") = py::none(),
           py::keep_alive<1, 4>(), py::keep_alive<1, 5>())
      .def("reset", bindings::guarded(&RpsdController::reset, "RpsdController.reset"))
      .def("command",
           [](RpsdController& c, const Output& s, double ag, double pe, double fe) {
             bindings::require_idle(&c, "RpsdController.command");
             return c.command(s, ag, pe, fe);
           },
           py::arg("sensors"), py::arg("ground_acceleration"), py::arg("external_force") = 0.0,
           py::arg("restoring_force_error") = 0.0)
      .def(
          "command_output",
          [](RpsdController& c, const Output& s, double ag, double pe, double fe) {
            bindings::require_idle(&c, "RpsdController.command_output");
            RpsdOutput o;
            c.command(s, ag, pe, fe, &o);
            return o;
          },
          py::arg("sensors"), py::arg("ground_acceleration"), py::arg("external_force") = 0.0,
          py::arg("restoring_force_error") = 0.0, "As command(), returning every channel (RpsdOutput)")
      .def_property_readonly("config", &RpsdController::config)
      .def_property_readonly("integrator_state", &RpsdController::integrator_state)
      .def_property_readonly("k_m", &RpsdController::k_m)
      .def_property_readonly("subtract_mass", &RpsdController::subtract_mass)
      .def_property_readonly("subtract_damping", &RpsdController::subtract_damping);
  py::class_<RealTimePseudoDynamicTest>(m, "RealTimePseudoDynamicTest",
                                        "Real-time pseudodynamic testing loop (displacement control, Figs 1b, 7)")
      .def(py::init<const Rig&, const RpsdConfig&, const LoopConverters&, TrackingController*,
                    NumericalSubstructure*, const RpsdLoopOptions&>(),
           py::arg("rig"), py::arg("config"), py::arg("converters") = LoopConverters{},
           py::arg("tracking") = py::none(), py::arg("substructure") = py::none(),
           py::arg("options") = RpsdLoopOptions{}, py::keep_alive<1, 5>(), py::keep_alive<1, 6>(),
           "tracking: a TrackingController in place of the amplitude lead; substructure: a NumericalSubstructure "
           "(e.g. rths.LinearSubstructure, rths.PythonSubstructure) in place of Eq (15)'s 1-DOF model")
      .def_property_readonly("converters", [](const RealTimePseudoDynamicTest& t) { return t.converters().config(); })
      .def("reset",
           [](RealTimePseudoDynamicTest& t) {
             bindings::require_idle(&t, "RealTimePseudoDynamicTest.reset");
             t.reset();
           })
      .def(
          "step",
          [](RealTimePseudoDynamicTest& t, double ag, double pe, double fe) {
            bindings::require_idle(&t, "RealTimePseudoDynamicTest.step");
            RpsdOutput o;
            Status s = t.step(ag, pe, fe, o);
            return py::make_tuple(s, o);
          },
          py::arg("ground_acceleration"), py::arg("external_force") = 0.0, py::arg("restoring_force_error") = 0.0)
      .def(
          "run",
          [](RealTimePseudoDynamicTest& t, Arr ag, std::optional<Arr> pe, std::optional<Arr> fe) {
            if (ag.ndim() != 1) throw Error("ground_acceleration must be a 1-D array");
            const auto n = static_cast<std::size_t>(ag.shape(0));
            const double* pp = optional_input(pe, n, "external_force");
            const double* pf = optional_input(fe, n, "restoring_force_error");
            std::vector<RpsdOutput> rows(n);
            RunSummary sum;
            const double* a = ag.data();
            {
              bindings::BusyGuard busy({&t, &t.plant(), &t.controller(), &t.controller().substructure(),
                                        &t.controller().tracking()},
                                       "RealTimePseudoDynamicTest.run");
              py::gil_scoped_release release;
              sum = run_rpsd(t, a, pp, pf, n, rows.data());
            }
            return py::make_tuple(to_dict(rows, sum.rows, kRpsdChannels), sum);
          },
          py::arg("ground_acceleration"), py::arg("external_force") = py::none(),
          py::arg("restoring_force_error") = py::none(),
          "Runs one sample per element from the current state; returns (channels dict, RunSummary). Releases the GIL.")
      .def_property_readonly("plant", &RealTimePseudoDynamicTest::plant, py::return_value_policy::reference_internal)
      .def_property_readonly("controller", &RealTimePseudoDynamicTest::controller,
                             py::return_value_policy::reference_internal)
      .def_property_readonly("integrator_state", &RealTimePseudoDynamicTest::integrator_state)
      .def_static("physical_rig", &RealTimePseudoDynamicTest::physical_rig, py::arg("rig"), py::arg("config"),
                  py::arg("options") = RpsdLoopOptions{},
                  "The rig the plant simulates: rig with m = options.physical_mass_fraction * config.model.m_m")
      .def_property_readonly("k_m", &RealTimePseudoDynamicTest::k_m)
      .def_property_readonly("subtract_mass", &RealTimePseudoDynamicTest::subtract_mass)
      .def_property_readonly("subtract_damping", &RealTimePseudoDynamicTest::subtract_damping);
}
