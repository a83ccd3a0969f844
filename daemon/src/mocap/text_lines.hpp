// text_lines.hpp -- shared text helpers of the readers (private to src/mocap).
#pragma once

#include <fstream>
#include <istream>
#include <string>
#include <vector>

namespace ictus::detail
{

// Reads a whole stream and splits it into lines. "\r\n", "\n" and a lone "\r"
// all end a line, so files with mixed line endings (the CMU BVH has both)
// read the same as clean ones. Refuses streams larger than max_bytes.
std::vector<std::string> read_lines(std::istream &in, const std::string &source_name,
                                    std::size_t max_bytes);

// Opens a capture file `what` ("BVH", "CSV") for reading: a folder, or a
// file that cannot be opened, is a MocapError that says so, with the
// system's reason ("No such file or directory").
std::ifstream open_capture(const std::string &path, const char *what);

// Splits on blanks (space, tab, and any other isspace character).
std::vector<std::string> split_blanks(const std::string &line);

// Parses a whole token as a double (strtod, "C" rules); false if any
// character is left over or the token is empty. Does not check finiteness.
bool parse_double(const std::string &token, double &value);

// Text shown for a token in an error message: quoted and cut to 40 chars.
std::string quote(const std::string &token);

std::string trim(const std::string &text);

} // namespace ictus::detail
