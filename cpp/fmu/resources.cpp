#include "resources.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <locale>
#include <sstream>

namespace servohydraulics::fmu {

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

[[noreturn]] void fail(const Entry& e, const std::string& why) {
  throw Error(e.where + ": " + e.key + " = " + e.value + ": " + why);
}

// Locale-independent (a host tool may run under a locale with a decimal comma).
double number(const Entry& e, const std::string& text) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  double v = 0.0;
  in >> v;
  if (in.fail() || !in.eof()) fail(e, "expected a number");
  return v;
}

bool is_string(const std::string& v) { return v.size() >= 2 && v.front() == '"' && v.back() == '"'; }

std::string string_value(const Entry& e) {
  if (!is_string(e.value) || e.value.find('\\') != std::string::npos) fail(e, "expected a \"string\"");
  return e.value.substr(1, e.value.size() - 2);
}

std::vector<double> array_value(const Entry& e) {
  if (e.value.size() < 2 || e.value.front() != '[' || e.value.back() != ']') fail(e, "expected a [list] of numbers");
  std::vector<double> out;
  std::stringstream items(e.value.substr(1, e.value.size() - 2));
  for (std::string item; std::getline(items, item, ',');) {
    item = trim(item);
    if (!item.empty()) out.push_back(number(e, item));
  }
  return out;
}

//! The value of a scalar entry as the variable's double (Enumeration items by name).
double scalar_value(const Entry& e, const Variable& var) {
  if (var.type == Type::Enumeration && is_string(e.value)) return item_index(var, string_value(e));
  if (var.type == Type::Boolean) {
    if (e.value == "true") return 1.0;
    if (e.value == "false") return 0.0;
    fail(e, "expected true or false");
  }
  return number(e, e.value);
}

bool flow_curve_entry(const Entry& e, FlowCurve& fc) {
  const std::string prefix = "servovalve.flow_curve.";
  if (e.key.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string key = e.key.substr(prefix.size());
  if (key == "kind") {
    const std::string kind = string_value(e);
    const auto* row = std::find_if(std::begin(kFlowCurveKindNames), std::end(kFlowCurveKindNames),
                                   [&](const auto& r) { return kind == r.name; });
    if (row == std::end(kFlowCurveKindNames)) fail(e, "expected one of " + names_of(kFlowCurveKindNames));
    fc.kind = row->value;
  } else if (key == "b") {
    fc.b = number(e, e.value);
  } else if (key == "opening") {
    fc.opening = array_value(e);
  } else if (key == "flow") {
    fc.flow = array_value(e);
  } else {
    fail(e, "unknown flow-curve key (expected kind, b, opening, flow)");
  }
  return true;
}

void apply(const std::vector<Entry>& entries, const std::vector<Variable>& vars, Values& values) {
  for (const Entry& e : entries) {
    if (e.key == "kind" || e.key == "mode" || e.key == "guid") continue;
    if (flow_curve_entry(e, values.settings.rig.flow_curve)) continue;
    const int i = find(vars, e.key);
    if (i < 0 || vars[i].causality != Causality::Parameter) fail(e, "not a parameter of this FMU");
    try {
      vars[i].set(values, scalar_value(e, vars[i]));
    } catch (const Error& err) {
      throw Error(e.where + ": " + err.what());
    }
  }
}

const Entry* lookup(const std::vector<Entry>& entries, const char* key) {
  for (const Entry& e : entries)
    if (e.key == key) return &e;
  return nullptr;
}

}  // namespace

std::vector<Entry> read_entries(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read the FMU resource " + path);
  std::vector<Entry> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const auto eq = line.find('=');
    const std::string where = path + ":" + std::to_string(n);
    if (eq == std::string::npos) throw Error(where + ": expected key = value, got: " + line);
    out.push_back({trim(line.substr(0, eq)), trim(line.substr(eq + 1)), where});
  }
  return out;
}

Loaded load_resources(const std::string& dir) {
  const std::vector<Entry> fmu = read_entries(dir + "/fmu.toml");
  const std::vector<Entry> rig = read_entries(dir + "/rig.toml");
  Loaded out;
  const Entry* kind = lookup(fmu, "kind");
  const Entry* guid = lookup(fmu, "guid");
  if (!kind || !guid) throw Error(dir + "/fmu.toml: kind and guid are required");
  out.guid = string_value(*guid);
  Values values;
  Settings& s = values.settings;
  s.kind = parse_kind(string_value(*kind));
  if (const Entry* mode = lookup(fmu, "mode")) s.mode = parse_mode(string_value(*mode));
  const std::vector<Variable> vars = variables(s.kind, s.mode);
  apply(rig, vars, values);
  apply(fmu, vars, values);
  s.rig.validate();
  resolve_defaults(s);
  out.settings = s;
  return out;
}

std::string path_from_uri(const std::string& uri) {
  std::string rest;
  if (uri.compare(0, 7, "file://") == 0) rest = uri.substr(7);
  else if (uri.compare(0, 5, "file:") == 0) rest = uri.substr(5);
  else throw Error("unsupported fmuResourceLocation \"" + uri + "\": expected a file: URI");
  if (rest.compare(0, 9, "localhost") == 0) rest = rest.substr(9);
  std::string path;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    if (rest[i] == '%' && i + 2 < rest.size()) {
      path += static_cast<char>(std::strtol(rest.substr(i + 1, 2).c_str(), nullptr, 16));
      i += 2;
    } else {
      path += rest[i];
    }
  }
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  return path;
}

}  // namespace servohydraulics::fmu
