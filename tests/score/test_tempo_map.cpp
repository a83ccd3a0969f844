// The tempo map: beat times are the integral of 60 / tempo(beat). Checked
// against the closed form of a linear ramp and against a numerical integral
// (Simpson's rule on the tempo curve, a second method).
#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

using namespace ictus;

namespace
{

// Simpson's rule of 60 / bpm(b) over [0, beat], n even.
double simpson_time(const std::function<double(double)> &bpm, double beat, int n = 2000)
{
    const double h = beat / n;
    double sum = 60.0 / bpm(0.0) + 60.0 / bpm(beat);
    for (int i = 1; i < n; ++i)
        sum += (i % 2 ? 4.0 : 2.0) * 60.0 / bpm(i * h);
    return sum * h / 3.0;
}

} // namespace

TEST_CASE("tempo map: constant tempo", "[score][tempo]")
{
    TempoMap m(96.0);
    CHECK(m.time_at_beat(0.0) == 0.0);
    CHECK(m.time_at_beat(96.0) == Approx(60.0).epsilon(1e-12));
    CHECK(m.time_at_beat(-1.0) == Approx(-0.625).epsilon(1e-12));
    CHECK(m.beat_at_time(30.0) == Approx(48.0).epsilon(1e-12));
}

TEST_CASE("tempo map: a linear ramp against its closed-form integral", "[score][tempo]")
{
    // 120 bpm for 2 beats, then 120 -> 160 over 8 beats, then 160.
    TempoMap m(120.0);
    m.add(2.0, 120.0, 160.0, 8.0);
    const double t2 = 2.0 * 60.0 / 120.0; // 1 s
    // In the ramp: tempo(b) = 120 + 5 (b - 2); t = t2 + 60/5 ln(tempo/120).
    for (double b : {2.0, 3.0, 4.5, 7.25, 10.0}) {
        const double tempo = 120.0 + 5.0 * (b - 2.0);
        const double expected = t2 + 12.0 * std::log(tempo / 120.0);
        CHECK(m.time_at_beat(b) == Approx(expected).epsilon(1e-12));
        CHECK(m.tempo_at_beat(b) == Approx(tempo).epsilon(1e-12));
        CHECK(m.beat_at_time(expected) == Approx(b).epsilon(1e-12));
    }
    const double t10 = t2 + 12.0 * std::log(160.0 / 120.0);
    CHECK(m.time_at_beat(14.0) == Approx(t10 + 4.0 * 60.0 / 160.0).epsilon(1e-12));
    CHECK(m.beat_at_time(t10 + 1.5) == Approx(10.0 + 1.5 * 160.0 / 60.0).epsilon(1e-12));

    // The same map by numerical integration of the tempo curve.
    auto bpm = [](double b) { return b < 2 ? 120.0 : b < 10 ? 120.0 + 5.0 * (b - 2.0) : 160.0; };
    CHECK(m.time_at_beat(6.0) == Approx(simpson_time(bpm, 6.0)).epsilon(1e-9));
    CHECK(m.time_at_beat(12.5) == Approx(simpson_time(bpm, 12.5)).epsilon(1e-9));
}

TEST_CASE("tempo map: slowing down and a change that cuts a ramp short", "[score][tempo]")
{
    // 200 -> 40 over 16 beats, cut at beat 8 by an instant 90.
    TempoMap m(200.0);
    m.add(0.0, 200.0, 40.0, 16.0); // replaces the initial tempo at beat 0
    m.add(8.0, 90.0, 90.0, 0.0);
    auto bpm = [](double b) { return b < 8 ? 200.0 - 10.0 * b : 90.0; };
    CHECK(m.changes().size() == 2);
    CHECK(m.tempo_at_beat(7.999) == Approx(120.01));
    CHECK(m.tempo_at_beat(8.0) == 90.0);
    // Closed form of the cut ramp: 60/(-10) ln(120/200).
    const double t8 = -6.0 * std::log(120.0 / 200.0);
    CHECK(m.time_at_beat(8.0) == Approx(t8).epsilon(1e-12));
    CHECK(m.time_at_beat(11.0) == Approx(t8 + 2.0).epsilon(1e-12));
    CHECK(m.time_at_beat(5.0) == Approx(simpson_time(bpm, 5.0)).epsilon(1e-9));
    for (double t = 0.0; t < 6.0; t += 0.37)
        CHECK(m.time_at_beat(m.beat_at_time(t)) == Approx(t).margin(1e-12));
    CHECK_THROWS_AS(m.add(4.0, 100.0, 100.0, 0.0), std::invalid_argument);
    CHECK_THROWS_AS(m.add(9.0, 0.0, 100.0, 0.0), std::invalid_argument);
}

TEST_CASE("tempo map: a score's ramp from the current tempo", "[score][tempo]")
{
    // 'tempo -> 60 over 4' in the middle of 'tempo 100 -> 180 over 8' at beat 4
    // starts from the tempo reached there, 140.
    const Score s = parse_score(
        "tempo 100 -> 180 over 8\nR\nR\nR\nR\ntempo -> 60 over 4\nR\nR\nR\nR\nR\n", "mid");
    CHECK(s.tempo.tempo_at_beat(4.0) == Approx(140.0));
    CHECK(s.tempo.tempo_at_beat(6.0) == Approx(100.0));
    CHECK(s.tempo.tempo_at_beat(8.5) == Approx(60.0));
    const double t4 = 60.0 / 10.0 * std::log(140.0 / 100.0);
    const double t8 = t4 + 60.0 / -20.0 * std::log(60.0 / 140.0);
    CHECK(s.note_time_s(s.notes[4]) == Approx(t4).epsilon(1e-12));
    CHECK(s.note_time_s(s.notes[8]) == Approx(t8).epsilon(1e-12));
    REQUIRE(s.notes.size() == 9);
    CHECK(s.duration_s() == Approx(t8 + 1.0).epsilon(1e-12));
}
