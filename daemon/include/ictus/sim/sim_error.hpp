// The error type of the sim area (docs/architecture.md, "Errors").
#pragma once

#include <stdexcept>

namespace ictus {

/// What the sim area throws: a scene, drum or control input that the simulation refuses.
class SimError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

} // namespace ictus
