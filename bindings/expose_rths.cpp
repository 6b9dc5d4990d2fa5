// The RTHS benchmark's blocks (servohydraulics/rths/*.hpp): no logic here.
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "busy.hpp"
#include "channels_py.hpp"
#include "tracking_trampoline.hpp"
#include "servohydraulics/rths/loop.hpp"

namespace py = pybind11;
using namespace servohydraulics;
using namespace servohydraulics::rths;

namespace {
using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> to_vector(const Arr& a, const char* name) {
  if (a.ndim() != 1) throw Error(std::string("invalid ") + name + ": expected a 1-D array");
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

// Calls from a loop that runs without the GIL into a Python object: each call takes the GIL;
// the first exception marks the object failed (later calls are skipped) and keeps its
// "Type: message" (without the traceback pybind11 appends) for run() to raise.
class PythonCalls {
 public:
  explicit PythonCalls(py::object obj) : obj_(std::move(obj)) {}
  py::object attr(const char* name) const { return obj_.attr(name); }
  //! The loop's reset: clears a failure, calls the object's reset(), then then().
  template <class F>
  void reset(F&& then) noexcept {
    failed_ = false;
    error_.clear();
    (*this)([&] {
      obj_.attr("reset")();
      then();
    });
  }
  template <class F>
  void operator()(F&& f) const noexcept {
    if (failed_) return;
    py::gil_scoped_acquire gil;
    try {
      f();
    } catch (py::error_already_set& e) {
      failed_ = true;
      try {
        error_ = py::str(e.type().attr("__name__")).cast<std::string>() + ": " + py::str(e.value()).cast<std::string>();
      } catch (...) {
        error_ = e.what();
      }
    } catch (const std::exception& e) {
      failed_ = true;
      error_ = e.what();
    }
  }
  bool failed() const noexcept { return failed_; }
  const std::string& error() const noexcept { return error_; }
  const py::object& object() const noexcept { return obj_; }

 private:
  py::object obj_;
  mutable bool failed_ = false;
  mutable std::string error_;
};

// A Python object as the loop's numerical substructure (e.g. rths.OpenSeesSubstructure).
// Its protocol: attributes h, size, interface_dof; methods reset(), step(ag0, ag_mid,
// ag1, f_in), displacements() -> size floats, interface_velocity(),
// interface_acceleration(ag, f_in).  The loop runs without the GIL: each call
// takes it.  A Python exception marks the substructure failed (healthy() false,
// the loop stops); run() then raises it with its message.
class PythonSubstructure final : public NumericalSubstructure {
 public:
  explicit PythonSubstructure(py::object obj) : py_(std::move(obj)) {
    h_ = py_.attr("h").cast<double>();
    n_ = py_.attr("size").cast<Eigen::Index>();
    dof_ = py_.attr("interface_dof").cast<Eigen::Index>();
    if (!(std::isfinite(h_) && h_ > 0.0)) throw Error("invalid numerical.h = " + std::to_string(h_) + ": finite and > 0");
    if (n_ < 1) throw Error("invalid numerical.size = " + std::to_string(n_) + ": >= 1");
    if (dof_ < 0 || dof_ >= n_)
      throw Error("invalid numerical.interface_dof = " + std::to_string(dof_) + ": one of its DOFs (0 .. size-1)");
    x_.setZero(n_);
  }
  void reset() noexcept override { py_.reset([&] { pull(); }); }
  void step(double ag0, double ag_mid, double ag1, double f_in) noexcept override {
    py_([&] {
      py_.attr("step")(ag0, ag_mid, ag1, f_in);
      pull();
    });
  }
  Eigen::Index dof_count() const noexcept override { return n_; }
  double dof_displacement(Eigen::Index i) const noexcept override { return x_(i); }
  Eigen::Index interface_dof() const noexcept override { return dof_; }
  double interface_velocity() const noexcept override { return v_; }
  double interface_acceleration(double ag, double f_in) const noexcept override {
    double a = std::nan("");
    py_([&] { a = py_.attr("interface_acceleration")(ag, f_in).cast<double>(); });
    return a;
  }
  double sample_time() const noexcept override { return h_; }
  bool healthy() const noexcept override { return !py_.failed() && x_.allFinite() && std::isfinite(v_); }
  const std::string& error() const noexcept { return py_.error(); }
  const py::object& object() const noexcept { return py_.object(); }

 private:
  void pull() {
    const auto d = py_.attr("displacements")().cast<std::vector<double>>();
    if (static_cast<Eigen::Index>(d.size()) != n_)
      throw Error("invalid numerical.displacements(): " + std::to_string(d.size()) + " values, expected size = " +
                  std::to_string(n_));
    for (Eigen::Index i = 0; i < n_; ++i) x_(i) = d[static_cast<std::size_t>(i)];
    v_ = py_.attr("interface_velocity")().cast<double>();
  }
  PythonCalls py_;
  double h_ = 0.0, v_ = 0.0;
  Eigen::Index n_ = 0, dof_ = 0;
  Eigen::VectorXd x_;
};

// A Python object as the loop's experimental substructure (e.g. distributed.RemoteSite: a
// site across the network).  Its protocol: attribute dt; methods reset(), step(command),
// specimen() -> (m, c, k); attributes displacement, velocity, actuator_force (read after
// every reset and step).  Each call takes the GIL.  A Python exception marks it failed:
// step() returns NonFinite (the loop stops) and run() raises the exception's message.
class PythonExperimentalSubstructure final : public ExperimentalSubstructure {
 public:
  explicit PythonExperimentalSubstructure(py::object obj) : py_(std::move(obj)) {
    dt_ = py_.attr("dt").cast<double>();
    if (!(std::isfinite(dt_) && dt_ > 0.0))
      throw Error("invalid experimental.dt = " + std::to_string(dt_) + ": finite and > 0");
    const auto s = py_.attr("specimen")().cast<std::vector<double>>();
    if (s.size() != 3 || !(std::isfinite(s[0]) && std::isfinite(s[1]) && std::isfinite(s[2])))
      throw Error("invalid experimental.specimen(): expected three finite values (m, c, k)");
    specimen_ = {s[0], s[1], s[2]};
  }
  void reset() noexcept override { py_.reset([&] { pull(); }); }
  Status step(double command) noexcept override {
    py_([&] {
      py_.attr("step")(command);
      pull();
    });
    Status s;
    if (py_.failed() || !(std::isfinite(x_) && std::isfinite(v_) && std::isfinite(f_))) s.code = Status::NonFinite;
    return s;
  }
  double displacement() const noexcept override { return x_; }
  double velocity() const noexcept override { return v_; }
  double actuator_force() const noexcept override { return f_; }
  SpecimenModel specimen() const noexcept override { return specimen_; }
  double dt() const noexcept override { return dt_; }
  const std::string& error() const noexcept { return py_.error(); }
  const py::object& object() const noexcept { return py_.object(); }

 private:
  void pull() {
    x_ = py_.attr("displacement").cast<double>();
    v_ = py_.attr("velocity").cast<double>();
    f_ = py_.attr("actuator_force").cast<double>();
  }
  PythonCalls py_;
  double dt_ = 0.0, x_ = 0.0, v_ = 0.0, f_ = 0.0;
  SpecimenModel specimen_;
};

py::tuple run_loop(RthsLoop& loop, const NumericalSubstructure& num, const GroundMotion& ag, std::size_t n,
                   bool timing) {
  if (&num != &loop.numerical())
    throw Error("invalid numerical: expected the loop's own numerical substructure (the one it was built with)");
  const auto nd = static_cast<py::ssize_t>(num.dof_count());
  const auto N = static_cast<py::ssize_t>(n);
  std::vector<RthsOutput> rows(n);
  Arr numerical({N, nd}), steps(timing ? N : 0);
  RunSummary s;
  {
    bindings::BusyGuard busy({&loop, &loop.experimental(), &loop.numerical(), &loop.controller(), &ag},
                             "RthsLoop.run");
    py::gil_scoped_release release;
    loop.reset();
    s = loop.run(ag, n, rows.data(), numerical.mutable_data(), timing ? steps.mutable_data() : nullptr);
  }
  bindings::raise_controller_error(loop.controller(), loop.config().dt);
  if (const auto* e = dynamic_cast<const PythonExperimentalSubstructure*>(&loop.experimental());
      e && !e->error().empty())
    throw std::runtime_error("experimental substructure failed at t = " + std::to_string(s.failure_time) +
                             " s: " + e->error());
  if (const auto* p = dynamic_cast<const PythonSubstructure*>(&num); p && !p->error().empty())
    throw std::runtime_error("numerical substructure failed at t = " + std::to_string(s.failure_time) +
                             " s: " + p->error());
  const auto m = static_cast<py::ssize_t>(s.rows);
  py::dict out;
  sh_py::rows_to_dict(out, kRthsChannels, rows, s.rows);
  out["numerical"] = numerical[py::slice(0, m, 1)];
  if (timing) out["step_seconds"] = steps[py::slice(0, m, 1)];
  return py::make_tuple(out, s);
}

template <class T>
void pi_and_converters(py::class_<T>& c) {
  c.def_readwrite("dt", &T::dt).def_readwrite("pi", &T::pi).def_readwrite("converters", &T::converters)
      .def("validate", &T::validate);
}
}  // namespace

void expose_rths(py::module_& m) {
  py::module_ r = m.def_submodule("rths", "RTHS benchmark blocks (Silva et al. 2020)");

  // --- converters (the core's blocks, converters.hpp; rths.* names kept as aliases) -------------------------------------------------------------------------------------
  py::class_<Saturation>(m, "Saturation").def(py::init<>())
      .def(py::init([](double lo, double hi) { return Saturation{lo, hi}; }), py::arg("lower"), py::arg("upper"))
      .def_readwrite("lower", &Saturation::lower).def_readwrite("upper", &Saturation::upper)
      .def("__call__", &Saturation::operator());
  py::class_<Quantizer>(m, "Quantizer").def(py::init<>())
      .def(py::init([](double q) { return Quantizer{q}; }), py::arg("step"))
      .def_readwrite("step", &Quantizer::step).def("__call__", &Quantizer::operator());
  py::class_<Converter> conv(m, "Converter");
  py::enum_<Converter::Kind>(conv, "Kind")
      .value("AnalogToDigital", Converter::Kind::AnalogToDigital)
      .value("DigitalToAnalog", Converter::Kind::DigitalToAnalog);
  conv.def(py::init<>()).def_readwrite("kind", &Converter::kind).def_readwrite("saturation", &Converter::saturation)
      .def_readwrite("quantizer", &Converter::quantizer).def_readwrite("enabled", &Converter::enabled)
      .def("validate", &Converter::validate).def("__call__", &Converter::operator());
  m.def("benchmark_converter", &benchmark_converter, py::arg("kind"));
  m.def("ideal_converter", &ideal_converter, py::arg("kind") = Converter::Kind::AnalogToDigital);
  py::enum_<NoiseGenerator>(m, "NoiseGenerator")
      .value("MersenneTwister", NoiseGenerator::MersenneTwister)
      .value("SimulinkRandomNumber", NoiseGenerator::SimulinkRandomNumber);
  py::class_<GaussianSequence>(m, "GaussianSequence")
      .def(py::init<std::uint64_t, NoiseGenerator>(), py::arg("seed") = 0,
           py::arg("generator") = NoiseGenerator::MersenneTwister)
      .def("reset", &GaussianSequence::reset, py::arg("seed"), py::arg("generator") = NoiseGenerator::MersenneTwister)
      .def("next", &GaussianSequence::next)
      .def_property_readonly("generator", &GaussianSequence::generator)
      .def_static("simulink_state", &GaussianSequence::simulink_state, py::arg("seed"));
  py::class_<SensorNoise>(m, "SensorNoise").def(py::init<>())
      .def(py::init([](double s, double g) { return SensorNoise{s, g}; }), py::arg("sigma"), py::arg("gain") = 1.0)
      .def_readwrite("sigma", &SensorNoise::sigma).def_readwrite("gain", &SensorNoise::gain)
      .def_static("band_limited_sigma", &SensorNoise::band_limited_sigma, py::arg("noise_power"),
                  py::arg("sample_time"));
  for (const char* name : {"Saturation", "Quantizer", "Converter", "benchmark_converter", "ideal_converter",
                           "NoiseGenerator", "GaussianSequence", "SensorNoise"})
    r.attr(name) = m.attr(name);
  py::class_<ControllerConverters>(r, "ControllerConverters").def(py::init<>())
      .def_readwrite("ad", &ControllerConverters::ad).def_readwrite("da", &ControllerConverters::da);

  // --- plants -------------------------------------------------------------------------------------------
  py::class_<SpecimenModel>(r, "SpecimenModel").def(py::init<>())
      .def_readwrite("m", &SpecimenModel::m).def_readwrite("c", &SpecimenModel::c).def_readwrite("k", &SpecimenModel::k);
  py::class_<BenchmarkPlantParameters>(r, "BenchmarkPlantParameters").def(py::init<>())
      .def_readwrite("a1_beta0", &BenchmarkPlantParameters::a1_beta0)
      .def_readwrite("a2", &BenchmarkPlantParameters::a2).def_readwrite("a3", &BenchmarkPlantParameters::a3)
      .def_readwrite("beta1", &BenchmarkPlantParameters::beta1)
      .def_readwrite("beta2", &BenchmarkPlantParameters::beta2)
      .def_readwrite("m_e", &BenchmarkPlantParameters::m_e).def_readwrite("k_e", &BenchmarkPlantParameters::k_e)
      .def_readwrite("zeta_e", &BenchmarkPlantParameters::zeta_e)
      .def_readwrite("gain", &BenchmarkPlantParameters::gain)
      .def_readwrite("csi_derivative_block", &BenchmarkPlantParameters::csi_derivative_block)
      .def("validate", &BenchmarkPlantParameters::validate)
      .def_property_readonly("c_e", &BenchmarkPlantParameters::c_e)
      .def("specimen", &BenchmarkPlantParameters::specimen)
      .def("denominator", &BenchmarkPlantParameters::denominator)
      .def("numerator", &BenchmarkPlantParameters::numerator);
  py::class_<BenchmarkPlantUncertainty>(r, "BenchmarkPlantUncertainty").def(py::init<>())
      .def_readwrite("k_e", &BenchmarkPlantUncertainty::k_e)
      .def_readwrite("beta1", &BenchmarkPlantUncertainty::beta1)
      .def_readwrite("beta2", &BenchmarkPlantUncertainty::beta2)
      .def_readwrite("a3", &BenchmarkPlantUncertainty::a3)
      .def("draw", &BenchmarkPlantUncertainty::draw, py::arg("nominal"), py::arg("seed"));
  py::class_<ExperimentalSubstructure>(r, "ExperimentalSubstructure")
      .def("reset", [](ExperimentalSubstructure& e) { bindings::require_idle(&e, "ExperimentalSubstructure.reset"); e.reset(); })
      .def("step", [](ExperimentalSubstructure& e, double u) {
        bindings::require_idle(&e, "ExperimentalSubstructure.step");
        return e.step(u);
      }, py::arg("command"))
      .def_property_readonly("displacement", &ExperimentalSubstructure::displacement)
      .def_property_readonly("velocity", &ExperimentalSubstructure::velocity)
      .def_property_readonly("actuator_force", &ExperimentalSubstructure::actuator_force)
      .def_property_readonly("dt", &ExperimentalSubstructure::dt)
      .def("specimen", &ExperimentalSubstructure::specimen);
  py::class_<BenchmarkPlant, ExperimentalSubstructure>(r, "BenchmarkPlant")
      .def(py::init<const BenchmarkPlantParameters&, double>(), py::arg("parameters"), py::arg("dt"))
      .def_property_readonly("parameters", &BenchmarkPlant::parameters)
      .def_property_readonly("state", &BenchmarkPlant::state);
  py::class_<PythonExperimentalSubstructure, ExperimentalSubstructure>(
      r, "PythonExperimentalSubstructure", "a Python object (e.g. distributed.RemoteSite) as the loop's experimental substructure")
      .def(py::init<py::object>(), py::arg("substructure"))
      .def_property_readonly("error", &PythonExperimentalSubstructure::error)
      .def_property_readonly("substructure", &PythonExperimentalSubstructure::object);
  py::class_<ServoHydraulicSubstructure, ExperimentalSubstructure>(r, "ServoHydraulicSubstructure")
      .def(py::init<const Rig&, double, const SolverOptions&>(), py::arg("rig"), py::arg("dt"),
           py::arg("options") = SolverOptions{});

  // --- numerical substructure -----------------------------------------------------------------------
  r.attr("SubstructureScheme") = m.attr("StructuralScheme");  // one enum (integration.hpp)
  py::class_<LinearSubstructureModel>(r, "LinearSubstructureModel").def(py::init<>())
      .def(py::init([](Eigen::MatrixXd M, Eigen::MatrixXd C, Eigen::MatrixXd K, Eigen::VectorXd g,
                       Eigen::VectorXd gam) { return LinearSubstructureModel{M, C, K, g, gam}; }),
           py::arg("M"), py::arg("C"), py::arg("K"), py::arg("ground"), py::arg("interface"))
      .def_readwrite("M", &LinearSubstructureModel::M).def_readwrite("C", &LinearSubstructureModel::C)
      .def_readwrite("K", &LinearSubstructureModel::K).def_readwrite("ground", &LinearSubstructureModel::ground)
      .def_readwrite("interface", &LinearSubstructureModel::interface)
      .def("validate", &LinearSubstructureModel::validate);
  py::class_<NumericalSubstructure>(r, "NumericalSubstructure")
      .def_property_readonly("dof_count", &NumericalSubstructure::dof_count)
      .def_property_readonly("interface_dof", &NumericalSubstructure::interface_dof)
      .def_property_readonly("sample_time", &NumericalSubstructure::sample_time)
      .def_property_readonly("healthy", &NumericalSubstructure::healthy);
  py::class_<PythonSubstructure, NumericalSubstructure>(r, "PythonSubstructure",
                                                        "a Python object as the RTHS loop's numerical substructure")
      .def(py::init<py::object>(), py::arg("substructure"))
      .def_property_readonly("error", &PythonSubstructure::error)
      .def_property_readonly("substructure", &PythonSubstructure::object);
  py::class_<LinearSubstructure, NumericalSubstructure>(r, "LinearSubstructure")
      .def(py::init<const LinearSubstructureModel&, double, SubstructureScheme>(), py::arg("model"), py::arg("h"),
           py::arg("scheme") = SubstructureScheme::RungeKutta4)
      .def("reset", [](LinearSubstructure& s) { bindings::require_idle(&s, "LinearSubstructure.reset"); s.reset(); })
      .def("step", [](LinearSubstructure& s, double a0, double am, double a1, double f) {
        bindings::require_idle(&s, "LinearSubstructure.step");
        s.step(a0, am, a1, f);
      }, py::arg("ag0"), py::arg("ag_mid"), py::arg("ag1"), py::arg("f_in"))
      .def_property_readonly("displacement", &LinearSubstructure::displacement)
      .def_property_readonly("velocity", &LinearSubstructure::velocity)
      .def("acceleration", &LinearSubstructure::acceleration, py::arg("dof"), py::arg("ag"), py::arg("f_in"));
  py::class_<GroundMotion>(m, "GroundMotion", "a ground-motion record, linearly interpolated and scaled (ground_motion.hpp)")
      .def(py::init([](const Arr& t, const Arr& a, double s) {
             return GroundMotion(to_vector(t, "time"), to_vector(a, "acceleration"), s);
           }),
           py::arg("time"), py::arg("acceleration"), py::arg("scale") = 1.0)
      .def("__call__", &GroundMotion::operator(), py::arg("t"))
      .def_property_readonly("end_time", &GroundMotion::end_time)
      .def_property_readonly("scale", &GroundMotion::scale);
  r.attr("GroundMotion") = m.attr("GroundMotion");

  // --- controllers --------------------------------------------------------------------------------------
  py::class_<PiGains>(r, "PiGains").def(py::init<>())
      .def(py::init([](double kp, double ki) { return PiGains{kp, ki}; }), py::arg("Kp"), py::arg("Ki"))
      .def_readwrite("Kp", &PiGains::Kp).def_readwrite("Ki", &PiGains::Ki);
  py::class_<TrackingInput>(r, "TrackingInput").def(py::init<>())
      .def(py::init([](double d, double dv, double da, double xm, double fm, double vm, double pm) {
             return TrackingInput{d, dv, da, xm, fm, vm, pm};
           }),
           py::arg("desired"), py::arg("desired_velocity") = 0.0, py::arg("desired_acceleration") = 0.0,
           py::arg("measured") = 0.0, py::arg("measured_force") = 0.0, py::arg("measured_velocity") = 0.0,
           py::arg("measured_pressure") = 0.0)
      .def_readwrite("desired", &TrackingInput::desired)
      .def_readwrite("desired_velocity", &TrackingInput::desired_velocity)
      .def_readwrite("desired_acceleration", &TrackingInput::desired_acceleration)
      .def_readwrite("measured", &TrackingInput::measured)
      .def_readwrite("measured_force", &TrackingInput::measured_force)
      .def_readwrite("measured_velocity", &TrackingInput::measured_velocity)
      .def_readwrite("measured_pressure", &TrackingInput::measured_pressure);
  // Python controllers (tracking_trampoline.hpp): subclass TrackingController, or wrap any object.
  py::class_<TrackingController, bindings::PyTrackingController>(r, "TrackingController")
      .def(py::init<>())
      .def("reset", [](TrackingController& c) {
        bindings::require_idle(&c, "TrackingController.reset");
        c.reset();
        bindings::raise_controller_error(c, std::nan(""));
      })
      .def("command", [](TrackingController& c, double d, double dv, double da, double xm, double fm, double vm,
                         double pm) {
        bindings::require_idle(&c, "TrackingController.command");
        const double u = c.command(TrackingInput{d, dv, da, xm, fm, vm, pm});
        bindings::raise_controller_error(c, std::nan(""));
        return u;
      }, py::arg("desired"), py::arg("desired_velocity") = 0.0, py::arg("desired_acceleration") = 0.0,
         py::arg("measured") = 0.0, py::arg("measured_force") = 0.0, py::arg("measured_velocity") = 0.0,
         py::arg("measured_pressure") = 0.0,
         "The command from the desired value (displacement [m] in RPsD/RTHS, force [N] in EFT), its velocity and "
         "acceleration, and the measured displacement [m], force [N], velocity [m/s] and pressure [Pa].")
      .def("raise_stored_error", [](const TrackingController& c, double dt) { bindings::raise_controller_error(c, dt); },
           py::arg("dt"),
           "After a loop ran this controller (GIL held): re-raise what a Python controller raised in it, naming the "
           "sample and its time (dt [s]); nothing for a C++ controller or a clean run.")
      .def("command", [](TrackingController& c, const TrackingInput& in) {
        bindings::require_idle(&c, "TrackingController.command");
        const double u = c.command(in);
        bindings::raise_controller_error(c, std::nan(""));
        return u;
      }, py::arg("input"));
  py::class_<bindings::PythonTrackingController, TrackingController>(
      r, "PythonController", "any object with reset() and command(...) as a tracking controller")
      .def(py::init<py::object>(), py::arg("controller"))
      .def_property_readonly("controller", &bindings::PythonTrackingController::object)
      .def_property_readonly(
          "keywords",
          [](const bindings::PythonTrackingController& c) {
            py::list out;
            if (c.signature().measured_velocity) out.append("measured_velocity");
            if (c.signature().measured_pressure) out.append("measured_pressure");
            return py::tuple(out);
          },
          "The optional inputs command() receives as keywords (read once from its signature, when wrapped)");
  py::class_<SampleControllerConfig> sc(r, "SampleControllerConfig");
  sc.def(py::init<>()).def_readwrite("lead_b1", &SampleControllerConfig::lead_b1)
      .def_readwrite("lead_b0", &SampleControllerConfig::lead_b0)
      .def_readwrite("lead_a0", &SampleControllerConfig::lead_a0);
  pi_and_converters(sc);
  py::class_<PolynomialConfig> pc(r, "PolynomialConfig");
  pc.def(py::init<>()).def_readwrite("tau", &PolynomialConfig::tau).def_readwrite("order", &PolynomialConfig::order)
      .def_readwrite("stride", &PolynomialConfig::stride).def_readwrite("static_gain", &PolynomialConfig::static_gain);
  pi_and_converters(pc);
  py::class_<AtsConfig> ac(r, "AtsConfig");
  ac.def(py::init<>()).def_readwrite("initial", &AtsConfig::initial).def_readwrite("lower", &AtsConfig::lower)
      .def_readwrite("upper", &AtsConfig::upper).def_readwrite("window", &AtsConfig::window)
      .def_readwrite("filter_hz", &AtsConfig::filter_hz).def_readwrite("update_every", &AtsConfig::update_every)
      .def_readwrite("min_amplitude", &AtsConfig::min_amplitude);
  pi_and_converters(ac);
  py::class_<ModelBasedConfig> mc(r, "ModelBasedConfig");
  mc.def(py::init<>()).def_readwrite("coefficients", &ModelBasedConfig::coefficients)
      .def_static("from_plant", &model_based_config, py::arg("plant"), py::arg("order") = 2)
      .def_static("from_denominator", &ModelBasedConfig::from_denominator, py::arg("A"), py::arg("b0"),
                  py::arg("order") = 2);
  pi_and_converters(mc);
  py::class_<SampleController, TrackingController>(r, "SampleController")
      .def(py::init<const SampleControllerConfig&>(), py::arg("config") = SampleControllerConfig{})
      .def_property_readonly("lead_coefficients", [](const SampleController& c) {
        return py::make_tuple(c.lead().n0(), c.lead().n1(), c.lead().d1());
      })
      .def_property_readonly("pi_coefficients", [](const SampleController& c) {
        return py::make_tuple(c.pi().n0(), c.pi().n1(), c.pi().d1());
      });
  py::class_<PolynomialExtrapolation, TrackingController>(r, "PolynomialExtrapolation")
      .def(py::init<const PolynomialConfig&>(), py::arg("config"))
      .def_property_readonly("weights", &PolynomialExtrapolation::weights);
  py::class_<AdaptiveTimeSeries, TrackingController>(r, "AdaptiveTimeSeries")
      .def(py::init<const AtsConfig&>(), py::arg("config"))
      .def_property_readonly("coefficients", &AdaptiveTimeSeries::coefficients);
  py::class_<ModelBasedCompensator, TrackingController>(r, "ModelBasedCompensator")
      .def(py::init<const ModelBasedConfig&>(), py::arg("config"));
  r.def("plant_delay", &plant_delay, py::arg("plant"));
  // The paper's compensators as TrackingControllers of the core (tracking.hpp), usable in every loop.
  m.attr("TrackingInput") = r.attr("TrackingInput");
  m.attr("TrackingController") = r.attr("TrackingController");
  py::class_<AmplitudeLead, TrackingController>(m, "AmplitudeLead",
                                                "the paper's amplitude compensation: u = lead(desired) (RPsD)")
      .def(py::init<double, double, double>(), py::arg("T"), py::arg("alpha"), py::arg("dt"))
      .def_property_readonly("lead", &AmplitudeLead::lead);
  py::class_<VelocityFeedbackTracking, TrackingController>(
      m, "VelocityFeedbackTracking", "the paper's velocity feedback compensation: u = desired + du (EFT)")
      .def(py::init<const Rig&, VelocityFeedbackCompensator::Kind, double, double, double>(), py::arg("model"),
           py::arg("kind"), py::arg("lead_T"), py::arg("alpha"), py::arg("dt"))
      .def_property_readonly("last_compensation", &VelocityFeedbackTracking::last_compensation);

  // --- loop -----------------------------------------------------------------------------------------------
  py::class_<RthsLoopConfig>(r, "RthsLoopConfig").def(py::init<>())
      .def_readwrite("dt", &RthsLoopConfig::dt)
      .def_readwrite("displacement_noise", &RthsLoopConfig::displacement_noise)
      .def_readwrite("force_noise", &RthsLoopConfig::force_noise)
      .def_readwrite("independent_noise", &RthsLoopConfig::independent_noise)
      .def_readwrite("seed", &RthsLoopConfig::seed)
      .def_readwrite("generator", &RthsLoopConfig::generator)
      .def("validate", &RthsLoopConfig::validate);
  r.attr("RTHS_CHANNELS") = sh_py::channel_units(kRthsChannels);
  py::class_<RthsLoop>(r, "RthsLoop")
      .def(py::init<ExperimentalSubstructure&, NumericalSubstructure&, TrackingController&, const RthsLoopConfig&>(),
           py::arg("experimental"), py::arg("numerical"), py::arg("controller"), py::arg("config") = RthsLoopConfig{},
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>(), py::keep_alive<1, 4>())
      .def("run",
           [](RthsLoop& loop, const NumericalSubstructure& num, const GroundMotion& ag, std::size_t n, bool timing) {
             return run_loop(loop, num, ag, n, timing);
           },
           py::arg("numerical"), py::arg("ground_motion"), py::arg("n"), py::arg("timing") = false,
           "Reset, then run n samples; numerical: the loop's numerical substructure (for the row width). Returns "
           "(channels dict, RunSummary) as the EFT and RPsD loops: one column per RTHS_CHANNELS entry, numerical "
           "(rows x dofs) and step_seconds (if timing); the summary's peak_force is the actuator force's.");
}
