// The one table of the plant's channels: name, unit and the Output member that
// holds it.  Records (record.hpp), the bindings and the CSV files take their
// channel names and units from here.
#pragma once

#include <cstddef>

#include "servohydraulics/output.hpp"

namespace servohydraulics {

//! One channel of a per-sample struct S: its name, SI unit, a line of doc and the member.
template <class S>
struct ChannelInfoOf {
  const char* name;
  const char* unit;
  const char* doc;
  double S::*member;
};
using ChannelInfo = ChannelInfoOf<Output>;

//! Indices into kPlantChannels (and Channels::channel).
enum class Channel : int {
  Time, Displacement, Velocity, Acceleration, Force, Pressure, Spool, Drive, Flow, SpecimenForce
};

constexpr ChannelInfo kPlantChannels[] = {
    {"time", "s", "time of the sample", &Output::time},
    {"displacement", "m", "structure (and piston) displacement x", &Output::displacement},
    {"velocity", "m/s", "velocity dx/dt", &Output::velocity},
    {"acceleration", "m/s^2", "acceleration d2x/dt2", &Output::acceleration},
    {"force", "N", "load-cell force between piston and structure", &Output::force},
    {"pressure", "Pa", "load pressure p", &Output::pressure},
    {"spool", "-", "metering spool opening x_v", &Output::spool},
    {"drive", "V", "valve drive v", &Output::drive},
    {"flow", "m^3/s", "valve flow Q", &Output::flow},
    {"specimen_force", "N", "force of the Bouc-Wen and MR damper specimens (0 when off)", &Output::specimen_force},
};
constexpr std::size_t kNumPlantChannels = sizeof(kPlantChannels) / sizeof(kPlantChannels[0]);

constexpr const ChannelInfo& channel_info(Channel c) noexcept { return kPlantChannels[static_cast<int>(c)]; }

static_assert(channel_info(Channel::Time).member == &Output::time, "kPlantChannels out of order");
static_assert(channel_info(Channel::Force).member == &Output::force, "kPlantChannels out of order");
static_assert(channel_info(Channel::Flow).member == &Output::flow, "kPlantChannels out of order");
static_assert(channel_info(Channel::SpecimenForce).member == &Output::specimen_force, "kPlantChannels out of order");
static_assert(static_cast<std::size_t>(Channel::SpecimenForce) + 1 == kNumPlantChannels,
              "Channel and kPlantChannels differ");

}  // namespace servohydraulics
