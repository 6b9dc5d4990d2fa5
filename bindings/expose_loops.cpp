#include <optional>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "servohydraulics/loops.hpp"

namespace py = pybind11;
using namespace servohydraulics;

namespace {
using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;

const std::pair<const char*, double Output::*> kPlantFields[] = {
    {"time", &Output::t},         {"displacement", &Output::displacement}, {"velocity", &Output::velocity},
    {"acceleration", &Output::acceleration}, {"force", &Output::force},   {"pressure", &Output::pressure},
    {"spool", &Output::spool},    {"drive", &Output::drive},               {"flow", &Output::flow}};

const std::pair<const char*, double EftOutput::*> kEftFields[] = {
    {"ground_acceleration", &EftOutput::ground_acceleration},
    {"effective_force", &EftOutput::effective_force},
    {"compensation", &EftOutput::compensation},
    {"compensation_opening", &EftOutput::compensation_opening},
    {"command", &EftOutput::command}};

const std::pair<const char*, double RpsdOutput::*> kRpsdFields[] = {
    {"ground_acceleration", &RpsdOutput::ground_acceleration},
    {"external_force", &RpsdOutput::external_force},
    {"measured_restoring_force", &RpsdOutput::measured_restoring_force},
    {"restoring_force", &RpsdOutput::restoring_force},
    {"calc_displacement", &RpsdOutput::calc_displacement},
    {"calc_velocity", &RpsdOutput::calc_velocity},
    {"calc_acceleration", &RpsdOutput::calc_acceleration},
    {"target_displacement", &RpsdOutput::target_displacement},
    {"command", &RpsdOutput::command}};

template <class Row, std::size_t N>
py::dict to_dict(const std::vector<Row>& rows, std::size_t n, const std::pair<const char*, double Row::*> (&extra)[N]) {
  py::dict out;
  for (const auto& [name, mp] : kPlantFields) {
    py::array_t<double> a(static_cast<py::ssize_t>(n));
    double* d = a.mutable_data();
    for (std::size_t k = 0; k < n; ++k) d[k] = rows[k].plant.*mp;
    out[name] = a;
  }
  py::array_t<std::uint32_t> flags(static_cast<py::ssize_t>(n));
  for (std::size_t k = 0; k < n; ++k) flags.mutable_data()[k] = rows[k].plant.flags;
  out["flags"] = flags;
  for (const auto& [name, mp] : extra) {
    py::array_t<double> a(static_cast<py::ssize_t>(n));
    double* d = a.mutable_data();
    for (std::size_t k = 0; k < n; ++k) d[k] = rows[k].*mp;
    out[name] = a;
  }
  return out;
}

const double* optional_input(const std::optional<Arr>& a, std::size_t n, const char* name) {
  if (!a) return nullptr;
  if (a->ndim() != 1 || static_cast<std::size_t>(a->shape(0)) != n)
    throw Error(std::string("invalid ") + name + ": expected a 1-D array as long as ground_acceleration");
  return a->data();
}
}  // namespace

void expose_loops(py::module_& m) {
  // --- solvers ---------------------------------------------------------------
  py::class_<ModelSDOF>(m, "ModelSDOF", "Modelled SDOF system of Eq (15): m_m [kg], c_m [N s/m]")
      .def(py::init<>())
      .def(py::init([](double m_m, double c_m) { return ModelSDOF{m_m, c_m}; }), py::arg("m_m"), py::arg("c_m"))
      .def_readwrite("m_m", &ModelSDOF::m_m)
      .def_readwrite("c_m", &ModelSDOF::c_m)
      .def("validate", &ModelSDOF::validate);
  py::class_<SolverState>(m, "SolverState")
      .def_readonly("displacement", &SolverState::displacement)
      .def_readonly("velocity", &SolverState::velocity)
      .def_readonly("acceleration", &SolverState::acceleration)
      .def_readonly("next_displacement", &SolverState::next_displacement);
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
  py::class_<EftConfig>(m, "EftConfig")
      .def(py::init<>())
      .def_readwrite("dt", &EftConfig::dt)
      .def_readwrite("mass", &EftConfig::mass)
      .def_readwrite("compensation", &EftConfig::compensation)
      .def_readwrite("lead_T", &EftConfig::lead_T)
      .def_readwrite("alpha", &EftConfig::alpha)
      .def_readwrite("compute_delay", &EftConfig::compute_delay)
      .def_readwrite("plant_options", &EftConfig::plant_options)
      .def("validate", &EftConfig::validate);
  py::class_<EftOutput>(m, "EftOutput")
      .def_readonly("plant", &EftOutput::plant)
      .def_readonly("ground_acceleration", &EftOutput::ground_acceleration)
      .def_readonly("effective_force", &EftOutput::effective_force)
      .def_readonly("compensation", &EftOutput::compensation)
      .def_readonly("compensation_opening", &EftOutput::compensation_opening)
      .def_readonly("command", &EftOutput::command);
  py::class_<EffectiveForceTest>(m, "EffectiveForceTest", "Effective force testing loop (force control, Fig 1a)")
      .def(py::init([](const Rig& rig, const EftConfig& cfg, std::optional<Rig> model) {
             return std::make_unique<EffectiveForceTest>(rig, cfg, model ? &*model : nullptr);
           }),
           py::arg("rig"), py::arg("config"), py::arg("model") = py::none())
      .def("reset", &EffectiveForceTest::reset)
      .def(
          "step",
          [](EffectiveForceTest& t, double ag) {
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
              py::gil_scoped_release release;
              sum = run_eft(t, a, n, rows.data());
            }
            return py::make_tuple(to_dict(rows, sum.rows, kEftFields), sum);
          },
          py::arg("ground_acceleration"),
          "Runs one sample per element from the current state; returns (channels dict, RunSummary). Releases the GIL.")
      .def_property_readonly("plant", &EffectiveForceTest::plant, py::return_value_policy::reference_internal)
      .def_property_readonly("compensator", &EffectiveForceTest::compensator,
                             py::return_value_policy::reference_internal);

  // --- RPsD ------------------------------------------------------------------
  py::enum_<RestoringForce>(m, "RestoringForce")
      .value("CalculatedDisplacement", RestoringForce::CalculatedDisplacement)
      .value("MeasuredDisplacement", RestoringForce::MeasuredDisplacement)
      .value("MeasuredForce", RestoringForce::MeasuredForce)
      .value("MeasuredForceCorrected", RestoringForce::MeasuredForceCorrected);
  py::enum_<SolverKind>(m, "SolverKind")
      .value("CentralDifference", SolverKind::CentralDifference)
      .value("ExplicitNewmark", SolverKind::ExplicitNewmark);
  py::enum_<ForceMeasurement>(m, "ForceMeasurement")
      .value("LoadCell", ForceMeasurement::LoadCell)
      .value("ActuatorPressure", ForceMeasurement::ActuatorPressure);
  py::class_<RpsdConfig>(m, "RpsdConfig")
      .def(py::init<>())
      .def_readwrite("dt", &RpsdConfig::dt)
      .def_readwrite("model", &RpsdConfig::model)
      .def_readwrite("k_m", &RpsdConfig::k_m)
      .def_readwrite("solver", &RpsdConfig::solver)
      .def_readwrite("restoring_force", &RpsdConfig::restoring_force)
      .def_readwrite("force_measurement", &RpsdConfig::force_measurement)
      .def_readwrite("amplitude_T", &RpsdConfig::amplitude_T)
      .def_readwrite("delay_T", &RpsdConfig::delay_T)
      .def_readwrite("alpha", &RpsdConfig::alpha)
      .def_readwrite("physical_mass_fraction", &RpsdConfig::physical_mass_fraction)
      .def_readwrite("subtract_mass", &RpsdConfig::subtract_mass)
      .def_readwrite("subtract_damping", &RpsdConfig::subtract_damping)
      .def_readwrite("compute_delay", &RpsdConfig::compute_delay)
      .def_readwrite("plant_options", &RpsdConfig::plant_options)
      .def("validate", &RpsdConfig::validate);
  py::class_<RpsdOutput>(m, "RpsdOutput")
      .def_readonly("plant", &RpsdOutput::plant)
      .def_readonly("ground_acceleration", &RpsdOutput::ground_acceleration)
      .def_readonly("external_force", &RpsdOutput::external_force)
      .def_readonly("measured_restoring_force", &RpsdOutput::measured_restoring_force)
      .def_readonly("restoring_force", &RpsdOutput::restoring_force)
      .def_readonly("calc_displacement", &RpsdOutput::calc_displacement)
      .def_readonly("calc_velocity", &RpsdOutput::calc_velocity)
      .def_readonly("calc_acceleration", &RpsdOutput::calc_acceleration)
      .def_readonly("target_displacement", &RpsdOutput::target_displacement)
      .def_readonly("command", &RpsdOutput::command);
  py::class_<RealTimePseudoDynamicTest>(m, "RealTimePseudoDynamicTest",
                                        "Real-time pseudodynamic testing loop (displacement control, Figs 1b, 7)")
      .def(py::init<const Rig&, const RpsdConfig&>(), py::arg("rig"), py::arg("config"))
      .def("reset", &RealTimePseudoDynamicTest::reset)
      .def(
          "step",
          [](RealTimePseudoDynamicTest& t, double ag, double pe, double fe) {
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
              py::gil_scoped_release release;
              sum = run_rpsd(t, a, pp, pf, n, rows.data());
            }
            return py::make_tuple(to_dict(rows, sum.rows, kRpsdFields), sum);
          },
          py::arg("ground_acceleration"), py::arg("external_force") = py::none(),
          py::arg("restoring_force_error") = py::none(),
          "Runs one sample per element from the current state; returns (channels dict, RunSummary). Releases the GIL.")
      .def_property_readonly("plant", &RealTimePseudoDynamicTest::plant, py::return_value_policy::reference_internal)
      .def_property_readonly("solver_state", &RealTimePseudoDynamicTest::solver_state)
      .def_property_readonly("k_m", &RealTimePseudoDynamicTest::k_m)
      .def_property_readonly("subtract_mass", &RealTimePseudoDynamicTest::subtract_mass)
      .def_property_readonly("subtract_damping", &RealTimePseudoDynamicTest::subtract_damping);
}
