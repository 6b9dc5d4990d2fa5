// Name tables of the enums a user selects by name.  Each enum that Python, the
// FMU, rig files or the command line spell out has one table, beside the enum,
// in the enum's order:
//
//   inline constexpr EnumName<IntegrationScheme> kSchemeNames[] = {
//       {IntegrationScheme::CentralDifference, "central_difference", "CentralDifference"}, ...};
//
// The binding makes the Python enum from it (the identifiers) and exports the
// names (`_core.SCHEME_NAMES`), which the Python layer's dictionaries, the FMU's
// Enumeration items and the CLI's choices read.  A new enumerator needs one row.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

template <class E>
struct EnumName {
  E value;
  const char* name;        //!< what users write: "dopri5", "central_difference" (Python, FMU items, CLI)
  const char* identifier;  //!< the enumerator's name in the Python binding: "Dopri5" ("None_" for None)
};

//! True when row i holds the enumerator of value i: the FMU stores an enum as its item index.
template <class E, std::size_t N>
constexpr bool in_enum_order(const EnumName<E> (&table)[N]) noexcept {
  for (std::size_t i = 0; i < N; ++i)
    if (static_cast<std::size_t>(table[i].value) != i) return false;
  return true;
}

//! The name of value ("?" if the table lacks it).
template <class E, std::size_t N>
constexpr const char* name_of(const EnumName<E> (&table)[N], E value) noexcept {
  for (const auto& row : table)
    if (row.value == value) return row.name;
  return "?";
}

//! "a, b, c": the names of a table, for messages.
template <class E, std::size_t N>
std::string names_of(const EnumName<E> (&table)[N]) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) (s += i ? ", " : "") += table[i].name;
  return s;
}

//! The value named name; throws Error("invalid <field> = "<name>": expected one of ...") otherwise.
template <class E, std::size_t N>
E parse_enum(const EnumName<E> (&table)[N], std::string_view field, std::string_view name) {
  for (const auto& row : table)
    if (name == row.name) return row.value;
  throw Error("invalid " + std::string(field) + " = \"" + std::string(name) + "\": expected one of " +
              names_of(table));
}

}  // namespace servohydraulics
