// fuzz_score.cpp -- libFuzzer harness of the score language (score/score.hpp)
// in both its forms: a whole file (parse_score) and statements arriving one
// by one as from a Pd message box over OSC (ScoreBuilder::add_statement, one
// call per line). The two must agree: the same notes, tempo and length, or
// the same first fault at the same line and column.
//
// A refusal (ScoreError) is a pass; a crash, a sanitizer report, a run over
// the -timeout (repeats expanded for ever), a disagreement between the two
// forms or a note outside the documented limits is a finding. See
// docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/score/score.hpp"

#include <optional>

using namespace ictus;

namespace
{

// Statements are short; a few KiB hold any structure (nested repeats, tempo
// ramps) the parser has, and the repeats multiply them up to the limits.
constexpr std::size_t kMaxInputBytes = 8 * 1024;

struct Outcome {
    std::optional<Score> score;
    std::optional<ScoreError> error;
};

Outcome whole_file(const std::string &text)
{
    Outcome o;
    try {
        o.score = parse_score(text, "fuzz");
    } catch (const ScoreError &e) {
        o.error = e;
    }
    return o;
}

// One add_statement() per line, as parse_score splits them: a line ends in
// LF, CRLF or a lone CR, a last line without an end counts, an empty one after
// the last end does not; a UTF-8 byte order mark at the start is skipped.
Outcome statement_by_statement(const std::string &text)
{
    Outcome o;
    ScoreBuilder builder("fuzz");
    bool threw = false;
    std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    while (start < text.size()) {
        std::size_t end = text.find_first_of("\r\n", start);
        if (end == std::string::npos)
            end = text.size();
        try {
            builder.add_statement(text.substr(start, end - start));
        } catch (const ScoreError &) {
            threw = true;
        }
        start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    }
    ICTUS_FUZZ_CHECK(builder.failed() == threw, "failed() does not say a statement threw");
    try {
        o.score = builder.finish();
        ICTUS_FUZZ_CHECK(!threw, "finish() played a score with a faulty statement");
    } catch (const ScoreError &e) {
        o.error = e;
    }
    return o;
}

void check_score(const Score &score)
{
    // The limit is checked before each statement: `R+L` may take the last
    // two places, one past it.
    ICTUS_FUZZ_CHECK(score.notes.size() <= static_cast<std::size_t>(kMaxScoreNotes) + 1,
                     "more notes than the limit");
    ICTUS_FUZZ_CHECK(std::isfinite(score.length_beats) && score.length_beats >= 0.0 &&
                         score.length_beats <= kMaxScoreBeats,
                     "length outside 0..kMaxScoreBeats");
    double previous = 0.0;
    for (const ScoreNote &n : score.notes) {
        ICTUS_FUZZ_CHECK(std::isfinite(n.beat) && n.beat >= previous, "notes not in beat order");
        previous = n.beat;
        ICTUS_FUZZ_CHECK(n.beats >= kMinNoteBeats && n.beats <= kMaxNoteBeats,
                         "note duration outside the limits");
        ICTUS_FUZZ_CHECK(n.beat + n.beats <= score.length_beats + 1e-9,
                         "a note ends after the score");
        ICTUS_FUZZ_CHECK(n.dynamics >= 0.0 && n.dynamics <= 1.0, "dynamics outside 0..1");
        ICTUS_FUZZ_CHECK(n.r_over_a >= 0.0 && n.r_over_a <= kMaxRadiusFraction,
                         "r/a outside the head");
        ICTUS_FUZZ_CHECK(std::isfinite(n.theta_deg), "non-finite angle");
        ICTUS_FUZZ_CHECK(n.line >= 1 && n.column >= 1, "a note without its position");
    }
    // The tempo map: within the limits, time growing with the beat, and its inverse.
    for (const TempoMap::Change &c : score.tempo.changes()) {
        ICTUS_FUZZ_CHECK(c.start_bpm >= kMinTempoBpm && c.start_bpm <= kMaxTempoBpm &&
                             c.end_bpm >= kMinTempoBpm && c.end_bpm <= kMaxTempoBpm,
                         "tempo outside the limits");
        ICTUS_FUZZ_CHECK(c.ramp_beats >= 0.0 && c.ramp_beats <= kMaxNoteBeats,
                         "ramp outside the limits");
    }
    const double duration = score.duration_s();
    ICTUS_FUZZ_CHECK(std::isfinite(duration) && duration >= 0.0, "duration not finite, >= 0");
    // At most 20 bpm: a beat lasts at most 3 s.
    ICTUS_FUZZ_CHECK(duration <= 3.0 * score.length_beats * (1.0 + 1e-9) + 1e-9,
                     "duration beyond 20 bpm");
    double previous_time = -1.0;
    const std::size_t step = score.notes.size() / 64 + 1; // a sample of the notes
    for (std::size_t i = 0; i < score.notes.size(); i += step) {
        const double t = score.note_time_s(score.notes[i]);
        ICTUS_FUZZ_CHECK(std::isfinite(t) && t >= previous_time, "note times not in order");
        previous_time = t;
        const double back = score.tempo.beat_at_time(t);
        ICTUS_FUZZ_CHECK(std::fabs(back - score.notes[i].beat) <=
                             1e-6 * std::max(1.0, score.notes[i].beat),
                         "beat_at_time(time_at_beat(b)) != b");
    }
}

bool same_note(const ScoreNote &a, const ScoreNote &b)
{
    return a.beat == b.beat && a.beats == b.beats && a.hand == b.hand && a.nuance == b.nuance &&
           a.grip == b.grip && a.dynamics == b.dynamics && a.r_over_a == b.r_over_a &&
           a.theta_deg == b.theta_deg && a.line == b.line && a.column == b.column;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    const std::string text = ictus_fuzz::text_of(data, size);
    const Outcome file = whole_file(text);
    // UTF-16 text (a NUL beside each of its first characters) is refused as a whole, at
    // 1:1, before its statements are read: one statement at a time, as the live path
    // takes them, cannot see a file's encoding (docs/score.md).
    if (file.error && file.error->message().rfind("the file is UTF-16 text", 0) == 0) {
        ICTUS_FUZZ_CHECK(file.error->line() == 1 && file.error->column() == 1,
                         "UTF-16 text refused elsewhere than at its start");
        return 0;
    }
    const Outcome statements = statement_by_statement(text);

    ICTUS_FUZZ_CHECK(file.score.has_value() == statements.score.has_value(),
                     "a file and its statements one by one: one accepted, one refused");
    if (file.error) {
        ICTUS_FUZZ_CHECK(file.error->line() == statements.error->line() &&
                             file.error->column() == statements.error->column(),
                         "a file and its statements one by one: faults at different places");
        ICTUS_FUZZ_CHECK(file.error->line() >= 1 && file.error->column() >= 1,
                         "a fault without its position");
        return 0;
    }
    const Score &a = *file.score;
    const Score &b = *statements.score;
    ICTUS_FUZZ_CHECK(a.notes.size() == b.notes.size() && a.length_beats == b.length_beats &&
                         a.tempo.changes().size() == b.tempo.changes().size(),
                     "a file and its statements one by one: different scores");
    for (std::size_t i = 0; i < a.notes.size(); ++i)
        ICTUS_FUZZ_CHECK(same_note(a.notes[i], b.notes[i]),
                         "a file and its statements one by one: different notes");
    check_score(a);
    return 0;
}
