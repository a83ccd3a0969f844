// A Standard MIDI File's drum part as a score (score/midi_score.hpp,
// docs/midi.md "MIDI in"): files written here byte by byte from the SMF 1.0
// format, read back, and their drum part checked against the General MIDI
// map, the hand rule and the tempo map computed by hand.
#include "ictus/score/midi_score.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

using namespace ictus;

namespace
{
std::string bytes(std::initializer_list<int> v)
{
    std::string s;
    for (int b : v)
        s += static_cast<char>(b);
    return s;
}
std::string chunk(const std::string &type, const std::string &data)
{
    const size_t n = data.size();
    return type +
           bytes({static_cast<int>(n >> 24), static_cast<int>((n >> 16) & 0xff),
                  static_cast<int>((n >> 8) & 0xff), static_cast<int>(n & 0xff)}) +
           data;
}
// MThd: format, tracks, 96 ticks a quarter.
std::string header(int format, int tracks, int division = 96)
{
    return chunk("MThd", bytes({0, format, 0, tracks, division >> 8, division & 0xff}));
}
const std::string kEnd = bytes({0x00, 0xff, 0x2f, 0x00});

// A format-0 file of one track at `bpm`, 96 ticks a quarter, notes on channel 10 in tick
// order (deltas under 128 ticks).
struct Track {
    std::string events;
    int last = 0;
    explicit Track(double bpm)
    {
        const int us = static_cast<int>(std::lround(60e6 / bpm));
        events = bytes({0x00, 0xff, 0x51, 0x03, us >> 16, (us >> 8) & 0xff, us & 0xff});
    }
    void at(int tick, int note, int velocity)
    {
        events += bytes({tick - last, 0x99, note, velocity});
        last = tick;
    }
    std::string file() const { return header(0, 1) + chunk("MTrk", events + kEnd); }
};

// No hand of a part at a steady `bpm` strikes twice within kMidiSameHandMin_s.
void check_hands_apart(const MidiDrumPart &p, double bpm)
{
    for (Side h : {Side::left, Side::right}) {
        double last = -1.0;
        for (const ScoreNote &n : p.score.notes)
            if (n.hand == h && !n.foot) {
                if (last >= 0.0)
                    CHECK((n.beat - last) * 60.0 / bpm >= kMidiSameHandMin_s);
                last = n.beat;
            }
    }
}

std::string what_of(const std::string &file)
{
    try {
        read_smf(file, "t.mid");
    } catch (const MidiFileError &e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST_CASE("midi in: a file read event by event", "[score][midi]")
{
    // Track 0: tempo 500 000 us (120 bpm) at 0, 3/4 at 0, 750 000 us (80
    // bpm) at tick 192 (beat 2). Track 1: a sysex, then on channel 10 a
    // snare at 0 (v 100), with running status a note-on of velocity 0 (a
    // note-off) at 48 and a tom 45 at 96 (v 64), a program change (one data
    // byte), and a kick 36 at tick 0x81 0x00 = 128 later (224).
    const std::string t0 = bytes({0x00, 0xff, 0x51, 0x03, 0x07, 0xa1, 0x20}) +
                           bytes({0x00, 0xff, 0x58, 0x04, 0x03, 0x02, 0x18, 0x08}) +
                           bytes({0x81, 0x40, 0xff, 0x51, 0x03, 0x0b, 0x71, 0xb0}) + kEnd;
    const std::string t1 = bytes({0x00, 0xf0, 0x02, 0x7e, 0xf7}) +
                           bytes({0x00, 0x99, 38, 100, 0x30, 38, 0, 0x30, 45, 64}) +
                           bytes({0x00, 0xc9, 5}) + bytes({0x81, 0x00, 0x99, 36, 90}) + kEnd;
    const Smf smf = read_smf(
        header(1, 2) + chunk("MTrk", t0) + chunk("XXXX", "ab") + chunk("MTrk", t1), "t.mid");
    CHECK(smf.format == 1);
    CHECK(smf.ticks_per_quarter == 96);
    REQUIRE(smf.notes.size() == 3);
    CHECK((smf.notes[0].tick == 0 && smf.notes[0].note == 38 && smf.notes[0].velocity == 100 &&
           smf.notes[0].channel == 9 && smf.notes[0].track == 1));
    CHECK((smf.notes[1].tick == 96 && smf.notes[1].note == 45 && smf.notes[1].velocity == 64));
    CHECK((smf.notes[2].tick == 224 && smf.notes[2].note == 36));
    REQUIRE(smf.tempo.size() == 2);
    CHECK((smf.tempo[0].tick == 0 && smf.tempo[0].us_per_quarter == 500000));
    CHECK((smf.tempo[1].tick == 192 && smf.tempo[1].us_per_quarter == 750000));
    REQUIRE(smf.meters.size() == 1);
    CHECK((smf.meters[0].numerator == 3 && smf.meters[0].denominator == 4));

    // The drum part on a kit: the snare on the snare, 45 on tom2 (47 and 43
    // are both 2 away: the kit's first), the kick left out. Times: 120 bpm
    // to beat 2 (1 s), 80 bpm after: the kick's beat 224/96 would be at
    // 1 + (1/3) x 0.75 s.
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47}, {"floor", 43}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    CHECK(part.channel == 9);
    REQUIRE(part.score.notes.size() == 2);
    CHECK(part.score.notes[0].drum == "snare");
    CHECK(part.score.notes[1].drum == "tom2");
    CHECK(part.score.notes[0].dynamics == Approx(100.0 / 127.0));
    CHECK(part.score.notes[1].beat == Approx(1.0));
    CHECK(part.skipped.at(36) == 1);
    CHECK(part.score.tempo.time_at_beat(224.0 / 96.0) == Approx(1.0 + 0.75 / 3.0));
    REQUIRE(part.score.meters.size() == 1);
    CHECK(part.score.meters[0].numerator == 3);
    // 0.5 s apart: both right (the lead hand).
    CHECK(part.score.notes[0].hand == Side::right);
    CHECK(part.score.notes[1].hand == Side::right);
    // The one drum: the snare and the tom both on it.
    const MidiDrumPart one = drum_part_score(smf, {}, "t.mid");
    REQUIRE(one.score.notes.size() == 2);
    CHECK((one.score.notes[0].drum.empty() && one.score.notes[1].drum.empty()));
}

TEST_CASE("midi in: hands as a drummer's, the drum channel, the GM toms", "[score][midi]")
{
    // 120 bpm (the default), 96 ticks a quarter = 0.5 s: 16ths (24 ticks,
    // 0.125 s) alternate R L R; a note 0.5 s later goes back to R; two at one
    // tick: R then L; a third at that tick: no hand (too_fast). Channel 1
    // notes are not read while channel 10 has notes.
    std::string t = bytes({0x00, 0x99, 38, 10, 0x18, 38, 20, 0x18, 38, 30}) + // R L R
                    bytes({0x00, 0x90, 38, 40}) +                             // channel 1
                    bytes({0x60, 0x99, 50, 127, 0x00, 41, 1, 0x00, 48, 9}) + kEnd;
    const Smf smf = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47}, {"floor", 43}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    REQUIRE(part.score.notes.size() == 5);
    const Side R = Side::right, L = Side::left;
    const Side want[5] = {R, L, R, R, L};
    for (int i = 0; i < 5; ++i)
        CHECK(part.score.notes[static_cast<size_t>(i)].hand == want[i]);
    CHECK(part.score.notes[3].drum == "tom1");  // 50 -> the nearest, 48
    CHECK(part.score.notes[4].drum == "floor"); // 41 -> 43
    CHECK(part.too_fast == 1);
    CHECK(part.other_channels == 1); // the channel 1 note, counted
    CHECK(part.score.notes[3].dynamics == Approx(1.0));
    // No channel 10: every channel is read.
    const std::string t1 = bytes({0x00, 0x90, 38, 40, 0x18, 0x91, 40, 50}) + kEnd;
    const MidiDrumPart any =
        drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t1), "t.mid"), kit, "t.mid");
    CHECK(any.channel == -1);
    CHECK(any.score.notes.size() == 2);
    CHECK(any.other_channels == 0);
}

TEST_CASE("midi in: General MIDI's cymbals on a kit's crash and ride", "[score][midi]")
{
    // Half a second apart (96 ticks at 96 a quarter, 120 bpm: each the right
    // hand's): crash 49, crash 2 57, ride 51, ride 2 59, ride bell 53, hi-hat
    // 42 (no hi-hat in the kit).
    std::string t;
    for (int note : {49, 57, 51, 59, 53, 42})
        t += bytes({0x60, 0x99, note, 100});
    t += kEnd;
    const Smf smf = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48},  {"tom2", 47},
                                       {"floor", 43}, {"crash", 49}, {"ride", 51}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    REQUIRE(part.score.notes.size() == 5);
    const char *want[5] = {"crash", "crash", "ride", "ride", "ride"};
    for (size_t i = 0; i < 5; ++i) {
        INFO(i);
        CHECK(part.score.notes[i].drum == want[i]);
        // No spot but the bell's: the planner plays a cymbal's own (kCymbal*).
        CHECK(part.score.notes[i].spot_given == (i == 4));
    }
    CHECK(part.score.notes[4].r_over_a == Approx(kMidiRideBellRadiusFraction));
    CHECK(part.score.notes[4].theta_deg == Approx(kCymbalThetaDeg[1])); // toward the performer
    CHECK(part.skipped.at(42) == 1);
    // The crash's notes are the left hand's (on its side of the kit), the
    // ride's the right's.
    for (size_t i = 0; i < 5; ++i)
        CHECK(part.score.notes[i].hand == (i < 2 ? Side::left : Side::right));
    // After a fill of 16ths ending on the left hand (125 ms apart), the crash
    // is still the left's; a snare on the crash's tick, written before it,
    // is the right's.
    std::string fill;
    for (int k = 0; k < 4; ++k)
        fill += bytes({k == 0 ? 0 : 24, 0x99, 48, 100});
    fill += bytes({24, 0x99, 38, 100}) + bytes({0, 0x99, 49, 120}) + kEnd;
    const MidiDrumPart f =
        drum_part_score(read_smf(header(0, 1) + chunk("MTrk", fill), "f.mid"), kit, "f.mid");
    REQUIRE(f.score.notes.size() == 6);
    CHECK(f.score.notes[3].hand == Side::left); // the fill: R L R L
    CHECK(f.score.notes[4].drum == "crash");
    CHECK(f.score.notes[4].hand == Side::left);
    CHECK(f.score.notes[5].drum == "snare");
    CHECK(f.score.notes[5].hand == Side::right);
    // Without cymbals in the kit (or without a kit) every cymbal note is left out, counted.
    const std::vector<MidiDrum> drums = {{"snare", 38}, {"tom1", 48}};
    t = bytes({0x00, 0x99, 38, 100}) + t;
    const Smf with_snare = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    for (const std::vector<MidiDrum> &k : {drums, std::vector<MidiDrum>{}}) {
        const MidiDrumPart none = drum_part_score(with_snare, k, "t.mid");
        REQUIRE(none.score.notes.size() == 1);
        CHECK(none.skipped.at(49) == 1);
        CHECK(none.skipped.at(53) == 1);
    }
}

TEST_CASE("midi in: a malformed file names its byte and track", "[score][midi]")
{
    CHECK(what_of("RIFF....") == "t.mid: byte 0: not a Standard MIDI File (no MThd header)");
    CHECK(what_of(header(2, 1)) == "t.mid: byte 8: format 2 (0 and 1 are read)");
    CHECK(what_of(header(0, 1, 0xe728)) ==
          "t.mid: byte 12: SMPTE time division (ticks per quarter note are read)");
    CHECK(what_of(header(0, 1)) == "t.mid: byte 14: no track (MTrk chunk)");
    // Track data starts at byte 22 (14 header + 8 chunk header).
    CHECK(what_of(header(0, 1) + chunk("MTrk", bytes({0x00, 0x99, 38}))) ==
          "t.mid: byte 25 (track 0): unexpected end of track");
    CHECK(what_of(header(0, 1) + chunk("MTrk", bytes({0x00, 38, 10}))) ==
          "t.mid: byte 23 (track 0): data byte with no running status");
    CHECK(what_of(header(0, 1) + chunk("MTrk", kEnd) +
                  chunk("MTrk", bytes({0xff, 0xff, 0xff, 0xff, 0x7f}))) ==
          "t.mid: byte 34 (track 1): variable-length number longer than 4 bytes");
    CHECK(what_of(header(0, 1) + chunk("MTrk", bytes({0x00, 0xff, 0x01, 0x10, 'a'}))) ==
          "t.mid: byte 26 (track 0): length 16 runs past the end of the track");
    CHECK(what_of(header(0, 1) + chunk("MTrk", bytes({0x00, 0x99, 0x90, 1}))) ==
          "t.mid: byte 24 (track 0): data byte expected, got status byte 144");
    CHECK(what_of(header(0, 1) + "MTrk" + bytes({0, 0, 1, 0})) ==
          "t.mid: byte 18: chunk length 256 runs past the end of the file");
    CHECK(what_of(header(0, 1).substr(0, 10)) ==
          "t.mid: byte 0: truncated header (10 bytes, 14 needed)");
    // Fewer than 8 bytes after every declared track: padding, read past; before the
    // declared tracks are all there: a truncated chunk header.
    const std::string one = header(0, 1) + chunk("MTrk", bytes({0x00, 0x99, 38, 100}) + kEnd);
    CHECK(what_of(one + bytes({0, 0, 0})) == "");
    CHECK(read_smf(one + bytes({0, 0, 0}), "t.mid").notes.size() == 1);
    CHECK(what_of(header(1, 2) + chunk("MTrk", kEnd) + "MTr") ==
          "t.mid: byte 26: truncated chunk header");
    // A file that ends where a chunk ends, before the declared tracks are all there: cut
    // short (mido refuses it too), not its first tracks played alone. Seeded files of 2..5
    // tracks of 1..4 notes each, cut after each of their chunks but the last.
    CHECK(what_of(header(1, 2) + chunk("MTrk", kEnd)) ==
          "t.mid: byte 26: the file ends after 1 of the 2 tracks its header declares (cut "
          "short?)");
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 12; ++trial) {
        const int tracks = 2 + static_cast<int>(rng() % 4);
        std::string file = header(1, tracks);
        for (int k = 0; k < tracks; ++k) {
            std::string events;
            for (int n = 0, count = 1 + static_cast<int>(rng() % 4); n < count; ++n)
                events += bytes({0x10, 0x99, 38, 100});
            file += chunk("MTrk", events + kEnd);
            INFO("trial " << trial << ": cut after track " << k << " of " << tracks);
            if (k + 1 < tracks)
                CHECK(what_of(file) == "t.mid: byte " + std::to_string(file.size()) +
                                           ": the file ends after " + std::to_string(k + 1) +
                                           " of the " + std::to_string(tracks) +
                                           " tracks its header declares (cut short?)");
            else
                CHECK(what_of(file).empty());
        }
    }
}

// A note past the score's 100000 beats was refused as "note 2 at beat 268435455.000000, past
// the score's 100000.000000". Seeded files: a snare at 0, a second one at a tick past the
// limit (whole or half beats, 2..2000 ticks a quarter); the beat said as written, the limit
// named as one.
TEST_CASE("midi in: a note past the score's beats is refused, its place and beat said plainly",
          "[score][midi]")
{
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 16; ++trial) {
        // Even (half a beat is whole) and at most 2000: the tick within a delta's 4 bytes.
        const int tpq = 2 * (1 + static_cast<int>(rng() % 1000));
        const long room = 0x0fffffffL / tpq - 1 - 100001;
        const long beats = 100001 + static_cast<long>(rng() % static_cast<unsigned long>(room));
        const bool half = trial % 2 == 1;
        const long tick = beats * tpq + (half ? tpq / 2 : 0);
        std::string delta;
        for (long v = tick, first = 1; first || v > 0; v >>= 7, first = 0)
            delta.insert(delta.begin(), static_cast<char>((v & 0x7f) | (first ? 0 : 0x80)));
        const std::string events = bytes({0x00, 0x99, 38, 100}) + delta + bytes({0x99, 38, 90});
        const std::string file = header(0, 1, tpq) + chunk("MTrk", events + kEnd);
        const std::string beat = std::to_string(beats) + (half ? ".5" : "");
        INFO("trial " << trial << ": " << tpq << " ticks a quarter, tick " << tick);
        std::string what;
        try {
            drum_part_score(read_smf(file, "t.mid"), {}, "t.mid");
        } catch (const MidiFileError &e) {
            what = e.what();
        }
        CHECK(what == "t.mid: note 2 at beat " + beat +
                          " is past the score's limit of 100000 beats (docs/score.md)");
    }
}

TEST_CASE("midi in: General MIDI's hi-hat on a kit's hi-hat, closed 42 and open 46, the pedal 44 "
          "the left foot's chick",
          "[score][midi][hihat]")
{
    // Half a second apart (the right hand's): closed 42, open 46, pedal 44, closed 42; then
    // two pedals 10 ticks (52 ms) apart: the second left out (faster than the left foot).
    std::string t;
    for (int note : {42, 46, 44, 42, 44})
        t += bytes({0x60, 0x99, note, 100});
    t += bytes({0x0a, 0x99, 44, 100});
    t += kEnd;
    const Smf smf = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47}, {"floor", 43},
                                       {"crash", 49}, {"ride", 51}, {"hihat", 42}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    REQUIRE(part.score.notes.size() == 5);
    const double want[5] = {kHihatClosed, kHihatOpen, -1.0, kHihatClosed, -1.0};
    const double beat[5] = {1.0, 2.0, 3.0, 4.0, 5.0};
    for (size_t i = 0; i < 5; ++i) {
        INFO(i);
        const ScoreNote &n = part.score.notes[i];
        CHECK(n.drum == "hihat");
        CHECK(n.beat == Approx(beat[i]));
        const bool chick = i == 2 || i == 4;
        CHECK(n.foot == chick); // 44: the left foot's
        if (chick) {
            CHECK(n.hand == Side::left);
            CHECK(n.openness < 0.0); // the chick closes the pedal; the note carries none
        } else {
            CHECK(n.hand == Side::right);
            CHECK(n.openness == want[i]);
            CHECK_FALSE(n.spot_given); // the cymbal's own spot
        }
    }
    CHECK(part.skipped.empty());
    CHECK(part.too_fast == 0); // the chick too soon is the foot's, not a hand's
    CHECK(part.feet_too_fast == 1);
    // A kit without a hi-hat, and no kit: 42, 46 and 44 left out, counted.
    const std::vector<MidiDrum> cymbals(kit.begin(), kit.end() - 1);
    for (const std::vector<MidiDrum> &k : {cymbals, std::vector<MidiDrum>{}}) {
        const MidiDrumPart none = drum_part_score(smf, k, "t.mid");
        CHECK(none.score.notes.empty());
        CHECK(none.skipped.at(42) == 2);
        CHECK(none.skipped.at(46) == 1);
        CHECK(none.skipped.at(44) == 3);
    }
}

TEST_CASE("midi in: a closed and an open hi-hat on one tick are one open note (one pedal)",
          "[score][midi][hihat]")
{
    // Quarters at 120 bpm: 42 then 46 on a tick, 46 then 42, 42 alone, 42 with the snare,
    // 46 with 42 on channel 1 (not the drum part's).
    std::string t;
    for (int pair : {0, 1, 2, 3, 4}) {
        const int first = pair == 1 ? 46 : 42;
        t += bytes({pair == 0 ? 0 : 96, 0x99, first, 90});
        if (pair < 2)
            t += bytes({0, 0x99, first == 42 ? 46 : 42, 70});
        else if (pair == 3)
            t += bytes({0, 0x99, 38, 70});
        else if (pair == 4)
            t += bytes({0, 0x90, 46, 70});
    }
    t += kEnd;
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"crash", 49}, {"hihat", 42}};
    const MidiDrumPart part =
        drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t), "t.mid"), kit, "t.mid");
    CHECK(part.hihats_opened == 2);
    CHECK(part.other_channels == 1);
    CHECK(part.too_fast == 0);
    // Each note as (beat, drum and pedal word), in any order on a tick.
    std::vector<std::pair<double, std::string>> got;
    for (const ScoreNote &n : part.score.notes)
        got.push_back({n.beat, n.drum + " " + hihat_openness_word(n.openness)});
    std::sort(got.begin(), got.end());
    const std::vector<std::pair<double, std::string>> want = {
        {0.0, "hihat open"},   {1.0, "hihat open"}, {2.0, "hihat closed"},
        {3.0, "hihat closed"}, {3.0, "snare "},     {4.0, "hihat closed"}};
    CHECK(got == want);
}

TEST_CASE("midi in: General MIDI's bass drums 35 and 36 on a kit's kick, the right foot's",
          "[score][midi][kick]")
{
    // 96 ticks a quarter at 120 bpm: a kick 36 with a snare on the same
    // tick, a kick 35 half a second later, one 10 ticks (52 ms) after it
    // (faster than the pedal: left out, counted), one 12 ticks after that
    // (115 ms after the last one played), then a snare.
    std::string t = bytes({0x00, 0x99, 36, 127, 0x00, 0x99, 38, 100, 0x60, 0x99, 35, 64,
                           0x0a, 0x99, 36, 90,  0x0c, 0x99, 36, 90,  0x60, 0x99, 38, 100});
    t += kEnd;
    const Smf smf = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47},  {"floor", 43},
                                       {"crash", 49}, {"ride", 51}, {"hihat", 42}, {"kick", 36}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    REQUIRE(part.score.notes.size() == 5);
    std::vector<const ScoreNote *> feet, hands;
    for (const ScoreNote &n : part.score.notes)
        (n.foot ? feet : hands).push_back(&n);
    REQUIRE(feet.size() == 3);
    REQUIRE(hands.size() == 2);
    const double beat[3] = {0.0, 1.0, (96.0 + 22.0) / 96.0};
    const double vel[3] = {127.0, 64.0, 90.0};
    for (size_t i = 0; i < 3; ++i) {
        INFO(i);
        CHECK(feet[i]->drum == "kick");
        CHECK(feet[i]->hand == Side::right);
        CHECK(feet[i]->beat == Approx(beat[i]));
        CHECK(feet[i]->dynamics == Approx(vel[i] / 127.0));
    }
    // The snare on the kick's tick is the right hand's: the foot takes no hand.
    CHECK((hands[0]->drum == "snare" && hands[0]->hand == Side::right && hands[0]->beat == 0.0));
    CHECK(part.too_fast == 0);
    CHECK(part.feet_too_fast == 1); // the kick 52 ms after the last
    CHECK(part.skipped.empty());
    // Without a kick in the kit, and without a kit, 35 and 36 are left out, counted.
    const std::vector<MidiDrum> no_kick(kit.begin(), kit.end() - 1);
    for (const std::vector<MidiDrum> &k : {no_kick, std::vector<MidiDrum>{}}) {
        const MidiDrumPart none = drum_part_score(smf, k, "t.mid");
        CHECK(none.score.notes.size() == 2);
        CHECK(none.skipped.at(36) == 3);
        CHECK(none.skipped.at(35) == 1);
    }
}

TEST_CASE("midi in: the right hand keeps time on the hi-hat and the ride, the left plays under it",
          "[score][midi][hihat]")
{
    // Two bars at 120 bpm (96 ticks a quarter): 8th-note closed hi-hats, the snare on 2 and 4
    // written before the hi-hat of its tick, then a bar of 8th-note ride with a tom on each
    // beat. A drummer: every hi-hat and ride note the right hand's, the snare and the toms
    // the left's (crossed over the hi-hat).
    std::string t;
    int delta = 0;
    for (int eighth = 0; eighth < 16; ++eighth) {
        if (eighth % 4 == 2) {
            t += bytes({delta, 0x99, 38, 100});
            delta = 0;
        }
        t += bytes({delta, 0x99, 42, 90});
        delta = 48;
    }
    for (int eighth = 0; eighth < 8; ++eighth) {
        if (eighth % 2 == 0) {
            t += bytes({delta, 0x99, 45, 100});
            delta = 0;
        }
        t += bytes({delta, 0x99, 51, 90});
        delta = 48;
    }
    t += kEnd;
    const Smf smf = read_smf(header(0, 1) + chunk("MTrk", t), "t.mid");
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47}, {"floor", 43},
                                       {"crash", 49}, {"ride", 51}, {"hihat", 42}};
    const MidiDrumPart part = drum_part_score(smf, kit, "t.mid");
    REQUIRE(part.score.notes.size() == 16 + 4 + 8 + 4);
    CHECK(part.too_fast == 0);
    for (const ScoreNote &n : part.score.notes) {
        INFO(n.drum << " at beat " << n.beat << ", note line " << n.line);
        const bool keeps_time = n.drum == "hihat" || n.drum == "ride";
        CHECK(n.hand == (keeps_time ? Side::right : Side::left));
    }
    // Each note keeps its line in the file (the snare before the hi-hat of its tick).
    CHECK(part.score.notes[2].drum == "hihat");
    CHECK(part.score.notes[3].drum == "snare");
    CHECK(part.score.notes[3].line + 1 == part.score.notes[2].line);
}

TEST_CASE("midi in: the ride and the hi-hat on one tick, the ride the right hand's",
          "[score][midi][hihat]")
{
    // Quarters at 120 bpm (96 ticks a quarter): the ride with the closed or the open hi-hat or
    // the bell with the hi-hat on each, the hi-hat written first. The ride stands on the
    // right, the hi-hat on the left: the right hand on the ride, the left on the hi-hat
    // (uncrossed), whichever is written first.
    std::string t;
    int delta = 0;
    for (int ride : {51, 59, 53, 51})
        for (int hat : {42, 46}) {
            t += bytes({delta, 0x99, hat, 80}) + bytes({0, 0x99, ride, 90});
            delta = 96;
        }
    t += kEnd;
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"crash", 49}, {"ride", 51}, {"hihat", 42}};
    const MidiDrumPart part =
        drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t), "t.mid"), kit, "t.mid");
    REQUIRE(part.score.notes.size() == 16);
    for (const ScoreNote &n : part.score.notes) {
        INFO(n.drum << " at beat " << n.beat);
        CHECK(n.hand == (n.drum == "ride" ? Side::right : Side::left));
    }
}

TEST_CASE("midi in: a run of alternating strokes starts on the hand that leaves each the most time",
          "[score][midi]")
{
    // The full kit's places (m: right, up, forward); 96 ticks a quarter at 120 bpm, a 16th
    // (24 ticks) 125 ms. Four 16ths on tom1 after a rest, then the crash (the left hand's) a
    // 16th after the last: R L R L leaves the left 125 ms for tom1 -> crash, 0.497 m (plus a
    // stroke's 0.1 m: 4.8 m/s); L R L R leaves it 250 ms (2.4 m/s) and the right nothing to
    // reach: the run starts on the left.
    std::vector<MidiDrum> kit = {{"snare", 38, true, {0.0, 0.0, 0.0}},
                                 {"tom1", 48, true, {-0.15, 0.23, 0.30}},
                                 {"crash", 49, true, {-0.64, 0.30, 0.36}},
                                 {"ride", 51, true, {0.62, 0.22, 0.28}}};
    auto part = [&](bool ride) {
        std::string t;
        for (int k = 0; k < 4; ++k)
            t += bytes({k == 0 ? 0 : 24, 0x99, 48, 100});
        t += bytes({24, 0x99, 49, 120});
        if (ride)
            t += bytes({0, 0x99, 51, 90});
        return drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t + kEnd), "r.mid"), kit,
                               "r.mid");
    };
    const MidiDrumPart a = part(false);
    REQUIRE(a.score.notes.size() == 5);
    for (size_t i = 0; i < 4; ++i) {
        INFO(i);
        CHECK(a.score.notes[i].hand == (i % 2 == 0 ? Side::left : Side::right));
        CHECK(a.score.notes[i].theta_deg == kDefaultThetaDeg[i % 2 == 0 ? 0 : 1]);
    }
    CHECK(a.score.notes[4].hand == Side::left);
    // With the ride (the right hand's) on the crash's tick, L R L R would leave the right
    // 125 ms for tom1 -> ride (0.77 + 0.1 m: 7.0 m/s) against R L R L's 4.8 (the left to the
    // crash) and 3.5 m/s (the right to the ride in 250 ms): the run keeps the lead.
    const MidiDrumPart b = part(true);
    REQUIRE(b.score.notes.size() == 6);
    for (size_t i = 0; i < 4; ++i)
        CHECK(b.score.notes[i].hand == (i % 2 == 0 ? Side::right : Side::left));
    // Without places the hand rule alone: R L R L.
    for (MidiDrum &d : kit)
        d.placed = false;
    const MidiDrumPart c = part(false);
    for (size_t i = 0; i < 4; ++i)
        CHECK(c.score.notes[i].hand == (i % 2 == 0 ? Side::right : Side::left));
}

// The full kit's places (m: right, up, forward; kit.cpp), for the sticking's moves.
const std::vector<MidiDrum> kFullKit = {
    {"snare", 38, true, {0.0, 0.0, 0.0}},      {"tom1", 48, true, {-0.15, 0.23, 0.30}},
    {"tom2", 47, true, {0.19, 0.21, 0.32}},    {"floor", 43, true, {0.56, 0.0, -0.20}},
    {"crash", 49, true, {-0.64, 0.30, 0.36}},  {"ride", 51, true, {0.62, 0.22, 0.28}},
    {"hihat", 42, true, {-0.42, 0.26, -0.02}}, {"kick", 36, true, {0.0, 0.28, 0.27}}};

TEST_CASE("midi in: a run whose crash is out of reach as it stands is turned for any gain",
          "[score][midi]")
{
    // A new user's part (112 bpm, 96 ticks a quarter, a 16th 134 ms): 16th hi-hats with a
    // ghost snare on the 16th before a fill, the fill 38 50 48 47 45 43 41 38 in 16ths, the
    // crash and kick a 16th after it. The full kit's places (kit.cpp). As it stands the
    // fill runs R L ... L: the left goes snare -> crash (0.74 m + a stroke's 0.1 m) in
    // 134 ms, 6.3 m/s, and the crash was 33 ms late. Turned, its fastest move is 5.2 m/s:
    // less than the 0.8 gain asks, but as it stands no arm makes it (above
    // kMidiPedalHihatAbove_mps), so any gain turns it.
    const std::vector<MidiDrum> &kit = kFullKit;
    Track track(112.0);
    auto at = [&](int tick, int note, int velocity) { track.at(tick, note, velocity); };
    for (int e = 0; e < 8; ++e) {
        at(24 * e, 42, 80);
        if (e == 0)
            at(0, 36, 100);
        if (e == 4)
            at(96, 38, 110);
        if (e == 7)
            at(168, 38, 30);
    }
    const int fill[8] = {38, 50, 48, 47, 45, 43, 41, 38};
    for (int k = 0; k < 8; ++k)
        at(192 + 24 * k, fill[k], 100);
    at(384, 49, 120);
    at(384, 36, 110);
    const MidiDrumPart part = drum_part_score(read_smf(track.file(), "f.mid"), kit, "f.mid");
    const ScoreNote *last_fill = nullptr, *crash = nullptr;
    for (const ScoreNote &n : part.score.notes) {
        if (n.drum == "crash")
            crash = &n;
        else if (n.drum != "kick" && n.drum != "hihat")
            last_fill = &n;
    }
    REQUIRE(crash);
    REQUIRE(last_fill);
    CHECK(crash->hand == Side::left);
    CHECK(last_fill->drum == "snare");
    CHECK(last_fill->hand == Side::right); // the fill ends on the hand that is not crashing
}

TEST_CASE("midi in: a ghost note a 16th after the right hand's hi-hat, before a fill into a "
          "crash, is the left's: a double, not a cross",
          "[score][midi]")
{
    // A new user's groove (99 bpm, a 16th 152 ms): hi-hat 8ths, the snare on 2 and 4, the
    // kick on 1 and 3, a ghost snare a 16th after the last hi-hat, a fill of 16ths 38 38 48
    // 48 47 47 43 43, the crash and kick a 16th after it. Singles from the ghost on end the
    // fill on the left, a 16th from the crash; turned, the ghost is the right's, from the
    // hi-hat (0.49 m + a stroke's 0.1 m) in one 16th, 3.9 m/s: it struck 30 ms early. With
    // a double somewhere in the run no hand has to move that fast.
    const std::vector<MidiDrum> &kit = kFullKit;
    const double bpm = 99.0;
    Track track(bpm);
    for (int e = 0; e < 8; ++e) {
        track.at(48 * e, 42, 80);
        if (e == 0 || e == 4)
            track.at(48 * e, 36, 100);
        if (e == 2 || e == 6)
            track.at(48 * e, 38, 100);
    }
    track.at(360, 38, 21);
    const int fill[8] = {38, 38, 48, 48, 47, 47, 43, 43};
    for (int k = 0; k < 8; ++k)
        track.at(384 + 24 * k, fill[k], 100);
    track.at(576, 49, 120);
    track.at(576, 36, 110);
    const MidiDrumPart part = drum_part_score(read_smf(track.file(), "g.mid"), kit, "g.mid");
    REQUIRE(part.score.notes.size() == 23);
    check_hands_apart(part, bpm);
    // Each hand's moves, from the places here: no move faster than an arm reaches in time.
    auto place = [&](const std::string &name) {
        const auto d =
            std::find_if(kit.begin(), kit.end(), [&](const MidiDrum &k) { return k.name == name; });
        REQUIRE(d != kit.end());
        return d->place_m;
    };
    auto apart = [&](const std::string &a, const std::string &b) {
        const double *p = place(a), *q = place(b);
        return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    };
    for (Side h : {Side::left, Side::right}) {
        const ScoreNote *last = nullptr;
        for (const ScoreNote &n : part.score.notes) {
            if (n.foot || n.hand != h)
                continue;
            if (last && n.beat > last->beat) {
                const double dt = (n.beat - last->beat) * 60.0 / bpm;
                const double v = (apart(n.drum, last->drum) + 0.1) / dt;
                INFO((h == Side::left ? "left " : "right ")
                     << last->drum << " -> " << n.drum << " in " << dt << " s");
                CHECK(v <= kMidiPedalHihatAbove_mps);
            }
            last = &n;
        }
    }
    for (const ScoreNote &n : part.score.notes) {
        if (n.drum == "snare" && n.beat == Approx(3.75))
            CHECK(n.hand == Side::left); // the ghost
        if (n.drum == "crash")
            CHECK(n.hand == Side::left);
        if (n.drum == "hihat")
            CHECK(n.hand == Side::right);
    }
}

TEST_CASE("midi in: under the hi-hat a flam keeps its accent and leaves out its grace",
          "[score][midi]")
{
    // 90 bpm (96 ticks a quarter, 0.667 s): 8th hi-hats; on beat 2 a grace snare (vel 50)
    // 4 ticks (28 ms) before a main snare (vel 120). The grace takes the right hand (0.3 s
    // after the hi-hat), so the beat's hi-hat goes left and the main note finds both hands
    // 28 ms after a stroke: three notes in 28 ms for two hands. The accent is kept (the
    // grace left out, counted), not the grace. Without the hi-hat both are played.
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"hihat", 42}};
    auto part = [&](bool hihat) {
        Track track(90.0);
        auto at = [&](int tick, int note, int velocity) { track.at(tick, note, velocity); };
        for (int e = 0; e < 4; ++e) {
            if (e == 2)
                at(92, 38, 50);
            if (hihat || e != 2)
                at(48 * e, 42, 80);
            if (e == 2)
                at(96, 38, 120);
        }
        return drum_part_score(read_smf(track.file(), "f.mid"), kit, "f.mid");
    };
    const MidiDrumPart with = part(true);
    std::vector<double> snares;
    for (const ScoreNote &n : with.score.notes)
        if (n.drum == "snare")
            snares.push_back(n.dynamics);
    REQUIRE(snares.size() == 1);
    CHECK(snares[0] == Approx(120.0 / 127.0));
    CHECK(with.too_fast == 1);
    CHECK(with.score.notes.size() == 5); // four hi-hats and the accent
    for (size_t i = 0; i + 1 < with.score.notes.size(); ++i)
        CHECK(with.score.notes[i].beats > 0.0);
    const MidiDrumPart without = part(false);
    CHECK(without.too_fast == 0);
    CHECK(without.score.notes.size() == 5); // three hi-hats, the grace and the accent
}

TEST_CASE("midi in: a closed hi-hat the right hand cannot reach while the left crashes is the "
          "left foot's chick",
          "[score][midi][hihat]")
{
    // The full kit's places (m: right, up, forward, from the snare). Four notes on the floor
    // tom, then the crash (the left hand's) with the hi-hat on the next one. From the floor
    // tom to the hi-hat is 1.03 m: with the right hand's last note a 16th (125 ms at 120 bpm)
    // or two before, (1.03 + 0.1) / 0.25 = 4.5 m/s at the least, over 3.5: the left foot's.
    // With the notes 0.5 s apart (8ths at 60 bpm) 2.3 m/s: the right hand's.
    const std::vector<MidiDrum> kit = {{"snare", 38, true, {0.0, 0.0, 0.0}},
                                       {"floor", 43, true, {0.56, 0.0, -0.20}},
                                       {"crash", 49, true, {-0.64, 0.30, 0.36}},
                                       {"hihat", 42, true, {-0.42, 0.26, -0.02}}};
    const double d = std::hypot(0.56 + 0.42, 0.26, -0.20 + 0.02);
    REQUIRE((d + 0.1) / 0.25 > kMidiPedalHihatAbove_mps);
    REQUIRE((d + 0.1) / 0.5 < kMidiPedalHihatAbove_mps);
    auto part = [&](int delta, int tempo_us, int hat, bool chick) {
        std::string t =
            bytes({0, 0xff, 0x51, 3, tempo_us >> 16, (tempo_us >> 8) & 0xff, tempo_us & 0xff});
        for (int k = 0; k < 4; ++k)
            t += bytes({k == 0 ? 0 : delta, 0x99, 43, 100});
        t += bytes({delta, 0x99, 49, 120}) + bytes({0, 0x99, hat, 90});
        if (chick)
            t += bytes({0, 0x99, 44, 70});
        return drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t + kEnd), "h.mid"), kit,
                               "h.mid");
    };
    auto hat_note = [](const MidiDrumPart &p) {
        const ScoreNote *hat = nullptr;
        for (const ScoreNote &n : p.score.notes)
            if (n.drum == "hihat")
                hat = &n;
        REQUIRE(hat);
        return *hat;
    };
    // 16ths at 120 bpm: the chick, on the crash's beat, counted.
    const MidiDrumPart fast = part(24, 500000, 42, false);
    REQUIRE(fast.score.notes.size() == 6);
    const ScoreNote a = hat_note(fast);
    CHECK(a.foot);
    CHECK(a.hand == Side::left);
    CHECK(a.beat == Approx(1.0));
    CHECK(fast.hihats_pedalled == 1);
    for (const ScoreNote &n : fast.score.notes)
        if (n.drum == "crash")
            CHECK((n.hand == Side::left && !n.foot));
    // 8ths at 60 bpm: the right hand's, crossed over.
    const MidiDrumPart slow = part(48, 1000000, 42, false);
    const ScoreNote b = hat_note(slow);
    CHECK(!b.foot);
    CHECK(b.hand == Side::right);
    CHECK(slow.hihats_pedalled == 0);
    // An open hi-hat (the pedal up) and a closed one with the foot's own chick on the tick
    // stay the right hand's.
    const MidiDrumPart open = part(24, 500000, 46, false);
    CHECK(!hat_note(open).foot);
    CHECK(open.hihats_pedalled == 0);
    const MidiDrumPart busy = part(24, 500000, 42, true);
    REQUIRE(busy.score.notes.size() == 7);
    int feet = 0;
    for (const ScoreNote &n : busy.score.notes)
        feet += n.foot;
    CHECK(feet == 1);
    CHECK(busy.hihats_pedalled == 0);
    // Without a left-hand note on its tick (no crash) the hi-hat stays the right hand's,
    // however fast: the left could take it.
    {
        std::string t;
        for (int k = 0; k < 4; ++k)
            t += bytes({k == 0 ? 0 : 24, 0x99, 43, 100});
        t += bytes({24, 0x99, 42, 90});
        const MidiDrumPart alone = drum_part_score(
            read_smf(header(0, 1) + chunk("MTrk", t + kEnd), "a.mid"), kit, "a.mid");
        CHECK(!hat_note(alone).foot);
        CHECK(alone.hihats_pedalled == 0);
    }
    // Two crowded hi-hats 62.5 ms apart (32nds at 120 bpm), each with a crash: the second
    // is within 100 ms of the first's chick, so it stays a hand's.
    {
        std::string t;
        for (int k = 0; k < 4; ++k)
            t += bytes({k == 0 ? 0 : 24, 0x99, 43, 100});
        t += bytes({24, 0x99, 49, 120}) + bytes({0, 0x99, 42, 90});
        t += bytes({12, 0x99, 57, 120}) + bytes({0, 0x99, 42, 90});
        const MidiDrumPart two = drum_part_score(
            read_smf(header(0, 1) + chunk("MTrk", t + kEnd), "t.mid"), kit, "t.mid");
        CHECK(two.hihats_pedalled == 1);
        int feet = 0;
        for (const ScoreNote &n : two.score.notes)
            feet += n.foot;
        CHECK(feet == 1);
    }
}

TEST_CASE("midi in: a hi-hat made crowded by the sticking's second look is the foot's too",
          "[score][midi][hihat]")
{
    // Four 16ths on the snare at 100 bpm (150 ms apart) after a rest, then the crash with the
    // closed hi-hat. The hand rule plays them R L R L: the right's last note 300 ms before
    // the hi-hat, 0.494 m away ((0.494 + 0.1) / 0.3 = 2.0 m/s): the right hand's. The second
    // look turns the run (the left's move to the crash, 0.793 m: 6.0 m/s from one 16th
    // before, 3.0 from two) to L R L R, and the right's last note is then one 16th before
    // (4.0 m/s, over 3.5): the left foot's chick, found after the turn.
    const std::vector<MidiDrum> kit = {{"snare", 38, true, {0.0, 0.0, 0.0}},
                                       {"crash", 49, true, {-0.64, 0.30, 0.36}},
                                       {"hihat", 42, true, {-0.42, 0.26, -0.02}}};
    const double hat = std::hypot(0.42, 0.26, 0.02), crash = std::hypot(0.64, 0.30, 0.36);
    REQUIRE((hat + 0.1) / 0.3 < kMidiPedalHihatAbove_mps);
    REQUIRE((hat + 0.1) / 0.15 > kMidiPedalHihatAbove_mps);
    REQUIRE((crash + 0.1) / 0.15 * kMidiTurnRunGain > (hat + 0.1) / 0.3);
    std::string t = bytes({0, 0xff, 0x51, 3, 0x09, 0x27, 0xc0}); // 600000 us: 100 bpm
    for (int k = 0; k < 4; ++k)
        t += bytes({k == 0 ? 0 : 24, 0x99, 38, 100});
    t += bytes({24, 0x99, 49, 120}) + bytes({0, 0x99, 42, 90});
    const MidiDrumPart p =
        drum_part_score(read_smf(header(0, 1) + chunk("MTrk", t + kEnd), "s.mid"), kit, "s.mid");
    REQUIRE(p.score.notes.size() == 6);
    std::string hands;
    for (const ScoreNote &n : p.score.notes)
        if (n.drum == "snare")
            hands += n.hand == Side::left ? 'L' : 'R';
    CHECK(hands == "LRLR");
    CHECK(p.hihats_pedalled == 1);
    for (const ScoreNote &n : p.score.notes)
        if (n.drum == "hihat")
            CHECK((n.foot && n.hand == Side::left));
}

TEST_CASE("midi in: the left hand keeps the hi-hat going while the right crosses to or from the "
          "ride",
          "[score][midi][hihat]")
{
    // The full kit's places. 16ths at 130 bpm (115 ms): a bar on the ride, a bar on the
    // hi-hat, a bar on the ride, the snare on 2 and 4 (the left hand's). Ride to hi-hat is
    // 1.083 m: the right hand's move, (1.083 + 0.1) / dt, is over kMidiLendHihatAbove_mps
    // in one 16th and within it in two; the left's, hi-hat to snare, within
    // kMidiPedalHihatAbove_mps in two 16ths, not in one.
    const std::vector<MidiDrum> kit = {{"snare", 38, true, {0.0, 0.0, 0.0}},
                                       {"ride", 51, true, {0.62, 0.22, 0.28}},
                                       {"hihat", 42, true, {-0.42, 0.26, -0.02}}};
    auto part = [&](double bpm) {
        Track t(bpm);
        for (int k = 0; k < 48; ++k) {
            t.at(k * 24, k / 16 == 1 ? 42 : 51, 80);
            if (k % 16 == 4 || k % 16 == 12)
                t.at(k * 24, 38, 100);
        }
        return drum_part_score(read_smf(t.file(), "c.mid"), kit, "c.mid");
    };
    const double e16 = 60.0 / 130.0 / 4.0;
    const double cross = std::hypot(0.62 + 0.42, 0.22 - 0.26, 0.28 + 0.02) + 0.1;
    const double hat = std::hypot(0.42, 0.26, 0.02) + 0.1; // to the snare
    REQUIRE(cross / e16 > kMidiLendHihatAbove_mps);
    REQUIRE(cross / (2 * e16) < kMidiLendHihatAbove_mps);
    REQUIRE(hat / (2 * e16) < kMidiPedalHihatAbove_mps);
    REQUIRE(hat / e16 > kMidiPedalHihatAbove_mps);
    const MidiDrumPart p = part(130.0);
    REQUIRE(p.score.notes.size() == 54);
    CHECK(p.too_fast == 0);
    // Into the hi-hat its first 16th is the left's (the snares four 16ths away), and the
    // right has two 16ths from the ride; out of it its last is the left's, and the right
    // leaves the hi-hat two 16ths before the ride.
    std::string hands;
    for (const ScoreNote &n : p.score.notes)
        if (n.drum == "hihat")
            hands += n.hand == Side::left ? 'L' : 'R';
    CHECK(hands == "LRRRRRRRRRRRRRRL");
    CHECK(p.hihats_lent == 2);
    for (const ScoreNote &n : p.score.notes)
        if (n.drum == "ride")
            CHECK(n.hand == Side::right);
    check_hands_apart(p, 130.0);
    // At 60 bpm one 16th (250 ms) is enough: every hi-hat the right hand's.
    REQUIRE(cross / 0.25 < kMidiLendHihatAbove_mps);
    const MidiDrumPart q = part(60.0);
    CHECK(q.hihats_lent == 0);
    for (const ScoreNote &n : q.score.notes)
        if (n.drum == "hihat")
            CHECK(n.hand == Side::right);
}

TEST_CASE("midi in: the right hand takes a crash the left cannot reach in time", "[score][midi]")
{
    // The full kit's places (the kit's frame, x to the right). A bar of 16th hi-hats (the
    // right hand's), the snare on 2 and 4 and a ghost note on the last 16th (both the
    // left's, under the hi-hat), then the crash with the kick on the next downbeat. From the
    // ghost the left would cross 0.76 m to the crash in one 16th; the right, on the hi-hat
    // beside the crash, is free on that tick.
    const std::vector<MidiDrum> kit = {{"snare", 38, true, {0.0, 0.0, 0.0}},
                                       {"crash", 49, true, {-0.64, 0.30, 0.36}},
                                       {"ride", 51, true, {0.62, 0.22, 0.28}},
                                       {"hihat", 42, true, {-0.42, 0.26, -0.02}},
                                       {"kick", 36, true, {0.26, -0.32, 0.28}}};
    auto part = [&](double bpm, bool ride_too) {
        Track t(bpm);
        for (int k = 0; k < 16; ++k) {
            t.at(k * 24, 42, 80);
            if (k == 4 || k == 12)
                t.at(k * 24, 38, 100);
            if (k == 15)
                t.at(k * 24, 38, 35);
        }
        if (ride_too)
            t.at(16 * 24, 51, 90);
        t.at(16 * 24, 49, 120);
        t.at(16 * 24, 36, 110);
        return drum_part_score(read_smf(t.file(), "g.mid"), kit, "g.mid");
    };
    const double crash_from_snare = std::hypot(0.64, 0.30, 0.36) + 0.1;
    const double crash_from_hihat = std::hypot(0.64 - 0.42, 0.30 - 0.26, 0.36 + 0.02) + 0.1;
    const double e16 = 60.0 / 120.0 / 4.0;
    REQUIRE(crash_from_snare / e16 > kMidiLendHihatAbove_mps);
    REQUIRE(crash_from_hihat / e16 < kMidiLendHihatAbove_mps);
    auto crash_hand = [](const MidiDrumPart &p) {
        for (const ScoreNote &n : p.score.notes)
            if (n.drum == "crash")
                return n.hand;
        FAIL("no crash note");
        return Side::left;
    };
    const MidiDrumPart p = part(120.0, false);
    CHECK(p.too_fast == 0);
    CHECK(p.crashes_given == 1);
    CHECK(crash_hand(p) == Side::right);
    for (const ScoreNote &n : p.score.notes)
        if (n.drum == "snare")
            CHECK(n.hand == Side::left);
    check_hands_apart(p, 120.0);
    // The right hand busy on the ride on that tick: the crash stays the left's.
    const MidiDrumPart busy = part(120.0, true);
    CHECK(busy.crashes_given == 0);
    CHECK(crash_hand(busy) == Side::left);
    // At 60 bpm the left reaches the crash in a 16th (250 ms): the left's.
    REQUIRE(crash_from_snare / (2.0 * e16) < kMidiLendHihatAbove_mps);
    const MidiDrumPart slow = part(60.0, false);
    CHECK(slow.crashes_given == 0);
    CHECK(crash_hand(slow) == Side::left);
}

TEST_CASE("midi in: of tempo events on one tick the later in the file wins, at tick 0 too",
          "[score][midi]")
{
    // A DAW's export may carry a tempo event at tick 0 and the song's tempo after it on
    // the same tick (or a tempo track and a drum track each with one): the part played
    // the whole file at the first (a groove at 138 bpm rendered at 117). Seeded files of
    // one or two tracks, two or three tempo events on some ticks (tick 0 among them), a
    // note on every beat: each note's time against the file's tempo map read here, where
    // the last event at a tick is in force from that tick on.
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 24; ++trial) {
        const int tpq = 96;
        // (tick, bpm) in file order: ticks on beats 0..7, some repeated.
        std::vector<std::pair<int, int>> tempi;
        for (int beat = 0; beat < 8; ++beat)
            if (beat == 0 || rng() % 3 == 0)
                for (int k = 0, n = 1 + static_cast<int>(rng() % 3); k < n; ++k)
                    tempi.push_back({beat * tpq, 60 + static_cast<int>(rng() % 121)});
        // Events (tick, message) in file order -> a track's bytes (deltas < 2^14: two
        // bytes of their variable-length form).
        using Events = std::vector<std::pair<int, std::string>>;
        auto track = [](const Events &ev) {
            std::string out;
            int last = 0;
            for (const auto &[tick, message] : ev) {
                const int delta = tick - last;
                out += bytes({0x80 | (delta >> 7), delta & 0x7f}) + message;
                last = tick;
            }
            return chunk("MTrk", out + kEnd);
        };
        Events meta, notes;
        for (const auto &[tick, bpm] : tempi) {
            const int us = static_cast<int>(std::lround(60e6 / bpm));
            meta.push_back(
                {tick, bytes({0xff, 0x51, 0x03, us >> 16, (us >> 8) & 0xff, us & 0xff})});
        }
        for (int beat = 0; beat < 10; ++beat)
            notes.push_back({beat * tpq, bytes({0x99, 38, 100})});
        const bool two = trial % 2;
        Events merged = meta;
        merged.insert(merged.end(), notes.begin(), notes.end());
        std::stable_sort(merged.begin(), merged.end(),
                         [](const auto &a, const auto &b) { return a.first < b.first; });
        const std::string file =
            two ? header(1, 2) + track(meta) + track(notes) : header(0, 1) + track(merged);
        INFO("trial " << trial << (two ? " (format 1)" : " (format 0)"));
        const MidiDrumPart part = drum_part_score(read_smf(file, "t.mid"), {}, "t.mid");
        REQUIRE(part.score.notes.size() == 10);
        std::map<int, int> in_force; // tick -> the last bpm written there
        for (const auto &[tick, bpm] : tempi)
            in_force[tick] = bpm;
        double t = 0.0;
        for (int beat = 0; beat < 10; ++beat) {
            const ScoreNote &n = part.score.notes[static_cast<size_t>(beat)];
            CHECK(part.score.note_time_s(n) == Approx(t).margin(1e-6));
            const int bpm = std::prev(in_force.upper_bound(beat * tpq))->second;
            t += static_cast<double>(std::lround(60e6 / bpm)) / 1e6; // a quarter, as written
        }
    }
}
