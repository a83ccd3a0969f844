// midi_score.hpp -- a Standard MIDI File's drum part as a Score (docs/midi.md,
// "MIDI in"): the reader of the file, and the General MIDI drum map, the
// hands and the dynamics that make its notes the strokes of a score, so
// everything after the score (the planner, the performance) is unchanged.
#pragma once

#include "ictus/score/score.hpp"

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{

// A malformed file. what() is "SOURCE: byte OFFSET (track T): message"
// (track 0 is the first MTrk; no track: the header).
class MidiFileError : public std::runtime_error
{
  public:
    explicit MidiFileError(const std::string &what) : std::runtime_error(what) {}
};

struct SmfNote {
    long tick = 0;
    int track = 0;
    int channel = 0; // 0..15 (General MIDI's drums: 9, "channel 10")
    int note = 0;
    int velocity = 0; // 1..127 (a note-on of velocity 0 is a note-off: not kept)
};
struct SmfTempo {
    long tick = 0;
    long us_per_quarter = 500000;
};
struct SmfMeter {
    long tick = 0;
    int numerator = 4;
    int denominator = 4;
};
// The parts of a file a drum part needs, each sorted by tick (ties: in the
// file's order, track by track).
struct Smf {
    int format = 0;
    int ticks_per_quarter = 480;
    std::vector<SmfNote> notes;
    std::vector<SmfTempo> tempo;
    std::vector<SmfMeter> meters;
};

// Limits of the reader: ticks beyond kMaxSmfTick, more than kMaxSmfNotes
// note-ons, or formats other than 0 and 1 and SMPTE time are refused.
constexpr long kMaxSmfTick = 1L << 40;
constexpr long kMaxSmfNotes = kMaxScoreNotes;

// Reads a Standard MIDI File (SMF 1.0: MThd, then MTrk chunks; other chunks
// are skipped). Throws MidiFileError naming `source`, the byte offset and
// the track.
Smf read_smf(const std::string &bytes, const std::string &source);

// A kit's drum for the General MIDI drum map: its name and its note.
struct MidiDrum {
    std::string name;
    int midi_note = 38;
    // Where it stands (m, any fixed frame; the kit's), for the sticking's moves; without
    // places (placed false) no run of alternating strokes is turned (docs/midi.md).
    bool placed = false;
    double place_m[3] = {0.0, 0.0, 0.0};
};

// General MIDI's side stick (37) is the snare's rim: a stroke aimed this far out, where the
// stick meets the hoop (docs/rim.md; aimed at 0.95, strikes land at r/a 0.97, zone 1).
constexpr int kMidiSideStick = 37;
constexpr int kMidiSnare = 38; // Acoustic Snare: a kit's snare's note; MIDI out writes a rim strike
                               // on it as the side stick
constexpr double kMidiSideStickRadiusFraction = kMaxRadiusFraction;
// ... on the hoop nearest the performer (theta 90 degrees, docs/kit.md), whichever hand plays
// it: the hands' own sides (0 and 180 degrees) lie under the hi-hat and toward the floor tom.
constexpr double kMidiSideStickThetaDeg = 90.0;
// General MIDI's cymbals, played on a kit's cymbal of that note (docs/midi.md): crash 49 and
// 57 on its crash (49), ride 51 and 59 on its ride (51), ride bell 53 on the ride's bell
// (kBellRadiusFraction, as `on ride-bell`).
constexpr int kMidiCrash = 49;
constexpr int kMidiRide = 51;
constexpr int kMidiRideBell = 53;
constexpr double kMidiRideBellRadiusFraction = kBellRadiusFraction;
// General MIDI's hi-hat played by a hand on a kit's hi-hat (its note 42): closed 42 with the
// pedal down, open 46 with it up (ScoreNote::openness); a 42 on a 46's tick is left out
// (one pedal: the open one wins, MidiDrumPart::hihats_opened). The pedal hi-hat 44 is the left
// foot's chick on that hi-hat's pedal (`LF`, docs/pedal.md), no sooner than
// kMidiChickMin_s after the last (sooner: left out, MidiDrumPart::too_fast).
// General MIDI's bass drums, Acoustic (35) and Bass Drum 1 (36), played by the right foot
// on a kit's kick (its note 36; docs/pedal.md), no sooner than kMidiFootMin_s after the
// last: a foot note (ScoreNote::foot), whatever the hands do.
constexpr int kMidiAcousticBass = 35;
constexpr int kMidiKick = 36;
constexpr double kMidiFootMin_s = 0.06;
constexpr int kMidiClosedHihat = 42;
constexpr int kMidiOpenHihat = 46;
constexpr int kMidiPedalHihat = 44;
constexpr double kMidiChickMin_s = 0.1;

// Notes closer than this alternate hands; farther apart, the right hand
// (the lead) plays.
constexpr double kMidiAlternateBelow_s = 0.3;
// A hand strikes again no sooner than this after its previous stroke (the
// planner refuses a stroke 40 ms after one of the same hand).
constexpr double kMidiSameHandMin_s = 0.05;
// A run of alternating strokes between notes whose hands are set (a crash, the time-keeper,
// two at once, or a rest) starts on the other hand when that makes the fastest of the
// hands' moves into and out of the run (distance over time) at most this fraction of it.
constexpr double kMidiTurnRunGain = 0.8;
// A closed hi-hat (42) on a tick where the left hand plays too (a crash after a fill, say),
// which the right hand would reach from its last note faster than this (the distance
// between the pieces plus a stroke's 0.1 m, over the time between the notes), is the left
// foot's chick instead, when the foot is free (kMidiChickMin_s from its other chicks), as a
// drummer closes the hi-hat with the pedal when both hands are taken (docs/midi.md). On
// the random parts every such hi-hat or ride note the right hand reached at up to 3.55 m/s
// was found within 5 ms; of those above, most were late or lost.
constexpr double kMidiPedalHihatAbove_mps = 3.5;
// The time-keeper's hi-hat notes that the right hand would reach, or leave for its next
// note, faster than this (the same measure) are the left hand's when it is free: its other
// notes kMidiSameHandMin_s away, its moves into and out of the hi-hat within
// kMidiPedalHihatAbove_mps (docs/midi.md). On the random parts (seeds 41-100, before this
// rule) the right hand found 55 of the 56 time-keeper notes it reached at 3.5-5.5 m/s within
// 5 ms, 8 of 14 at 5.5-7 m/s and 3 of 18 faster.
constexpr double kMidiLendHihatAbove_mps = 5.5;

// The score of a file's drum part, and what was left out.
struct MidiDrumPart {
    Score score;
    int channel = 9;             // the channel read (0..15), -1: all
    std::map<int, long> skipped; // note number -> notes the kit cannot play
    long too_fast = 0;           // notes no hand could strike in time
    long feet_too_fast = 0;      // kicks and chicks sooner than their foot plays again
    long tempo_clamped = 0;      // tempi outside kMinTempoBpm..kMaxTempoBpm
    long hihats_pedalled = 0;    // closed hi-hats the left foot played (kMidiPedalHihatAbove_mps)
    long hihats_lent =
        0; // the time-keeper's hi-hats the left hand played (kMidiLendHihatAbove_mps)
    long crashes_given = 0;  // crashes the right hand played (kMidiLendHihatAbove_mps)
    long hihats_opened = 0;  // closed hi-hats (42) left out for an open one (46) on their tick
    long other_channels = 0; // notes on channels other than the drum part's (10) left out
};

// The drum part of `smf` (docs/midi.md): the notes on channel 10 if there
// are any, else on every channel; snares (38, 40) and toms (41, 43, 45,
// 47, 48, 50) to `drums` by the General MIDI map (a snare to the drum of
// note 38, a tom to the drum of its note, else the tom of the nearest
// note; no drums: the one drum plays them all), cymbals to the kit's crash,
// ride and hi-hat (42 closed, 46 open) when it has them, the rest skipped; velocity
// v to dynamics v / 127; hands as docs/midi.md says; the tempo map and the
// meters of the file, its quarter note the score's beat; before the file's first
// tempo event, start_bpm (ictusd --tempo; a Standard MIDI File's own default is 120).
MidiDrumPart drum_part_score(const Smf &smf, const std::vector<MidiDrum> &drums,
                             const std::string &source, double start_bpm = kDefaultTempoBpm);

// Reads the file at `path` and converts it. Throws MidiFileError (also when
// it cannot be read or holds no playable note).
MidiDrumPart load_midi_drum_part(const std::string &path, const std::vector<MidiDrum> &drums,
                                 double start_bpm = kDefaultTempoBpm);

} // namespace ictus
