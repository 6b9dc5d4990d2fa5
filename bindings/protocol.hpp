// The Python object protocol for plain parameter aggregates (proxsuite's
// expose-settings style): __repr__, __eq__/__ne__, __copy__, __deepcopy__ and
// pickle, all from one list of the fields' Python names.  Values of the fields
// are compared, printed and pickled through their own bindings, so a nested
// aggregate (Rig.flow_curve, Rig.effects, RpsdConfig.model) needs the protocol
// too.  Types must be default-constructible and copyable.
//
//   py::class_<Rig> rig(m, "Rig");  ...;  add_protocol(rig, {"m", "c", ...});
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>

namespace servohydraulics::bindings {

namespace py = pybind11;

template <class T, class... Options>
void add_protocol(py::class_<T, Options...>& cls, std::vector<std::string> fields) {
  auto names = std::make_shared<const std::vector<std::string>>(std::move(fields));
  cls.def("__repr__", [names](const py::object& self) {
    std::string s = py::str(py::type::of(self).attr("__name__"));
    s += "(";
    for (std::size_t i = 0; i < names->size(); ++i) {
      if (i) s += ", ";
      s += (*names)[i] + "=" + std::string(py::repr(self.attr((*names)[i].c_str())));
    }
    return s + ")";
  });
  cls.def(
      "__eq__",
      [names](const py::object& self, const py::object& other) {
        if (!py::isinstance(other, py::type::of(self))) return false;
        for (const auto& n : *names)
          if (!self.attr(n.c_str()).equal(other.attr(n.c_str()))) return false;
        return true;
      },
      py::is_operator());
  cls.def(
      "__ne__", [](const py::object& self, const py::object& other) { return !self.equal(other); },
      py::is_operator());
  cls.attr("__hash__") = py::none();  // mutable: unhashable, like a dataclass with eq
  cls.def("__copy__", [](const T& self) { return T(self); });
  cls.def("__deepcopy__", [](const T& self, const py::dict&) { return T(self); }, py::arg("memo"));
  cls.def(py::pickle(
      [names](const py::object& self) {
        py::dict state;
        for (const auto& n : *names) state[n.c_str()] = self.attr(n.c_str());
        return state;
      },
      [](const py::dict& state) {
        py::object obj = py::type::of<T>()();
        for (const auto& item : state) py::setattr(obj, item.first, item.second);
        return obj.cast<T>();
      }));
}

}  // namespace servohydraulics::bindings
