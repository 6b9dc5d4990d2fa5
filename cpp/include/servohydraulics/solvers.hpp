// Compatibility: the Eq (15) integration schemes moved to integration.hpp.
#pragma once
#include "servohydraulics/integration.hpp"
