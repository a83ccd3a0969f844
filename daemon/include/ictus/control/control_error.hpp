// The error type of the control area (docs/architecture.md, "Errors").
#pragma once

#include <stdexcept>

namespace ictus {

/// What the control area throws: a chain, gain or limit that the controllers refuse.
class ControlError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

} // namespace ictus
