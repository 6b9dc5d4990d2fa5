// servohydraulics/realtime.hpp: the wall-clock Pacer and its latency histogram
// (python/servohydraulics/realtime.py wraps them).
#include <pybind11/pybind11.h>

#include "busy.hpp"
#include "servohydraulics/realtime.hpp"

namespace py = pybind11;
using namespace servohydraulics;
using namespace servohydraulics::realtime;

void expose_realtime(py::module_& m) {
  m.def("monotonic_ns", &monotonic_ns, "CLOCK_MONOTONIC [ns] (the Pacer's clock; time.monotonic_ns() reads it too).");

  py::class_<Permission>(m, "RealtimePermission")
      .def_readonly("requested", &Permission::requested)
      .def_readonly("granted", &Permission::granted)
      .def_readonly("error", &Permission::error)
      .def_readonly("reason", &Permission::reason);
  py::class_<Percentiles>(m, "RealtimePercentiles")
      .def_readonly("min", &Percentiles::min)
      .def_readonly("p50", &Percentiles::p50)
      .def_readonly("p99", &Percentiles::p99)
      .def_readonly("p999", &Percentiles::p999)
      .def_readonly("max", &Percentiles::max)
      .def_readonly("mean", &Percentiles::mean);
  py::class_<PacerStats>(m, "PacerStats")
      .def_readonly("period_s", &PacerStats::period_s)
      .def_readonly("samples", &PacerStats::samples)
      .def_readonly("misses", &PacerStats::misses)
      .def_readonly("latency_us", &PacerStats::latency_us)
      .def_readonly("compute_us", &PacerStats::compute_us)
      .def_readonly("fifo", &PacerStats::fifo)
      .def_readonly("mlockall", &PacerStats::mlockall)
      .def_readonly("cpu_affinity", &PacerStats::cpu_affinity);

  py::class_<LatencyHistogram>(m, "LatencyHistogram")
      .def(py::init<>())
      .def("add", &LatencyHistogram::add, py::arg("ns"))
      .def("clear", &LatencyHistogram::clear)
      .def("quantile", &LatencyHistogram::quantile, py::arg("q"))
      .def_property_readonly("count", &LatencyHistogram::count)
      .def_property_readonly("min", &LatencyHistogram::min)
      .def_property_readonly("max", &LatencyHistogram::max)
      .def_property_readonly("mean", &LatencyHistogram::mean)
      .def("bin_count", &LatencyHistogram::bin_count, py::arg("bin"))
      .def_static("bin", &LatencyHistogram::bin, py::arg("ns"))
      .def_static("bin_lower", &LatencyHistogram::bin_lower, py::arg("bin"))
      .def_static("bin_upper", &LatencyHistogram::bin_upper, py::arg("bin"))
      .def_property_readonly_static("bins", [](py::object) { return LatencyHistogram::kBins; });

  py::class_<Pacer>(m, "Pacer")
      .def(py::init([](double period_s, int fifo_priority, int cpu, bool lock_memory) {
             PacerOptions o;
             o.fifo_priority = fifo_priority;
             o.cpu = cpu;
             o.lock_memory = lock_memory;
             return new Pacer(period_s, o);
           }),
           py::arg("period_s"), py::arg("fifo_priority") = 0, py::arg("cpu") = -1, py::arg("lock_memory") = false)
      .def("start", bindings::guarded(&Pacer::start, "Pacer.start"))
      .def(
          "wait",
          [](Pacer& p) {
            bindings::BusyGuard busy({&p}, "Pacer.wait");
            py::gil_scoped_release release;
            return p.wait();
          },
          "Sleeps to the next deadline; returns the wake-up latency [s]. Releases the GIL (one thread per Pacer).")
      .def("stop", bindings::guarded(&Pacer::stop, "Pacer.stop"))
      .def("stats", [](const Pacer& p) {
        bindings::require_idle(&p, "Pacer.stats");
        return p.stats();
      })
      .def("deadline_ns", &Pacer::deadline_ns, py::arg("k"))
      .def_property_readonly("started", &Pacer::started)
      .def_property_readonly("period_s", &Pacer::period_s)
      .def_property_readonly("period_ns", &Pacer::period_ns)
      .def_property_readonly("start_ns", &Pacer::start_ns)
      .def_property_readonly("next_deadline_ns", &Pacer::next_deadline_ns)
      .def_property_readonly("samples", &Pacer::samples)
      .def_property_readonly("misses", &Pacer::misses)
      .def_property_readonly("latency", &Pacer::latency, py::return_value_policy::reference_internal)
      .def_property_readonly("compute", &Pacer::compute, py::return_value_policy::reference_internal);
}
