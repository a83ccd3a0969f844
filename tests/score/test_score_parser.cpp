// The score language: every statement form, the defaults, every error with
// its exact line and column, nothing produced from a faulty score, and the
// Pd message-box form (one statement per message) equal to the file form.
#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <fstream>
#include <random>
#include <string>

#include "support/score_test_util.hpp"

using namespace ictus;
using Catch::Matchers::Contains;
using ictus_test::require_error;

namespace
{

bool same_notes(const Score &a, const Score &b)
{
    if (a.notes.size() != b.notes.size() || a.length_beats != b.length_beats)
        return false;
    for (size_t i = 0; i < a.notes.size(); ++i) {
        const ScoreNote &x = a.notes[i], &y = b.notes[i];
        if (x.beat != y.beat || x.beats != y.beats || x.hand != y.hand || x.nuance != y.nuance ||
            x.grip != y.grip || x.dynamics != y.dynamics || x.r_over_a != y.r_over_a ||
            x.theta_deg != y.theta_deg || a.note_time_s(x) != b.note_time_s(y))
            return false;
    }
    return true;
}

// The same notes as `ref`, each at its line and column.
void same_notes_at_same_places(const Score &m, const Score &ref)
{
    REQUIRE(m.notes.size() == ref.notes.size());
    CHECK(same_notes(m, ref));
    for (size_t i = 0; i < ref.notes.size(); ++i) {
        CHECK(m.notes[i].line == ref.notes[i].line);
        CHECK(m.notes[i].column == ref.notes[i].column);
    }
}

} // namespace

TEST_CASE("score: a bare note takes every default", "[score][parser]")
{
    const Score s = parse_score("R\nL\n", "d");
    REQUIRE(s.notes.size() == 2);
    const ScoreNote &r = s.notes[0], &l = s.notes[1];
    CHECK(r.hand == Side::right);
    CHECK(l.hand == Side::left);
    CHECK(r.nuance == Nuance::legato);
    CHECK(r.grip == Grip::french);
    CHECK(r.beats == 1.0);
    CHECK(r.dynamics == 0.6);
    CHECK(r.r_over_a == 0.3);
    CHECK(r.theta_deg == 180.0); // performer's right = world -X = membrane x_m < 0
    CHECK(l.theta_deg == 0.0);
    CHECK(r.beat == 0.0);
    CHECK(l.beat == 1.0);
    CHECK(s.length_beats == 2.0);
    // 120 bpm by default: a beat is half a second.
    CHECK(s.note_time_s(l) == Approx(0.5).epsilon(1e-12));
    CHECK(s.duration_s() == Approx(1.0).epsilon(1e-12));
    CHECK(r.line == 1);
    CHECK(l.line == 2);
    CHECK(r.column == 1);
}

TEST_CASE("score: every note option", "[score][parser]")
{
    const Score s = parse_score("  right accent 0.8 1/2 at 0.5 -90\n"
                                "left vertical_accent ff beats 1.5 at 0.2 270\n"
                                "R staccato pp\n"
                                "L tenuto p beats 3/4\n"
                                "r vertical-accent mp\n"
                                "l LEGATO MF at 0 540\n"
                                "R f\n",
                                "opts");
    REQUIRE(s.notes.size() == 7);
    const auto &n = s.notes;
    CHECK(n[0].hand == Side::right);
    CHECK(n[0].nuance == Nuance::accent);
    CHECK(n[0].dynamics == 0.8);
    CHECK(n[0].beats == 0.5);
    CHECK(n[0].r_over_a == 0.5);
    CHECK(n[0].theta_deg == -90.0);
    CHECK(n[0].column == 3);
    CHECK(n[1].nuance == Nuance::vertical_accent);
    CHECK(n[1].dynamics == 1.0);
    CHECK(n[1].beats == 1.5);
    CHECK(n[1].theta_deg == -90.0); // 270 into (-180, 180]
    CHECK(n[1].beat == 0.5);
    CHECK(n[2].nuance == Nuance::staccato);
    CHECK(n[2].dynamics == 0.2);
    CHECK(n[2].beat == 2.0);
    CHECK(n[3].nuance == Nuance::tenuto);
    CHECK(n[3].dynamics == 0.3);
    CHECK(n[3].beats == 0.75);
    CHECK(n[4].nuance == Nuance::vertical_accent);
    CHECK(n[4].dynamics == 0.45);
    CHECK(n[5].nuance == Nuance::legato);
    CHECK(n[5].dynamics == 0.6);
    CHECK(n[5].r_over_a == 0.0);
    CHECK(n[5].theta_deg == 180.0); // 540 = 180
    CHECK(n[6].nuance == Nuance::legato);
    CHECK(n[6].dynamics == 0.8);
    // 0.5 + 1.5 + 1 + 0.75 + 1 + 1 + 1
    CHECK(s.length_beats == 6.75);
}

TEST_CASE("score: R+L strikes both hands on one beat", "[score][parser]")
{
    const Score s = parse_score("R+L accent f 1/2\nboth\nL+R staccato\nR\n", "both");
    REQUIRE(s.notes.size() == 7);
    CHECK(s.notes[0].hand == Side::right);
    CHECK(s.notes[1].hand == Side::left);
    for (int i : {0, 1}) {
        CHECK(s.notes[i].beat == 0.0);
        CHECK(s.notes[i].beats == 0.5);
        CHECK(s.notes[i].nuance == Nuance::accent);
        CHECK(s.notes[i].dynamics == 0.8);
    }
    CHECK(s.notes[0].theta_deg == 180.0); // each hand on its own side
    CHECK(s.notes[1].theta_deg == 0.0);
    CHECK(s.notes[2].beat == 0.5);
    CHECK(s.notes[3].beat == 0.5);
    CHECK(s.notes[5].nuance == Nuance::staccato);
    CHECK(s.notes[6].beat == 2.5);
    CHECK(s.length_beats == 3.5);
    // The column is the faulty word's: the 'at'.
    require_error("R+L at 0.3 90", 1, 5, "'at' places one stick");
    require_error("both accent at 0.3 90", 1, 13, "'at' places one stick");
}

TEST_CASE("score: '+' joins a note of each hand on one beat, each with its options",
          "[score][parser]")
{
    // Beats: 0 (1/2 written, the other none: the chord lasts 1/2), 0.5 (the same), 1
    // (1/4 and 3/4 written: the longest, 3/4), 1.75 (none written: the default, 1), 2.75.
    const Score s = parse_score("R accent 1/2 at 0.2 170 + L ff\nL 1/2 + R\nR 1/4 + L 3/4\n"
                                "R + L\nR",
                                "chord");
    REQUIRE(s.notes.size() == 9);
    CHECK((s.notes[0].hand == Side::right && s.notes[1].hand == Side::left));
    for (int i : {0, 1})
        CHECK(s.notes[i].beat == 0.0);
    CHECK(s.notes[0].beats == 0.5);
    CHECK(s.notes[1].beats == 0.5); // none written: the chord's
    CHECK((s.notes[4].beat == 1.0 && s.notes[5].beat == 1.0));
    CHECK((s.notes[4].beats == 0.25 && s.notes[5].beats == 0.75));
    CHECK((s.notes[6].beat == 1.75 && s.notes[7].beat == 1.75 && s.notes[6].beats == 1.0));
    CHECK(s.notes[0].nuance == Nuance::accent);
    CHECK(s.notes[1].nuance == Nuance::legato);
    CHECK(s.notes[0].dynamics == 0.6);
    CHECK(s.notes[1].dynamics == 1.0);
    CHECK((s.notes[0].r_over_a == 0.2 && s.notes[0].theta_deg == 170.0));
    CHECK((s.notes[1].r_over_a == 0.3 && s.notes[1].theta_deg == 0.0));
    CHECK((s.notes[2].beat == 0.5 && s.notes[3].beat == 0.5));
    CHECK(s.notes[8].beat == 2.75);
    CHECK(s.length_beats == 3.75);
    // The same in a Pd message box (statements between commas).
    const Score m =
        parse_score("R accent 1/2 at 0.2 170 + L ff, L 1/2 + R, R 1/4 + L 3/4, R + L, R", "box");
    REQUIRE(m.notes.size() == s.notes.size());
    for (size_t i = 0; i < m.notes.size(); ++i)
        CHECK((m.notes[i].beat == s.notes[i].beat && m.notes[i].hand == s.notes[i].hand));
    require_error("R + R", 1, 5, "two notes joined by '+' are the right hand's");
    require_error("R +", 1, 3, "'+' joins notes played on one beat");
    require_error("+ L", 1, 1, "'+' joins notes played on one beat");
    require_error("R + tempo 90", 1, 5, "'+' joins notes of one limb each");
    require_error("R+L + L", 1, 1, "'+' joins notes of one limb each");
    require_error("R + L + R", 1, 9, "two notes joined by '+' are the right hand's");
    require_error("R + L + RF + LF + L", 1, 17, "a fourth '+'");
    require_error("R + L + RF + L", 1, 14, "two notes joined by '+' are the left hand's");
    require_error("LF + R + left-foot", 1, 10, "two notes joined by '+' are the left foot's");
    require_error("RF + R + RF", 1, 10, "two notes joined by '+' are the right foot's");
}

TEST_CASE("score: RF is the right foot's note on the kick, alone or in a chord", "[score][parser]")
{
    const Score s =
        parse_score("drum snare\nRF ff 1/2\nR on hihat + L + RF p\nRF on kick\nR\n", "feet");
    REQUIRE(s.notes.size() == 6);
    // A foot's note: the right side, the foot, and no drum but its own `on`
    // (the hands' current drum is not the kick's).
    CHECK((s.notes[0].foot && s.notes[0].hand == Side::right && s.notes[0].drum.empty()));
    CHECK((s.notes[0].beat == 0.0 && s.notes[0].dynamics == 1.0 && s.notes[0].beats == 0.5));
    // The chord: three notes on beat 0.5, the next note one beat later.
    for (int i = 1; i <= 3; ++i)
        CHECK(s.notes[static_cast<size_t>(i)].beat == 0.5);
    int feet = 0;
    for (int i = 1; i <= 3; ++i)
        feet += s.notes[static_cast<size_t>(i)].foot ? 1 : 0;
    CHECK(feet == 1);
    CHECK((s.notes[4].foot && s.notes[4].drum == "kick" && s.notes[4].beat == 1.5));
    CHECK((!s.notes[5].foot && s.notes[5].drum == "snare" && s.notes[5].beat == 2.5));
    // The same chord in a Pd message box.
    const Score m = parse_score("RF + R on hihat", "box");
    REQUIRE(m.notes.size() == 2);
    CHECK((m.notes[0].beat == 0.0 && m.notes[1].beat == 0.0));
    require_error("RF flam", 1, 4, "'RF' is the right foot's note on the kick's pedal");
    require_error("RF at 0.2 90", 1, 4, "'at' is a stick's");
    require_error("RF firmness 0.5", 1, 4, "'firmness' is a stick's");
    require_error("RF on hihat open", 1, 13, "'open' is the hi-hat's");
}

TEST_CASE("score: LF is the left foot's chick on the hi-hat's pedal, alone or in a chord",
          "[score][parser][chick]")
{
    const Score s = parse_score("drum snare\nLF ff 1/2\nR on ride + L + RF + LF p\nleft-foot on "
                                "hihat pp\nR\n",
                                "feet");
    REQUIRE(s.notes.size() == 7);
    // The left side, the foot, no drum but its own `on` (the planner finds the hi-hat).
    CHECK((s.notes[0].foot && s.notes[0].hand == Side::left && s.notes[0].drum.empty()));
    CHECK((s.notes[0].beat == 0.0 && s.notes[0].dynamics == 1.0 && s.notes[0].beats == 0.5));
    // The chord: four limbs on beat 0.5, each foot once.
    int left = 0, right = 0;
    for (int i = 1; i <= 4; ++i) {
        const ScoreNote &n = s.notes[static_cast<size_t>(i)];
        CHECK(n.beat == 0.5);
        left += n.foot && n.hand == Side::left ? 1 : 0;
        right += n.foot && n.hand == Side::right ? 1 : 0;
    }
    CHECK((left == 1 && right == 1));
    CHECK(s.notes[4].dynamics == Approx(0.3));
    CHECK((s.notes[5].foot && s.notes[5].hand == Side::left && s.notes[5].drum == "hihat"));
    CHECK((!s.notes[6].foot && s.notes[6].drum == "snare"));
    const Score m = parse_score("R on ride + LF", "box");
    REQUIRE(m.notes.size() == 2);
    CHECK((m.notes[1].foot && m.notes[1].hand == Side::left && m.notes[1].beat == 0.0));
    require_error("LF flam", 1, 4, "'LF' is the left foot's chick on the hi-hat's pedal");
    require_error("LF at 0.9 90", 1, 4, "'at' is a stick's (the plates meet");
    require_error("LF firmness 0.5", 1, 4, "'firmness' is a stick's");
    require_error("LF open", 1, 4, "'open' is a hand's note's (the chick closes it)");
    require_error("R + LF closed", 1, 8, "'closed' is a hand's note's");
}

TEST_CASE("score: the dynamics words rise from pp to ff and mf is the default", "[score][parser]")
{
    const auto &words = dynamics_words();
    REQUIRE(words.size() == 6);
    const char *order[] = {"pp", "p", "mp", "mf", "f", "ff"};
    for (size_t i = 0; i < words.size(); ++i) {
        CHECK(std::string(words[i].word) == order[i]);
        if (i > 0)
            CHECK(words[i].value > words[i - 1].value);
        const Score s = parse_score(std::string("R ") + order[i], "w");
        CHECK(s.notes[0].dynamics == words[i].value);
    }
    CHECK(words[3].value == kDefaultDynamics);
    CHECK(words[5].value == 1.0);
}

TEST_CASE("score: every nuance name the gesture database uses is accepted", "[score][parser]")
{
    for (int i = 0; i < kNuances; ++i) {
        const Nuance n = static_cast<Nuance>(i);
        const Score s = parse_score(std::string("L ") + to_string(n), "n");
        CHECK(s.notes[0].nuance == n);
    }
    CHECK(parse_score("R buzz", "n").notes[0].nuance == Nuance::buzz);
}

TEST_CASE("score: grip firmness per note and as a default, the performance's when none",
          "[score][parser]")
{
    const Score s = parse_score("R, L firmness 0.8, firmness 0.2\nR, L accent firmness 1 f, "
                                "R firmness 0\n",
                                "t.txt");
    REQUIRE(s.notes.size() == 5);
    CHECK(s.notes[0].firmness < 0.0); // the performance's own
    CHECK(s.notes[1].firmness == 0.8);
    CHECK(s.notes[2].firmness == 0.2);
    CHECK(s.notes[3].firmness == 1.0);
    CHECK(s.notes[3].dynamics == 0.8);
    CHECK(s.notes[4].firmness == 0.0);
    require_error("R firmness 1.5", 1, 12, "firmness 1.5 is out of range");
    require_error("R firmness", 1, 11, "'firmness' needs a value");
    require_error("R firmness 0.5 firmness 0.4", 1, 16, "second firmness");
    require_error("firmness -0.1", 1, 10, "out of range");
    require_error("firmness x", 1, 10, "firmness");
}

TEST_CASE("score: humanize sets the performance's motor noise, the last statement wins",
          "[score][parser]")
{
    CHECK(parse_score("R, L\n", "t.txt").humanize < 0.0); // not written: the performance's
    const Score s = parse_score("humanize 1.5, R\nhumanize 0.5\nL\n", "t.txt");
    CHECK(s.humanize == 0.5);
    REQUIRE(s.notes.size() == 2); // it plays no note and takes no time
    CHECK(s.notes[1].beat == 1.0);
    CHECK(parse_score("humanize 0\nR\n", "t.txt").humanize == 0.0);
    require_error("R\nhumanize -1", 2, 10, "humanize -1 is out of range (0..4");
    require_error("humanize 4.5", 1, 10, "out of range");
    require_error("humanize", 1, 9, "'humanize' needs an amount");
    require_error("humanize 1 2", 1, 12, "unexpected '2'");
}

TEST_CASE("score: a default nuance for the notes that name none (the panel's nuance selector)",
          "[score][parser]")
{
    const Score s = parse_score("R, nuance accent, L, R tenuto\nnuance vertical-accent, L\n"
                                "nuance legato, R",
                                "t.txt");
    REQUIRE(s.notes.size() == 5);
    CHECK(s.notes[0].nuance == Nuance::legato);
    CHECK(s.notes[1].nuance == Nuance::accent);
    CHECK(s.notes[2].nuance == Nuance::tenuto);
    CHECK(s.notes[3].nuance == Nuance::vertical_accent);
    CHECK(s.notes[4].nuance == Nuance::legato);
    require_error("nuance", 1, 7, "'nuance' needs a nuance");
    require_error("nuance legatto", 1, 8, "unknown nuance 'legatto'");
    require_error("nuance accent tenuto", 1, 15, "unexpected 'tenuto' after the nuance");
    // Set by the builder (/ictus/nuance), it is not a statement: the
    // positions of errors stay those of the statements received.
    ScoreBuilder b("osc");
    b.add_statement("R");
    b.set_default_nuance(Nuance::staccato);
    b.add_statement("L, R accent");
    CHECK(b.statements() == 2);
    const Score built = b.finish();
    REQUIRE(built.notes.size() == 3);
    CHECK(built.notes[0].nuance == Nuance::legato);
    CHECK(built.notes[1].nuance == Nuance::staccato);
    CHECK(built.notes[2].nuance == Nuance::accent);
    try {
        b.add_statement("R lgato");
        FAIL("a bad statement was accepted");
    } catch (const ScoreError &e) {
        CHECK(e.line() == 3);
        CHECK(e.column() == 3);
    }
}

TEST_CASE("score: tempo and grip and rest and default beats and dynamics", "[score][parser]")
{
    const Score s = parse_score("tempo 60\n"
                                "grip german\n"
                                "R\n"
                                "rest\n"
                                "rest 1/2\n"
                                "rest beats 2\n"
                                "beats 1/4\n"
                                "dynamics ff\n"
                                "L\n"
                                "grip french\n"
                                "dynamics 0.35\n"
                                "R accent\n",
                                "g");
    REQUIRE(s.notes.size() == 3);
    CHECK(s.notes[0].grip == Grip::german);
    CHECK(s.notes[0].beats == 1.0);
    CHECK(s.notes[1].beat == 4.5); // 1 + 1 + 0.5 + 2
    CHECK(s.notes[1].beats == 0.25);
    CHECK(s.notes[1].dynamics == 1.0);
    CHECK(s.notes[1].grip == Grip::german);
    CHECK(s.notes[2].grip == Grip::french);
    CHECK(s.notes[2].dynamics == 0.35);
    CHECK(s.notes[2].beat == 4.75);
    CHECK(s.length_beats == 5.0);
    // 60 bpm: one second a beat.
    CHECK(s.note_time_s(s.notes[2]) == Approx(4.75).epsilon(1e-12));
}

TEST_CASE("score: tempo changes instant and gradual", "[score][parser]")
{
    const Score s = parse_score("tempo 100\nR\ntempo 100 -> 200 over 4\nR\nR\nR\nR\nR\n"
                                "tempo -> 50 over 2\nR\nR\nR\n",
                                "tc");
    REQUIRE(s.notes.size() == 9);
    CHECK(s.tempo.tempo_at_beat(0.5) == 100.0);
    CHECK(s.tempo.tempo_at_beat(3.0) == Approx(150.0));
    CHECK(s.tempo.tempo_at_beat(5.0) == Approx(200.0));
    CHECK(s.tempo.tempo_at_beat(6.0) == Approx(200.0)); // the second ramp starts at beat 6
    CHECK(s.tempo.tempo_at_beat(7.0) == Approx(125.0)); // from 200 toward 50, half way
    CHECK(s.tempo.tempo_at_beat(8.5) == Approx(50.0));
    // A ramp 100 -> 200 over 4 beats starting at t = 0.6 s: t(b) = 0.6 + 60/25 ln((100+25b)/100).
    CHECK(s.note_time_s(s.notes[3]) == Approx(0.6 + 2.4 * std::log(1.5)).epsilon(1e-12));
    // 'to' is the same as '->'.
    const Score t = parse_score("tempo 100 to 200 over 4\nR\nR\n", "to");
    const Score u = parse_score("tempo 100 -> 200 over 4\nR\nR\n", "arrow");
    CHECK(same_notes(t, u));
}

TEST_CASE("score: repeat blocks expand and nest", "[score][parser]")
{
    const Score s =
        parse_score("repeat 3\n  R\n  repeat 2\n    L 1/2\n  end\nend\nR accent\n", "rep");
    REQUIRE(s.notes.size() == 3 * 3 + 1);
    CHECK(s.notes[0].hand == Side::right);
    CHECK(s.notes[1].hand == Side::left);
    CHECK(s.notes[2].beat == 1.5);
    CHECK(s.notes[3].beat == 2.0);
    CHECK(s.notes[9].nuance == Nuance::accent);
    CHECK(s.notes[9].beat == 6.0);
    CHECK(s.notes[4].line == 4); // a repeated note keeps where it was written
}

TEST_CASE("score: separators and comments", "[score][parser]")
{
    const Score a = parse_score("tempo 96, grip french, R legato, L accent 0.8 # a comment\n"
                                "# whole-line comment\n\n"
                                "R 1/2; L 1/2;\n",
                                "sep");
    const Score b =
        parse_score("tempo 96\ngrip french\nR legato\nL accent 0.8\nR 1/2\nL 1/2\n", "nl");
    REQUIRE(a.notes.size() == 4);
    CHECK(same_notes(a, b));
    CHECK(a.notes[1].column == 34);
    CHECK(a.notes[1].line == 1);
    CHECK(a.notes[3].line == 4);
    CHECK(a.notes[3].column == 8);
}

TEST_CASE("score: lines end in LF, CRLF or a lone CR, and a byte order mark is no statement",
          "[score][parser]")
{
    // The default score and a faulty one, each line ended at random (seeded)
    // by one of the three, with and without a UTF-8 BOM: the same notes at the
    // same lines and columns, the same error at the same place.
    const std::string text = default_score_text();
    const Score lf = parse_score(text, "lf");
    const char *const ends[] = {"\n", "\r\n", "\r"};
    std::mt19937 rng(20261127);
    for (int trial = 0; trial < 40; ++trial) {
        std::string mixed = trial % 2 ? "\xEF\xBB\xBF" : "";
        for (char c : text)
            mixed += c == '\n' ? ends[rng() % 3] : std::string(1, c);
        INFO("trial " << trial);
        same_notes_at_same_places(parse_score(mixed, "mixed"), lf);
    }
    require_error("tempo 100\rR\rL acent\r", 3, 3, "acent");
    require_error("\xEF\xBB\xBFR, L acent\r\n", 1, 6, "acent");
    require_error("\xEF\xBB\xBF\xEF\xBB\xBFR\n", 1, 1, "unknown statement"); // one mark only
    // UTF-16, either byte order: "tempo" with its NULs, said to be UTF-16.
    require_error(std::string("\xFF\xFEt\0e\0m\0p\0o\0", 12), 1, 1, "UTF-16");
    require_error(std::string("\xFE\xFF\0t\0e\0m\0p\0o", 12), 1, 1, "UTF-16");
}

TEST_CASE("score: a no-break space separates words as a space does, and columns count "
          "characters",
          "[score][parser]")
{
    // Option-Space on a Mac, or a score copied from a web page, puts no-break spaces
    // (U+00A0, UTF-8 C2 A0) between words: "unknown statement 'R L'" named a word the
    // user could not see. The default score with its spaces (seeded) made no-break: the
    // same notes, at the same lines and columns (a column is a character, as an editor
    // counts, not a byte).
    const std::string text = default_score_text();
    const Score plain = parse_score(text, "plain");
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 20; ++trial) {
        std::string mixed;
        for (char c : text)
            mixed += c == ' ' && rng() % 2 ? std::string("\xC2\xA0") : std::string(1, c);
        INFO("trial " << trial);
        same_notes_at_same_places(parse_score(mixed, "nbsp"), plain);
    }
    require_error("R\xC2\xA0legatto\n", 1, 3, "unknown nuance 'legatto'");
    require_error("R on tom1\xC2\xA0\xC2\xA0"
                  "flm\n",
                  1, 12, "unexpected 'flm' in a note");
    require_error("R accent, \xC3\xA9 L, X\n", 1, 11, "unknown statement '\xC3\xA9'");
    require_error("R 0.5, \xC3\xA9\xC3\xA9, X\n", 1, 8, "unknown statement");
}

TEST_CASE("score: a '+' written without its spaces is named as such, at the word",
          "[score][parser][errors]")
{
    // "R +L" said "unknown nuance '+L'" and "R+ L" "unknown statement 'R+'": the chord's
    // '+' stands between spaces. Words of limbs and '+' only; R+L and L+R are one note
    // of both hands, and other words keep their own errors.
    const char *const glued[] = {"+L", "R+", "RF+LF", "R+L+RF", "l+rf", "++", "right+left-foot"};
    for (const char *w : glued) {
        require_error(std::string("R, ") + w + "\n", 1, 4,
                      std::string("'") + w + "': '+' joins notes with a space on each side");
        require_error(std::string("R on snare ") + w + " on tom1\n", 1, 12, "'+' joins notes");
    }
    require_error("R+X\n", 1, 1, "unknown statement 'R+X'");
    require_error("R +2\n", 1, 3, "dynamics +2 is out of range");
    CHECK(parse_score("R+L, l+r, R + L, tempo 1e+2, R\n", "t").notes.size() == 7);
}

TEST_CASE("score: two notes on one line without a separator are named as such, at the second",
          "[score][parser][errors]")
{
    // "R L R L" said "unknown nuance 'L'": a limb's word after a note's options starts
    // another note, which a ',' or a new line separates (or ' + ' joins on one beat).
    // Seeded: a first note of any limb with some of its options, then a limb's word in
    // any case; the column is counted here from the pieces written.
    const char *const firsts[] = {"R", "L", "right", "left", "RF", "LF", "both", "R+L"};
    // at most one of each kind: a nuance, dynamics, a duration
    const char *const options[3][2] = {{"accent", "staccato"}, {"0.7", "ff"}, {"1/2", "beats 2"}};
    const char *const limbs[] = {"R",          "L",         "right", "left", "RF", "LF",
                                 "right-foot", "left-foot", "both",  "R+L",  "L+R"};
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 200; ++trial) {
        std::string line = firsts[rng() % 8];
        for (const auto &kind : options)
            if (rng() % 2)
                line += std::string(" ") + kind[rng() % 2];
        line += std::string(1 + rng() % 2, ' ');
        const size_t column = line.size() + 1;
        std::string limb = limbs[rng() % 11];
        for (char &c : limb)
            if (rng() % 2)
                c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        INFO(line + limb);
        require_error(line + limb + " accent\n", 1, static_cast<int>(column),
                      "'" + limb + "' starts another note: separate notes with ',' or a new line");
    }
    // Words that are not a limb's keep their errors.
    require_error("R X\n", 1, 3, "unknown nuance 'X'");
    require_error("R accent X\n", 1, 10, "unexpected 'X' in a note");
}

TEST_CASE("score: an error shows control bytes as hex escapes, a NUL included",
          "[score][parser][errors]")
{
    // A NUL in a statement cut the message at it (the list of statements lost).
    const std::string nul = std::string("R, X") + '\0' + "Y\n";
    require_error(nul, 1, 4, "unknown statement 'X\\x00Y'");
    require_error(nul, 1, 4, "tempo"); // the rest of the message is there
    require_error("R, Z\x1b[2J\n", 1, 4, "'Z\\x1b[2J'");
    // Bytes that are not UTF-8 (a Latin-1 file's accents, a binary file) were quoted raw,
    // which a terminal shows as replacement characters: escaped as a control byte is.
    // UTF-8 itself (an accent, an arrow) is quoted as typed.
    require_error("R, \x89PNG\n", 1, 4, "unknown statement '\\x89PNG'");
    require_error("R caf\xe9\n", 1, 3, "unknown nuance 'caf\\xe9'");
    require_error("R \xc3\n", 1, 3, "unknown nuance '\\xc3'"); // a lead byte cut short
    require_error("R \xc3\xa9\xa9\n", 1, 3, "unknown nuance '\xc3\xa9\\xa9'");
    require_error("R \xe2\x86\x92 L\n", 1, 3, "unknown nuance '\xe2\x86\x92'");
}

TEST_CASE("score: a UTF-16 file without a byte order mark is said to be one",
          "[score][parser][errors]")
{
    // Written as UTF-16 without its mark (Python's 'utf-16-le'), a score read as one
    // statement "R\x00" whose NULs follow every character. Seeded texts of the language,
    // little- and big-endian: refused at 1:1 as UTF-16, as one with the mark is.
    const char *const texts[] = {"R, L\n", "tempo 96\nR legato\n", "# a comment\nR\n",
                                 "repeat 2\nR+L ff\nend\n", "L\r\nR accent\r\n"};
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 10; ++trial) {
        const std::string text = texts[rng() % 5];
        const bool big = trial % 2 == 1;
        std::string wide;
        for (char c : text)
            wide += big ? std::string(1, '\0') + c : std::string(1, c) + '\0';
        INFO("trial " << trial << (big ? " big-endian" : " little-endian"));
        require_error(wide, 1, 1, "UTF-16");
    }
    // One NUL in an ASCII score is no UTF-16: named where it is.
    require_error(std::string("R, X") + '\0' + "Y\n", 1, 4, "unknown statement 'X\\x00Y'");
}

TEST_CASE("score: a Pd message box - statements one by one - equals the file", "[score][parser]")
{
    const std::string file = default_score_text();
    ScoreBuilder builder("osc");
    // As Pd sends it: each comma-separated message is one statement.
    std::string statement;
    int count = 0;
    for (char c : file + "\n") {
        if (c == ',' || c == '\n' || c == ';') {
            const auto hash = statement.find('#');
            if (hash != std::string::npos)
                statement.erase(hash);
            if (statement.find_first_not_of(' ') != std::string::npos) {
                builder.add_statement(statement);
                ++count;
            }
            statement.clear();
        } else {
            statement += c;
        }
    }
    CHECK(builder.statements() == count);
    CHECK(count > 30);
    CHECK(same_notes(builder.finish(), parse_score(file, "default")));
}

TEST_CASE("score: the default score is Figure 5 - both hands with legato and accents under a tempo "
          "change",
          "[score][parser]")
{
    const Score s = parse_score(default_score_text(), "default");
    int legato = 0, accent = 0, right = 0, left = 0;
    for (const auto &n : s.notes) {
        legato += n.nuance == Nuance::legato;
        accent += n.nuance == Nuance::accent;
        right += n.hand == Side::right;
        left += n.hand == Side::left;
    }
    CHECK(legato >= 8);
    CHECK(accent >= 6);
    CHECK(right >= 10);
    CHECK(left >= 10);
    CHECK(s.tempo.changes().size() >= 2);
    double lo = 1e9, hi = 0;
    for (double b = 0; b < s.length_beats; b += 0.25) {
        lo = std::min(lo, s.tempo.tempo_at_beat(b));
        hi = std::max(hi, s.tempo.tempo_at_beat(b));
    }
    CHECK(hi - lo >= 40.0);
    CHECK(s.duration_s() >= 10.0);
    CHECK(s.duration_s() <= 16.0);
}

TEST_CASE("score: errors name the source and line and column and the fault",
          "[score][parser][errors]")
{
    require_error("R legatto", 1, 3,
                  "unknown nuance 'legatto' (valid: legato, tenuto, accent, vertical_accent, "
                  "staccato, buzz)");
    require_error("R\nX legato", 2, 1, "unknown statement 'X'");
    require_error("R+X", 1, 1, "unknown statement 'R+X' (expected a hand R, L, right, left, R+L");
    require_error("tempo 96\n  tempo 9x6", 2, 9, "malformed number '9x6' for tempo");
    require_error("tempo 500", 1, 7, "tempo 500 is out of range (20..400 bpm)");
    require_error("tempo 10", 1, 7, "out of range (20..400 bpm)");
    require_error("tempo", 1, 6, "tempo needs beats per minute");
    require_error("tempo 96 -> 500 over 4", 1, 13, "tempo 500 is out of range");
    require_error("tempo 96 -> 120 in 4", 1, 17, "expected 'over BEATS'");
    require_error("tempo 96 -> 120 over", 1, 21, "needs the number of beats after 'over'");
    require_error("tempo 96 -> 120 over 0", 1, 22, "out of range (1/32..64 beats)");
    require_error("tempo 96 97", 1, 10, "unexpected '97' after the tempo");
    require_error("grip spanish", 1, 6, "unknown grip 'spanish' (valid: french, german)");
    require_error("grip", 1, 5, "grip needs a name");
    require_error("L accent 1.5", 1, 10, "dynamics 1.5 is out of range (0..1");
    require_error("L accent -0.1", 1, 10, "out of range (0..1");
    require_error("L accent 0.8.1", 1, 10, "malformed number '0.8.1' for dynamics");
    require_error("L accent fff", 1, 10, "unexpected 'fff' in a note");
    require_error("L accent tenuto", 1, 10, "second nuance 'tenuto'");
    require_error("L accent f 0.5", 1, 12, "second dynamics");
    // A whole beat written as a number reads as dynamics 1: the message says how to write it.
    require_error("R on snare f 1", 1, 14,
                  "second dynamics '1' in one note (for a duration write 'beats 1' or N/D)");
    require_error("L 1/2 beats 1", 1, 7, "second duration");
    require_error("L accent 1/0", 1, 10, "divides by zero");
    require_error("L accent 1/x", 1, 10, "malformed fraction '1/x'");
    require_error("L accent 1/64", 1, 10, "out of range (1/32..64 beats)");
    require_error("L accent beats 65", 1, 16, "out of range (1/32..64 beats)");
    require_error("L accent beats", 1, 15, "'beats' needs a duration");
    require_error("L at 1.2 0", 1, 6, "r/a 1.2 is out of range (0..0.95");
    require_error("L at 0.3", 1, 9, "'at' needs theta");
    require_error("L at 0.3 north", 1, 10, "malformed number 'north' for theta");
    require_error("L at nan 0", 1, 6, "malformed number 'nan'");
    require_error("rest 0", 1, 6, "out of range");
    require_error("rest 1 2", 1, 8, "unexpected '2' after the rest");
    require_error("beats", 1, 6, "'beats' needs a duration");
    require_error("dynamics loud", 1, 10, "unknown dynamics 'loud'");
    require_error("repeat 2.5\nR\nend", 1, 8, "whole number 1..1000");
    require_error("repeat 0\nR\nend", 1, 8, "whole number 1..1000");
    require_error("R\nend", 2, 1, "'end' without 'repeat'");
    require_error("R\n  repeat 2\nR\n", 2, 3, "'repeat' without 'end'");
    require_error("end now", 1, 5, "unexpected 'now'");
    // A count that would expand past the limits is refused, not expanded.
    require_error("repeat 1000\nrepeat 1000\nR\nend\nend", 3, 1, "more than 100000 notes");
    // Repeats nested around no note or rest reach neither limit: the count of
    // statements executed stops them (this score used to expand for ever).
    require_error(
        "repeat 1000\nrepeat 1000\nrepeat 1000\nrepeat 1000\ngrip german\nend\nend\nend\nend", 5, 1,
        "more than 1000000 statements");
}

TEST_CASE("score: the statement budget refuses empty loops at any depth and admits full scores",
          "[score][parser][errors]")
{
    // Seeded random nests of repeats around statements that neither play nor
    // advance: refused with the budget's message whenever the product of the
    // counts times the body exceeds the budget, accepted otherwise.
    std::mt19937 rng(1311);
    const char *idle[] = {"grip german", "grip french", "tempo 100", "beats 1/2", "dynamics p"};
    for (int trial = 0; trial < 200; ++trial) {
        const int depth = std::uniform_int_distribution<int>(1, 5)(rng);
        std::string text;
        double executed = 0.0, passes = 1.0;
        std::vector<int> counts;
        for (int d = 0; d < depth; ++d) {
            const int c = std::uniform_int_distribution<int>(1, 1000)(rng);
            counts.push_back(c);
            text += "repeat " + std::to_string(c) + "\n";
        }
        const int body = std::uniform_int_distribution<int>(1, 3)(rng);
        for (int b = 0; b < body; ++b)
            text += std::string(idle[std::uniform_int_distribution<int>(0, 4)(rng)]) + "\n";
        for (int d = 0; d < depth; ++d)
            text += "end\n";
        // Statements executed, counted independently: each level runs its
        // 'repeat' once per pass of its parent and its 'end' once per own pass.
        for (int d = 0; d < depth; ++d) {
            executed += passes; // the repeat line
            passes *= counts[d];
            executed += passes; // its end line
        }
        executed += passes * body;
        INFO("trial " << trial << ":\n" << text);
        if (executed > static_cast<double>(kMaxScoreSteps)) {
            REQUIRE_THROWS_WITH(parse_score(text, "nest"),
                                Contains("more than 1000000 statements"));
        } else {
            REQUIRE_NOTHROW(parse_score(text, "nest"));
        }
    }
    // A score at the note limit stays well inside the budget.
    REQUIRE(parse_score("repeat 1000\nrepeat 50\nR\nL\nend\nend\n", "full").notes.size() == 100000);
}

TEST_CASE("score: nothing is produced from a faulty score", "[score][parser][errors]")
{
    // The fault is on the last line: the first lines are fine but no Score is returned.
    bool produced = false;
    try {
        Score s = parse_score("tempo 96\nR\nL\nR accent\nL bogus\n", "bad");
        produced = true;
    } catch (const ScoreError &e) {
        CHECK(e.line() == 5);
    }
    CHECK_FALSE(produced);

    // Statement by statement: the failing statement changes nothing, and the
    // score is refused until reset.
    ScoreBuilder b;
    b.add_statement("tempo 96");
    b.add_statement("R legato");
    CHECK_THROWS_AS(b.add_statement("L legatto"), ScoreError);
    CHECK(b.failed());
    b.add_statement("L accent");
    try {
        b.finish();
        FAIL("a score with a failed statement was produced");
    } catch (const ScoreError &e) {
        CHECK(e.source() == "osc");
        CHECK(e.line() == 3); // the third statement
        CHECK(e.column() == 3);
        CHECK_THAT(e.what(), Contains("refused"));
    }
    b.reset();
    CHECK_FALSE(b.failed());
    CHECK(b.statements() == 0);
    b.add_statement("R legato");
    b.add_statement("L accent, R 1/2"); // a message may hold several statements
    const Score s = b.finish();
    REQUIRE(s.notes.size() == 3);
    CHECK(s.notes[1].line == 2);
    CHECK(s.notes[2].column == 11);

    // A stray 'end' inside a message leaves the open repeat untouched.
    ScoreBuilder r;
    r.add_statement("repeat 2");
    r.add_statement("R");
    CHECK_THROWS_AS(r.add_statement("end, end"), ScoreError);
    r.reset();
    r.add_statement("repeat 2");
    r.add_statement("R");
    r.add_statement("end");
    CHECK(r.finish().notes.size() == 2);
}

TEST_CASE("score: example files parse", "[score][parser]")
{
    for (const char *name : {"figure5.txt", "nuances.txt", "tempo_ramp.txt", "groove.txt"}) {
        const std::string path = std::string(ICTUS_SOURCE_DIR) + "/examples/scores/" + name;
        INFO(path);
        const Score s = load_score(path);
        CHECK(s.notes.size() > 4);
    }
    CHECK_THROWS_AS(load_score("/nonexistent/score.txt"), ScoreError);
}

TEST_CASE("score: balancing repeat/end takes a time linear in the depth of the repeats open",
          "[score][parser]")
{
    // Nested `repeat 1` around one note, `depth` deep: each line's balance
    // must not cost the depth open (a quadratic balance took 2.7 s at 10^5,
    // 13.9 s at 2 x 10^5). Sixteen times the depth: about 16 times the time if
    // linear, 256 if quadratic; the bound is their geometric mean, 64, a factor
    // of four from each (with four times the depth and a bound of 8, a loaded
    // CI run measured a linear balance at 8.04x: the larger text's cache misses
    // grow with the load). The best of five runs each, the two depths in turn,
    // so that a load on the machine weighs on both alike.
    auto seconds = [](int depth) {
        std::string text;
        for (int i = 0; i < depth; ++i)
            text += "repeat 1\n";
        text += "R\n";
        for (int i = 0; i < depth; ++i)
            text += "end\n";
        const auto t0 = std::chrono::steady_clock::now();
        const Score s = parse_score(text, "deep");
        const double took =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        REQUIRE(s.notes.size() == 1);
        return took;
    };
    double small = 1e9, large = 1e9;
    for (int run = 0; run < 5; ++run) {
        small = std::min(small, seconds(12500));
        large = std::min(large, seconds(200000));
    }
    INFO("12500 deep: " << small << " s, 200000 deep: " << large << " s");
    CHECK(large < 64.0 * small);
}

TEST_CASE("score: a builder counts the statements its lines held", "[score][parser]")
{
    ScoreBuilder b;
    b.add_statement("R, L, R+L");
    b.add_statement("# a comment alone");
    b.add_statement("repeat 2");
    b.add_statement("R; end");
    CHECK(b.statements() == 4);
    CHECK(b.parsed_statements() == 6u); // R, L, R+L, repeat, R, end
    REQUIRE_THROWS(b.add_statement("end"));
    CHECK(b.parsed_statements() == 6u); // a refused line adds nothing
}

TEST_CASE("score: a text of blank lines and comments only holds no statement, as an empty one",
          "[score][parser]")
{
    // `--score` refuses such a file as one with no notes (tests/cli, test_verbs.cpp).
    for (const char *none :
         {"", " \t\n\n", "# a comment\n\n  # another", "\xEF\xBB\xBF# x\r\n\r", "\xC2\xA0\r\n"}) {
        INFO('"' << none << '"');
        CHECK_FALSE(score_text_has_statements(none));
        CHECK(parse_score(none, "t").notes.empty());
    }
    // One statement, a note or not, faulty or not, after comments and blank lines.
    for (const char *some : {"R", "# a comment\n\nR legato", "\r\rgrip german # no note",
                             "\xEF\xBB\xBF"
                             "rest",
                             "# c\nR legatto"})
        CHECK(score_text_has_statements(some));
}

// A CR in one /ictus/score string (a patch's text pasted from Windows, or an old Mac's)
// did not separate statements as LF does; a '#' comment ran past the line break to the
// end of the string. Seeded statements in one string, each line break LF, CRLF or CR,
// some lines with a comment: the notes of the same statements one per line of a file.
TEST_CASE("score: a line break in one statement string separates as in a file, CR too",
          "[score][parser]")
{
    const std::vector<std::string> words = {"R legato",     "L accent 0.8", "R staccato pp",
                                            "L 1/2",        "tempo 90",     "R+L tenuto f",
                                            "rest 1/4",     "L legato mp",  "R vertical_accent ff",
                                            "dynamics 0.3", "R 1/4",        "grip german"};
    std::mt19937 rng(20261204);
    for (int trial = 0; trial < 50; ++trial) {
        std::string file, message;
        const int n = std::uniform_int_distribution<int>(2, 9)(rng);
        ictus_test::join_statements(rng, words, n, " # a comment, R ff", file, message);
        INFO("trial " << trial << ": " << file);
        ictus_test::check_same_notes(message, file);
    }
}
