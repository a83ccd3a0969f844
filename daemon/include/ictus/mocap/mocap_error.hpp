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

// Out-of-bounds values of a capture (capture_bounds.hpp), as every reader
// treats them: refused with MocapBoundError, or, when the caller accepts them,
// read with one warning per kind (the first value of that kind).
class BoundsReport
{
  public:
    BoundsReport(const std::string &source, bool accept, MocapWarnings *warnings)
        : source_(source), accept_(accept), warnings_(warnings)
    {
    }
    void out_of_bounds(int line, const std::string &kind, const std::string &message);

  private:
    const std::string &source_;
    bool accept_;
    MocapWarnings *warnings_;
    std::vector<std::string> warned_; // kinds already reported (a few)
};

} // namespace ictus
