// Strikes as MIDI (docs/midi.md): the mapping of a strike to a note and a
// velocity, and a Standard MIDI File of a performance, written here (format
// 0, one track; the format is small). The same mapping is in
// patches/ui/ictus-midi.pd for the live patch.
#pragma once

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

// A tempo from time_s on (seconds from the start of the file).
struct MidiTempo {
    double time_s = 0.0;
    double bpm = 120.0;
};

// A time signature N/D from time_s on (D a power of two, 1..64; N 1..255).
struct MidiMeter {
    double time_s = 0.0;
    int numerator = 4;
    int denominator = 4;
};

// The file: track name, the time signature (the first of `meter` if it is at
// 0 s, else 4/4; the others at their ticks, FF 58 nn dd 24 8: a metronome
// click per quarter), the tempo map (at least one entry; the first
// applies from 0), then for each strike in order a note-on on `channel`
// (0..15) at its time_s, preceded by a text event "bounce" at the same tick
// when it is a bounce, and its note-off. Times are rounded to the nearest
// tick of the tempo map (3840 per quarter: within 0.4 ms at 20 bpm and faster).
// With a kit, `drum_notes` gives each drum's note (StrikeEvent::drum indexes
// it: the General MIDI drum map, docs/midi.md); without, midi_note().
std::string standard_midi_file(const std::vector<StrikeEvent> &strikes,
                               const std::vector<MidiTempo> &tempo, int channel,
                               const std::vector<int> *drum_notes = nullptr,
                               const std::vector<MidiMeter> &meter = {});

} // namespace cli
} // namespace ictus
