// The error type of the sim area (docs/architecture.md, "Errors").
#pragma once

#include "ictus/base/area_error.hpp"

namespace ictus
{

/// What the sim area throws: a scene, drum or control input that the simulation refuses.
using SimError = AreaError<struct SimArea>;

} // namespace ictus
