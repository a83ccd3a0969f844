// The drummers' notation of the score language (docs/score.md, "Flams,
// drags and rolls", "Hairpins", "Meter"): grace strokes at their times
// before their notes, rolls expanded into their strokes, hairpins'
// dynamics against hand-computed values, meters, and the errors.
#include "ictus/score/gesture_score.hpp"
#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "support/score_test_util.hpp"

using namespace ictus;
using Catch::Matchers::Contains;
using ictus_test::require_error;

namespace
{

std::vector<ScoreNote> graces(const Score &s)
{
    std::vector<ScoreNote> out;
    for (const ScoreNote &n : s.notes)
        if (n.grace != Grace::none)
            out.push_back(n);
    return out;
}

} // namespace

TEST_CASE("score: a flam is one soft grace stroke of the other hand 30 ms before its note",
          "[score][notation]")
{
    // 100 bpm: beat 1 at 0.6 s. The flam's grace at 0.6 - 0.030 = 0.570 s.
    const Score s = parse_score("tempo 100\nL\nR accent f flam\nL", "t.txt");
    REQUIRE(s.notes.size() == 4);
    CHECK(s.length_beats == 3.0);
    const ScoreNote &g = s.notes[1];
    CHECK(g.grace == Grace::flam);
    CHECK(g.hand == Side::left);
    CHECK(g.beat == 1.0);
    CHECK(g.beats == 0.0);
    CHECK(s.note_time_s(g) == Approx(0.570).margin(1e-12));
    CHECK(g.nuance == Nuance::legato);
    CHECK(g.dynamics == Approx(0.15));         // kGraceDynamics, below half of f
    CHECK(g.theta_deg == kDefaultThetaDeg[0]); // the left hand's own spot
    CHECK(g.line == 3);
    CHECK(g.column == 12); // the word 'flam'
    const ScoreNote &n = s.notes[2];
    CHECK(n.grace == Grace::none);
    CHECK(n.hand == Side::right);
    CHECK(n.nuance == Nuance::accent);
    CHECK(n.dynamics == 0.8);
    CHECK(s.note_time_s(n) == Approx(0.6).margin(1e-12));
    // A soft note's grace is half as loud as it.
    const Score soft = parse_score("L flam 0.2", "t.txt");
    REQUIRE(graces(soft).size() == 1);
    CHECK(graces(soft)[0].dynamics == Approx(0.1));
    CHECK(graces(soft)[0].hand == Side::right);
}

TEST_CASE("score: a drag's two grace strokes are a double of the other hand before its note",
          "[score][notation]")
{
    // 80 bpm, beat 2 at 1.5 s: graces at 1.5 - 0.070 = 1.430 s and 1.5 - 0.030 = 1.470 s.
    const Score s = parse_score("tempo 80\nbeats 2\nR\nL drag mp\n", "t.txt");
    REQUIRE(s.notes.size() == 4);
    const std::vector<ScoreNote> g = graces(s);
    REQUIRE(g.size() == 2);
    for (const ScoreNote &x : g) {
        CHECK(x.grace == Grace::drag);
        CHECK(x.hand == Side::right);
        CHECK(x.dynamics == Approx(0.15)); // half of mp (0.225) is more
    }
    CHECK(s.note_time_s(g[0]) == Approx(1.430).margin(1e-12));
    CHECK(s.note_time_s(g[1]) == Approx(1.470).margin(1e-12));
    // Time order: R at 0, the two graces, the note.
    CHECK(s.notes[0].hand == Side::right);
    CHECK(s.notes[0].grace == Grace::none);
    CHECK(s.notes[3].hand == Side::left);
    CHECK(s.note_time_s(s.notes[3]) == Approx(1.5).margin(1e-12));
}

TEST_CASE("score: grace strokes come in time order before notes written earlier",
          "[score][notation]")
{
    // 240 bpm, beats 1/8: 31.25 ms a note. The flam on the third note
    // (62.5 ms) has its grace at 32.5 ms, the drag on the fifth (125 ms) at
    // 55 and 95 ms: between notes written before them. (Parsed only: the
    // planner refuses those graces so close to the right hand's strokes.)
    const Score s = parse_score("tempo 240, beats 1/8, R, R, L flam, R, L drag", "t.txt");
    std::vector<double> t;
    for (const ScoreNote &n : s.notes)
        t.push_back(s.note_time_s(n));
    REQUIRE(t.size() == 8);
    const std::vector<double> want = {0.0, 0.03125, 0.0325, 0.0625, 0.055, 0.09375, 0.095, 0.125};
    std::vector<double> sorted = want;
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i < t.size(); ++i)
        CHECK(t[i] == Approx(sorted[i]).margin(1e-12));
}

TEST_CASE("score: rolls are strokes at the beats default, alternating", "[score][notation]")
{
    SECTION("single: R L R L")
    {
        const Score s = parse_score("beats 1/4\nnuance staccato\nroll single 2\nR", "t.txt");
        REQUIRE(s.notes.size() == 9);
        for (size_t k = 0; k < 8; ++k) {
            CHECK(s.notes[k].beat == Approx(0.25 * static_cast<double>(k)));
            CHECK(s.notes[k].beats == 0.25);
            CHECK(s.notes[k].hand == (k % 2 == 0 ? Side::right : Side::left));
            CHECK(s.notes[k].nuance == Nuance::staccato); // the default nuance
            CHECK(s.notes[k].line == 3);
        }
        CHECK(s.notes[8].beat == 2.0);
    }
    SECTION("double: R R L L")
    {
        const Score s = parse_score("beats 1/8, roll double 1", "t.txt");
        REQUIRE(s.notes.size() == 8);
        const char *want = "RRLLRRLL";
        for (size_t k = 0; k < 8; ++k)
            CHECK(s.notes[k].hand == (want[k] == 'R' ? Side::right : Side::left));
        CHECK(s.length_beats == 1.0);
    }
    SECTION("buzz: buzz strokes R L at the dynamics")
    {
        const Score s = parse_score("beats 1/3, dynamics p, roll buzz 2/3, roll buzz 1", "t.txt");
        REQUIRE(s.notes.size() == 5);
        for (size_t k = 0; k < 5; ++k) {
            CHECK(s.notes[k].nuance == Nuance::buzz);
            CHECK(s.notes[k].dynamics == 0.3);
        }
        // Each roll starts with the right hand: R L, then R L R.
        const char *want = "RLRLR";
        for (size_t k = 0; k < 5; ++k)
            CHECK(s.notes[k].hand == (want[k] == 'R' ? Side::right : Side::left));
        CHECK(s.length_beats == Approx(5.0 / 3.0));
    }
}

TEST_CASE("score: a hairpin ramps the dynamics of each note by its beat", "[score][notation]")
{
    // p (0.3) -> f (0.8) over 4 beats from beat 1: 0.3 + 0.125 (b - 1).
    const Score s = parse_score("R\ndynamics p -> f over 4\nbeats 1/2\n"
                                "repeat 6\nR, L\nend\nR 0.1",
                                "t.txt");
    REQUIRE(s.notes.size() == 14);
    CHECK(s.notes[0].dynamics == 0.6); // before the hairpin
    for (size_t k = 1; k < 13; ++k) {
        const double b = 1.0 + 0.5 * static_cast<double>(k - 1);
        const double want = b >= 5.0 ? 0.8 : 0.3 + 0.125 * (b - 1.0);
        CHECK(s.notes[k].beat == b);
        CHECK(s.notes[k].dynamics == Approx(want).margin(1e-12));
    }
    CHECK(s.notes[13].dynamics == 0.1); // a note's own dynamics win

    // From the current dynamics, cut by a later hairpin and by `dynamics D`:
    // mf 0.6 -> 0.2 over 2 from beat 0 (0.6, 0.4, then cut at beat 2 at
    // 0.2) -> 1.0 over 4 (beat 3: 0.4), `dynamics 0.5` at beat 4.
    const Score c = parse_score("dynamics -> 0.2 over 2\nR, R\ndynamics to ff over 4\nR, R\n"
                                "dynamics 0.5\nR",
                                "t.txt");
    REQUIRE(c.notes.size() == 5);
    const double want[] = {0.6, 0.4, 0.2, 0.4, 0.5};
    for (size_t k = 0; k < 5; ++k)
        CHECK(c.notes[k].dynamics == Approx(want[k]).margin(1e-12));
    // A roll crescendo: pp (0.2) -> ff (1.0) over 1 beat in 16ths: 0.2, 0.4, 0.6, 0.8.
    const Score r = parse_score("beats 1/4, dynamics pp -> ff over 1, roll single 1", "t.txt");
    REQUIRE(r.notes.size() == 4);
    for (size_t k = 0; k < 4; ++k)
        CHECK(r.notes[k].dynamics == Approx(0.2 + 0.2 * static_cast<double>(k)).margin(1e-12));
}

TEST_CASE("score: meters are kept at their beats", "[score][notation]")
{
    const Score none = parse_score("R", "t.txt");
    CHECK(none.meters.empty());
    const Score s = parse_score("meter 3/4\nmeter 6/8\nR, R, R\nmeter 7/16\nR", "t.txt");
    REQUIRE(s.meters.size() == 2); // two at beat 0: the later one
    CHECK(s.meters[0].beat == 0.0);
    CHECK(s.meters[0].numerator == 6);
    CHECK(s.meters[0].denominator == 8);
    CHECK(s.meters[1].beat == 3.0);
    CHECK(s.meters[1].numerator == 7);
    CHECK(s.meters[1].denominator == 16);
    CHECK(s.meters[1].line == 4);
}

TEST_CASE("score: the notation's errors name the line, the column and what was expected",
          "[score][notation][errors]")
{
    require_error("R flam drag", 1, 8, "second ornament 'drag'");
    require_error("R flam flam", 1, 8, "second ornament");
    require_error("R+L flam", 1, 5, "write R flam or L flam");
    require_error("both drag", 1, 6, "write R drag or L drag");
    require_error("roll", 1, 5, "roll needs a kind and a length");
    require_error("roll triple 2", 1, 6, "unknown roll 'triple' (valid: single, double, buzz)");
    require_error("roll single", 1, 12, "roll needs its length in beats");
    require_error("roll single 0", 1, 13, "roll length 0 is out of range");
    require_error("roll single x", 1, 13, "malformed number 'x' for roll length");
    require_error("roll single 2 R", 1, 15, "unexpected 'R' after the roll length");
    require_error("R\nbeats 1/4\nroll double 3/8", 3, 1,
                  "a roll of 0.375 beats is not a whole number of strokes at 'beats' 0.25");
    require_error("beats 1/2, roll single 1/4", 1, 12, "not a whole number of strokes");
    require_error("dynamics p ->", 1, 14, "a hairpin needs the target dynamics");
    require_error("dynamics p -> loud over 2", 1, 15, "unknown dynamics 'loud'");
    require_error("dynamics p -> f in 2", 1, 17, "expected 'over BEATS' after the target dynamics");
    require_error("dynamics p -> f over", 1, 21, "a hairpin needs the number of beats");
    require_error("dynamics p -> f over 0", 1, 22, "hairpin length 0 is out of range");
    require_error("dynamics p f", 1, 12, "unexpected 'f' after the dynamics");
    require_error("dynamics", 1, 9, "'dynamics' needs a value 0..1 or pp..ff, or a hairpin");
    require_error("meter", 1, 6, "meter needs N/D");
    require_error("meter 3", 1, 7, "malformed meter '3'");
    require_error("meter 3/x", 1, 7, "malformed meter");
    require_error("meter 0/4", 1, 7, "out of range (1..64)");
    require_error("meter 65/4", 1, 7, "out of range (1..64)");
    require_error("meter 3/6", 1, 7, "the note value 6 must be a power of two");
    require_error("meter 4/128", 1, 7, "must be a power of two");
    require_error("meter 4/4 4/4", 1, 11, "unexpected '4/4' after the meter");
}

TEST_CASE("plan: grace strokes are planned strokes, refused only under the same-hand limit",
          "[score][notation][plan]")
{
    const GestureDatabase db = GestureDatabase::builtin();
    const PerformerFrame frame;
    // Alternating flams in 8ths at 120 bpm: each hand's grace 250 - 30 = 220 ms
    // after its own stroke: played. The grace is a planned note, marked.
    const Score ok = parse_score("beats 1/2, R flam, L flam, R flam", "t.txt");
    const GesturePlan plan = plan_performance(ok, db, frame);
    REQUIRE(plan.notes.size() == 6);
    int marked = 0;
    for (const PlannedNote &n : plan.notes)
        marked += n.grace == Grace::flam ? 1 : 0;
    CHECK(marked == 3);
    CHECK(plan.notes[0].grace == Grace::flam);
    CHECK(plan.notes[1].time_s - plan.notes[0].time_s == Approx(0.030).margin(1e-9));
    // A grace 31.25 - 30 = 1.25 ms after the same hand's 32nd at 240 bpm: refused, on its line.
    const Score bad = parse_score("tempo 240, beats 1/8\nR\nL flam", "t.txt");
    try {
        plan_performance(bad, db, frame);
        FAIL("no error");
    } catch (const ScoreError &e) {
        CHECK(e.line() == 3);
        CHECK_THAT(e.message(),
                   Contains("right-hand stroke (the flam's grace stroke) comes 1.25 ms "
                            "after the previous one (line 2)"));
    }
    // The meter reaches the plan at its time: beat 2 at 120 bpm, after the 1 s lead-in.
    const Score m = parse_score("R, R, meter 3/4, R", "t.txt");
    const GesturePlan mp = plan_performance(m, db, frame);
    REQUIRE(mp.meters.size() == 1);
    CHECK(mp.meters[0].time_s == Approx(2.0).margin(1e-12));
    CHECK(mp.meters[0].numerator == 3);
}

TEST_CASE("score: the rudiments example plays every ornament and roll", "[score][notation]")
{
    const Score s = load_score(std::string(ICTUS_SOURCE_DIR) + "/examples/scores/rudiments.txt");
    int flams = 0, drags = 0, buzz = 0;
    for (const ScoreNote &n : s.notes) {
        flams += n.grace == Grace::flam ? 1 : 0;
        drags += n.grace == Grace::drag ? 1 : 0;
        buzz += n.nuance == Nuance::buzz ? 1 : 0;
    }
    CHECK(flams == 8); // 4 flams and 2 x 2 flam taps
    CHECK(drags == 8); // 4 drags, 2 graces each
    CHECK(buzz == 6);  // 2 beats of triplets
    REQUIRE(s.meters.size() == 1);
    const GesturePlan plan = plan_performance(s, GestureDatabase::builtin(), PerformerFrame());
    CHECK(plan.notes.size() == s.notes.size());
}

TEST_CASE("score: the notation one statement at a time (a Pd message box) equals the file",
          "[score][notation]")
{
    const std::vector<std::string> lines = {
        "meter 3/4", "beats 1/4", "dynamics p -> f over 1", "roll single 1",
        "R flam",    "L drag ff", "dynamics -> pp over 2",  "roll buzz 1/2"};
    ScoreBuilder b("osc");
    std::string text;
    for (const std::string &l : lines) {
        b.add_statement(l);
        text += l + "\n";
    }
    const Score x = b.finish(), y = parse_score(text, "t.txt");
    REQUIRE(x.notes.size() == y.notes.size());
    for (size_t i = 0; i < x.notes.size(); ++i) {
        CHECK(x.notes[i].hand == y.notes[i].hand);
        CHECK(x.notes[i].grace == y.notes[i].grace);
        CHECK(x.notes[i].dynamics == y.notes[i].dynamics);
        CHECK(x.note_time_s(x.notes[i]) == y.note_time_s(y.notes[i]));
    }
    CHECK(x.meters.size() == 1);
    // A roll that does not fit the subdivision is refused when the score is finished.
    ScoreBuilder c("osc");
    c.add_statement("beats 1/2");
    c.add_statement("roll double 3/4");
    CHECK_THROWS_WITH(c.finish(), Contains("osc:2:1: a roll of 0.75 beats"));
}

// `tempo 96 -> 140 over 4` as a newcomer types it, `tempo 96->140 over 4`, was refused
// ("malformed number '96->140' for tempo"); '->' is now a word of its own with or without
// spaces around it. Seeded tempo ramps and hairpins, each side of each '->' spaced or not:
// the same beat times and dynamics as the spaced form; an error after a glued arrow is at
// the column an editor counts.
TEST_CASE("score: '->' needs no spaces around it, in tempo ramps and hairpins alike",
          "[score][notation]")
{
    std::mt19937 rng(20261202);
    const std::vector<std::string> words = {"pp", "p", "mp", "mf", "f", "ff", "0.1", "0.9"};
    auto arrow = [&]() {
        return std::string(rng() % 2 ? " " : "") + "->" + (rng() % 2 ? " " : "");
    };
    for (int trial = 0; trial < 40; ++trial) {
        const int t0 = 40 + static_cast<int>(rng() % 300), t1 = 40 + static_cast<int>(rng() % 300);
        const int b = 1 + static_cast<int>(rng() % 8);
        const std::string d0 = words[rng() % words.size()], d1 = words[rng() % words.size()];
        const bool from_current = rng() % 2;
        auto score = [&](const std::string &a1, const std::string &a2) {
            return "tempo " + std::to_string(t0) + a1 + std::to_string(t1) + " over " +
                   std::to_string(b) + "\ndynamics " + (from_current ? std::string() : d0) + a2 +
                   d1 + " over " + std::to_string(b) + "\nrepeat 8\nR, L\nend\n";
        };
        const std::string spaced = score(" -> ", from_current ? "-> " : " -> ");
        const std::string glued =
            score(arrow(), from_current ? "->" + std::string(rng() % 2 ? " " : "") : arrow());
        INFO(glued);
        const Score want = parse_score(spaced, "t.txt");
        const Score got = parse_score(glued, "t.txt");
        REQUIRE(got.notes.size() == want.notes.size());
        for (size_t i = 0; i < want.notes.size(); ++i) {
            CHECK(got.notes[i].beat == want.notes[i].beat);
            CHECK(got.notes[i].dynamics == want.notes[i].dynamics);
        }
        for (double beat : {0.5, 1.0 * b, 7.5, 16.0})
            CHECK(got.tempo.time_at_beat(beat) == want.tempo.time_at_beat(beat));
    }
    // 1:11 is the 5 of 500, counted by hand.
    require_error("tempo 96->500 over 4\nR", 1, 11, "tempo 500 is out of range");
    require_error("dynamics p->2 over 4\nR", 1, 13, "2");
}
