// The FMU's model: what one servohydraulics FMU is (its kind, its settings) and
// its variable table (name, value reference, type, causality, variability,
// unit, and how to read and write the value), generated from the core's tables
// (kRigParameters, kEffects, kPlantChannels, kEftChannels, kRpsdChannels,
// kEftConfigFields, kRpsdConfigFields), so a new rig key, channel or config field
// appears in the FMU by itself.
//
// The table is the one home of the FMU's interface: the fmi2 functions
// (fmi2_functions.cpp) serve it and the Python exporter writes
// modelDescription.xml from it (_core.fmu_variables).  No FMI header is needed
// here: value references are plain unsigned ints.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "servohydraulics/controllers.hpp"
#include "servohydraulics/plant.hpp"

namespace servohydraulics::fmu {

//! What the FMU simulates.
enum class Kind {
  Plant,  //!< the plant: input the command, outputs every plant channel
  Eft,    //!< the EFT controller: inputs a_g and the sensors, output the force command
  Rpsd,   //!< the RPsD controller: inputs a_g, P_ext, the restoring-force error and the sensors
};
inline constexpr EnumName<Kind> kKindNames[] = {
    {Kind::Plant, "plant", "Plant"}, {Kind::Eft, "eft", "Eft"}, {Kind::Rpsd, "rpsd", "Rpsd"}};
static_assert(in_enum_order(kKindNames), "kKindNames: one row per enumerator, in order");
const char* to_string(Kind kind) noexcept;
Kind parse_kind(const std::string& name);          //!< kKindNames: "plant", "eft", "rpsd"; throws Error
ControlMode parse_mode(const std::string& name);  //!< "displacement", "force", "free"; throws Error

//! Everything the FMU's parameters set.  The optional defaults of the configs
//! (EFT mass, RPsD k_m, subtract_mass, subtract_damping) are resolved to
//! explicit values by resolve_defaults(), so each is one plain parameter.
struct Settings {
  Kind kind = Kind::Plant;
  ControlMode mode = ControlMode::Displacement;  //!< plant: its control mode (the command's unit)
  Rig rig;               //!< plant: the rig; EFT: the controller's model; RPsD: the physical rig
  double dt = 5e-4;      //!< controller sample [s]: doStep sizes are whole multiples of it
  double x0 = 0.0;       //!< plant: initial displacement [m] (static equilibrium there)
  SolverOptions solver;  //!< plant: the ODE integrator
  EftConfig eft;         //!< EFT controller (its dt is `dt`)
  RpsdConfig rpsd;       //!< RPsD controller (its dt is `dt`)
};
//! Bounds of the FMU's timing.  A doStep runs at most kMaxSamplesPerStep
//! controller samples (seconds of work, not hours: a longer communication step
//! is an error naming it), and dt is at least kMinDt (a 10 MHz controller;
//! a smaller dt made an ordinary doStep of a host trillions of samples).
inline constexpr double kMinDt = 1e-7;               // [s]
inline constexpr long kMaxSamplesPerStep = 10000000;  // 1.4 h at the paper's 2 kHz

//! Throws Error naming dt unless it is finite and >= kMinDt.
void check_dt(double dt);

//! Fills the configs' "none = from the rig" fields with the values the core
//! would use (validates, dt too; throws Error), and copies dt into the configs.
void resolve_defaults(Settings& s);

//! The controllers' config tables (kEftConfigFields, kRpsdConfigFields) are the FMU's parameters:
//! every field is "eft.<name>" or "rpsd.<name>" (a nested struct's fields flattened: "rpsd.m_m"),
//! with the table's unit and meaning, in table order, but the config's dt, which is the FMU's own
//! parameter dt (doStep sizes are whole multiples of it) copied into the config (resolve_defaults).
//! A field of a type the generator has no rule for does not compile.  A config holds only what its
//! controller uses, so no field is skipped (the simulated loops' own settings are loops.hpp's).

//! The values a variable reads and writes: settings, inputs, outputs.
struct Values {
  Settings settings;
  Output sensors;                   //!< controllers: the plant's channels as inputs
  double command = 0.0;             //!< plant: the held command [m or N]
  double ground_acceleration = 0.0; //!< controllers: a_g [m/s^2]
  double external_force = 0.0;      //!< RPsD: P_ext [N]
  double restoring_force_error = 0.0;  //!< RPsD: added to f [N]
  Output plant_out;                 //!< plant: the outputs at the current time
  EftOutput eft_out;                //!< EFT: the sample computed from the current inputs
  RpsdOutput rpsd_out;              //!< RPsD: idem
};

enum class Type { Real, Integer, Boolean, Enumeration };
enum class Causality { Parameter, Input, Output };
enum class Variability { Fixed, Tunable, Discrete, Continuous };
const char* to_string(Type t) noexcept;
const char* to_string(Causality c) noexcept;
const char* to_string(Variability v) noexcept;

//! One scalar variable.  Every value travels as a double (Integer,
//! Enumeration and Boolean values are whole numbers); set() throws Error
//! naming the variable and the value when the value is out of its domain.
struct Variable {
  std::string name;
  Type type = Type::Real;
  Causality causality = Causality::Parameter;
  Variability variability = Variability::Fixed;
  std::string unit;  //!< SI unit ("" for none)
  std::string doc;
  std::string type_name;           //!< Enumeration: the name of its type
  std::vector<std::string> items;  //!< Enumeration: item names; item value = index
  bool in_rig = false;             //!< a key of the rig file (resources/rig.toml), else of resources/fmu.toml
  std::function<double(const Values&)> get;
  std::function<void(Values&, double)> set;  //!< empty for outputs
};

//! The variables of an FMU of this kind (and, for the plant, mode); the value
//! reference of a variable is its index.
std::vector<Variable> variables(Kind kind, ControlMode mode);

//! Index of the variable named `name`, or -1.
int find(const std::vector<Variable>& vars, const std::string& name) noexcept;

//! The item index of `item` in an Enumeration variable; throws Error naming both.
int item_index(const Variable& var, const std::string& item);

}  // namespace servohydraulics::fmu
