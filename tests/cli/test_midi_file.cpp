// performance.mid's writer (cli/midi_file.hpp, docs/midi.md): the mapping at
// its boundaries, and a small file compared byte by byte with a hand
// computation of the Standard MIDI File format (tests/e2e/test_midi.py reads
// real renders with an independent reader).
#include "ictus/cli/midi_file.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace ictus;
using namespace ictus::cli;

TEST_CASE("midi: zones, notes and velocities at their boundaries", "[cli][midi]")
{
    CHECK(midi_zone(0.0) == 0);
    CHECK(midi_zone(0.2499) == 0);
    CHECK(midi_zone(0.25) == 1);
    CHECK(midi_zone(0.6499) == 1);
    CHECK(midi_zone(0.65) == 2);
    CHECK(midi_zone(1.0) == 2);
    CHECK(midi_note(0, 0.1) == 48);
    CHECK(midi_note(0, 0.4) == 49);
    CHECK(midi_note(0, 0.9) == 50);
    CHECK(midi_note(1, 0.1) == 52);
    CHECK(midi_note(1, 0.4) == 53);
    CHECK(midi_note(1, 0.9) == 54);
    // 1 + 126 ln(v / 0.1) / ln(100): 1 m/s is half way in dB -> 64
    CHECK(midi_velocity(1.0) == 64);
    CHECK(midi_velocity(10.0) == 127);
    CHECK(midi_velocity(50.0) == 127);
    CHECK(midi_velocity(0.1) == 1);
    CHECK(midi_velocity(0.0) == 1);
    CHECK(midi_velocity(-1.0) == 1);
    CHECK(midi_velocity(std::numeric_limits<double>::quiet_NaN()) == 1);
    // 4.3652 m/s (the default score's legato): 1 + 126 * 0.82006 = 104.3
    CHECK(midi_velocity(4.3652) == 104);
}

namespace
{
StrikeEvent strike(int hand, double time_s, double r_over_a, double v, bool bounce)
{
    StrikeEvent e;
    e.hand = hand;
    e.time_s = time_s;
    e.r_over_a = r_over_a;
    e.normal_velocity_mps = v;
    e.bounce = bounce;
    return e;
}
std::string bytes(std::initializer_list<int> v)
{
    std::string s;
    for (int b : v)
        s += static_cast<char>(b);
    return s;
}
} // namespace

TEST_CASE("midi: a stroke and its bounce, byte by byte", "[cli][midi]")
{
    // 60 bpm: 3840 ticks a second. The stroke at 0.5 s = tick 1920, the bounce
    // at 0.52 s = 1996.8 -> 1997, which also ends the stroke (the same note);
    // the bounce ends 0.1 s later, 2380.8 -> 2381.
    const std::vector<StrikeEvent> s = {strike(1, 0.5, 0.1, 1.0, false),
                                        strike(1, 0.52, 0.1, 0.1, true)};
    const std::string track =
        bytes({0x00, 0xff, 0x03, 0x05}) + "ictus" +
        bytes({0x00, 0xff, 0x58, 0x04, 0x04, 0x02, 0x18, 0x08}) +
        bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) + // 1 000 000 us a quarter
        bytes({0x8f, 0x00, 0x99, 52, 64}) +                 // +1920, note-on ch 10
        bytes({0x4d, 0x89, 52, 0x00}) +                     // +77, the stroke ends
        bytes({0x00, 0xff, 0x01, 0x06}) + "bounce" +        // flag, same tick
        bytes({0x00, 0x99, 52, 1}) +                        // the bounce
        bytes({0x83, 0x00, 0x89, 52, 0x00}) +               // +384, it ends
        bytes({0x00, 0xff, 0x2f, 0x00});
    const std::string want = std::string("MThd") + bytes({0, 0, 0, 6, 0, 0, 0, 1, 0x0f, 0x00}) +
                             "MTrk" + bytes({0, 0, 0, static_cast<int>(track.size())}) + track;
    CHECK(standard_midi_file(s, midi_timeline(60.0), 9) == want);
}

TEST_CASE("midi: a tempo change lands on a tick and later notes follow it", "[cli][midi]")
{
    // 60 bpm to 0.5 s (1920 ticks), then 120 bpm (7680 ticks a second): the
    // note at 1.0 s is 3840 ticks after the tempo change, and lasts 768.
    const std::vector<StrikeEvent> s = {strike(0, 1.0, 0.5, 1.0, false)};
    MidiTimeline two = midi_timeline(60.0);
    two.tempo.push_back({1920, midi_us_per_quarter(120.0)});
    const std::string f = standard_midi_file(s, two, 0);
    const std::string tail =
        bytes({0x8f, 0x00, 0xff, 0x51, 0x03, 0x07, 0xa1, 0x20}) + // +1920: 500 000 us
        bytes({0x9e, 0x00, 0x90, 49, 64}) +                       // +3840 = 0x1e00
        bytes({0x86, 0x00, 0x80, 49, 0x00}) +                     // +0.1 s = 768 ticks
        bytes({0x00, 0xff, 0x2f, 0x00});
    REQUIRE(f.size() > tail.size());
    CHECK(f.substr(f.size() - tail.size()) == tail);
    CHECK_THROWS(standard_midi_file(s, MidiTimeline{}, 0));
    CHECK_THROWS(standard_midi_file(s, midi_timeline(60.0), 16));
}

TEST_CASE("midi: with a kit each strike is its drum's General MIDI note", "[cli][midi]")
{
    // The right hand on the snare (drum 0: 38) at 0.5 s, then on tom1 (drum
    // 1: 48) at 0.52 s: two notes, so the snare's is not cut by the tom's and
    // lasts its 0.1 s (0.6 s = tick 2304); the tom's ends at 0.62 s = 2380.8
    // -> 2381. Without the kit both would be note 52 (hand 1, zone 0).
    std::vector<StrikeEvent> s = {strike(1, 0.5, 0.1, 1.0, false),
                                  strike(1, 0.52, 0.1, 1.0, false)};
    s[1].drum = 1;
    const std::vector<int> notes = {38, 48};
    const std::string track = bytes({0x00, 0xff, 0x03, 0x05}) + "ictus" +
                              bytes({0x00, 0xff, 0x58, 0x04, 0x04, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) +
                              bytes({0x8f, 0x00, 0x99, 38, 64}) + // +1920, the snare
                              bytes({0x4d, 0x99, 48, 64}) +       // +77, tom1
                              bytes({0x82, 0x33, 0x89, 38, 0}) +  // +307, the snare ends
                              bytes({0x4d, 0x89, 48, 0}) +        // +77, tom1 ends
                              bytes({0x00, 0xff, 0x2f, 0x00});
    const std::string want = std::string("MThd") + bytes({0, 0, 0, 6, 0, 0, 0, 1, 0x0f, 0x00}) +
                             "MTrk" + bytes({0, 0, 0, static_cast<int>(track.size())}) + track;
    CHECK(standard_midi_file(s, midi_timeline(60.0), 9, &notes) == want);
    CHECK(standard_midi_file(s, midi_timeline(60.0), 9) != want);
    // A strike on the snare's rim is the side stick (37), as --midi reads 37; a rim strike
    // on tom1 stays tom1's note. The same bytes but the first note's two 38s.
    s[0].zone = kZoneRim;
    std::string rim = want;
    for (size_t k = 0; k + 1 < rim.size(); ++k)
        if ((static_cast<unsigned char>(rim[k]) & 0xef) == 0x89 && rim[k + 1] == 38)
            rim[k + 1] = 37;
    REQUIRE(rim != want);
    CHECK(standard_midi_file(s, midi_timeline(60.0), 9, &notes) == rim);
    s[0].zone = kZoneHead;
    s[1].zone = kZoneRim;
    CHECK(standard_midi_file(s, midi_timeline(60.0), 9, &notes) == want);
}

TEST_CASE("midi: a hi-hat strike is 42 closed, 46 half or open, 44 the left foot's chick",
          "[cli][midi]")
{
    // Drum 0 a hi-hat (42): the right hand with the pedal closed, half, open, then the
    // left foot (the chick), each 0.2 s apart; the note-ons read back from the bytes.
    std::vector<StrikeEvent> s;
    const double openness[] = {0.0, 0.5, 1.0, 0.0};
    for (int i = 0; i < 4; ++i) {
        s.push_back(strike(i == 3 ? kFootLeft : 1, 0.5 + 0.2 * i, 0.1, 1.0, false));
        s.back().pedal_openness = openness[i];
    }
    const std::vector<int> notes = {42};
    const std::string f = standard_midi_file(s, midi_timeline(60.0), 9, &notes);
    std::vector<int> on;
    for (size_t k = 0; k + 2 < f.size(); ++k)
        if (static_cast<unsigned char>(f[k]) == 0x99 && f[k + 2] != 0)
            on.push_back(f[k + 1]);
    CHECK(on == std::vector<int>{42, 46, 46, 44});
}

TEST_CASE("midi: the score's meters as time signatures, 4/4 without one", "[cli][midi]")
{
    // 60 bpm, 3840 ticks a second. 6/8 from 0 s replaces the 4/4 (FF 58 04
    // 06 03 18 08: 6, 2^3, 24 clocks a click, 8 32nds a quarter), 3/4 at 0.5 s
    // at tick 1920 (FF 58 04 03 02 18 08), after the tempo at tick 0.
    const std::vector<StrikeEvent> none;
    const std::string head = bytes({0x00, 0xff, 0x03, 0x05}) + "ictus";
    MidiTimeline t = midi_timeline(60.0);
    t.meter = {{0, 6, 8}, {1920, 3, 4}};
    const std::string f = standard_midi_file(none, t, 0);
    const std::string track = head + bytes({0x00, 0xff, 0x58, 0x04, 0x06, 0x03, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) +
                              bytes({0x8f, 0x00, 0xff, 0x58, 0x04, 0x03, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x2f, 0x00});
    CHECK(f.substr(22) == track);
    // A first meter after 0 s: 4/4 at tick 0, then 5/4 at tick 960 (0x87 0x40).
    t.meter = {{960, 5, 4}};
    const std::string g = standard_midi_file(none, t, 0);
    CHECK(g.substr(22) == head + bytes({0x00, 0xff, 0x58, 0x04, 0x04, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) +
                              bytes({0x87, 0x40, 0xff, 0x58, 0x04, 0x05, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x2f, 0x00}));
    t.meter = {{0, 3, 6}};
    CHECK_THROWS(standard_midi_file(none, t, 0));
}

namespace
{
// The time of `tick` through a timeline's tempo events, as a reader computes it.
double seconds_at(const MidiTimeline &t, long tick)
{
    double s = 0.0;
    for (size_t i = 0; i < t.tempo.size(); ++i) {
        const long from = t.tempo[i].tick;
        const long to = i + 1 < t.tempo.size() ? std::min(tick, t.tempo[i + 1].tick) : tick;
        if (to > from)
            s += static_cast<double>(to - from) / 3840.0 * t.tempo[i].us_per_quarter * 1e-6;
    }
    return s;
}
} // namespace

TEST_CASE("midi: a score's beat 0 on a bar line after a pickup bar of its meter", "[cli][midi]")
{
    // meter 3/4 at 100 bpm: a bar is 3 quarters = 11520 ticks = 1.8 s, so
    // with beat 0 at 1.0 s (the lead-in) tick 0 is at 1.0 - 1.8 = -0.8 s.
    const Score score = parse_score("meter 3/4, tempo 100, R 1/4", "t");
    const MidiTimeline t = midi_timeline(score.tempo, score.meters, 1.0, 1.0);
    CHECK(t.first_beat_tick == 11520);
    CHECK(t.start_s == Approx(-0.8).margin(1e-12));
    REQUIRE(t.tempo.size() >= 1);
    CHECK(t.tempo.front().tick == 0);
    CHECK(t.tempo.front().us_per_quarter == 600000);
    REQUIRE(t.meter.size() == 1);
    CHECK((t.meter[0].tick == 0 && t.meter[0].numerator == 3 && t.meter[0].denominator == 4));
    // A strike 1.5 bars before beat 0 (2.7 s) needs two pickup bars.
    const MidiTimeline u = midi_timeline(score.tempo, score.meters, 3.0, 3.0 - 2.7);
    CHECK(u.first_beat_tick == 2 * 11520);
    CHECK(u.start_s == Approx(3.0 - 3.6).margin(1e-12));
    // No meter: a 4/4 pickup (4 quarters at 120 bpm = 2 s).
    const Score plain = parse_score("R", "t");
    const MidiTimeline v = midi_timeline(plain.tempo, plain.meters, 1.0, 1.0);
    CHECK(v.first_beat_tick == 4 * 3840);
    REQUIRE(v.meter.size() == 1);
    CHECK((v.meter[0].numerator == 4 && v.meter[0].denominator == 4));
    // A later meter at its beat: 6/8 at beat 3 = tick 11520 + 11520.
    const Score two = parse_score("meter 3/4, tempo 100, R, R, R, meter 6/8, R", "t");
    const MidiTimeline w = midi_timeline(two.tempo, two.meters, 1.0, 1.0);
    REQUIRE(w.meter.size() == 2);
    CHECK((w.meter[1].tick == 23040 && w.meter[1].numerator == 6 && w.meter[1].denominator == 8));
}

TEST_CASE("midi: tempo changes and ramps on the score's beats", "[cli][midi]")
{
    // tempo 60, 2 beats, then 60 -> 120 over 4 beats, then held. A ramp
    // T(b) = 60 + 15 b (bpm, b from its start) takes t = (60 / 15) ln(T / 60)
    // s to reach b; its end (b = 4): 4 ln 2 = 2.7726 s.
    const Score score = parse_score("tempo 60, R, R, tempo 60 -> 120 over 4, R beats 4, R", "t");
    const MidiTimeline t = midi_timeline(score.tempo, score.meters, 1.0, 1.0);
    const long b0 = t.first_beat_tick;
    CHECK(b0 == 4 * 3840);
    CHECK(seconds_at(t, b0) == Approx(4.0).margin(1e-9)); // a 4/4 bar at 60 bpm
    double worst = 0.0;
    for (long k = 0; k <= 4 * 16; ++k) { // every 1/16 beat through the ramp
        const double b = k / 16.0;
        const double want = 2.0 + 4.0 * std::log((60.0 + 15.0 * b) / 60.0);
        worst = std::max(worst, std::abs(seconds_at(t, b0 + 2 * 3840 + k * 240) - 4.0 - want));
    }
    CHECK(worst < 1e-6);
    // Within a step the file's time is linear in ticks: half way, off by at
    // most h^2 / 8 |t''| (linear interpolation), h = 1/16 beat, t'' = -60 k /
    // T^2 = -0.25 s per beat^2 at the ramp's start: 122 us.
    const double mid = 2.0 + 4.0 * std::log((60.0 + 15.0 * (1.0 / 32.0)) / 60.0);
    CHECK(std::abs(seconds_at(t, b0 + 2 * 3840 + 120) - 4.0 - mid) <
          (1.0 / 256.0) / 8.0 * 0.25 + 1e-6);
    // After the ramp: 120 bpm, 500 000 us a quarter.
    CHECK(t.tempo.back().us_per_quarter == 500000);
    CHECK(seconds_at(t, b0 + 7 * 3840) - 4.0 ==
          Approx(2.0 + 4.0 * std::log(2.0) + 0.5).margin(1e-6));
}

TEST_CASE("midi: a strike keeps its real time on the score's grid", "[cli][midi]")
{
    // 100 bpm 3/4: tick 0 at -0.8 s; a strike at 1.15 s is 1.95 s after tick
    // 0 = 3.25 quarters = 12480 ticks; one 2 ms late at 1.152 s is 12.8 ticks later.
    const Score score = parse_score("meter 3/4, tempo 100, R 1/4", "t");
    const MidiTimeline t = midi_timeline(score.tempo, score.meters, 1.0, 1.0);
    const std::vector<StrikeEvent> s = {strike(1, 1.15, 0.1, 1.0, false)};
    const std::vector<StrikeEvent> late = {strike(1, 1.152, 0.1, 1.0, false)};
    const std::string head = bytes({0x00, 0xff, 0x03, 0x05}) + "ictus" +
                             bytes({0x00, 0xff, 0x58, 0x04, 0x03, 0x02, 0x18, 0x08}) +
                             bytes({0x00, 0xff, 0x51, 0x03, 0x09, 0x27, 0xc0}); // 600 000
    CHECK(standard_midi_file(s, t, 0).substr(22, head.size() + 3) ==
          head + bytes({0xe1, 0x40, 0x90})); // +12480 = 0x30c0
    CHECK(standard_midi_file(late, t, 0).substr(22, head.size() + 3) ==
          head + bytes({0xe1, 0x4d, 0x90})); // +12493
}
