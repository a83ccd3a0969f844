// score_file.cpp -- a score's text into statements, line by line (line ends, byte order
// marks, UTF-16), its words quoted in errors (UTF-8, control bytes), a score file, and the
// built-in score (docs/score.md, "The language").
#include "ictus/score/score.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

namespace ictus
{

namespace
{
// The length of the UTF-8 sequence at s[i] (1 for ASCII), or 0 when the bytes
// there are not one (a Latin-1 accent, a binary file, a sequence cut short).
size_t utf8_length(const std::string &s, size_t i)
{
    const auto u = static_cast<unsigned char>(s[i]);
    const size_t n = u < 0x80                 ? 1
                     : u >= 0xC2 && u <= 0xDF ? 2
                     : u >= 0xE0 && u <= 0xEF ? 3
                     : u >= 0xF0 && u <= 0xF4 ? 4
                                              : 0;
    if (n == 0 || i + n > s.size())
        return 0;
    for (size_t k = 1; k < n; ++k)
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80)
            return 0;
    return n;
}

// A message quotes the score's words as typed: control bytes in them (a NUL
// cut the message short on a terminal, and in C strings) and bytes that are
// not UTF-8 (which a terminal shows as replacement characters) as \xNN.
std::string printable(const std::string &message)
{
    std::string out;
    for (size_t i = 0; i < message.size();) {
        const auto u = static_cast<unsigned char>(message[i]);
        const size_t n = utf8_length(message, i);
        if (n == 0 || (u < 0x20 && u != '\t') || u == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[u >> 4];
            out += hex[u & 15];
            ++i;
        } else {
            out.append(message, i, n);
            i += n;
        }
    }
    return out;
}

// Calls line(text, number) for each line of a score's text, numbered from 1. Lines end in
// LF, CRLF or a lone CR (old Mac editors): a score saved with CRs alone would otherwise be
// one line, and its first statement's error would name the second's word. A UTF-8 byte
// order mark, which Windows editors write, is not part of the first statement.
template <class Line> void for_each_line(const std::string &text, Line &&line)
{
    std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    int number = 0;
    while (start < text.size()) {
        const std::size_t end = text.find_first_of("\r\n", start);
        if (end == std::string::npos) {
            line(text.substr(start), ++number);
            break;
        }
        line(text.substr(start, end - start), ++number);
        start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    }
}

// UTF-16 without its byte order mark (Python's 'utf-16-le', some exporters): each
// of the first characters a byte and a NUL, in the same order. A score's text has no
// NUL, so one pair is not enough: at least two, all alike.
bool utf16_without_mark(const std::string &text)
{
    const std::size_t pairs = std::min<std::size_t>(text.size() / 2, 32);
    if (pairs < 2)
        return false;
    for (const std::size_t nul : {std::size_t{0}, std::size_t{1}}) {
        bool all = true;
        for (std::size_t k = 0; all && k < pairs; ++k)
            all = text[2 * k + nul] == '\0' && text[2 * k + 1 - nul] != '\0';
        if (all)
            return true;
    }
    return false;
}
} // namespace

ScoreError::ScoreError(const std::string &source, int line, int column, const std::string &message)
    : std::runtime_error(source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                         printable(message)),
      source_(source), line_(line), column_(column), message_(printable(message))
{
}

Score parse_score(const std::string &text, const std::string &source_name, double start_bpm)
{
    ScoreBuilder builder(source_name);
    if (start_bpm != kDefaultTempoBpm)
        builder.set_start_tempo(start_bpm);
    // A UTF-16 file (its byte order mark, as Windows' Notepad may write) would read as
    // one unknown statement of NULs: said for what it is.
    if (text.compare(0, 2, "\xFF\xFE") == 0 || text.compare(0, 2, "\xFE\xFF") == 0)
        throw ScoreError(source_name, 1, 1,
                         "the file is UTF-16 text (it starts with a UTF-16 byte order mark): "
                         "save the score as UTF-8 or ASCII");
    if (utf16_without_mark(text))
        throw ScoreError(source_name, 1, 1,
                         "the file is UTF-16 text (no byte order mark, but a NUL byte beside "
                         "each character): save the score as UTF-8 or ASCII");
    for_each_line(text,
                  [&](const std::string &line, int number) { builder.add_line(line, number); });
    return builder.finish();
}

bool score_text_has_statements(const std::string &text)
{
    ScoreBuilder builder;
    try {
        for_each_line(text, [&](const std::string &line, int) { builder.add_statement(line); });
    } catch (const ScoreError &) {
        return true; // a faulty one: parse_score says where
    }
    return builder.parsed_statements() > 0;
}

Score load_score(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw ScoreError(path, 0, 0, "cannot read the score file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_score(text.str(), path);
}

const char *default_score_text()
{
    // The paper's Figure 5: legato and accent beats of both hands under a
    // tempo change (here an accelerando then a ritardando), ~15 s.
    return R"(# ictus default score: legato and accent beats under a tempo change
# (the paper's Figure 5). See docs/score.md for the language.
tempo 90
grip french
R legato, L legato, R legato, L legato
R accent f, L legato, R accent f, L legato
tempo 90 -> 160 over 8
R legato, L accent f, R legato, L accent f
R legato, L legato, R accent ff, L accent ff
R legato 1/2, L legato 1/2, R legato 1/2, L legato 1/2, R accent f, L accent f
R tenuto p, L tenuto p, R staccato, L staccato
tempo 160 -> 100 over 6
R legato, L legato, R vertical_accent f, L vertical_accent f
R accent ff, L accent ff
)";
}

} // namespace ictus
