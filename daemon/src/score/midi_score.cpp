// midi_score.cpp -- a Standard MIDI File's drum part as a Score (docs/midi.md,
// "MIDI in"). SMF 1.0: "MThd" length 6: format, tracks, division; then "MTrk"
// chunks of events, each after a variable-length delta time: channel
// messages (with running status), meta events FF type length data (tempo FF
// 51, time signature FF 58), system exclusive F0/F7 length data.
#include "ictus/score/midi_score.hpp"

#include "ictus/base/input_file.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

namespace ictus
{

namespace
{

// A cursor over one chunk: every read is bounds-checked and names the byte.
class Reader
{
  public:
    Reader(const std::string &bytes, size_t begin, size_t end, const std::string &source, int track)
        : b_(bytes), pos_(begin), end_(end), source_(source), track_(track)
    {
    }
    bool done() const { return pos_ >= end_; }
    size_t pos() const { return pos_; }
    [[noreturn]] void fail(const std::string &message, size_t at) const
    {
        std::string where = source_ + ": byte " + std::to_string(at);
        if (track_ >= 0)
            where += " (track " + std::to_string(track_) + ")";
        throw MidiFileError(where + ": " + message);
    }
    int byte()
    {
        if (pos_ >= end_)
            fail("unexpected end of " + std::string(track_ >= 0 ? "track" : "file"), pos_);
        return static_cast<unsigned char>(b_[pos_++]);
    }
    int peek() const
    {
        if (pos_ >= end_)
            fail("unexpected end of track", pos_);
        return static_cast<unsigned char>(b_[pos_]);
    }
    long vlq()
    {
        const size_t at = pos_;
        long v = 0;
        for (int i = 0; i < 4; ++i) {
            const int c = byte();
            v = (v << 7) | (c & 0x7f);
            if (!(c & 0x80))
                return v;
        }
        fail("variable-length number longer than 4 bytes", at);
    }
    void skip(long n)
    {
        if (n < 0 || static_cast<size_t>(n) > end_ - pos_)
            fail("length " + std::to_string(n) + " runs past the end of the track", pos_);
        pos_ += static_cast<size_t>(n);
    }
    int data_byte()
    {
        const size_t at = pos_;
        const int c = byte();
        if (c & 0x80)
            fail("data byte expected, got status byte " + std::to_string(c), at);
        return c;
    }

  private:
    const std::string &b_;
    size_t pos_, end_;
    const std::string &source_;
    int track_;
};

long u32(const std::string &b, size_t at)
{
    long v = 0;
    for (size_t i = 0; i < 4; ++i)
        v = (v << 8) | static_cast<unsigned char>(b[at + i]);
    return v;
}

// A meta event's data, after FF and its type.
void read_meta(Reader &r, int type, long tick, Smf &smf)
{
    const size_t at = r.pos();
    const long len = r.vlq();
    if (type == 0x51 && len == 3) {
        long us = 0;
        for (int i = 0; i < 3; ++i)
            us = (us << 8) | r.byte();
        if (us == 0)
            r.fail("tempo of 0 microseconds per quarter", at);
        smf.tempo.push_back({tick, us});
    } else if (type == 0x58 && len >= 2) {
        const int n = r.byte();
        const int dd = r.byte();
        r.skip(len - 2);
        // Kept when the score can say it (N 1..64, D 1..64).
        if (n >= 1 && n <= kMaxMeterNumerator && dd <= 6)
            smf.meters.push_back({tick, n, 1 << dd});
    } else {
        r.skip(len);
    }
}

// One MTrk chunk's events, from `r`.
void read_track(Reader &r, int track, Smf &smf)
{
    long tick = 0;
    int status = 0;
    while (!r.done()) {
        tick += r.vlq();
        if (tick > kMaxSmfTick)
            r.fail("time past " + std::to_string(kMaxSmfTick) + " ticks", r.pos());
        const size_t at = r.pos();
        int c = r.peek();
        if (c & 0x80) {
            r.byte();
            if (c == 0xff) {
                const int type = r.byte();
                if (type == 0x2f)
                    return; // end of track
                read_meta(r, type, tick, smf);
                continue;
            }
            if (c == 0xf0 || c == 0xf7) {
                r.skip(r.vlq());
                continue;
            }
            if (c >= 0xf1)
                r.fail("system message " + std::to_string(c) + " in a file", at);
            status = c;
        } else if (status == 0) {
            r.fail("data byte with no running status", at);
        }
        const int kind = status & 0xf0;
        const int a = r.data_byte();
        if (kind == 0xc0 || kind == 0xd0)
            continue;
        const int v = r.data_byte();
        if (kind == 0x90 && v > 0) {
            if (static_cast<long>(smf.notes.size()) >= kMaxSmfNotes)
                r.fail("more than " + std::to_string(kMaxSmfNotes) + " notes", at);
            smf.notes.push_back({tick, track, status & 0x0f, a, v});
        }
    }
}

} // namespace

Smf read_smf(const std::string &b, const std::string &source)
{
    Reader head(b, 0, b.size(), source, -1);
    if (b.compare(0, 4, "MThd") != 0)
        head.fail("not a Standard MIDI File (no MThd header)", 0);
    if (b.size() < 14)
        head.fail("truncated header (" + std::to_string(b.size()) + " bytes, 14 needed)", 0);
    const long head_len = u32(b, 4);
    if (head_len < 6 || static_cast<size_t>(head_len) > b.size() - 8)
        head.fail("header length " + std::to_string(head_len), 4);
    Smf smf;
    smf.format = (static_cast<unsigned char>(b[8]) << 8) | static_cast<unsigned char>(b[9]);
    const int division =
        (static_cast<unsigned char>(b[12]) << 8) | static_cast<unsigned char>(b[13]);
    if (smf.format > 1)
        head.fail("format " + std::to_string(smf.format) + " (0 and 1 are read)", 8);
    if (division & 0x8000)
        head.fail("SMPTE time division (ticks per quarter note are read)", 12);
    if (division == 0)
        head.fail("0 ticks per quarter note", 12);
    smf.ticks_per_quarter = division;
    size_t at = 8 + static_cast<size_t>(head_len);
    int track = 0;
    const int declared =
        (static_cast<unsigned char>(b[10]) << 8) | static_cast<unsigned char>(b[11]);
    while (at < b.size()) {
        // A few bytes after every track the header declares: padding some writers leave.
        if (b.size() - at < 8 && track > 0 && track >= declared)
            break;
        if (b.size() - at < 8)
            head.fail("truncated chunk header", at);
        const long len = u32(b, at + 4);
        if (static_cast<size_t>(len) > b.size() - at - 8)
            head.fail("chunk length " + std::to_string(len) + " runs past the end of the file",
                      at + 4);
        if (b.compare(at, 4, "MTrk") == 0) {
            Reader r(b, at + 8, at + 8 + static_cast<size_t>(len), source, track);
            read_track(r, track, smf);
            ++track;
        }
        at += 8 + static_cast<size_t>(len);
    }
    if (track == 0)
        head.fail("no track (MTrk chunk)", at);
    // A file that ends where a chunk does, before every track the header declares: cut
    // short (its other tracks' notes would be lost without a word).
    if (track < declared)
        head.fail("the file ends after " + std::to_string(track) + " of the " +
                      std::to_string(declared) + " tracks its header declares (cut short?)",
                  at);
    auto by_tick = [](const auto &x, const auto &y) { return x.tick < y.tick; };
    std::stable_sort(smf.notes.begin(), smf.notes.end(), by_tick);
    std::stable_sort(smf.tempo.begin(), smf.tempo.end(), by_tick);
    std::stable_sort(smf.meters.begin(), smf.meters.end(), by_tick);
    return smf;
}

namespace
{

// The snare's notes: 38, 40 on the head, 37 (side stick) on its rim.
bool is_snare(int note)
{
    return note == 38 || note == 40 || note == kMidiSideStick;
}
bool is_tom(int note)
{
    return note == 41 || note == 43 || note == 45 || note == 47 || note == 48 || note == 50;
}

// A note the right hand keeps time on: the hi-hat's (42, 46) and the ride's (51, 59, 53).
bool keeps_time(int note)
{
    return note == kMidiClosedHihat || note == kMidiOpenHihat || note == kMidiRide || note == 59 ||
           note == kMidiRideBell;
}

// A crash's note (49, 57): the left hand's, on whose side the built-in kits'
// crash stands (docs/kit.md: the right hand does not reach it).
bool left_hands(int note)
{
    return note == kMidiCrash || note == 57;
}

// A cymbal's note: the kit's cymbal that plays it (crash, ride or hi-hat), 0 for another note.
int cymbal_of(int note)
{
    if (note == kMidiClosedHihat || note == kMidiOpenHihat || note == kMidiPedalHihat)
        return kMidiClosedHihat;
    if (note == kMidiCrash || note == 57)
        return kMidiCrash;
    if (note == kMidiRide || note == 59 || note == kMidiRideBell)
        return kMidiRide;
    return 0;
}

// The drum (index into `drums`) of a General MIDI note, -1: not played;
// no drums: 0, the one drum, for every snare and tom. A cymbal's note plays on
// the kit's drum of its cymbal's note, if the kit has one.
int drum_of(int note, const std::vector<MidiDrum> &drums)
{
    if (note == kMidiAcousticBass || note == kMidiKick) {
        for (size_t i = 0; i < drums.size(); ++i)
            if (drums[i].midi_note == kMidiKick)
                return static_cast<int>(i);
        return -1;
    }
    if (const int cymbal = cymbal_of(note)) {
        for (size_t i = 0; i < drums.size(); ++i)
            if (drums[i].midi_note == cymbal)
                return static_cast<int>(i);
        return -1;
    }
    if (!is_snare(note) && !is_tom(note))
        return -1;
    if (drums.empty())
        return 0;
    const int want = is_snare(note) ? kMidiSnare : note;
    for (size_t i = 0; i < drums.size(); ++i)
        if (drums[i].midi_note == want)
            return static_cast<int>(i);
    if (is_snare(note))
        return -1;
    int best = -1;
    for (size_t i = 0; i < drums.size(); ++i)
        if (is_tom(drums[i].midi_note) && (best < 0 || std::abs(drums[i].midi_note - note) <
                                                           std::abs(drums[best].midi_note - note)))
            best = static_cast<int>(i);
    return best;
}

// The file's tempo map (start_bpm before its first tempo event) and meters on the
// score's beats (a quarter a beat).
void add_timing(const Smf &smf, MidiDrumPart &part, double start_bpm)
{
    const double tpq = smf.ticks_per_quarter;
    auto bpm_of = [&part](long us) {
        const double bpm = 60e6 / static_cast<double>(us);
        const double kept = std::clamp(bpm, kMinTempoBpm, kMaxTempoBpm);
        if (kept != bpm)
            ++part.tempo_clamped;
        return kept;
    };
    // Of two tempo events at one tick, the later in the file wins (TempoMap::add), at
    // tick 0 too: the first of them played the whole part at the wrong tempo.
    part.score.tempo = TempoMap(start_bpm);
    for (const SmfTempo &t : smf.tempo) {
        const double bpm = bpm_of(t.us_per_quarter);
        part.score.tempo.add(static_cast<double>(t.tick) / tpq, bpm, bpm, 0.0);
    }
    for (const SmfMeter &m : smf.meters)
        part.score.meters.push_back(
            {static_cast<double>(m.tick) / tpq, m.numerator, m.denominator, 0});
}

// The channel of the drum part: 10 (9) if it has notes, else all (-1).
int drum_channel(const Smf &smf)
{
    for (const SmfNote &n : smf.notes)
        if (n.channel == 9)
            return 9;
    return -1;
}

// A hand's note, for the second look at the sticking (turn_runs).
struct HandNote {
    size_t index = 0; // in the score's notes
    double t = 0.0;   // s
    long tick = 0;
    int drum = 0;
    bool set = false; // its hand is its instrument's (a crash, the time-keeper)
};

// How fast a hand moves from note a to note b: the distance between their pieces, plus a
// stroke's own travel, over the time between them (m/s); 0 when the pieces are not placed.
double move_speed(const std::vector<MidiDrum> &drums, const HandNote &a, const HandNote &b)
{
    const MidiDrum &p = drums[static_cast<size_t>(a.drum)], &q = drums[static_cast<size_t>(b.drum)];
    if (!p.placed || !q.placed)
        return 0.0;
    const double d = std::hypot(p.place_m[0] - q.place_m[0], p.place_m[1] - q.place_m[1],
                                p.place_m[2] - q.place_m[2]);
    return (d + kStrokeTravel_m) / std::max(b.t - a.t, 1e-9);
}

// The sticking's second look (docs/midi.md): a run of strokes that alternate between notes
// whose hands are set (a crash, the time-keeper, two notes at once) or a rest of
// kMidiAlternateBelow_s starts on the other hand when that makes the fastest move of a hand
// into or out of it at most kMidiTurnRunGain of what it was (a fill ends on the hand that
// does not go to the crash), each hand's strokes still kMidiSameHandMin_s apart.
void turn_runs(std::vector<ScoreNote> &score, const std::vector<HandNote> &notes,
               const std::vector<MidiDrum> &drums)
{
    const size_t n = notes.size();
    auto hand = [&](size_t i) { return score[notes[i].index].hand == Side::left ? 0 : 1; };
    auto fixed = [&](size_t i) {
        return notes[i].set || (i > 0 && notes[i - 1].tick == notes[i].tick) ||
               (i + 1 < n && notes[i + 1].tick == notes[i].tick);
    };
    auto joined = [&](size_t i) { // note i continues the run of note i - 1
        return !fixed(i) && !fixed(i - 1) && notes[i].t - notes[i - 1].t < kMidiAlternateBelow_s &&
               hand(i) != hand(i - 1);
    };
    for (size_t s = 0, e = 0; s < n; s = e + 1) {
        e = s;
        if (fixed(s))
            continue;
        while (e + 1 < n && joined(e + 1))
            ++e;
        const bool open_in =
            s == 0 || fixed(s - 1) || notes[s].t - notes[s - 1].t >= kMidiAlternateBelow_s;
        const bool open_out =
            e + 1 == n || fixed(e + 1) || notes[e + 1].t - notes[e].t >= kMidiAlternateBelow_s;
        if (!open_in || !open_out)
            continue;
        // The fastest move into and out of the run with its notes from `from` on turned
        // (e + 1: as they are; s: all), and, when from is inside it, between the notes
        // from - 1 and from, which one hand then plays (a double); infinite when a hand
        // would strike too soon.
        auto fastest = [&](size_t from, double *entry = nullptr) {
            double worst = 0.0;
            auto played = [&](size_t i) { return hand(i) ^ (i >= from ? 1 : 0); };
            for (int h = 0; h < 2; ++h) {
                const HandNote *before = nullptr, *after = nullptr, *first = nullptr,
                               *last = nullptr;
                for (size_t i = s; i-- > 0;)
                    if (hand(i) == h) {
                        before = &notes[i];
                        break;
                    }
                for (size_t i = e + 1; i < n && !after; ++i)
                    after = hand(i) == h ? &notes[i] : nullptr;
                for (size_t i = s; i <= e; ++i)
                    if (played(i) == h) {
                        first = first ? first : &notes[i];
                        last = &notes[i];
                    }
                if (!first)
                    continue;
                if ((before && first->t - before->t < kMidiSameHandMin_s) ||
                    (after && after->t - last->t < kMidiSameHandMin_s))
                    return std::numeric_limits<double>::infinity();
                const double in = before ? move_speed(drums, *before, *first) : 0.0;
                if (entry)
                    *entry = std::max(*entry, in);
                worst = std::max({worst, in, after ? move_speed(drums, *last, *after) : 0.0});
            }
            if (from > s && from <= e) {
                if (notes[from].t - notes[from - 1].t < kMidiSameHandMin_s)
                    return std::numeric_limits<double>::infinity();
                worst = std::max(worst, move_speed(drums, notes[from - 1], notes[from]));
            }
            return worst;
        };
        // Turned when that gains enough, or at all when a move as it is is beyond what an
        // arm reaches in time (a fill's last note a 16th before the crash, 0.74 m away).
        const double as_is = fastest(e + 1), turned = fastest(s);
        size_t from = e + 1;
        if (turned < kMidiTurnRunGain * as_is ||
            (as_is > kMidiPedalHihatAbove_mps && turned < as_is))
            from = s;
        // When the way chosen still asks a hand to come into the run faster than an arm
        // reaches in time (a ghost note a 16th after the right hand's hi-hat, before a fill
        // that ends on the right for the crash), turned from a later note on when that
        // brings its fastest move to at most kMidiTurnRunGain of what it was: the hand of
        // the note before it plays it too, a double (the ghost the left's, the fill ending
        // on two strokes of the right on the floor tom).
        double entry = 0.0;
        const double chosen = fastest(from, &entry);
        if (entry > kMidiPedalHihatAbove_mps) {
            double split = std::numeric_limits<double>::infinity();
            size_t at = 0;
            for (size_t j = s + 1; j <= e; ++j) {
                const double v = fastest(j);
                if (v < split) {
                    split = v;
                    at = j;
                }
            }
            if (at > 0 && split < kMidiTurnRunGain * chosen)
                from = at;
        }
        for (size_t i = from; i <= e; ++i) {
            ScoreNote &note = score[notes[i].index];
            note.hand = note.hand == Side::left ? Side::right : Side::left;
            if (!note.spot_given)
                note.theta_deg = kDefaultThetaDeg[note.hand == Side::left ? 0 : 1];
        }
    }
}

// The closed hi-hats on ticks both hands play that the right hand would reach from its last
// note faster than kMidiPedalHihatAbove_mps: the left foot's chicks when the foot is free
// (no chick within kMidiChickMin_s, `chick_s` its chicks' times); they leave the hands'
// notes. Returns how many.
long pedal_crowded_hihats(std::vector<ScoreNote> &score, std::vector<HandNote> &notes,
                          std::vector<double> &chick_s, const std::vector<MidiDrum> &drums)
{
    auto right = [&](size_t i) { return score[notes[i].index].hand == Side::right; };
    auto left_hand = [&](size_t j) { return !right(j) && !score[notes[j].index].foot; };
    auto left_on_tick = [&](size_t i) {
        for (size_t j = i; j-- > 0 && notes[j].tick == notes[i].tick;)
            if (left_hand(j))
                return true;
        for (size_t j = i + 1; j < notes.size() && notes[j].tick == notes[i].tick; ++j)
            if (left_hand(j))
                return true;
        return false;
    };
    auto foot_free = [&](double t) {
        for (double c : chick_s)
            if (std::abs(c - t) < kMidiChickMin_s - 1e-9)
                return false;
        return true;
    };
    std::vector<HandNote> kept;
    long pedalled = 0;
    size_t last_right = notes.size();
    for (size_t i = 0; i < notes.size(); ++i) {
        ScoreNote &s = score[notes[i].index];
        const bool closed_hat =
            right(i) && drums[static_cast<size_t>(notes[i].drum)].midi_note == kMidiClosedHihat &&
            s.openness == kHihatClosed;
        if (closed_hat && last_right < notes.size() && left_on_tick(i) &&
            move_speed(drums, notes[last_right], notes[i]) > kMidiPedalHihatAbove_mps &&
            foot_free(notes[i].t)) {
            s.foot = true; // as a 44's note
            s.hand = Side::left;
            s.openness = ScoreNote{}.openness;
            s.theta_deg = ScoreNote{}.theta_deg;
            chick_s.push_back(notes[i].t);
            ++pedalled;
            continue;
        }
        if (right(i))
            last_right = i;
        kept.push_back(notes[i]);
    }
    notes.swap(kept);
    return pedalled;
}

// The time-keeper's hi-hat notes that the right hand would reach, or leave for its next note,
// faster than kMidiLendHihatAbove_mps (the time-keeper changing between the ride and the
// hi-hat in a 16th, a metre) are the left hand's when it is free there: no note of its own
// within kMidiSameHandMin_s, its moves into and out of the hi-hat within
// kMidiPedalHihatAbove_mps, as a drummer keeps the hi-hat going with the left hand, uncrossed,
// while the right crosses the kit. From the change outward, one note at a time, until the
// right hand's move is within reach or the left is not free. Returns how many.
long lend_hihats_to_left(std::vector<ScoreNote> &score, const std::vector<HandNote> &notes,
                         const std::vector<MidiDrum> &drums)
{
    const size_t n = notes.size();
    auto right = [&](size_t i) { return score[notes[i].index].hand == Side::right; };
    auto hihat = [&](size_t i) {
        return drums[static_cast<size_t>(notes[i].drum)].midi_note == kMidiClosedHihat;
    };
    auto fast = [&](size_t a, size_t b, double above) {
        return move_speed(drums, notes[a], notes[b]) > above;
    };
    auto left_free = [&](size_t j) {
        if (!hihat(j))
            return false;
        for (size_t i = j; i-- > 0;)
            if (!right(i)) {
                if (notes[j].t - notes[i].t < kMidiSameHandMin_s ||
                    fast(i, j, kMidiPedalHihatAbove_mps))
                    return false;
                break;
            }
        for (size_t i = j + 1; i < n; ++i)
            if (!right(i)) {
                if (notes[i].t - notes[j].t < kMidiSameHandMin_s ||
                    fast(j, i, kMidiPedalHihatAbove_mps))
                    return false;
                break;
            }
        return true;
    };
    auto lend = [&](size_t j) {
        ScoreNote &s = score[notes[j].index];
        s.hand = Side::left;
        if (!s.spot_given)
            s.theta_deg = kDefaultThetaDeg[0];
    };
    long lent = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!right(i))
            continue;
        // The right hand's note before it, and lending on either side until the move from
        // it is within reach.
        for (size_t guard = 0; guard < n; ++guard) {
            size_t p = i;
            while (p-- > 0 && !right(p)) {
            }
            if (p >= i || !fast(p, i, kMidiLendHihatAbove_mps))
                break;
            if (left_free(i)) {
                lend(i);
                ++lent;
                break; // the next right note is measured from p
            }
            if (!left_free(p))
                break;
            lend(p);
            ++lent;
        }
    }
    return lent;
}

// The crash notes the left hand would reach from its last note faster than
// kMidiLendHihatAbove_mps (a ghost note on the snare a 16th before, 0.74 m away) are the right
// hand's when it is free there: no note of its own on the tick or within kMidiSameHandMin_s,
// its moves into and out of the crash within kMidiLendHihatAbove_mps and slower than the
// left's, as a drummer keeping time on the hi-hat, beside the crash, takes the crash with the
// right hand. Returns how many.
long give_crashes_to_right(std::vector<ScoreNote> &score, const std::vector<HandNote> &notes,
                           const std::vector<MidiDrum> &drums)
{
    const size_t n = notes.size();
    auto hand_of = [&](size_t i) { return score[notes[i].index].hand; };
    // The note of `hand` before (step -1) or after (+1) note i; n when none.
    auto next_of = [&](size_t i, Side hand, int step) {
        for (size_t j = i; step < 0 ? j-- > 0 : ++j < n;)
            if (hand_of(j) == hand)
                return j;
        return n;
    };
    long given = 0;
    for (size_t i = 0; i < n; ++i) {
        if (hand_of(i) != Side::left ||
            drums[static_cast<size_t>(notes[i].drum)].midi_note != kMidiCrash)
            continue;
        const size_t from = next_of(i, Side::left, -1);
        if (from == n)
            continue;
        const double left = move_speed(drums, notes[from], notes[i]);
        if (left <= kMidiLendHihatAbove_mps)
            continue;
        const size_t before = next_of(i, Side::right, -1), after = next_of(i, Side::right, +1);
        bool free = true;
        double right = 0.0;
        if (before < n) {
            free = free && notes[i].t - notes[before].t >= kMidiSameHandMin_s;
            right = std::max(right, move_speed(drums, notes[before], notes[i]));
        }
        if (after < n) {
            free = free && notes[after].t - notes[i].t >= kMidiSameHandMin_s;
            right = std::max(right, move_speed(drums, notes[i], notes[after]));
        }
        if (!free || right > kMidiLendHihatAbove_mps || right >= left)
            continue;
        ScoreNote &s = score[notes[i].index];
        s.hand = Side::right;
        if (!s.spot_given)
            s.theta_deg = kDefaultThetaDeg[1];
        ++given;
    }
    return given;
}

// Takes the notes marked in dropped out of the score, and out of the hands' notes, whose
// indices follow.
void drop_notes(std::vector<ScoreNote> &notes, std::vector<HandNote> &hand_notes,
                const std::vector<bool> &dropped)
{
    std::vector<size_t> moved_to(notes.size());
    size_t kept = 0;
    for (size_t i = 0; i < notes.size(); ++i) {
        moved_to[i] = kept;
        if (!dropped[i])
            notes[kept++] = notes[i];
    }
    notes.resize(kept);
    std::vector<HandNote> still;
    for (HandNote h : hand_notes)
        if (!dropped[h.index]) {
            h.index = moved_to[h.index];
            still.push_back(h);
        }
    hand_notes = std::move(still);
}
} // namespace

MidiDrumPart drum_part_score(const Smf &smf, const std::vector<MidiDrum> &drums,
                             const std::string &source, double start_bpm)
{
    MidiDrumPart part;
    part.score.source = source;
    add_timing(smf, part, start_bpm);
    part.channel = drum_channel(smf);
    const double tpq = smf.ticks_per_quarter;
    const TempoMap &map = part.score.tempo;
    // The hands' last strokes (s; -inf: none yet) and the last note kept; each hand's last
    // note (in hand_notes; -1: none) and the stroke before it, for a louder note that
    // takes the hand from a soft one just before (a flam's grace under the hi-hat).
    double last_of[2] = {-1e300, -1e300}, before_last_of[2] = {-1e300, -1e300};
    long last_note_of[2] = {-1, -1};
    std::vector<bool> dropped;
    double last_foot_s[2] = {-1e300, -1e300}; // the right foot's, the left's
    double last_s = -1e300;
    long last_tick = -1;
    int last_hand = 1, at_tick = 0;
    std::vector<HandNote> hand_notes;
    std::vector<double> chick_s; // the left foot's chicks (44)
    // The notes in file order, but at one tick the ride's, then the hi-hat's first: the
    // right hand keeps time on them and the other hand plays what falls with them (crossed
    // over the hi-hat, as a right-handed drummer plays a groove; the hi-hat the left's
    // beside the ride, on the right, uncrossed).
    std::vector<size_t> order(smf.notes.size());
    for (size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const SmfNote &x = smf.notes[a], &y = smf.notes[b];
        if (x.tick != y.tick)
            return x.tick < y.tick;
        // At one tick: the right hand's time first (the ride before the hi-hat), then the
        // left's crash.
        auto rank = [](int note) {
            return cymbal_of(note) == kMidiRide ? 0
                   : keeps_time(note)           ? 1
                   : left_hands(note)           ? 2
                                                : 3;
        };
        return rank(x.note) < rank(y.note);
    });
    std::set<long> open_hihat_ticks; // the drum part's 46s (42's drum, when the kit has one)
    for (const SmfNote &n : smf.notes)
        if (n.note == kMidiOpenHihat && (part.channel < 0 || n.channel == part.channel))
            open_hihat_ticks.insert(n.tick);
    for (size_t index : order) {
        const SmfNote &n = smf.notes[index];
        const int line = static_cast<int>(index) + 1;
        if (part.channel >= 0 && n.channel != part.channel) {
            ++part.other_channels;
            continue;
        }
        const int drum = drum_of(n.note, drums);
        if (drum < 0) {
            ++part.skipped[n.note];
            continue;
        }
        if (n.note == kMidiClosedHihat && open_hihat_ticks.count(n.tick)) {
            ++part.hihats_opened; // one pedal: the open hi-hat on its tick wins
            continue;
        }
        const double beat = static_cast<double>(n.tick) / tpq;
        if (beat > kMaxScoreBeats) {
            std::ostringstream what; // the beat as written: 296827.5, not 296827.500000
            what << source << ": note " << line << " at beat " << std::setprecision(15) << beat
                 << " is past the score's limit of " << kMaxScoreBeats << " beats (docs/score.md)";
            throw MidiFileError(what.str());
        }
        const double t = map.time_at_beat(beat);
        const bool kick = n.note == kMidiAcousticBass || n.note == kMidiKick;
        if (kick || n.note == kMidiPedalHihat) {
            // A foot's, beside the hands: the right on the kick, the left's
            // chick on the hi-hat.
            double &last_foot = last_foot_s[kick ? 0 : 1];
            if (t - last_foot < (kick ? kMidiFootMin_s : kMidiChickMin_s) - 1e-9) {
                ++part.feet_too_fast;
                continue;
            }
            ScoreNote s;
            s.beat = beat;
            s.beats = kMinNoteBeats;
            s.hand = kick ? Side::right : Side::left;
            s.foot = true;
            s.dynamics = n.velocity / 127.0;
            s.line = line;
            s.drum_line = line;
            s.drum = drums[static_cast<size_t>(drum)].name;
            part.score.notes.push_back(s);
            last_foot = t;
            if (!kick)
                chick_s.push_back(t);
            continue;
        }
        // Hands: at the same tick the other hand (two at once at most);
        // close to the previous note the other hand; far from it the right.
        int hand;
        if (n.tick == last_tick) {
            if (++at_tick > 1) {
                ++part.too_fast;
                continue;
            }
            hand = 1 - last_hand;
        } else {
            at_tick = 0;
            hand = left_hands(n.note)                                          ? 0
                   : keeps_time(n.note) || t - last_s >= kMidiAlternateBelow_s ? 1
                                                                               : 1 - last_hand;
            if (t - last_of[hand] < kMidiSameHandMin_s)
                hand = 1 - hand;
        }
        if (t - last_of[hand] < kMidiSameHandMin_s) {
            // Both hands taken: a louder note than the hand's last, a soft note of its own
            // choosing (not the time-keeper's or the crash's), takes the hand from it, as a
            // drummer leaves out the grace and keeps the accent.
            const HandNote *prev = last_note_of[hand] >= 0
                                       ? &hand_notes[static_cast<size_t>(last_note_of[hand])]
                                       : nullptr;
            const bool takes = prev && !prev->set &&
                               n.velocity / 127.0 > part.score.notes[prev->index].dynamics &&
                               t - before_last_of[hand] >= kMidiSameHandMin_s;
            ++part.too_fast;
            if (!takes)
                continue;
            dropped.resize(part.score.notes.size(), false); // the feet's notes too
            dropped[prev->index] = true;
            last_of[hand] = before_last_of[hand];
        }
        ScoreNote s;
        s.beat = beat;
        s.beats = kMinNoteBeats;
        s.hand = hand == 0 ? Side::left : Side::right;
        s.dynamics = n.velocity / 127.0;
        s.theta_deg = kDefaultThetaDeg[hand];
        if (n.note == kMidiSideStick) {
            s.r_over_a = kMidiSideStickRadiusFraction;
            s.theta_deg = kMidiSideStickThetaDeg;
        } else if (n.note == kMidiRideBell) {
            s.r_over_a = kMidiRideBellRadiusFraction;
            s.theta_deg = kCymbalThetaDeg[hand == 0 ? 0 : 1];
        }
        s.spot_given = n.note == kMidiSideStick || n.note == kMidiRideBell;
        if (n.note == kMidiClosedHihat || n.note == kMidiOpenHihat)
            s.openness = n.note == kMidiOpenHihat ? kHihatOpen : kHihatClosed;
        s.line = line;
        s.drum_line = line;
        if (!drums.empty())
            s.drum = drums[static_cast<size_t>(drum)].name;
        last_note_of[hand] = static_cast<long>(hand_notes.size());
        hand_notes.push_back(
            {part.score.notes.size(), t, n.tick, drum, left_hands(n.note) || keeps_time(n.note)});
        part.score.notes.push_back(s);
        before_last_of[hand] = last_of[hand];
        last_of[hand] = t;
        last_s = t;
        last_tick = n.tick;
        last_hand = hand;
    }
    dropped.resize(part.score.notes.size(), false);
    drop_notes(part.score.notes, hand_notes, dropped);
    if (!drums.empty()) {
        // Before the second look, which then sees the right hand free, and after it, for a
        // run it turned onto the right hand's last note.
        part.hihats_pedalled = pedal_crowded_hihats(part.score.notes, hand_notes, chick_s, drums);
        turn_runs(part.score.notes, hand_notes, drums);
        part.hihats_pedalled += pedal_crowded_hihats(part.score.notes, hand_notes, chick_s, drums);
        part.crashes_given = give_crashes_to_right(part.score.notes, hand_notes, drums);
        part.hihats_lent = lend_hihats_to_left(part.score.notes, hand_notes, drums);
    }
    for (size_t i = 0; i + 1 < part.score.notes.size(); ++i)
        part.score.notes[i].beats =
            std::max(kMinNoteBeats, part.score.notes[i + 1].beat - part.score.notes[i].beat);
    if (!part.score.notes.empty())
        part.score.length_beats = part.score.notes.back().beat + 1.0;
    return part;
}

MidiDrumPart load_midi_drum_part(const std::string &path, const std::vector<MidiDrum> &drums,
                                 double start_bpm)
{
    InputFile in = open_input_file(path);
    if (in.is_folder)
        throw MidiFileError(path + ": a folder, not a MIDI file");
    if (!in.opened)
        throw MidiFileError(path + ": cannot be read" + in.reason_suffix());
    std::ostringstream bytes;
    bytes << in.stream.rdbuf();
    MidiDrumPart part = drum_part_score(read_smf(bytes.str(), path), drums, path, start_bpm);
    if (part.score.notes.empty())
        throw MidiFileError(path + ": no note the " + (drums.empty() ? "drum" : "kit") +
                            " can play (snares 38, 40, side stick 37, toms 41..50 and, on a kit "
                            "with cymbals, crash 49, 57, ride 51, 53, 59 and hi-hat 42, 46, 44, "
                            "on a kit with a kick, 35, 36 of the General MIDI drum map, on channel "
                            "10 "
                            "if it has notes)");
    return part;
}

} // namespace ictus
