// The error type of the control area (docs/architecture.md, "Errors").
#pragma once

#include "ictus/base/area_error.hpp"

namespace ictus
{

/// What the control area throws: a chain, gain or limit that the controllers refuse.
using ControlError = AreaError<struct ControlArea>;

} // namespace ictus
