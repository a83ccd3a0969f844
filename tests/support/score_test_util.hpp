// Score tests' shared check: the error a score gives, at its position, with a word of
// its message (docs/score.md, "Errors").
#pragma once

#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <string>

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

} // namespace ictus_test
