// Score tests' shared check: the error a score gives, at its position, with a word of
// its message (docs/score.md, "Errors").
#pragma once

#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <random>
#include <string>
#include <vector>

namespace ictus_test
{

inline void require_error(const std::string &text, int line, int column, const std::string &words)
{
    try {
        ictus::parse_score(text, "t.txt");
        FAIL("no error for: " << text);
    } catch (const ictus::ScoreError &e) {
        INFO(e.what());
        CHECK(e.source() == "t.txt");
        CHECK(e.line() == line);
        CHECK(e.column() == column);
        CHECK_THAT(e.message(), Catch::Matchers::Contains(words));
    }
}

// n statements drawn from `words` (seeded by rng), as a client might send them in one
// string: each maybe followed by `comment`, separated by LF, CRLF or CR; `file` gets the
// same statements one per line, as a score file holds them.
inline void join_statements(std::mt19937 &rng, const std::vector<std::string> &words, int n,
                            const std::string &comment, std::string &file, std::string &message)
{
    for (int k = 0; k < n; ++k) {
        const std::string &w = words[rng() % words.size()];
        file += w + "\n";
        message += w;
        if (rng() % 3 == 0)
            message += comment;
        if (k + 1 < n)
            message += std::vector<std::string>{"\n", "\r\n", "\r"}[rng() % 3];
    }
}

// One score string, read as ScoreBuilder reads a statement string (an OSC /ictus/score),
// gives the notes of `file` read as a score file: beat, hand, nuance, dynamics and grip.
inline void check_same_notes(const std::string &message, const std::string &file)
{
    const ictus::Score want = ictus::parse_score(file, "file");
    ictus::ScoreBuilder b;
    b.add_statement(message);
    const ictus::Score got = b.finish();
    REQUIRE(got.notes.size() == want.notes.size());
    for (size_t i = 0; i < want.notes.size(); ++i) {
        CHECK(got.notes[i].beat == want.notes[i].beat);
        CHECK(got.notes[i].hand == want.notes[i].hand);
        CHECK(got.notes[i].nuance == want.notes[i].nuance);
        CHECK(got.notes[i].dynamics == want.notes[i].dynamics);
        CHECK(got.notes[i].grip == want.notes[i].grip);
    }
    CHECK(got.tempo.time_at_beat(8.0) == want.tempo.time_at_beat(8.0));
}

} // namespace ictus_test
