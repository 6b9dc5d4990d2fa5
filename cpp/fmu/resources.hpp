// The FMU's resources: what the exporter wrote into resources/ and the binary
// reads at fmi2Instantiate.  Two files of `key = value` lines, each a valid
// TOML document of dotted keys:
//
//   fmu.toml   kind, mode, guid, then the FMU's own parameters (dt, solver.*, the
//              controller's configuration), named as the FMU's variables
//   rig.toml   the rig: `structure.m = 7084.0`, `effects.coulomb_friction = true`,
//              `servovalve.flow_curve.kind = "rational"`, ... (sh.load_rig reads it)
//
// Values: a number, true/false, a "string" (an Enumeration item, or the flow
// curve's kind), or a one-line [array] of numbers (the flow curve's table).
#pragma once

#include <string>
#include <vector>

#include "model.hpp"

namespace servohydraulics::fmu {

//! One `key = value` line.
struct Entry {
  std::string key;
  std::string value;  //!< as written (trimmed)
  std::string where;  //!< "file:line", for messages
};

//! The lines of a resource file; throws Error naming the file (and line) when
//! it cannot be read or a line is not `key = value`.
std::vector<Entry> read_entries(const std::string& path);

//! What the resources say: the settings (defaults resolved) and the GUID the
//! exporter wrote into modelDescription.xml.  Throws Error naming the file, the
//! line, the key and the value at the first problem.
struct Loaded {
  Settings settings;
  std::string guid;
};
Loaded load_resources(const std::string& resource_dir);

//! The directory of an fmuResourceLocation URI ("file:///a/b/resources" or
//! "file:/a/b/resources", percent-escapes decoded); throws Error otherwise.
std::string path_from_uri(const std::string& uri);

}  // namespace servohydraulics::fmu
