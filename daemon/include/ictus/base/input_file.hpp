// An input file opened for reading, or why it could not be: the one place the readers
// (--score, BVH, CSV, MIDI) learn that a path is a folder or what the system said.
#pragma once

#include <fstream>
#include <string>

namespace ictus
{

struct InputFile {
    std::ifstream stream; ///< open, binary, when opened
    bool opened = false;
    bool is_folder = false; ///< a folder (not opened: it would read as empty)
    std::string reason;     ///< the system's, when not opened ("No such file or directory")

    /// " (REASON)" when the system gave a reason, else "": for the end of a message.
    std::string reason_suffix() const { return reason.empty() ? "" : " (" + reason + ")"; }
};

/// Opens `path` for binary reading.
InputFile open_input_file(const std::string &path);

} // namespace ictus
