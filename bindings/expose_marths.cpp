// The multi-actuator seam (multi_actuator.hpp, coupler.hpp) and the maRTHS benchmark's blocks
// (servohydraulics/marths/*.hpp): no logic here.
#include <cmath>
#include <complex>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "busy.hpp"
#include "channels_py.hpp"
#include "multi_trampoline.hpp"
#include "servohydraulics/coupler.hpp"
#include "servohydraulics/marths/controllers.hpp"
#include "servohydraulics/marths/loop.hpp"

namespace py = pybind11;
using namespace servohydraulics;
using namespace servohydraulics::marths;

namespace {
using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;

const double* vector_of(const Arr& a, std::size_t n, const char* name) {
  if (a.ndim() != 1 || static_cast<std::size_t>(a.size()) != n)
    throw Error(std::string("invalid ") + name + ": expected " + std::to_string(n) + " values");
  return a.data();
}

py::tuple run_loop(MarthsLoop& loop, const GroundMotion& ag, std::size_t n, bool timing) {
  std::vector<MarthsOutput> rows(n);
  Arr steps(timing ? static_cast<py::ssize_t>(n) : 0);
  RunSummary s;
  {
    bindings::BusyGuard busy({&loop, &loop.plant(), &loop.controller(), &ag}, "MarthsLoop.run");
    py::gil_scoped_release release;
    loop.reset();
    s = loop.run(ag, n, rows.data(), timing ? steps.mutable_data() : nullptr);
  }
  const double dt = loop.config().dt;
  bindings::raise_multi_controller_error(loop.controller(), dt);
  if (const auto* d = dynamic_cast<const DecentralizedController*>(&loop.controller()))
    for (std::size_t i = 0; i < d->actuators(); ++i) bindings::raise_controller_error(d->channel(i), dt);
  if (const auto* p = dynamic_cast<const bindings::PythonMultiActuatorSystem*>(&loop.plant()); p && !p->error().empty())
    throw std::runtime_error("plant failed at t = " + std::to_string(s.failure_time) + " s: " + p->error());
  py::dict out;
  sh_py::rows_to_dict(out, kMarthsChannels, rows, s.rows);
  if (timing) out["step_seconds"] = steps[py::slice(0, static_cast<py::ssize_t>(s.rows), 1)];
  return py::make_tuple(out, s);
}
}  // namespace

void expose_marths(py::module_& m) {
  // --- the seam (multi_actuator.hpp, coupler.hpp) ------------------------------------------------------
  py::class_<MultiActuatorSystem>(m, "MultiActuatorSystem",
                                  "N displacement-commanded actuators on one specimen (multi_actuator.hpp)")
      .def_property_readonly("actuators", &MultiActuatorSystem::actuators)
      .def_property_readonly("dt", &MultiActuatorSystem::dt)
      .def("reset", [](MultiActuatorSystem& s) {
        bindings::require_idle(&s, "MultiActuatorSystem.reset");
        s.reset();
      })
      .def("displacements", [](const MultiActuatorSystem& s) {
        bindings::require_idle(&s, "MultiActuatorSystem.displacements");
        std::vector<double> y(s.actuators());
        s.displacements(y.data());
        return py::array_t<double>(static_cast<py::ssize_t>(y.size()), y.data());
      }, "the N actuator displacements at the current time [m]")
      .def("step", [](MultiActuatorSystem& s, const Arr& u) {
        bindings::require_idle(&s, "MultiActuatorSystem.step");
        return s.step(vector_of(u, s.actuators(), "u"));
      }, py::arg("u"), "one sample with the N commands u [m] held; returns the Status");
  py::class_<bindings::PythonMultiActuatorSystem, MultiActuatorSystem>(
      m, "PythonMultiActuatorSystem",
      "a Python object (attributes actuators, dt; reset(), displacements() -> N floats [m], step(u)) as a "
      "MultiActuatorSystem")
      .def(py::init<py::object>(), py::arg("plant"))
      .def_property_readonly("plant", &bindings::PythonMultiActuatorSystem::object)
      .def_property_readonly("error", &bindings::PythonMultiActuatorSystem::error);
  py::class_<MultiTrackingController, bindings::PyMultiTrackingController>(
      m, "MultiTrackingController",
      "a multi-actuator tracking compensator: subclass it (super().__init__(N); reset(); command(desired, measured, "
      "[desired_velocity=, desired_acceleration=]) -> N commands [m])")
      .def(py::init<std::size_t>(), py::arg("actuators"))
      .def_property_readonly("actuators", &MultiTrackingController::actuators)
      .def("reset", [](MultiTrackingController& c) {
        bindings::require_idle(&c, "MultiTrackingController.reset");
        c.reset();
        bindings::raise_multi_controller_error(c, std::nan(""));
      })
      .def("command", [](MultiTrackingController& c, const Arr& desired, const Arr& measured,
                         std::optional<Arr> dv, std::optional<Arr> da) {
        bindings::require_idle(&c, "MultiTrackingController.command");
        const std::size_t n = c.actuators();
        MultiTrackingInput in{n, vector_of(desired, n, "desired"), vector_of(measured, n, "measured"),
                              dv ? vector_of(*dv, n, "desired_velocity") : nullptr,
                              da ? vector_of(*da, n, "desired_acceleration") : nullptr};
        std::vector<double> u(n);
        c.command(in, u.data());
        bindings::raise_multi_controller_error(c, std::nan(""));
        return py::array_t<double>(static_cast<py::ssize_t>(n), u.data());
      }, py::arg("desired"), py::arg("measured"), py::arg("desired_velocity") = py::none(),
         py::arg("desired_acceleration") = py::none(),
         "The N commands [m] from the targets and measurements [m] (and the targets' rates [m/s, m/s^2]).");
  py::class_<bindings::PythonMultiController, MultiTrackingController>(
      m, "PythonMultiController", "any object with reset() and command(...) as a multi-actuator controller")
      .def(py::init<py::object, std::size_t>(), py::arg("controller"), py::arg("actuators") = 2)
      .def_property_readonly("controller", &bindings::PythonMultiController::object);

  py::class_<Coupler>(m, "Coupler", "the fixture kinematics: N actuators on rigid arms to one node (coupler.hpp)")
      .def(py::init([](const std::vector<double>& d, const std::vector<double>& a) {
             if (d.size() != a.size()) throw Error("invalid alpha: one angle per arm length d");
             return Coupler(d.size(), d.data(), a.data());
           }),
           py::arg("d"), py::arg("alpha"))
      .def_static("marths", &Coupler::marths)
      .def_property_readonly("actuators", &Coupler::actuators)
      .def("arm", &Coupler::arm, py::arg("i"))
      .def("angle", &Coupler::angle, py::arg("i"))
      .def("strokes", [](const Coupler& c, double x, double th) {
        std::vector<double> s(c.actuators());
        c.strokes(x, th, s.data());
        return py::array_t<double>(static_cast<py::ssize_t>(s.size()), s.data());
      }, py::arg("x"), py::arg("theta"))
      .def("dstroke_dtheta", &Coupler::dstroke_dtheta, py::arg("i"), py::arg("theta"))
      .def("d2stroke_dtheta2", &Coupler::d2stroke_dtheta2, py::arg("i"), py::arg("theta"))
      .def("node_from_strokes", [](const Coupler& c, const Arr& s) -> py::object {
        double x = 0.0, th = 0.0;
        if (!c.node_from_strokes(vector_of(s, c.actuators(), "s"), &x, &th)) return py::none();
        return py::make_tuple(x, th);
      }, py::arg("s"))
      .def("benchmark_estimate", [](const Coupler& c, const Arr& s) {
        double x = 0.0, th = 0.0;
        c.benchmark_estimate(vector_of(s, 2, "s"), &x, &th);
        return py::make_tuple(x, th);
      }, py::arg("s"));

  py::module_ r = m.def_submodule("marths", "the maRTHS benchmark's blocks (Condori Uribe et al. 2023)");
  r.attr("GroundMotion") = m.attr("GroundMotion");

  // --- filters (iir_filter.hpp) ------------------------------------------------------------------------------
  py::class_<IirCoefficients>(m, "IirCoefficients").def(py::init<>())
      .def(py::init([](const std::vector<double>& b, const std::vector<double>& a) {
             if (b.size() != a.size() || b.empty() || b.size() > IirCoefficients::kMaxOrder + 1)
               throw Error("invalid filter: b and a of one length, 1 to 9 coefficients");
             IirCoefficients c;
             c.order = b.size() - 1;
             for (std::size_t i = 0; i < b.size(); ++i) {
               c.b[i] = b[i] / a[0];
               c.a[i] = a[i] / a[0];
             }
             c.validate();
             return c;
           }),
           py::arg("b"), py::arg("a"))
      .def_readonly("order", &IirCoefficients::order)
      .def_property_readonly("b", [](const IirCoefficients& c) {
        return std::vector<double>(c.b.begin(), c.b.begin() + static_cast<long>(c.order) + 1);
      })
      .def_property_readonly("a", [](const IirCoefficients& c) {
        return std::vector<double>(c.a.begin(), c.a.begin() + static_cast<long>(c.order) + 1);
      })
      .def("dc_gain", &IirCoefficients::dc_gain);
  m.def("butterworth_lowpass", &butterworth_lowpass, py::arg("order"), py::arg("cutoff"), py::arg("fs"),
        "MATLAB's butter(order, cutoff / (fs/2)) low-pass (cutoff, fs in Hz)");
  py::class_<IirFilter>(m, "IirFilter")
      .def(py::init<const IirCoefficients&>(), py::arg("coefficients"))
      .def("reset", &IirFilter::reset)
      .def("step", &IirFilter::step, py::arg("u"))
      .def_property_readonly("pending", &IirFilter::pending)
      .def_property_readonly("feedthrough", &IirFilter::feedthrough);

  // --- the plant (marths/plant.hpp) --------------------------------------------------------------------------
  py::class_<StateSpace>(r, "StateSpace").def(py::init<>())
      .def(py::init([](Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, std::optional<Eigen::MatrixXd> D) {
             StateSpace s{A, B, C, D ? *D : Eigen::MatrixXd::Zero(C.rows(), B.cols())};
             s.validate(false);
             return s;
           }),
           py::arg("A"), py::arg("B"), py::arg("C"), py::arg("D") = py::none())
      .def_readwrite("A", &StateSpace::A).def_readwrite("B", &StateSpace::B)
      .def_readwrite("C", &StateSpace::C).def_readwrite("D", &StateSpace::D)
      .def("validate", &StateSpace::validate, py::arg("strictly_proper") = true)
      .def("frequency_response", &StateSpace::frequency_response, py::arg("s"))
      .def("taylor_coefficients", &StateSpace::taylor_coefficients, py::arg("order"));
  r.def("ode4_matrices", [](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h) {
    Eigen::MatrixXd P, G;
    ode4_matrices(A, B, h, P, G);
    return py::make_tuple(P, G);
  }, py::arg("A"), py::arg("B"), py::arg("h"), "(Phi, Gamma) of one ode4 step with the input held");
  py::class_<TransferMatrix>(r, "TransferMatrix").def(py::init<>())
      .def_readwrite("size", &TransferMatrix::size).def_readwrite("poles", &TransferMatrix::poles)
      .def_readwrite("zeros", &TransferMatrix::zeros).def_readwrite("gains", &TransferMatrix::gains)
      .def("validate", &TransferMatrix::validate)
      .def("element", &TransferMatrix::element, py::arg("i"), py::arg("j"), py::arg("s"))
      .def("frequency_response", &TransferMatrix::frequency_response, py::arg("s"))
      .def("dc_gain", &TransferMatrix::dc_gain)
      .def("realize", &TransferMatrix::realize);
  py::class_<BenchmarkPlantModel>(r, "BenchmarkPlantModel").def(py::init<>())
      .def_readwrite("h1_zero_1", &BenchmarkPlantModel::h1_zero_1)
      .def_readwrite("h1_zero_2", &BenchmarkPlantModel::h1_zero_2)
      .def_readwrite("h1_pole_1", &BenchmarkPlantModel::h1_pole_1)
      .def_readwrite("h1_pole_2", &BenchmarkPlantModel::h1_pole_2)
      .def_readwrite("frame_pole", &BenchmarkPlantModel::frame_pole)
      .def_readwrite("h12_zero", &BenchmarkPlantModel::h12_zero)
      .def_readwrite("h22_zero", &BenchmarkPlantModel::h22_zero)
      .def_readwrite("h2_pole_1", &BenchmarkPlantModel::h2_pole_1)
      .def_readwrite("h2_pole_2", &BenchmarkPlantModel::h2_pole_2)
      .def_readwrite("gain_11", &BenchmarkPlantModel::gain_11).def_readwrite("gain_21", &BenchmarkPlantModel::gain_21)
      .def_readwrite("gain_12", &BenchmarkPlantModel::gain_12).def_readwrite("gain_22", &BenchmarkPlantModel::gain_22)
      .def("transfer_matrix", &BenchmarkPlantModel::transfer_matrix);
  py::class_<PlantUncertainty>(r, "PlantUncertainty").def(py::init<>())
      .def_readwrite("h1_zeros", &PlantUncertainty::h1_zeros).def_readwrite("h1_poles", &PlantUncertainty::h1_poles)
      .def_readwrite("frame_pole", &PlantUncertainty::frame_pole)
      .def_readwrite("h12_zero", &PlantUncertainty::h12_zero).def_readwrite("h2_poles", &PlantUncertainty::h2_poles)
      .def_readwrite("h22_zero", &PlantUncertainty::h22_zero)
      .def_readwrite("match_frequency", &PlantUncertainty::match_frequency)
      .def("validate", &PlantUncertainty::validate)
      .def("perturb", [](const PlantUncertainty& u, const BenchmarkPlantModel& nominal, const std::vector<double>& z) {
        if (z.size() != 9) throw Error("invalid z: expected the nine standard normals");
        return u.perturb(nominal, z.data());
      }, py::arg("nominal"), py::arg("z"))
      .def("rescaled", &PlantUncertainty::rescaled, py::arg("nominal"), py::arg("perturbed"))
      .def("draw", &PlantUncertainty::draw, py::arg("nominal"), py::arg("seed"));
  py::class_<IdentifiedPlant, MultiActuatorSystem>(r, "IdentifiedPlant")
      .def(py::init<const StateSpace&, double, double>(), py::arg("model"), py::arg("dt"), py::arg("unit") = 1e-3)
      .def_property_readonly("model", &IdentifiedPlant::model)
      .def_property_readonly("phi", &IdentifiedPlant::phi)
      .def_property_readonly("gamma", &IdentifiedPlant::gamma)
      .def_property_readonly("state", &IdentifiedPlant::state)
      .def_property_readonly("unit", &IdentifiedPlant::unit);

  // --- structures (marths/structure.hpp) ---------------------------------------------------------------------
  py::class_<StructureMatrices>(r, "StructureMatrices").def(py::init<>())
      .def(py::init([](Eigen::MatrixXd M, Eigen::MatrixXd C, Eigen::MatrixXd K, Eigen::VectorXd l) {
             return StructureMatrices{M, C, K, l};
           }),
           py::arg("M"), py::arg("C"), py::arg("K"), py::arg("influence"))
      .def_readwrite("M", &StructureMatrices::M).def_readwrite("C", &StructureMatrices::C)
      .def_readwrite("K", &StructureMatrices::K).def_readwrite("influence", &StructureMatrices::influence)
      .def("validate", &StructureMatrices::validate);
  py::class_<NewmarkStructure>(r, "NewmarkStructure")
      .def(py::init<const StructureMatrices&, double, double, double>(), py::arg("matrices"), py::arg("dt"),
           py::arg("delta") = 0.5, py::arg("alpha") = 0.25)
      .def("reset", &NewmarkStructure::reset)
      .def("step", [](NewmarkStructure& s, double ag, std::optional<Arr> F) {
        s.step(ag, F ? vector_of(*F, static_cast<std::size_t>(s.matrices().size()), "F") : nullptr);
      }, py::arg("ag"), py::arg("F") = py::none())
      .def_property_readonly("displacement", &NewmarkStructure::displacement)
      .def_property_readonly("velocity", &NewmarkStructure::velocity)
      .def_property_readonly("acceleration", &NewmarkStructure::acceleration)
      .def_property_readonly("dynamic_stiffness_inverse", &NewmarkStructure::dynamic_stiffness_inverse);
  r.def("rayleigh_coefficients", &rayleigh_coefficients, py::arg("omega_i"), py::arg("omega_j"), py::arg("zeta"));
  py::class_<MarthsDofs>(r, "MarthsDofs").def(py::init<>())
      .def_readwrite("x", &MarthsDofs::x).def_readwrite("theta", &MarthsDofs::theta)
      .def_readwrite("theta_b", &MarthsDofs::theta_b).def_readwrite("x_2nd", &MarthsDofs::x_2nd)
      .def_readwrite("theta_2nd", &MarthsDofs::theta_2nd).def_readwrite("x_3rd", &MarthsDofs::x_3rd)
      .def_readwrite("theta_3rd", &MarthsDofs::theta_3rd);
  py::class_<IdealFrameParameters>(r, "IdealFrameParameters").def(py::init<>())
      .def_readwrite("Lb", &IdealFrameParameters::Lb).def_readwrite("Lc", &IdealFrameParameters::Lc)
      .def_readwrite("Ic", &IdealFrameParameters::Ic).def_readwrite("Ib", &IdealFrameParameters::Ib)
      .def_readwrite("Ac", &IdealFrameParameters::Ac).def_readwrite("Ab", &IdealFrameParameters::Ab)
      .def_readwrite("E", &IdealFrameParameters::E).def_readwrite("rho", &IdealFrameParameters::rho)
      .def_readwrite("zeta", &IdealFrameParameters::zeta)
      .def("K", &IdealFrameParameters::K).def("M", &IdealFrameParameters::M).def("C", &IdealFrameParameters::C);
  py::class_<PhysicalFrameParameters>(r, "PhysicalFrameParameters").def(py::init<>())
      .def_readwrite("Lb", &PhysicalFrameParameters::Lb).def_readwrite("Lc", &PhysicalFrameParameters::Lc)
      .def_readwrite("Ic", &PhysicalFrameParameters::Ic).def_readwrite("Ib", &PhysicalFrameParameters::Ib)
      .def_readwrite("Ac", &PhysicalFrameParameters::Ac).def_readwrite("Ab", &PhysicalFrameParameters::Ab)
      .def_readwrite("E", &PhysicalFrameParameters::E).def_readwrite("rho", &PhysicalFrameParameters::rho)
      .def_readwrite("mass_factor", &PhysicalFrameParameters::mass_factor)
      .def_readwrite("zeta", &PhysicalFrameParameters::zeta);
  py::class_<PhysicalFrame>(r, "PhysicalFrame")
      .def_static("from_parameters", &PhysicalFrame::from, py::arg("parameters") = PhysicalFrameParameters{})
      .def_readonly("K", &PhysicalFrame::K).def_readonly("M", &PhysicalFrame::M).def_readonly("C", &PhysicalFrame::C)
      .def_readonly("G", &PhysicalFrame::G).def_readonly("omegas", &PhysicalFrame::omegas);
  py::enum_<FrameReduction>(r, "FrameReduction")
      .value("Guyan", FrameReduction::Guyan)
      .value("Static", FrameReduction::Static);
  py::class_<CondensedFrame>(r, "CondensedFrame")
      .def_static("from_parameters", &CondensedFrame::from, py::arg("parameters") = PhysicalFrameParameters{},
                  py::arg("reduction") = FrameReduction::Guyan)
      .def_readonly("K", &CondensedFrame::K).def_readonly("M", &CondensedFrame::M).def_readonly("C", &CondensedFrame::C);
  py::class_<FrameFeedback>(r, "FrameFeedback")
      .def(py::init<const PhysicalFrame&, double>(), py::arg("frame"), py::arg("dt"))
      .def("reset", &FrameFeedback::reset)
      .def("__call__", [](FrameFeedback& f, double x, double th) {
        double out[5];
        f(x, th, out);
        return py::array_t<double>(5, out);
      }, py::arg("x"), py::arg("theta"), "the 5 generalised forces [N, N m] at this sample's (x [m], theta [rad])");
  py::class_<MarthsStructures>(r, "MarthsStructures")
      .def_static("build", &MarthsStructures::build, py::arg("K"), py::arg("M"), py::arg("influence"),
                  py::arg("ideal") = IdealFrameParameters{}, py::arg("physical") = PhysicalFrameParameters{},
                  py::arg("omega_i") = 13.493, py::arg("omega_j") = 165.125, py::arg("zeta") = 0.05,
                  py::arg("dofs") = MarthsDofs{})
      .def_readonly("reference", &MarthsStructures::reference)
      .def_readonly("numerical", &MarthsStructures::numerical)
      .def_readonly("frame", &MarthsStructures::frame)
      .def_readonly("dofs", &MarthsStructures::dofs);

  // --- controllers (marths/controllers.hpp) ------------------------------------------------------------------
  py::class_<RodeacChannel>(r, "RodeacChannel").def(py::init<>())
      .def(py::init([](Eigen::VectorXd th, Eigen::MatrixXd P) { return RodeacChannel{th, P}; }), py::arg("theta0"),
           py::arg("P0"))
      .def_readwrite("theta0", &RodeacChannel::theta0).def_readwrite("P0", &RodeacChannel::P0);
  py::class_<RodeacConfig>(r, "RodeacConfig").def(py::init<>())
      .def_readwrite("channels", &RodeacConfig::channels).def_readwrite("forgetting", &RodeacConfig::forgetting)
      .def_readwrite("filter", &RodeacConfig::filter).def_readwrite("unit", &RodeacConfig::unit)
      .def("validate", &RodeacConfig::validate);
  py::class_<RodeacController, MultiTrackingController>(r, "RodeacController")
      .def(py::init<const RodeacConfig&>(), py::arg("config"))
      .def("theta", [](const RodeacController& c, std::size_t i) { return Eigen::VectorXd(c.theta(i)); }, py::arg("i"))
      .def("P", [](const RodeacController& c, std::size_t i) { return Eigen::MatrixXd(c.P(i)); }, py::arg("i"));
  py::class_<PassThrough, MultiTrackingController>(r, "PassThrough")
      .def(py::init<std::size_t>(), py::arg("actuators") = 2);
  py::class_<DecentralizedController, MultiTrackingController>(r, "DecentralizedController")
      .def(py::init([](const std::vector<TrackingController*>& ch, double dt) {
             return new DecentralizedController(ch, dt);
           }),
           py::arg("channels"), py::arg("dt") = 0.0, py::keep_alive<1, 2>(),
           "one single-actuator TrackingController per actuator (the list is kept alive with this object); dt > 0: "
           "the targets' rates by backward differences at dt, 0: the loop's")
      .def_property_readonly("dt", &DecentralizedController::dt);
  py::class_<MimoFeedforwardConfig>(r, "MimoFeedforwardConfig").def(py::init<>())
      .def_readwrite("dt", &MimoFeedforwardConfig::dt)
      .def_readwrite("coefficients", &MimoFeedforwardConfig::coefficients)
      .def_readwrite("pi", &MimoFeedforwardConfig::pi)
      .def("validate", &MimoFeedforwardConfig::validate)
      .def_static("from_plant", &MimoFeedforwardConfig::from_plant, py::arg("plant"), py::arg("order") = 2,
                  py::arg("dt") = 1.0 / 1024.0);
  py::class_<MimoFeedforward, MultiTrackingController>(r, "MimoFeedforward")
      .def(py::init<const MimoFeedforwardConfig&>(), py::arg("config"));

  // --- the loop (marths/loop.hpp) ----------------------------------------------------------------------------
  py::class_<CommandVoltage>(r, "CommandVoltage").def(py::init<>())
      .def(py::init([](double g, double o, double c) { return CommandVoltage{g, o, c}; }), py::arg("gain"),
           py::arg("offset"), py::arg("correction"))
      .def_readwrite("gain", &CommandVoltage::gain).def_readwrite("offset", &CommandVoltage::offset)
      .def_readwrite("correction", &CommandVoltage::correction)
      .def("volts", &CommandVoltage::volts, py::arg("u_mm"))
      .def("millimetres", &CommandVoltage::millimetres, py::arg("v"));
  py::class_<MarthsLoopConfig>(r, "MarthsLoopConfig").def(py::init<>())
      .def_readwrite("dt", &MarthsLoopConfig::dt)
      .def_readwrite("noise_power", &MarthsLoopConfig::noise_power)
      .def_readwrite("sensor_unit", &MarthsLoopConfig::sensor_unit)
      .def_readwrite("independent_noise", &MarthsLoopConfig::independent_noise)
      .def_readwrite("seed", &MarthsLoopConfig::seed)
      .def_readwrite("generator", &MarthsLoopConfig::generator)
      .def_readwrite("voltage", &MarthsLoopConfig::voltage)
      .def_readwrite("daq_quantizer", &MarthsLoopConfig::daq_quantizer)
      .def_readwrite("daq_saturation", &MarthsLoopConfig::daq_saturation)
      .def_readwrite("daq_quantum", &MarthsLoopConfig::daq_quantum)
      .def_readwrite("daq_limit", &MarthsLoopConfig::daq_limit)
      .def_readwrite("exact_kinematics", &MarthsLoopConfig::exact_kinematics)
      .def("validate", &MarthsLoopConfig::validate)
      .def("noise_sigma", &MarthsLoopConfig::noise_sigma);
  r.attr("MARTHS_CHANNELS") = sh_py::channel_units(kMarthsChannels);
  py::class_<MarthsLoop>(r, "MarthsLoop")
      .def(py::init<MultiActuatorSystem&, MultiTrackingController&, const MarthsStructures&, const MarthsLoopConfig&,
                    const Coupler&>(),
           py::arg("plant"), py::arg("controller"), py::arg("structures"), py::arg("config") = MarthsLoopConfig{},
           py::arg("coupler") = Coupler::marths(), py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def("run", &run_loop, py::arg("ground_motion"), py::arg("n"), py::arg("timing") = false,
           "Reset, then run n samples: (channels dict, RunSummary); one column per MARTHS_CHANNELS entry "
           "and step_seconds (if timing). Releases the GIL; what a Python controller or plant raised is re-raised.")
      .def_property_readonly("config", &MarthsLoop::config);
}
