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
//! switched on (Bouc-Wen specimen, MR damper, Pade loop delay) append their
//! states after them, in that order, only when on: Dynamics::num_states() is the
//! active count and Dynamics::layout() says where each element's states are.
enum StateIndex : int { kX = 0, kV = 1, kP = 2, kXv = 3, kXvDot = 4, kZ = 5, kNumStates = 6 };

//! Highest order of the Pade loop delay (effects.loop_delay, Rig::loop_delay_order).
constexpr int kMaxPadeOrder = 6;
//! Fixed capacity of the state vector: the base states, Bouc-Wen z, the MR
//! damper's y and z, and the Pade states, with room to spare.
constexpr int kMaxStates = 16;
static_assert(kNumStates + 1 + 2 + kMaxPadeOrder <= kMaxStates, "kMaxStates too small");

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
//! The appended states of the switchable elements (Dynamics::state_info gives them by index).
constexpr StateInfo kBoucWenState = {"bw_z", "m", "Bouc-Wen hysteretic displacement z (effects.bouc_wen_hysteresis)"};
constexpr StateInfo kMrStates[2] = {
    {"mr_y", "m", "MR damper internal displacement y (Spencer et al. 1997; effects.mr_damper)"},
    {"mr_z", "m", "MR damper evolutionary variable z (Spencer et al. 1997; effects.mr_damper)"},
};
constexpr StateInfo kPadeStates[kMaxPadeOrder] = {
    {"delay_1", "V", "Pade loop-delay state 1 (effects.loop_delay)"},
    {"delay_2", "V", "Pade loop-delay state 2"},
    {"delay_3", "V", "Pade loop-delay state 3"},
    {"delay_4", "V", "Pade loop-delay state 4"},
    {"delay_5", "V", "Pade loop-delay state 5"},
    {"delay_6", "V", "Pade loop-delay state 6"},
};

//! Where the switchable elements' states sit in the state vector (-1: element off).
struct StateLayout {
  int num_states = kNumStates;  //!< active count
  int bw_z = -1;                //!< Bouc-Wen z
  int mr_y = -1;                //!< MR damper y (mr_y + 1 is its z)
  int pade = -1;                //!< first Pade state (pade_order of them)
  int pade_order = 0;
};

}  // namespace servohydraulics
