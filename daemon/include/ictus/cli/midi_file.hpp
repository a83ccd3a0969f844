// Strikes as MIDI (docs/midi.md): the mapping of a strike to a note and a
// velocity, and a Standard MIDI File of a performance, written here (format
// 0, one track; the format is small). The same mapping is in
// patches/ui/ictus-midi.pd for the live patch.
#pragma once

#include "ictus/score/score.hpp"
#include "ictus/sim/strike_event.hpp"

#include <string>
#include <vector>

namespace ictus
{
namespace cli
{

// Zones of the head by r/a: centre below kMidiMiddleFrom, edge from kMidiEdgeFrom.
constexpr double kMidiMiddleFrom = 0.25;
constexpr double kMidiEdgeFrom = 0.65;
// Note = kMidiNoteBase + 4 * hand + zone (hand 0 left, 1 right; zone 0 centre,
// 1 middle, 2 edge): left 48 49 50, right 52 53 54 (C3 = 48).
constexpr int kMidiNoteBase = 48;
// Velocity = 1 + 126 ln(v / v_lo) / ln(v_hi / v_lo), rounded, within 1..127:
// linear in dB of the impact speed v, 0.1 m/s -> 1, 10 m/s -> 127.
constexpr double kMidiSpeedLo_mps = 0.1;
constexpr double kMidiSpeedHi_mps = 10.0;
// A note lasts this long, or until the same note strikes again.
constexpr double kMidiNoteLength_s = 0.1;
// Ticks per quarter note.
constexpr int kMidiTicksPerQuarter = 3840;

int midi_zone(double r_over_a);
int midi_note(int hand, double r_over_a);
int midi_velocity(double normal_velocity_mps);

// The file's clock. tick 0 is at start_s (seconds of the render's clock);
// a tempo (microseconds per quarter note) from `tick` on, the first at tick 0;
// a time signature N/D from `tick` on (D a power of two 1..64, N 1..255).
struct MidiTempo {
    long tick = 0;
    long us_per_quarter = 500000;
};
struct MidiMeter {
    long tick = 0;
    int numerator = 4;
    int denominator = 4;
};
struct MidiTimeline {
    double start_s = 0.0;
    std::vector<MidiTempo> tempo;
    std::vector<MidiMeter> meter; // none: 4/4 at tick 0
    long first_beat_tick = 0;     // the score's beat 0 (score mode)
};

// Microseconds per quarter of a tempo, rounded (4..1000 bpm, else throws
// std::invalid_argument).
long midi_us_per_quarter(double bpm);
// One tempo from render time 0 (a clip).
MidiTimeline midi_timeline(double bpm);
// A score's timeline (docs/midi.md): the score's beat b at tick
// first_beat_tick + b x 3840, first_beat_tick a whole number of pickup bars
// of the score's first meter (one, or as many as hold `earliest_s`, the
// render time of the first strike), the pickup at the score's first tempo;
// beat0_s is the render time of the score's beat 0. Tempo changes at their
// beats, a ramp as a tempo every kMidiRampStepTicks, each chosen so that the
// file's time at the step's end is the score's (within half a microsecond);
// the meters at their beats.
constexpr long kMidiRampStepTicks = kMidiTicksPerQuarter / 16;
constexpr int kMidiMaxPickupBars = 64;
MidiTimeline midi_timeline(const TempoMap &tempo, const std::vector<ScoreMeter> &meters,
                           double beat0_s, double earliest_s);

// The file: track name, the time signatures and the tempo map of
// `timeline`, then for each strike in order a note-on on `channel` (0..15)
// at its time_s on the timeline's clock (a strike before tick 0 at tick 0),
// preceded by a text event "bounce" at the same tick when it is a bounce,
// and its note-off. Times are rounded to the nearest tick (3840 per quarter:
// within 0.4 ms at 20 bpm and faster). With a kit, `drum_notes` gives each
// drum's note (StrikeEvent::drum indexes it: the General MIDI drum map,
// docs/midi.md); without, midi_note().
std::string standard_midi_file(const std::vector<StrikeEvent> &strikes,
                               const MidiTimeline &timeline, int channel,
                               const std::vector<int> *drum_notes = nullptr);

} // namespace cli
} // namespace ictus
