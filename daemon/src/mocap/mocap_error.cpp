// mocap_error.cpp -- MocapError: "FILE:LINE: message".
#include "ictus/mocap/mocap_error.hpp"

#include <algorithm>

namespace ictus
{

namespace
{
std::string compose(const std::string &file, int line, const std::string &message)
{
    if (file.empty())
        return message;
    if (line <= 0)
        return file + ": " + message;
    return file + ":" + std::to_string(line) + ": " + message;
}
} // namespace

MocapError::MocapError(const std::string &file, int line, const std::string &message)
    : std::runtime_error(compose(file, line, message)), file_(file), line_(line), message_(message)
{
}

void BoundsReport::out_of_bounds(int line, const std::string &kind, const std::string &message)
{
    if (!accept_)
        throw MocapBoundError(source_, line, message);
    if (!warnings_ || std::find(warned_.begin(), warned_.end(), kind) != warned_.end())
        return;
    warned_.push_back(kind);
    warnings_->push_back(std::string(MocapError(source_, line, message).what()) +
                         " (read anyway: out of bounds accepted; later values of this kind are "
                         "not reported)");
}

} // namespace ictus
