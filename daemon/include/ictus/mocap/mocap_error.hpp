// mocap_error.hpp -- the one error type of the motion-capture readers and learners.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{

// Thrown by the readers for anything they refuse: what() reads
// "FILE:LINE: expected X, got Y" (LINE is 1-based; 0 when the problem is not
// on one line, e.g. an empty series given to a learner).
class MocapError : public std::runtime_error
{
  public:
    MocapError(const std::string &file, int line, const std::string &message);
    const std::string &file() const { return file_; }
    int line() const { return line_; }
    // The message without the "FILE:LINE: " prefix.
    const std::string &message() const { return message_; }

  private:
    std::string file_;
    int line_;
    std::string message_;
};

// A value the file format allows but a capture of a human performer does not
// (capture_bounds.hpp): a frame time, a time step, a duration or a coordinate
// out of bounds. Same what() as MocapError; callers that let a user insist
// (`--force`) catch it to say so, or set the reader's accept_out_of_bounds.
class MocapBoundError : public MocapError
{
  public:
    using MocapError::MocapError;
};

// Readers append human-readable warnings ("FILE:LINE: ...") here when the
// caller passes a non-null pointer; nothing is printed by the library.
using MocapWarnings = std::vector<std::string>;

} // namespace ictus
