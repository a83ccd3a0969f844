// A Standard MIDI File of the strikes (docs/midi.md). SMF 1.0: a header chunk
// (format 0, one track, ticks per quarter) and one track chunk of events,
// each after a variable-length delta time; tempo as meta event FF 51
// (microseconds per quarter note).
#include "ictus/cli/midi_file.hpp"
#include "ictus/score/midi_score.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace ictus
{
namespace cli
{

int midi_zone(double r_over_a)
{
    if (r_over_a < kMidiMiddleFrom)
        return 0;
    return r_over_a < kMidiEdgeFrom ? 1 : 2;
}

int midi_note(int hand, double r_over_a)
{
    return kMidiNoteBase + 4 * (hand == 0 ? 0 : 1) + midi_zone(r_over_a);
}

int midi_velocity(double normal_velocity_mps)
{
    if (!(normal_velocity_mps > kMidiSpeedLo_mps)) // also NaN
        return 1;
    const double x = std::log(normal_velocity_mps / kMidiSpeedLo_mps) /
                     std::log(kMidiSpeedHi_mps / kMidiSpeedLo_mps);
    return static_cast<int>(std::clamp(std::lround(1.0 + 126.0 * x), 1L, 127L));
}

namespace
{

// The file's clock: each tempo's tick at the time the previous tempi give
// it (so a reader's tick -> seconds is exactly the map used here).
struct TempoSegment {
    long tick;
    double time_s;
    long us_per_quarter;
};

class FileClock
{
  public:
    explicit FileClock(const std::vector<MidiTempo> &tempo)
    {
        if (tempo.empty() || tempo.front().tick != 0)
            throw std::invalid_argument("standard_midi_file: no tempo at tick 0");
        for (const MidiTempo &t : tempo) {
            if (t.us_per_quarter < 1 || t.us_per_quarter > 0xffffff)
                throw std::invalid_argument("standard_midi_file: tempo out of range");
            if (!segments_.empty() && t.tick < segments_.back().tick)
                throw std::invalid_argument("standard_midi_file: tempi out of order");
            if (!segments_.empty() && t.tick == segments_.back().tick) {
                segments_.back().us_per_quarter = t.us_per_quarter;
                continue;
            }
            if (!segments_.empty() && t.us_per_quarter == segments_.back().us_per_quarter)
                continue;
            segments_.push_back({t.tick, time_of(t.tick), t.us_per_quarter});
        }
    }
    long tick_of(double time_s) const
    {
        size_t k = 0;
        while (k + 1 < segments_.size() && segments_[k + 1].time_s <= time_s)
            ++k;
        const TempoSegment &s = segments_[k];
        return s.tick + std::lround((time_s - s.time_s) * 1e6 /
                                    static_cast<double>(s.us_per_quarter) * kMidiTicksPerQuarter);
    }
    double time_of(long tick) const
    {
        if (segments_.empty())
            return 0.0;
        size_t k = 0;
        while (k + 1 < segments_.size() && segments_[k + 1].tick <= tick)
            ++k;
        const TempoSegment &s = segments_[k];
        return s.time_s + static_cast<double>(tick - s.tick) / kMidiTicksPerQuarter *
                              static_cast<double>(s.us_per_quarter) * 1e-6;
    }
    const std::vector<TempoSegment> &segments() const { return segments_; }

  private:
    std::vector<TempoSegment> segments_;
};

long beat_tick(double beat)
{
    return std::lround(beat * kMidiTicksPerQuarter);
}

// Appends the tempo events of a ramp from tick t0 to t1 (file ticks),
// `file_s` the file's time at t0 relative to the score's beat 0, kept up to
// date; each step's tempo lands the file's time on the score's at its end.
void append_ramp(const TempoMap &map, long pickup, long t0, long t1, double &file_s,
                 std::vector<MidiTempo> &out)
{
    for (long t = t0; t < t1;) {
        const long next = std::min(t1, t + kMidiRampStepTicks);
        const double target =
            map.time_at_beat(static_cast<double>(next - pickup) / kMidiTicksPerQuarter);
        const double quarters = static_cast<double>(next - t) / kMidiTicksPerQuarter;
        const long us = std::clamp(std::lround((target - file_s) * 1e6 / quarters), 1L, 0xffffffL);
        out.push_back({t, us});
        file_s += quarters * static_cast<double>(us) * 1e-6;
        t = next;
    }
}

struct TrackEvent {
    long tick;
    int order; // at one tick: meta 0, note-off 1, bounce text 2, note-on 3
    long seq;  // then in strike order
    std::string bytes;
};

void put_u32(std::string &out, uint32_t v)
{
    for (int shift = 24; shift >= 0; shift -= 8)
        out += static_cast<char>((v >> shift) & 0xff);
}

void put_vlq(std::string &out, uint32_t v)
{
    char buf[5];
    int n = 0;
    buf[n++] = static_cast<char>(v & 0x7f);
    while (v >>= 7)
        buf[n++] = static_cast<char>(0x80 | (v & 0x7f));
    while (n > 0)
        out += buf[--n];
}

std::string meta(int type, const std::string &data)
{
    std::string e;
    e += static_cast<char>(0xff);
    e += static_cast<char>(type);
    put_vlq(e, static_cast<uint32_t>(data.size()));
    return e + data;
}

std::string tempo_meta(uint32_t us)
{
    std::string d;
    d += static_cast<char>((us >> 16) & 0xff);
    d += static_cast<char>((us >> 8) & 0xff);
    d += static_cast<char>(us & 0xff);
    return meta(0x51, d);
}

// FF 58 04 nn dd cc bb: N/D (dd = log2 D), a click every quarter (24 MIDI
// clocks), 8 32nd notes per quarter.
std::string time_signature_meta(int numerator, int denominator)
{
    if (numerator < 1 || numerator > 255 || denominator < 1 || denominator > 64 ||
        (denominator & (denominator - 1)) != 0)
        throw std::invalid_argument("standard_midi_file: meter " + std::to_string(numerator) + "/" +
                                    std::to_string(denominator) +
                                    " (N 1..255, D a power of two 1..64)");
    int log2 = 0;
    while ((1 << log2) < denominator)
        ++log2;
    std::string d;
    d += static_cast<char>(numerator);
    d += static_cast<char>(log2);
    d += static_cast<char>(24);
    d += static_cast<char>(8);
    return meta(0x58, d);
}

std::string channel_message(int status, int channel, int a, int b)
{
    std::string e;
    e += static_cast<char>(status | channel);
    e += static_cast<char>(a);
    e += static_cast<char>(b);
    return e;
}

} // namespace

long midi_us_per_quarter(double bpm)
{
    if (!(bpm >= 4.0 && bpm <= 1000.0))
        throw std::invalid_argument("midi: tempo " + std::to_string(bpm) + " bpm outside 4..1000");
    return std::lround(60e6 / bpm);
}

MidiTimeline midi_timeline(double bpm)
{
    MidiTimeline t;
    t.tempo.push_back({0, midi_us_per_quarter(bpm)});
    return t;
}

MidiTimeline midi_timeline(const TempoMap &map, const std::vector<ScoreMeter> &meters,
                           double beat0_s, double earliest_s)
{
    MidiTimeline t;
    const bool first_at_0 = !meters.empty() && meters.front().beat <= 0.0;
    const int n = first_at_0 ? meters.front().numerator : 4;
    const int d = first_at_0 ? meters.front().denominator : 4;
    const long bar = std::max(1L, std::lround(n * 4.0 / d * kMidiTicksPerQuarter));
    const long us0 = midi_us_per_quarter(map.tempo_at_beat(0.0));
    const double bar_s = static_cast<double>(bar) / kMidiTicksPerQuarter * us0 * 1e-6;
    int bars = 1;
    while (bars < kMidiMaxPickupBars && earliest_s < beat0_s - bars * bar_s)
        ++bars;
    const long pickup = bars * bar;
    t.first_beat_tick = pickup;
    t.start_s = beat0_s - bars * bar_s;
    t.tempo.push_back({0, us0});
    if (!first_at_0)
        t.meter.push_back({0, 4, 4});
    for (const ScoreMeter &m : meters)
        t.meter.push_back(
            {m.beat <= 0.0 ? 0 : pickup + beat_tick(m.beat), m.numerator, m.denominator});
    // The file's time relative to beat 0, tempo by tempo.
    double file_s = 0.0;
    long tick = pickup;
    const std::vector<TempoMap::Change> &changes = map.changes();
    for (size_t i = 0; i < changes.size(); ++i) {
        const TempoMap::Change &c = changes[i];
        const long start = pickup + beat_tick(c.beat);
        const long next = i + 1 < changes.size() ? pickup + beat_tick(changes[i + 1].beat)
                                                 : std::numeric_limits<long>::max();
        file_s += static_cast<double>(start - tick) / kMidiTicksPerQuarter *
                  static_cast<double>(t.tempo.back().us_per_quarter) * 1e-6;
        tick = start;
        if (c.ramp_beats > 0.0 && c.start_bpm != c.end_bpm) {
            const long end = std::min(next, start + beat_tick(c.ramp_beats));
            append_ramp(map, pickup, start, end, file_s, t.tempo);
            tick = end;
            if (end < next)
                t.tempo.push_back({end, midi_us_per_quarter(c.end_bpm)});
        } else {
            t.tempo.push_back({start, midi_us_per_quarter(c.start_bpm)});
        }
    }
    return t;
}

std::string standard_midi_file(const std::vector<StrikeEvent> &strikes,
                               const MidiTimeline &timeline, int channel,
                               const std::vector<int> *drum_notes)
{
    auto note_of = [drum_notes](const StrikeEvent &e) {
        if (drum_notes && e.drum >= 0 && e.drum < static_cast<int>(drum_notes->size())) {
            const int note = (*drum_notes)[static_cast<size_t>(e.drum)];
            // A strike on the snare's rim is General MIDI's side stick, as --midi reads it;
            // the left foot's chick on the hi-hat its pedal hi-hat; a stick on the hi-hat
            // with its pedal not closed (half or open) its open hi-hat.
            if (note == kMidiClosedHihat && e.hand == kFootLeft)
                return kMidiPedalHihat;
            if (note == kMidiClosedHihat && e.pedal_openness > 0.0)
                return kMidiOpenHihat;
            return note == kMidiSnare && e.zone == kZoneRim ? kMidiSideStick : note;
        }
        return midi_note(e.hand, e.r_over_a);
    };
    if (channel < 0 || channel > 15)
        throw std::invalid_argument("standard_midi_file: channel must be 0..15");
    const FileClock map(timeline.tempo);
    std::vector<TrackEvent> events;
    events.push_back({0, 0, -3, meta(0x03, "ictus")});
    if (timeline.meter.empty() || timeline.meter.front().tick > 0)
        events.push_back({0, 0, -2, time_signature_meta(4, 4)});
    for (const MidiMeter &m : timeline.meter)
        events.push_back(
            {std::max(0L, m.tick), 0, -2, time_signature_meta(m.numerator, m.denominator)});
    for (const TempoSegment &s : map.segments())
        events.push_back({s.tick, 0, -1, tempo_meta(static_cast<uint32_t>(s.us_per_quarter))});
    for (size_t i = 0; i < strikes.size(); ++i) {
        const StrikeEvent &e = strikes[i];
        const int note = note_of(e);
        const double at_s = e.time_s - timeline.start_s;
        const long on = std::max(0L, map.tick_of(at_s));
        // The note ends after kMidiNoteLength_s, or where the same note strikes again.
        double off_s = at_s + kMidiNoteLength_s;
        for (size_t j = i + 1; j < strikes.size(); ++j)
            if (note_of(strikes[j]) == note) {
                off_s = std::min(off_s, strikes[j].time_s - timeline.start_s);
                break;
            }
        const long off = std::max(on + 1, map.tick_of(off_s));
        const long seq = static_cast<long>(i);
        if (e.bounce)
            events.push_back({on, 2, seq, meta(0x01, "bounce")});
        events.push_back(
            {on, 3, seq,
             channel_message(0x90, channel, note, midi_velocity(e.normal_velocity_mps))});
        events.push_back({off, 1, seq, channel_message(0x80, channel, note, 0)});
    }
    std::stable_sort(events.begin(), events.end(), [](const TrackEvent &a, const TrackEvent &b) {
        if (a.tick != b.tick)
            return a.tick < b.tick;
        if (a.order != b.order)
            return a.order < b.order;
        return a.seq < b.seq;
    });
    std::string track;
    long last = 0;
    for (const TrackEvent &e : events) {
        put_vlq(track, static_cast<uint32_t>(e.tick - last));
        track += e.bytes;
        last = e.tick;
    }
    put_vlq(track, 0);
    track += meta(0x2f, "");

    std::string file = "MThd";
    put_u32(file, 6);
    file += std::string("\x00\x00\x00\x01", 4); // format 0, one track
    file += static_cast<char>((kMidiTicksPerQuarter >> 8) & 0x7f);
    file += static_cast<char>(kMidiTicksPerQuarter & 0xff);
    file += "MTrk";
    put_u32(file, static_cast<uint32_t>(track.size()));
    return file + track;
}

} // namespace cli
} // namespace ictus
