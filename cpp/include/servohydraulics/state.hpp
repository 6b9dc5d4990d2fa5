// The plant's state vector and the control mode that selects its equations.
#pragma once

#include <array>

#include "servohydraulics/enum_name.hpp"

namespace servohydraulics {

//! What the analog servo controller feeds back (Eq 1), or no actuator at all.
enum class ControlMode {
  Displacement,  //!< LVDT displacement; command in [m]
  Force,         //!< load-cell force; command in [N]
  Free,          //!< structure alone, no actuator; command is an ideal external force [N]
};

inline constexpr EnumName<ControlMode> kControlModeNames[] = {
    {ControlMode::Displacement, "displacement", "Displacement"},
    {ControlMode::Force, "force", "Force"},
    {ControlMode::Free, "free", "Free"},
};
static_assert(in_enum_order(kControlModeNames), "kControlModeNames: one row per enumerator, in order");

constexpr const char* to_string(ControlMode mode) noexcept { return name_of(kControlModeNames, mode); }

//! Indices of the state vector's fixed part (always present, in this order).
//! kZ is the LuGre bristle deflection [m] (held at 0 unless effects.lugre_friction).
//! kNumStates is the count of these base states; the elements that can be
//! switched on (elements.hpp) append their states after them, in the order of
//! Elements, only when on: Dynamics::num_states() is the active count and
//! Dynamics::layout() says where each element's states are.
enum StateIndex : int { kX = 0, kV = 1, kP = 2, kXv = 3, kXvDot = 4, kZ = 5, kNumStates = 6 };

//! Highest order of the Pade loop delay (effects.loop_delay, Rig::loop_delay_order).
constexpr int kMaxPadeOrder = 6;
//! Fixed capacity of the state vector: the base states and those of every element
//! switched on (elements.hpp checks that they fit).
constexpr int kMaxStates = 16;

//! The state vector (fixed capacity; entries past Dynamics::num_states() are 0 and unused).
using State = std::array<double, kMaxStates>;
using Jacobian = std::array<std::array<double, kMaxStates>, kMaxStates>;  //!< J[row][col] = d f_row / d y_col

//! Name and unit of each state.
struct StateInfo {
  const char* name;
  const char* unit;
  const char* doc;
};
//! The base states, indexed by StateIndex.
constexpr StateInfo kStates[kNumStates] = {
    {"x", "m", "displacement of the structure and piston"},
    {"v", "m/s", "velocity"},
    {"p", "Pa", "load pressure (Eq 4)"},
    {"x_v", "-", "spool opening (Eq 2; 0 with a static valve)"},
    {"x_v_dot", "1/s", "spool rate"},
    {"z", "m", "LuGre bristle deflection (0 unless lugre_friction)"},
};
}  // namespace servohydraulics
