// text_lines.cpp -- line splitting and number parsing shared by the readers.
#include "text_lines.hpp"

#include "ictus/mocap/mocap_error.hpp"

#include "ictus/base/input_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <system_error>

namespace ictus::detail
{

namespace
{
// UTF-16 (a "Unicode" save on Windows, a spreadsheet's Unicode text): its byte order
// mark, or, without one, each of the first characters a byte and a NUL in the same
// order (a capture's text has no NUL, so at least two such pairs).
bool utf16_text(const std::string &head)
{
    if (head.compare(0, 2, "\xFF\xFE") == 0 || head.compare(0, 2, "\xFE\xFF") == 0)
        return true;
    const std::size_t pairs = std::min<std::size_t>(head.size() / 2, 32);
    if (pairs < 2)
        return false;
    for (const std::size_t nul : {std::size_t{0}, std::size_t{1}}) {
        bool all = true;
        for (std::size_t k = 0; all && k < pairs; ++k)
            all = head[2 * k + nul] == '\0' && head[2 * k + 1 - nul] != '\0';
        if (all)
            return true;
    }
    return false;
}
} // namespace

std::vector<std::string> read_lines(std::istream &in, const std::string &source_name,
                                    std::size_t max_bytes)
{
    std::vector<std::string> lines;
    std::string current;
    std::size_t total = 0;
    char buffer[65536];
    bool pending_cr = false;
    bool first = true;
    while (in) {
        in.read(buffer, sizeof buffer);
        const std::streamsize got = in.gcount();
        if (first && utf16_text(std::string(buffer, static_cast<std::size_t>(got))))
            throw MocapError(source_name, 1,
                             "expected UTF-8 or ASCII text, got UTF-16 (save the file as UTF-8)");
        first = false;
        total += static_cast<std::size_t>(got);
        if (total > max_bytes)
            throw MocapError(source_name, 0,
                             "expected at most " + std::to_string(max_bytes) +
                                 " bytes, got more (file too large)");
        for (std::streamsize i = 0; i < got; ++i) {
            const char c = buffer[i];
            if (pending_cr) {
                pending_cr = false;
                if (c == '\n')
                    continue; // second half of CRLF
            }
            if (c == '\r' || c == '\n') {
                lines.push_back(current);
                current.clear();
                pending_cr = (c == '\r');
            } else {
                current.push_back(c);
            }
        }
    }
    if (in.bad())
        throw MocapError(source_name, 0, "expected a readable stream, got a read error");
    if (!current.empty())
        lines.push_back(current);
    // A UTF-8 byte order mark (as Windows' Notepad writes) is not the file's text.
    if (!lines.empty() && lines.front().compare(0, 3, "\xEF\xBB\xBF") == 0)
        lines.front().erase(0, 3);
    return lines;
}

std::ifstream open_capture(const std::string &path, const char *what)
{
    const std::string expected = std::string("expected a readable ") + what + " file, got ";
    InputFile f = open_input_file(path);
    if (f.is_folder)
        throw MocapError(path, 0, expected + "a folder");
    if (!f.opened)
        throw MocapError(path, 0, expected + "one that cannot be opened" + f.reason_suffix());
    return std::move(f.stream);
}

std::vector<std::string> split_blanks(const std::string &line)
{
    std::vector<std::string> tokens;
    std::size_t i = 0;
    const std::size_t n = line.size();
    while (i < n) {
        while (i < n && std::isspace(static_cast<unsigned char>(line[i])))
            ++i;
        const std::size_t start = i;
        while (i < n && !std::isspace(static_cast<unsigned char>(line[i])))
            ++i;
        if (i > start)
            tokens.emplace_back(line, start, i - start);
    }
    return tokens;
}

bool parse_double(const std::string &token, double &value)
{
    // std::from_chars: locale-independent (strtod would follow a global locale
    // that may use ',' as the decimal point) and it accepts "nan"/"inf", which
    // the callers then reject or treat as gaps by name.
    const char *first = token.data();
    const char *last = token.data() + token.size();
    if (first != last && *first == '+')
        ++first;
    if (first == last)
        return false;
    double parsed = 0.0;
    const auto [end, error] = std::from_chars(first, last, parsed);
    if (end != last)
        return false;
    if (error == std::errc::result_out_of_range) {
        // Overflow: report as non-finite; underflow: zero is the right value.
        const bool negative = (*first == '-');
        double magnitude = 0.0;
        for (const char *c = first; c != last; ++c)
            if (*c == 'e' || *c == 'E') {
                magnitude = std::atof(c + 1);
                break;
            }
        parsed = magnitude > 0 ? (negative ? -HUGE_VAL : HUGE_VAL) : 0.0;
    } else if (error != std::errc()) {
        return false;
    }
    value = parsed;
    return true;
}

std::string quote(const std::string &token)
{
    std::string shown = token.size() > 40 ? token.substr(0, 40) + "..." : token;
    for (char &c : shown)
        if (!std::isprint(static_cast<unsigned char>(c)))
            c = '?';
    return "'" + shown + "'";
}

std::string trim(const std::string &text)
{
    std::size_t begin = 0, end = text.size();
    while (begin < end && std::isspace(static_cast<unsigned char>(text[begin])))
        ++begin;
    while (end > begin && std::isspace(static_cast<unsigned char>(text[end - 1])))
        --end;
    return text.substr(begin, end - begin);
}

} // namespace ictus::detail
