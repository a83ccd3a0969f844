// The error types of the daemon's areas (docs/architecture.md, "Errors").
#pragma once

#include <stdexcept>

namespace ictus
{

/// An error thrown by one area of the daemon, told apart from the others' by its tag: each
/// area names its own (`using SimError = AreaError<struct SimArea>;` in
/// `ictus/sim/sim_error.hpp`), so a catch site says whose refusals it handles. The message is
/// the whole report: callers print what() as it is.
template <class Area> class AreaError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

} // namespace ictus
