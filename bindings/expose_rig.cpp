#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "enums_py.hpp"
#include "protocol.hpp"
#include "servohydraulics/elements/mr_damper.hpp"
#include "servohydraulics/parameters.hpp"
#include "servohydraulics/rig.hpp"
#include "servohydraulics/zhao2003.hpp"

namespace py = pybind11;
using namespace servohydraulics;
using servohydraulics::bindings::add_protocol;

namespace {
// _core.RIG_PARAMETERS: one dict per row of kRigParameters, with the default
// (Rig's, i.e. the calibrated preset's) and the bound as text.
py::list rig_parameters() {
  const Rig d;
  py::list out;
  for (const ParameterInfo& p : kRigParameters) {
    py::dict row;
    row["section"] = p.section;
    row["key"] = p.key;
    row["unit"] = p.unit;
    row["doc"] = p.doc;
    row["source"] = p.source;
    row["default"] = d.*p.member;
    row["bound"] = bound_text(p.bound);
    out.append(row);
  }
  return out;
}

// _core.RIG_CHOICES: the rig-file keys whose value is a name (parameters.hpp: ChoiceInfo), with
// their (name, value) pairs (the enum's table) and the default's name.
template <class E, std::size_t N>
py::dict choice_row(const ChoiceInfo& c, const EnumName<E> (&table)[N], E def) {
  py::dict row;
  row["section"] = c.section;
  row["key"] = c.key;
  row["doc"] = c.doc;
  row["source"] = c.source;
  row["names"] = sh_py::enum_names(table);  // ((name, value), ...)
  row["default"] = name_of(table, def);
  return row;
}

py::list effects_table() {
  const Effects d;
  py::list out;
  for (const EffectInfo& e : kEffects) {
    py::dict row;
    row["key"] = e.key;
    row["doc"] = e.doc;
    row["default"] = d.*e.member;
    out.append(row);
  }
  return out;
}
}  // namespace

void expose_rig(py::module_& m) {
  py::class_<FlowCurve> fc(m, "FlowCurve", "Normalised flow-spool opening curve g(x_v) of Fig 4(a)");
  sh_py::bind_enum(fc, "Kind", kFlowCurveKindNames);
  m.attr("FLOW_CURVE_KIND_NAMES") = sh_py::enum_names(kFlowCurveKindNames);
  fc.def(py::init<>())
      .def_readwrite("kind", &FlowCurve::kind)
      .def_readwrite("b", &FlowCurve::b)
      .def_readwrite("opening", &FlowCurve::opening)
      .def_readwrite("flow", &FlowCurve::flow)
      // A table curve is assigned field by field, so it is validated where it is used
      // (ValueError naming the field): never an out-of-bounds read (rig.cpp).
      .def("eval", [](const FlowCurve& f, double x) { return f.validate(), f.eval(x); }, py::arg("x"))
      .def("slope", [](const FlowCurve& f, double x) { return f.validate(), f.slope(x); }, py::arg("x"))
      .def("inverse", [](const FlowCurve& f, double q) { return f.validate(), f.inverse(q); }, py::arg("q"))
      .def("validate", &FlowCurve::validate);
  add_protocol(fc, {"kind", "b", "opening", "flow"});

  py::class_<Effects> effects(m, "Effects", "Switches of the physical effects");
  effects.def(py::init<>());
  std::vector<std::string> effect_names;
  for (const EffectInfo& e : kEffects) {
    effects.def_readwrite(e.key, e.member, e.doc);
    effect_names.emplace_back(e.key);
  }
  add_protocol(effects, effect_names);
  m.attr("EFFECTS") = effects_table();

  py::class_<Rig> rig(m, "Rig", "Parameters of the rig, SI units, named after the paper's symbols");
  rig.def(py::init<>());
  std::vector<std::string> rig_names;
  for (const ParameterInfo& p : kRigParameters) {
    rig.def_readwrite(p.key, p.member, p.doc);
    rig_names.emplace_back(p.key);
  }
  sh_py::bind_enum(m, "MrInput", kMrInputNames);
  sh_py::bind_enum(m, "MrLaw", kMrLawNames);
  m.attr("MR_INPUT_NAMES") = sh_py::enum_names(kMrInputNames);
  m.attr("MR_LAW_NAMES") = sh_py::enum_names(kMrLawNames);
  rig.def_readwrite("flow_curve", &Rig::flow_curve)
      .def_readwrite("effects", &Rig::effects)
      .def_readwrite(kMrInputChoice.key, &Rig::mr_input, kMrInputChoice.doc)
      .def_readwrite(kMrLawChoice.key, &Rig::mr_law, kMrLawChoice.doc)
      .def("validate", &Rig::validate);
  rig_names.emplace_back("flow_curve");
  rig_names.emplace_back("effects");
  rig_names.emplace_back(kMrInputChoice.key);
  rig_names.emplace_back(kMrLawChoice.key);
  add_protocol(rig, rig_names);
  m.attr("RIG_PARAMETERS") = rig_parameters();
  {
    const Rig d;
    py::list choices;
    choices.append(choice_row(kMrInputChoice, kMrInputNames, d.mr_input));
    choices.append(choice_row(kMrLawChoice, kMrLawNames, d.mr_law));
    m.attr("RIG_CHOICES") = choices;
  }
  m.def(
      "mr_damper_law",
      [](const Rig& r) {
        const MrLawValues v = mr_damper_law(r);
        py::dict out;
        out["u"] = v.u;
        out["alpha"] = v.alpha;
        out["c0"] = v.c0;
        out["c1"] = v.c1;
        out["beta"] = v.beta;
        out["gamma"] = v.gamma;
        return out;
      },
      py::arg("rig"),
      "The MR damper's alpha [N/m], c0, c1 [N s/m], beta, gamma [1/m^n] at the rig's field input u "
      "[V or A] by its law (mr_input, mr_law; elements/mr_damper.hpp)");

  py::enum_<Zhao2003Variant>(m, "Zhao2003Variant")
      .value("Calibrated", Zhao2003Variant::Calibrated)
      .value("Printed", Zhao2003Variant::Printed);
  py::class_<Zhao2003TestMethods>(m, "Zhao2003TestMethods",
                                  "Constants of the paper's test methods (Table I and text), SI")
      .def(py::init<>())
      .def_readonly("dt", &Zhao2003TestMethods::dt)
      .def_readonly("eft_lead_T", &Zhao2003TestMethods::eft_lead_T)
      .def_readonly("amplitude_T", &Zhao2003TestMethods::amplitude_T)
      .def_readonly("delay_T", &Zhao2003TestMethods::delay_T)
      .def_readonly("alpha", &Zhao2003TestMethods::alpha)
      .def_readonly("model", &Zhao2003TestMethods::model);
  m.attr("ZHAO2003_TEST_METHODS") = Zhao2003TestMethods{};
  m.def("zhao2003", &zhao2003, py::arg("variant") = Zhao2003Variant::Calibrated, py::arg("actuator_attached") = true);
}
