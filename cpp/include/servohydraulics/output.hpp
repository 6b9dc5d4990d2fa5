// The plant's sensors and derived channels at one instant, and the flags a step raises.
#pragma once

#include <cstdint>

namespace servohydraulics {

//! Bit flags raised by a step (OR-ed over the sample's end state).
enum OutputFlag : std::uint32_t {
  kCapacityExceeded = 1u << 0,  //!< |load-cell force| > F_cap
  kSupplyLimited = 1u << 1,     //!< |p| >= 0.98 p_s: the force demand is at the supply-pressure limit
  kSpoolSaturated = 1u << 2,    //!< |x_v| >= x_v_max
  kDriveSaturated = 1u << 3,    //!< |valve drive| >= v_max
  kStrokeExceeded = 1u << 4,    //!< |x| > stroke: a real actuator would hit its end stop (not modelled)
};

//! Every channel of the plant at one instant (names and units: channels.hpp).
struct Output {
  double time = 0.0;          //!< time of the sample [s]
  double displacement = 0.0;  //!< x [m]
  double velocity = 0.0;      //!< dx/dt [m/s]
  double acceleration = 0.0;  //!< d2x/dt2 [m/s^2]
  double force = 0.0;         //!< load-cell force between piston and structure [N]
  double pressure = 0.0;      //!< load pressure p [Pa]
  double spool = 0.0;         //!< metering spool opening x_v [-]
  double drive = 0.0;         //!< valve drive v [V]
  double flow = 0.0;          //!< valve flow Q [m^3/s]
  double specimen_force = 0.0;  //!< force of the Bouc-Wen and MR damper specimens [N] (0 when off; docs/specimens.md)
  std::uint32_t flags = 0;    //!< OutputFlag bits
};

}  // namespace servohydraulics
