// Binding helpers over the core's enum name tables (EnumName<E> in
// servohydraulics/enum_name.hpp): the Python enum made from a table, and the
// table's names exported as ((name, value), ...), e.g. _core.METHOD_NAMES,
// which the Python layer reads into its dictionaries and the CLI into its choices.
#pragma once

#include <cstddef>

#include <pybind11/pybind11.h>

#include "servohydraulics/enum_name.hpp"

namespace sh_py {

namespace py = pybind11;

//! py::enum_<E>(scope, name) with one value per row of the table (its identifier).
template <class E, std::size_t N>
py::enum_<E> bind_enum(py::handle scope, const char* name, const servohydraulics::EnumName<E> (&table)[N]) {
  py::enum_<E> e(scope, name);
  for (const auto& row : table) e.value(row.identifier, row.value);
  return e;
}

//! The table as a tuple of (name, value) tuples, in the enum's order.
template <class E, std::size_t N>
py::tuple enum_names(const servohydraulics::EnumName<E> (&table)[N]) {
  py::tuple t(N);
  for (std::size_t i = 0; i < N; ++i) t[i] = py::make_tuple(table[i].name, table[i].value);
  return t;
}

}  // namespace sh_py
