// mocap_error.cpp -- MocapError: "FILE:LINE: message".
#include "ictus/mocap/mocap_error.hpp"

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

} // namespace ictus
