// Compatibility: the paper's presets moved to zhao2003.hpp.
#pragma once
#include "servohydraulics/zhao2003.hpp"
