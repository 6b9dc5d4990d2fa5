#include "model.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <variant>

#include "servohydraulics/error.hpp"
#include "servohydraulics/parameters.hpp"

namespace servohydraulics::fmu {

const char* to_string(Kind kind) noexcept { return name_of(kKindNames, kind); }
const char* to_string(Type t) noexcept {
  switch (t) {
    case Type::Real: return "Real";
    case Type::Integer: return "Integer";
    case Type::Boolean: return "Boolean";
    case Type::Enumeration: return "Enumeration";
  }
  return "?";
}
const char* to_string(Causality c) noexcept {
  switch (c) {
    case Causality::Parameter: return "parameter";
    case Causality::Input: return "input";
    case Causality::Output: return "output";
  }
  return "?";
}
const char* to_string(Variability v) noexcept {
  switch (v) {
    case Variability::Fixed: return "fixed";
    case Variability::Tunable: return "tunable";
    case Variability::Discrete: return "discrete";
    case Variability::Continuous: return "continuous";
  }
  return "?";
}

Kind parse_kind(const std::string& name) { return parse_enum(kKindNames, "kind", name); }

ControlMode parse_mode(const std::string& name) { return parse_enum(kControlModeNames, "mode", name); }

void check_dt(double dt) {
  require(std::isfinite(dt) && dt >= kMinDt, "dt", dt,
          "the FMU's controller sample time must be finite and >= 1e-07 s (fmu::kMinDt)");
}

void resolve_defaults(Settings& s) {
  check_dt(s.dt);
  s.eft.dt = s.dt;
  s.rpsd.dt = s.dt;
  if (s.kind == Kind::Eft && !s.eft.mass) s.eft.mass = EftController(s.eft, s.rig).mass();
  if (s.kind == Kind::Rpsd && !(s.rpsd.k_m && s.rpsd.subtract_mass && s.rpsd.subtract_damping)) {
    const RpsdController c(s.rpsd, s.rig);
    s.rpsd.k_m = c.k_m();
    s.rpsd.subtract_mass = c.subtract_mass();
    s.rpsd.subtract_damping = c.subtract_damping();
  }
}

int find(const std::vector<Variable>& vars, const std::string& name) noexcept {
  for (std::size_t i = 0; i < vars.size(); ++i)
    if (vars[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::string expected_items(const Variable& var) {
  std::ostringstream s;
  for (std::size_t i = 0; i < var.items.size(); ++i) s << (i ? ", " : "") << var.items[i] << " (" << i << ")";
  return s.str();
}

[[noreturn]] void bad_value(const std::string& name, double value, const std::string& expected) {
  std::ostringstream s;
  s.precision(17);
  s << "invalid " << name << " = " << value << ": " << expected;
  throw Error(s.str());
}

// --------------------------------------------------------------- builders
Variable base(std::string name, Type type, Causality c, Variability var, std::string unit, std::string doc) {
  Variable x;
  x.name = std::move(name);
  x.type = type;
  x.causality = c;
  x.variability = var;
  x.unit = std::move(unit);
  x.doc = std::move(doc);
  return x;
}

using RealRef = std::function<double&(Values&)>;

Variable real(std::string name, std::string unit, std::string doc, Causality c, Variability var, RealRef ref) {
  Variable x = base(std::move(name), Type::Real, c, var, std::move(unit), std::move(doc));
  x.get = [ref](const Values& v) { return ref(const_cast<Values&>(v)); };
  if (c != Causality::Output) x.set = [ref](Values& v, double d) { ref(v) = d; };
  return x;
}

Variable parameter(std::string name, std::string unit, std::string doc, RealRef ref) {
  return real(std::move(name), std::move(unit), std::move(doc), Causality::Parameter, Variability::Fixed, ref);
}

//! A config field that is "none = from the rig" in the core; explicit here (resolve_defaults).
Variable resolved(std::string name, std::string unit, std::string doc,
                  std::function<std::optional<double>&(Values&)> ref) {
  Variable x = base(std::move(name), Type::Real, Causality::Parameter, Variability::Fixed, std::move(unit),
                    std::move(doc));
  x.get = [ref](const Values& v) {
    const auto& o = ref(const_cast<Values&>(v));
    return o ? *o : std::numeric_limits<double>::quiet_NaN();
  };
  x.set = [ref](Values& v, double d) { ref(v) = d; };
  return x;
}

template <class I>
Variable integer(std::string name, std::string doc, std::function<I&(Values&)> ref) {
  Variable x = base(name, Type::Integer, Causality::Parameter, Variability::Fixed, "", std::move(doc));
  x.get = [ref](const Values& v) { return static_cast<double>(ref(const_cast<Values&>(v))); };
  x.set = [ref, name](Values& v, double d) {
    if (!(std::fabs(d) < 1e15) || d != std::floor(d)) bad_value(name, d, "expected a whole number");
    ref(v) = static_cast<I>(d);
  };
  return x;
}

//! An enum parameter; its items are the names of the enum's table (enum_name.hpp), in the enum's order
//! (the first `count` rows, where the setting takes only those).
template <class E, std::size_t N>
Variable enumeration(std::string name, std::string type_name, const EnumName<E> (&table)[N], std::string doc,
                     std::function<E&(Values&)> ref, std::size_t count = N) {
  Variable x = base(name, Type::Enumeration, Causality::Parameter, Variability::Fixed, "", std::move(doc));
  x.type_name = std::move(type_name);
  for (std::size_t i = 0; i < count && i < N; ++i) x.items.emplace_back(table[i].name);
  x.get = [ref](const Values& v) { return static_cast<double>(static_cast<int>(ref(const_cast<Values&>(v)))); };
  const std::string expected = "expected one of " + expected_items(x);
  const double n = static_cast<double>(x.items.size());
  x.set = [ref, name, expected, n](Values& v, double d) {
    if (!(d >= 0.0 && d < n) || d != std::floor(d)) bad_value(name, d, expected);
    ref(v) = static_cast<E>(static_cast<int>(d));
  };
  return x;
}

Variable boolean(std::string name, std::string doc, std::function<bool&(Values&)> ref) {
  Variable x = base(name, Type::Boolean, Causality::Parameter, Variability::Fixed, "", std::move(doc));
  x.get = [ref](const Values& v) { return ref(const_cast<Values&>(v)) ? 1.0 : 0.0; };
  x.set = [ref, name](Values& v, double d) {
    if (d != 0.0 && d != 1.0) bad_value(name, d, "expected a Boolean");
    ref(v) = d != 0.0;
  };
  return x;
}

// ------------------------------------------------------------ the groups
void add_rig(std::vector<Variable>& out, Kind kind) {
  for (const ParameterInfo& p : kRigParameters) {
    // The plant's servo-controller settings (gains, conversion factors, drive
    // limit) are what an operator tunes online: the FMU rebuilds the plant at
    // the current state.  The hardware's parameters, and every parameter of a
    // controller FMU (its compensators are built from them), are fixed.
    const bool tunable = kind == Kind::Plant && std::string(p.section) == "controller";
    const auto member = p.member;
    Variable x = real(std::string(p.section) + "." + p.key, p.unit, std::string(p.doc) + " (" + p.source + ")",
                      Causality::Parameter, tunable ? Variability::Tunable : Variability::Fixed,
                      [member](Values& v) -> double& { return v.settings.rig.*member; });
    x.in_rig = true;
    out.push_back(std::move(x));
  }
  // The rig keys whose value is a name (parameters.hpp: ChoiceInfo) as Enumeration parameters.
  for (auto x : {enumeration<MrInput>(std::string(kMrInputChoice.section) + "." + kMrInputChoice.key, "MrInput",
                                      kMrInputNames, kMrInputChoice.doc,
                                      [](Values& v) -> MrInput& { return v.settings.rig.mr_input; }),
                 enumeration<MrLaw>(std::string(kMrLawChoice.section) + "." + kMrLawChoice.key, "MrLaw", kMrLawNames,
                                    kMrLawChoice.doc, [](Values& v) -> MrLaw& { return v.settings.rig.mr_law; })}) {
    x.in_rig = true;
    out.push_back(std::move(x));
  }
  for (const EffectInfo& e : kEffects) {
    const auto member = e.member;
    Variable x = boolean(std::string("effects.") + e.key, e.doc,
                         [member](Values& v) -> bool& { return v.settings.rig.effects.*member; });
    x.in_rig = true;
    out.push_back(std::move(x));
  }
}

void add_sensors(std::vector<Variable>& out) {
  for (const ChannelInfo& c : kPlantChannels) {
    if (c.member == &Output::time) continue;  // the FMU's own time
    const auto member = c.member;
    out.push_back(real(std::string("sensors.") + c.name, c.unit, std::string("sensor input: ") + c.doc,
                       Causality::Input, Variability::Continuous,
                       [member](Values& v) -> double& { return v.sensors.*member; }));
  }
}

//! A controller's channel table as outputs, less the channels that echo an input of the same name.
template <class Row, std::size_t N>
void add_outputs(std::vector<Variable>& out, const ChannelInfoOf<Row> (&table)[N], Row Values::*row) {
  for (const auto& c : table) {
    if (find(out, c.name) >= 0) continue;
    const auto member = c.member;
    out.push_back(real(c.name, c.unit, c.doc, Causality::Output, Variability::Discrete,
                       [row, member](Values& v) -> double& { return (v.*row).*member; }));
  }
}

void add_dt(std::vector<Variable>& out) {
  out.push_back(parameter("dt", "s", "controller sample time: every doStep is a whole number of samples",
                          [](Values& v) -> double& { return v.settings.dt; }));
}

//! Every SolverOptions field as "solver.<name>" (kSolverOptionFields), so the plant FMU integrates
//! with exactly the options it was exported with.
void add_solver(std::vector<Variable>& out) {
  using SO = SolverOptions;
  for (const SolverOptionField& f : kSolverOptionFields) {
    const std::string name = std::string("solver.") + f.name;
    out.push_back(std::visit(
        [&](auto member) -> Variable {
          using T = std::remove_reference_t<decltype(std::declval<SO&>().*member)>;
          auto ref = [member](Values& v) -> T& { return v.settings.solver.*member; };
          if constexpr (std::is_same_v<T, SO::Method>) {
            return enumeration<T>(name, "SolverMethod", kMethodNames, f.doc, ref);
          } else if constexpr (std::is_same_v<T, SO::Restart>) {
            return enumeration<T>(name, "SolverRestart", kRestartNames, f.doc, ref);
          } else if constexpr (std::is_same_v<T, bool>) {
            return boolean(name, f.doc, ref);
          } else if constexpr (std::is_same_v<T, double>) {
            return parameter(name, f.unit, f.doc, ref);
          } else {
            return integer<T>(name, f.doc, ref);
          }
        },
        f.member));
  }
}

void add_plant(std::vector<Variable>& out, ControlMode mode) {
  out.push_back(real("command", mode == ControlMode::Displacement ? "m" : "N",
                     "command held over each sample (displacement [m] or force [N] per the control mode)",
                     Causality::Input, Variability::Continuous, [](Values& v) -> double& { return v.command; }));
  for (const ChannelInfo& c : kPlantChannels) {
    if (c.member == &Output::time) continue;
    const auto member = c.member;
    out.push_back(real(c.name, c.unit, c.doc, Causality::Output, Variability::Continuous,
                       [member](Values& v) -> double& { return v.plant_out.*member; }));
  }
  Variable flags = base("flags", Type::Integer, Causality::Output, Variability::Discrete, "",
                        "OutputFlag bits: 1 capacity, 2 supply-limited, 4 spool saturated, 8 drive saturated, "
                        "16 stroke exceeded");
  flags.get = [](const Values& v) { return static_cast<double>(v.plant_out.flags); };
  out.push_back(std::move(flags));
  add_dt(out);
  out.push_back(parameter("x0", "m", "initial displacement (static equilibrium there)",
                          [](Values& v) -> double& { return v.settings.x0; }));
  add_solver(out);
}

//! A config field of an enum type as an Enumeration parameter: the enum's name table, its FMU type name.
template <class E>
Variable enum_parameter(std::string name, std::string doc, std::function<E&(Values&)> ref) {
  if constexpr (std::is_same_v<E, VelocityFeedbackCompensator::Kind>) {
    return enumeration<E>(std::move(name), "Compensation", kCompensationNames, std::move(doc), ref);
  } else if constexpr (std::is_same_v<E, StructuralScheme>) {
    // Eq (15)'s schemes only: the RPsD controller's one-degree-of-freedom integrator
    return enumeration<E>(std::move(name), "IntegrationScheme", kSchemeNames, std::move(doc), ref, kEq15Schemes);
  } else if constexpr (std::is_same_v<E, RestoringForce>) {
    return enumeration<E>(std::move(name), "RestoringForce", kRestoringForceNames, std::move(doc), ref);
  } else if constexpr (std::is_same_v<E, ForceMeasurement>) {
    return enumeration<E>(std::move(name), "ForceMeasurement", kForceMeasurementNames, std::move(doc), ref);
  } else {
    static_assert(!std::is_same_v<E, E>, "a config field of an enum the FMU generator has no name table for");
  }
}

template <class C, class = void>
struct has_dt : std::false_type {};
template <class C>
struct has_dt<C, std::void_t<decltype(&C::dt)>> : std::true_type {};

//! One row of a config's field table (config_fields.hpp) as the parameter "<prefix><name>" (its unit
//! and meaning), read and written through `path` (the config inside Values); a nested struct's
//! fields are flattened under the same prefix (rpsd.model.m_m is "rpsd.m_m").
template <class Config, class T, class Path>
void add_field(std::vector<Variable>& out, const std::string& prefix, const ConfigField<Config, T>& f, Path path) {
  const auto member = f.member;
  if constexpr (std::is_same_v<T, double> && has_dt<Config>::value)
    if (member == &Config::dt) return;  // the FMU's own dt (add_dt), copied into the config
  auto ref = [path, member](Values& v) -> T& { return path(v).*member; };
  std::string name = prefix + f.name;
  if constexpr (std::is_same_v<T, double>) {
    out.push_back(parameter(std::move(name), f.unit, f.meaning, ref));
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    out.push_back(resolved(std::move(name), f.unit, f.meaning, ref));  // "none = from the rig": resolve_defaults
  } else if constexpr (std::is_same_v<T, int>) {
    out.push_back(integer<int>(std::move(name), f.meaning, ref));
  } else if constexpr (std::is_enum_v<T>) {
    out.push_back(enum_parameter<T>(std::move(name), f.meaning, ref));
  } else if constexpr (std::is_same_v<T, ModelSDOF>) {
    std::apply([&](const auto&... g) { (add_field(out, prefix, g, ref), ...); }, kModelSdofFields);
  } else {
    static_assert(!std::is_same_v<T, T>, "a config field of a type the FMU generator has no rule for");
  }
}

//! Every field of a config's table (kEftConfigFields, kRpsdConfigFields) but dt (the FMU's own).
template <class Table, class Path>
void add_config(std::vector<Variable>& out, const std::string& prefix, const Table& table, Path path) {
  std::apply([&](const auto&... f) { (add_field(out, prefix, f, path), ...); }, table);
}

void add_eft(std::vector<Variable>& out) {
  out.push_back(real("ground_acceleration", "m/s^2", "ground acceleration a_g(t_k)", Causality::Input,
                     Variability::Continuous, [](Values& v) -> double& { return v.ground_acceleration; }));
  add_sensors(out);
  add_outputs(out, kEftChannels, &Values::eft_out);
  add_dt(out);
  add_config(out, "eft.", kEftConfigFields, [](Values& v) -> EftConfig& { return v.settings.eft; });
}

void add_rpsd(std::vector<Variable>& out) {
  out.push_back(real("ground_acceleration", "m/s^2", "ground acceleration a_g(t_k)", Causality::Input,
                     Variability::Continuous, [](Values& v) -> double& { return v.ground_acceleration; }));
  out.push_back(real("external_force", "N", "external force P_ext into the solver", Causality::Input,
                     Variability::Continuous, [](Values& v) -> double& { return v.external_force; }));
  out.push_back(real("restoring_force_error", "N", "error added to the restoring force", Causality::Input,
                     Variability::Continuous, [](Values& v) -> double& { return v.restoring_force_error; }));
  add_sensors(out);
  add_outputs(out, kRpsdChannels, &Values::rpsd_out);
  add_dt(out);
  add_config(out, "rpsd.", kRpsdConfigFields, [](Values& v) -> RpsdConfig& { return v.settings.rpsd; });
}

}  // namespace

int item_index(const Variable& var, const std::string& item) {
  for (std::size_t i = 0; i < var.items.size(); ++i)
    if (var.items[i] == item) return static_cast<int>(i);
  throw Error("invalid " + var.name + " = \"" + item + "\": expected one of " + expected_items(var));
}

std::vector<Variable> variables(Kind kind, ControlMode mode) {
  std::vector<Variable> out;
  switch (kind) {
    case Kind::Plant: add_plant(out, mode); break;
    case Kind::Eft: add_eft(out); break;
    case Kind::Rpsd: add_rpsd(out); break;
  }
  add_rig(out, kind);
  return out;
}

}  // namespace servohydraulics::fmu
