// The panel's live controls in score mode (docs/osc.md): /ictus/tempo scales
// the score's tempo map from the first beat no hand has begun to play toward
// (the strokes under way keep their shape and time), /ictus/nuance sets the
// nuance of the statements that follow. The performance is the real one
// (planner, Tracker on the Scene, strike detector), run offline step by step;
// the expected beat times are computed here from the score's arithmetic.
#include "ictus/perform/performance.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

using namespace ictus;

namespace
{

Command command(CommandKind kind, double value = 0.0, const char *text = "")
{
    Command c;
    c.kind = kind;
    c.value = value;
    std::snprintf(c.text, sizeof c.text, "%s", text);
    std::snprintf(c.address, sizeof c.address, "/ictus/test");
    return c;
}

} // namespace

TEST_CASE("perform: /ictus/tempo in score mode scales the tempo map from the first beat not "
          "yet begun: the strokes under way keep their times, every note is struck on its "
          "new beat",
          "[perform][tempo]")
{
    PerformanceOptions o;
    // 100 bpm: 0.6 s a beat, R on even beats, L on odd ones.
    o.score.score_text = "tempo 100, repeat 5, R, L, end";
    o.score.score_name = "test";
    Performance perf(o);
    std::string why;
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    REQUIRE(perf.plan_active());
    const double lead = perf.plan()->score_start_s;
    CHECK(perf.tempo_bpm() == Approx(100.0));
    const GesturePlan before = *perf.plan();
    REQUIRE(before.notes.size() == 10);

    // Up to plan time 2.0 s (beat 1.67), strikes recorded.
    std::vector<StrikeEvent> strikes;
    StrikeEvent ev[2];
    while (perf.plan_time_s() < 2.0 - 1e-9) {
        const int k = perf.step(ev);
        strikes.insert(strikes.end(), ev, ev + k);
    }
    REQUIRE(perf.apply(command(CommandKind::tempo, 150.0), &why));
    INFO(why);
    // Where the change starts, by hand from the planner's rule (docs/osc.md):
    // at 2.0 + 0.25 s the right hand's next stroke (beat 4 at 1 + 2.4 s) has
    // not begun its cross-fade (2.2 + 0.25 x 1.2 = 2.5 s), the left hand's
    // toward beat 3 has (1.6 + 0.3 = 1.9 s), its next (beat 5) has not
    // (2.8 + 0.3 = 3.1 s): the tempo changes at beat 5 (1 + 3.0 s).
    auto expected_s = [&](double beat) {
        return beat <= 5.0 ? lead + 0.6 * beat : lead + 3.0 + 0.4 * (beat - 5.0);
    };
    const GesturePlan &after = *perf.plan();
    REQUIRE(after.notes.size() == 10);
    for (size_t i = 0; i < after.notes.size(); ++i) {
        INFO("note " << i);
        CHECK(after.notes[i].time_s == Approx(expected_s(static_cast<double>(i))).margin(1e-9));
        CHECK(before.notes[i].time_s == Approx(lead + 0.6 * static_cast<double>(i)).margin(1e-9));
    }
    // The targets the hands follow are the same up to the first stroke that
    // changes (the right hand's cross-fade toward beat 4 at 2.5 s).
    double max_diff = 0.0;
    for (double t = 0.0; t <= 2.5; t += 0.001)
        for (int s = 0; s < 2; ++s)
            max_diff =
                std::max(max_diff, (after.tips.sample(s, t) - before.tips.sample(s, t)).norm());
    CHECK(max_diff < 1e-9);
    CHECK(perf.tempo_bpm() == Approx(100.0)); // beat 1.67: before the change
    CHECK(perf.tempo_scale() == Approx(1.5));

    // To the end: one primary strike per note, each on its new beat.
    bool saw_new_tempo = false;
    while (perf.plan_active()) {
        const int k = perf.step(ev);
        strikes.insert(strikes.end(), ev, ev + k);
        if (perf.plan_active() && perf.plan_time_s() > lead + 3.5)
            saw_new_tempo = saw_new_tempo || perf.tempo_bpm() == Approx(150.0);
    }
    CHECK(saw_new_tempo);
    for (StrikeEvent last; perf.flush(last);)
        strikes.push_back(last);
    for (int hand = 0; hand < 2; ++hand) {
        std::vector<double> primary;
        for (const StrikeEvent &e : strikes)
            if (e.hand == hand && !e.bounce)
                primary.push_back(e.time_s - perf.plan_origin_s());
        INFO("hand " << hand);
        REQUIRE(primary.size() == 5);
        for (size_t k = 0; k < primary.size(); ++k) {
            // R (hand 1) on beats 0, 2, ...; L (hand 0) on 1, 3, ...
            const double beat = 2.0 * static_cast<double>(k) + (hand == 1 ? 0.0 : 1.0);
            INFO("beat " << beat << ": strike at " << primary[k] << " s");
            CHECK(std::abs(primary[k] - expected_s(beat)) <= 0.005);
        }
    }
    // Stopped, the tempo is the one the next play starts at: the score's
    // first tempo at the live scale (100 x 1.5); one asked for while stopped
    // starts the next play there; a new score plays at its own tempi.
    CHECK(perf.tempo_bpm() == Approx(150.0));
    REQUIRE(perf.apply(command(CommandKind::tempo, 80.0), &why));
    CHECK(perf.tempo_bpm() == Approx(80.0));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    CHECK(perf.plan()->notes[1].time_s - perf.plan()->notes[0].time_s == Approx(0.75));
    REQUIRE(perf.apply(command(CommandKind::stop), &why));
    REQUIRE(perf.apply(command(CommandKind::score_clear), &why));
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "tempo 60, R, L"), &why));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    CHECK(perf.plan()->notes[1].time_s - perf.plan()->notes[0].time_s == Approx(1.0));
}

TEST_CASE("perform: a new score sent without /ictus/score/clear plays at its own tempi, not "
          "at the live tempo of the score before it, and the stopped tempo says so",
          "[perform][tempo]")
{
    PerformanceOptions o;
    o.score.score_text = "tempo 100, repeat 4, R, L, end";
    o.score.score_name = "test";
    Performance perf(o);
    std::string why;
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    REQUIRE(perf.apply(command(CommandKind::tempo, 50.0), &why));
    INFO(why);
    CHECK(perf.tempo_scale() == Approx(0.5));
    REQUIRE(perf.apply(command(CommandKind::stop), &why));
    CHECK(perf.tempo_bpm() == Approx(50.0)); // a play now replays the score at its live scale

    // The first statement received begins a new score: the next play plays
    // it at its own tempo, and the stopped tempo is that one.
    for (const char *statement : {"tempo 120", "R", "L", "R", "L"})
        REQUIRE(perf.apply(command(CommandKind::score, 0.0, statement), &why));
    CHECK(perf.tempo_bpm() == Approx(120.0));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    REQUIRE(perf.plan()->notes.size() == 4);
    CHECK(perf.plan()->notes[1].time_s - perf.plan()->notes[0].time_s == Approx(0.5));
    CHECK(perf.tempo_bpm() == Approx(120.0));
    REQUIRE(perf.apply(command(CommandKind::stop), &why));

    // A tempo asked while stopped, after the statements, starts the next play.
    REQUIRE(perf.apply(command(CommandKind::tempo, 60.0), &why));
    CHECK(perf.tempo_bpm() == Approx(60.0));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    CHECK(perf.plan()->notes[1].time_s - perf.plan()->notes[0].time_s == Approx(1.0));
    REQUIRE(perf.apply(command(CommandKind::stop), &why));
    // Statements appended to that score extend it: its scale stays.
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "R"), &why));
    CHECK(perf.tempo_bpm() == Approx(60.0));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    REQUIRE(perf.plan()->notes.size() == 5);
    CHECK(perf.plan()->notes[4].time_s - perf.plan()->notes[3].time_s == Approx(1.0));
}

TEST_CASE("perform: a live tempo that would take the score's tempo map past 400 bpm is "
          "refused, naming the tempo, and the plan goes on unchanged",
          "[perform][tempo]")
{
    PerformanceOptions o;
    o.score.score_text = "tempo 100, repeat 4, R, L, end, tempo 300, R, L";
    o.score.score_name = "test";
    Performance perf(o);
    std::string why;
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    const std::vector<PlannedNote> notes = perf.plan()->notes;
    REQUIRE_FALSE(perf.apply(command(CommandKind::tempo, 200.0), &why));
    CHECK(why.find("300 bpm") != std::string::npos);
    CHECK(why.find("600 bpm") != std::string::npos);
    REQUIRE(perf.plan()->notes.size() == notes.size());
    for (size_t i = 0; i < notes.size(); ++i)
        CHECK(perf.plan()->notes[i].time_s == notes[i].time_s);
    CHECK(perf.tempo_scale() == 1.0);
}

TEST_CASE("perform: /ictus/nuance in score mode sets the nuance of the statements that follow "
          "and name none, also after a score/clear",
          "[perform][nuance]")
{
    PerformanceOptions o;
    o.score.score_text = "R, L";
    Performance perf(o);
    std::string why;
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "R"), &why));
    REQUIRE(perf.apply(command(CommandKind::nuance, 0.0, "accent"), &why));
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "L, R staccato"), &why));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    const std::vector<PlannedNote> &a = perf.plan()->notes;
    REQUIRE(a.size() == 3);
    CHECK(a[0].nuance == Nuance::legato);
    CHECK(a[1].nuance == Nuance::accent);
    CHECK(a[2].nuance == Nuance::staccato);
    REQUIRE(perf.apply(command(CommandKind::stop), &why));
    REQUIRE(perf.apply(command(CommandKind::score_clear), &why));
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "R, L tenuto"), &why));
    REQUIRE(perf.apply(command(CommandKind::play), &why));
    const std::vector<PlannedNote> &b = perf.plan()->notes;
    REQUIRE(b.size() == 2);
    CHECK(b[0].nuance == Nuance::accent);
    CHECK(b[1].nuance == Nuance::tenuto);
    // A statement refused after the default keeps its own position: the
    // default is not counted as a statement.
    REQUIRE(perf.apply(command(CommandKind::score_clear), &why));
    REQUIRE(perf.apply(command(CommandKind::score, 0.0, "R"), &why));
    REQUIRE_FALSE(perf.apply(command(CommandKind::score, 0.0, "R legatto"), &why));
    CHECK(why.find("osc:2:3") != std::string::npos);
}
