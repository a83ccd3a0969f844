// input_file.cpp -- see ictus/base/input_file.hpp.
#include "ictus/base/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace ictus
{

InputFile open_input_file(const std::string &path)
{
    InputFile f;
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        f.is_folder = true;
        return f;
    }
    errno = 0;
    f.stream.open(path, std::ios::binary);
    f.opened = static_cast<bool>(f.stream);
    if (!f.opened && errno != 0)
        f.reason = std::strerror(errno);
    return f;
}

} // namespace ictus
