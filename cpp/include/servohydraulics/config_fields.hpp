// A config's field table: name, unit, meaning and member of every field of a
// loop configuration (EftConfig, RpsdConfig; controllers.hpp; the simulated loops'
// EftLoopOptions, RpsdLoopOptions; loops.hpp).  The fields have
// different types, so a table is a std::tuple of ConfigField<Config, T>; the
// binding reads it for def_readwrite, the protocol's field list and the
// <NAME>_CONFIG_FIELDS table Python sees (loops.eft_config / rpsd_config set
// every field through it), and the controller FMUs' parameters are generated
// from the controllers' (cpp/fmu/model.cpp add_config; dt is the FMU's own parameter).
#pragma once

#include <tuple>

namespace servohydraulics {

template <class Config, class T>
struct ConfigField {
  const char* name;
  const char* unit;     //!< SI unit ("-" dimensionless, "" for a choice or a nested struct)
  const char* meaning;
  T Config::*member;
};

template <class Config, class T>
constexpr ConfigField<Config, T> config_field(const char* name, const char* unit, const char* meaning,
                                              T Config::*member) {
  return {name, unit, meaning, member};
}

}  // namespace servohydraulics
