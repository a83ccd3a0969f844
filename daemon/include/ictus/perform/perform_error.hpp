// The error type of the perform area (docs/architecture.md, "Errors").
#pragma once

#include "ictus/base/area_error.hpp"

namespace ictus
{

/// What the perform area throws: a score, clip or command that the performance refuses.
using PerformError = AreaError<struct PerformArea>;

} // namespace ictus
