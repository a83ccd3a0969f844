// The error type of the perform area (docs/architecture.md, "Errors").
#pragma once

#include <stdexcept>

namespace ictus {

/// What the perform area throws: a score, clip or command that the performance refuses.
class PerformError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

} // namespace ictus
