// fuzz_midi.cpp -- libFuzzer harness of the Standard MIDI File reader and
// its drum part as a score (score/midi_score.hpp, `ictusd --midi`), on the
// standard kit's notes and on the one drum.
//
// A refusal (MidiFileError) is a pass. A crash, a sanitizer report, a run
// over the -timeout, or a result that breaks the reader's promises (events
// sorted by tick within kMaxSmfTick, notes 0..127 of velocity 1..127 on
// channels 0..15) or the score's (notes in beat order with dynamics in
// (0, 1], tempi within 20..400 bpm, time growing with the beat, no hand
// striking twice within kMidiSameHandMin_s) is a finding. See docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/score/midi_score.hpp"

#include <cmath>

using namespace ictus;

namespace
{

constexpr std::size_t kMaxInputBytes = 64 * 1024;

void check_smf(const Smf &smf)
{
    ICTUS_FUZZ_CHECK(smf.ticks_per_quarter > 0 && smf.ticks_per_quarter < 0x8000,
                     "ticks per quarter out of 1..32767");
    long last = 0;
    for (const SmfNote &n : smf.notes) {
        ICTUS_FUZZ_CHECK(n.tick >= last && n.tick <= kMaxSmfTick, "notes not sorted by tick");
        ICTUS_FUZZ_CHECK(n.note >= 0 && n.note <= 127, "note outside 0..127");
        ICTUS_FUZZ_CHECK(n.velocity >= 1 && n.velocity <= 127, "velocity outside 1..127");
        ICTUS_FUZZ_CHECK(n.channel >= 0 && n.channel <= 15, "channel outside 0..15");
        last = n.tick;
    }
    for (const SmfTempo &t : smf.tempo)
        ICTUS_FUZZ_CHECK(t.us_per_quarter > 0 && t.us_per_quarter <= 0xffffff,
                         "tempo outside 1..2^24-1 us");
}

void check_part(const MidiDrumPart &part)
{
    const Score &s = part.score;
    double beat = 0.0, last_t[2] = {-1e300, -1e300};
    for (const ScoreNote &n : s.notes) {
        ICTUS_FUZZ_CHECK(n.beat >= beat, "score notes out of beat order");
        ICTUS_FUZZ_CHECK(n.dynamics > 0.0 && n.dynamics <= 1.0, "dynamics outside (0, 1]");
        const double t = s.tempo.time_at_beat(n.beat);
        ICTUS_FUZZ_CHECK(std::isfinite(t), "non-finite note time");
        const int h = n.hand == Side::left ? 0 : 1;
        ICTUS_FUZZ_CHECK(t - last_t[h] >= kMidiSameHandMin_s - 1e-9,
                         "a hand strikes twice within kMidiSameHandMin_s");
        last_t[h] = t;
        beat = n.beat;
    }
    double t_prev = -1.0;
    for (const TempoMap::Change &c : s.tempo.changes()) {
        ICTUS_FUZZ_CHECK(c.start_bpm >= kMinTempoBpm && c.start_bpm <= kMaxTempoBpm,
                         "tempo outside 20..400 bpm");
        ICTUS_FUZZ_CHECK(c.start_time_s > t_prev, "time not growing with the beat");
        t_prev = c.start_time_s;
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return 0;
    const std::string bytes(reinterpret_cast<const char *>(data), size);
    Smf smf;
    try {
        smf = read_smf(bytes, "fuzz");
    } catch (const MidiFileError &) {
        return 0;
    }
    check_smf(smf);
    const std::vector<MidiDrum> kit = {{"snare", 38}, {"tom1", 48}, {"tom2", 47}, {"floor", 43}};
    try {
        check_part(drum_part_score(smf, kit, "fuzz"));
        check_part(drum_part_score(smf, {}, "fuzz"));
    } catch (const MidiFileError &) {
    }
    return 0;
}
