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
    CHECK(standard_midi_file(s, {{0.0, 60.0}}, 9) == want);
}

TEST_CASE("midi: a tempo change lands on a tick and later notes follow it", "[cli][midi]")
{
    // 60 bpm to 0.5 s (1920 ticks), then 120 bpm (7680 ticks a second): the
    // note at 1.0 s is 3840 ticks after the tempo change, and lasts 768.
    const std::vector<StrikeEvent> s = {strike(0, 1.0, 0.5, 1.0, false)};
    const std::string f = standard_midi_file(s, {{0.0, 60.0}, {0.5, 120.0}}, 0);
    const std::string tail =
        bytes({0x8f, 0x00, 0xff, 0x51, 0x03, 0x07, 0xa1, 0x20}) + // +1920: 500 000 us
        bytes({0x9e, 0x00, 0x90, 49, 64}) +                       // +3840 = 0x1e00
        bytes({0x86, 0x00, 0x80, 49, 0x00}) +                     // +0.1 s = 768 ticks
        bytes({0x00, 0xff, 0x2f, 0x00});
    REQUIRE(f.size() > tail.size());
    CHECK(f.substr(f.size() - tail.size()) == tail);
    CHECK_THROWS(standard_midi_file(s, {}, 0));
    CHECK_THROWS(standard_midi_file(s, {{0.0, 60.0}}, 16));
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
    CHECK(standard_midi_file(s, {{0.0, 60.0}}, 9, &notes) == want);
    CHECK(standard_midi_file(s, {{0.0, 60.0}}, 9) != want);
}

TEST_CASE("midi: the score's meters as time signatures, 4/4 without one", "[cli][midi]")
{
    // 60 bpm, 3840 ticks a second. 6/8 from 0 s replaces the 4/4 (FF 58 04
    // 06 03 18 08: 6, 2^3, 24 clocks a click, 8 32nds a quarter), 3/4 at 0.5 s
    // = tick 1920 (FF 58 04 03 02 18 08), after the tempo at tick 0.
    const std::vector<StrikeEvent> none;
    const std::string head = bytes({0x00, 0xff, 0x03, 0x05}) + "ictus";
    const std::string f = standard_midi_file(none, {{0.0, 60.0}}, 0, nullptr, {{0.0, 6, 8}, {0.5, 3, 4}});
    const std::string track = head + bytes({0x00, 0xff, 0x58, 0x04, 0x06, 0x03, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) +
                              bytes({0x8f, 0x00, 0xff, 0x58, 0x04, 0x03, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x2f, 0x00});
    CHECK(f.substr(22) == track);
    // A first meter after 0 s: 4/4 at tick 0, then 5/4 at 0.25 s = tick 960 (0x87 0x40).
    const std::string g = standard_midi_file(none, {{0.0, 60.0}}, 0, nullptr, {{0.25, 5, 4}});
    CHECK(g.substr(22) == head + bytes({0x00, 0xff, 0x58, 0x04, 0x04, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x51, 0x03, 0x0f, 0x42, 0x40}) +
                              bytes({0x87, 0x40, 0xff, 0x58, 0x04, 0x05, 0x02, 0x18, 0x08}) +
                              bytes({0x00, 0xff, 0x2f, 0x00}));
    CHECK_THROWS(standard_midi_file(none, {{0.0, 60.0}}, 0, nullptr, {{0.0, 3, 6}}));
}
