// The FMU's variable table (cpp/fmu/model.hpp) for the Python exporter, which
// writes modelDescription.xml and resources/ from it.
#include <iterator>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "model.hpp"

namespace py = pybind11;
using namespace servohydraulics;

namespace {
//! Every variable of an FMU of this kind with its start value under these settings.
py::list fmu_variables(const std::string& kind, const std::string& mode, const Rig& rig, double dt, double x0,
                       const SolverOptions& solver, const EftConfig& eft, const RpsdConfig& rpsd) {
  fmu::Values v;
  fmu::Settings& s = v.settings;
  s.kind = fmu::parse_kind(kind);
  s.mode = fmu::parse_mode(mode);
  s.rig = rig;
  s.dt = dt;
  s.x0 = x0;
  s.solver = solver;
  s.eft = eft;
  s.rpsd = rpsd;
  fmu::resolve_defaults(s);
  py::list out;
  const auto vars = fmu::variables(s.kind, s.mode);
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const fmu::Variable& x = vars[i];
    py::dict d;
    d["name"] = x.name;
    d["value_reference"] = i;
    d["type"] = fmu::to_string(x.type);
    d["causality"] = fmu::to_string(x.causality);
    d["variability"] = fmu::to_string(x.variability);
    d["unit"] = x.unit;
    d["description"] = x.doc;
    d["type_name"] = x.type_name;
    d["items"] = x.items;
    d["in_rig"] = x.in_rig;
    d["start"] = x.get(v);
    out.append(d);
  }
  return out;
}
}  // namespace

void expose_fmu(py::module_& m) {
  py::tuple kinds(std::size(fmu::kKindNames));
  for (std::size_t i = 0; i < kinds.size(); ++i) kinds[i] = fmu::kKindNames[i].name;
  m.attr("FMU_KINDS") = kinds;  // fmu.KINDS, the CLI's --kind choices
  m.def("fmu_variables", &fmu_variables, py::arg("kind"), py::arg("mode"), py::arg("rig"), py::arg("dt"),
        py::arg("x0"), py::arg("solver"), py::arg("eft"), py::arg("rpsd"),
        "The FMU's variables (name, value_reference, type, causality, variability, unit, description, "
        "type_name, items, in_rig, start) for kind plant/eft/rpsd; validates and resolves the configs' "
        "defaults (cpp/fmu/model.hpp)");
}
