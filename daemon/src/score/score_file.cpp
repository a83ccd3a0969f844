// score_file.cpp -- a score's text into statements, line by line (line ends, byte order
// marks), a score file, and the built-in score (docs/score.md, "The language").
#include "ictus/score/score.hpp"

#include <fstream>
#include <sstream>
#include <string>

namespace ictus
{

namespace
{
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
} // namespace

Score parse_score(const std::string &text, const std::string &source_name)
{
    ScoreBuilder builder(source_name);
    // A UTF-16 file (its byte order mark, as Windows' Notepad may write) would read as
    // one unknown statement of NULs: said for what it is.
    if (text.compare(0, 2, "\xFF\xFE") == 0 || text.compare(0, 2, "\xFE\xFF") == 0)
        throw ScoreError(source_name, 1, 1,
                         "the file is UTF-16 text (it starts with a UTF-16 byte order mark): "
                         "save the score as UTF-8 or ASCII");
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
