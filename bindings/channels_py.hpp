// Binding helpers over the C++ channel tables (ChannelInfoOf<S> in
// servohydraulics/channels.hpp): a table as a Python tuple of (name, unit), and
// per-sample rows or preallocated columns as a dict of NumPy arrays keyed by the
// table's names.  One home for "a record of channels" in the bindings.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "servohydraulics/channels.hpp"

namespace sh_py {

namespace py = pybind11;

//! The table as a tuple of (name, unit) tuples, e.g. _core.PLANT_CHANNELS.
template <class S, std::size_t N>
py::tuple channel_units(const servohydraulics::ChannelInfoOf<S> (&table)[N]) {
  py::tuple t(N);
  for (std::size_t i = 0; i < N; ++i) t[i] = py::make_tuple(table[i].name, table[i].unit);
  return t;
}

//! A new 1-D array of n elements, stored in out[name]; returns its data.
template <class T>
T* add_column(py::dict& out, const char* name, std::size_t n, T fill = T{}) {
  py::array_t<T> a(static_cast<py::ssize_t>(n));
  T* d = a.mutable_data();
  for (std::size_t k = 0; k < n; ++k) d[k] = fill;
  out[name] = a;
  return d;
}

//! Adds one array per table entry to out; dst[i] receives the data pointer of entry i
//! (for a core routine that writes columns, e.g. run_record's Channels).
template <class S, std::size_t N>
void add_columns(py::dict& out, const servohydraulics::ChannelInfoOf<S> (&table)[N], std::size_t n, double** dst) {
  for (std::size_t i = 0; i < N; ++i) dst[i] = add_column<double>(out, table[i].name, n);
}

//! Adds one array per table entry to out, element k taken from project(rows[k]).*member:
//! rows_to_dict(out, kPlantChannels, rows, [](const EftOutput& r) -> const Output& { return r.plant; }).
template <class S, std::size_t N, class Row, class Project>
void rows_to_dict(py::dict& out, const servohydraulics::ChannelInfoOf<S> (&table)[N], const std::vector<Row>& rows,
                  std::size_t n, Project project) {
  for (const auto& info : table) {
    double* d = add_column<double>(out, info.name, n);
    for (std::size_t k = 0; k < n; ++k) d[k] = project(rows[k]).*info.member;
  }
}
template <class S, std::size_t N>
void rows_to_dict(py::dict& out, const servohydraulics::ChannelInfoOf<S> (&table)[N], const std::vector<S>& rows,
                  std::size_t n) {
  rows_to_dict(out, table, rows, n, [](const S& r) -> const S& { return r; });
}

}  // namespace sh_py
