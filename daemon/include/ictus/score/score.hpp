// score.hpp -- the score language: what the virtual percussionist plays,
// written the same way in a Pd message box (one statement per message) and in
// a text file (one statement per line, or separated by ';' or ','). A score
// is parsed whole before any note is produced, so a bad score plays nothing.
// The language, its defaults and its errors are documented in docs/score.md.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/gesture/gesture.hpp"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{

// A fault in a score. what() is "source:line:column: message"; line and
// column are 1-based (for statements added one by one, line is the
// statement's number and column counts in that statement's text).
class ScoreError : public std::runtime_error
{
  public:
    ScoreError(const std::string &source, int line, int column, const std::string &message);
    const std::string &source() const { return source_; }
    int line() const { return line_; }
    int column() const { return column_; }
    const std::string &message() const { return message_; }

  private:
    std::string source_;
    int line_;
    int column_;
    std::string message_;
};

// Limits the parser enforces (docs/score.md).
constexpr double kMinTempoBpm = 20.0;
constexpr double kMaxTempoBpm = 400.0;
constexpr double kMinNoteBeats = 1.0 / 32.0;
constexpr double kMaxNoteBeats = 64.0;
constexpr double kMaxRadiusFraction = 0.95; // r/a: the bead must land on the head
constexpr int kMaxRepeat = 1000;
constexpr double kMaxHumanize = 4.0;   // `humanize AMOUNT`: 0..4
constexpr int kMaxScoreNotes = 100000; // after repeats are expanded
constexpr double kMaxScoreBeats = 100000.0;
// Statements executed while repeats are expanded: bounds the work of scores
// whose loops hold no note or rest (e.g. nested repeats around a grip line).
constexpr long kMaxScoreSteps = 1000000;

// Defaults: a note with nothing but a hand.
constexpr double kDefaultTempoBpm = 120.0;
constexpr double kDefaultNoteBeats = 1.0;
constexpr double kDefaultDynamics = 0.6; // mf
constexpr double kDefaultRadiusFraction = 0.3;
// Membrane-frame angle (docs/osc.md: x_m along world +X, the performer's
// left; y_m along world -Z, toward the performer) of each hand's default
// spot: the right hand plays on the performer's right (x_m < 0).
constexpr double kDefaultThetaDeg[2] = {0.0, 180.0}; // [Side::left, Side::right]
// A kit's cymbal (docs/kit.md, "Cymbals") is played, where the note gives no
// spot, on its bow toward the performer: r/a 0.7, each hand 20 degrees to its
// own side of the point nearest the performer (theta 90).
constexpr double kCymbalRadiusFraction = 0.7;
constexpr double kCymbalThetaDeg[2] = {70.0, 110.0}; // [Side::left, Side::right]
// A cymbal note, given no spot, that its hand reaches from a note on another piece faster
// than kCymbalFaceAbove_mps (the distance from that note's strike point to the spot, plus a
// stroke's kStrokeTravel_m, over the time between them) is played on its bow turned from
// kCymbalThetaDeg toward that point by at most kCymbalFaceMostDeg: an arm crossing the kit
// fast overshoots along its way, and from the near side it lands on the plate instead of
// past its far edge (docs/kit.md, "The spot"; on bench/perform/random_parts.py's parts).
constexpr double kStrokeTravel_m = 0.1;
constexpr double kCymbalFaceAbove_mps = 3.5;
constexpr double kCymbalFaceMostDeg = 45.0;
// A cymbal's bell (`on ride-bell`, General MIDI's 53): a stroke aimed this near
// the centre (a 20-inch ride's bell is about 6 inches across), at the bow's
// kCymbalThetaDeg: the stick lies over the bow toward the performer. Aimed at
// the hand's drum angle (theta 180 for the right) the palm comes down through
// the ride's bow (4 mm in a swing ride at 140 bpm).
constexpr double kBellRadiusFraction = 0.12;
// A drum's rim (`on snare-rim`): a stroke aimed at the head's edge where it
// faces the hand's shoulder in plan, the stick's end kRimInset_m inside the
// edge, half the default bead's radius: the bead's centre, a bead's radius
// back along the stick from its end, is then within a bead's radius of the
// edge whichever way the stick points, and the bead meets the hoop on any drum
// (r/a 0.95 leaves 1 cm of head inside a 16-inch floor tom's edge: the bead on
// the head). Facing the shoulder, the edge is in reach wherever the drum
// stands (the left hand on the full kit's floor tom, far to the right, lost
// its notes aimed at the edge nearest the performer).
constexpr double kRimInset_m = 0.0035;
// A rim note's `at R THETA` gives the place along the edge (THETA), struck as
// above; R must be at least this, the spot's own way of saying "the edge"
// (e2e_rim_zone: aimed at r/a 0.87 and inside, the bead lands on the head).
// Below it the note names the rim and a spot on the head: a ScoreError.
constexpr double kRimAtLeastRadiusFraction = 0.9;

// The hi-hat's pedal as a note writes it (docs/score.md, `open`, `half`,
// `closed`): membrane~'s `openness` (docs/plates.md, "The hi-hat"), 0 the
// plates pressed together, 1 held apart by the stand's spring. A hi-hat
// note that names none is closed.
constexpr double kHihatClosed = 0.0;
constexpr double kHihatHalf = 0.5;
constexpr double kHihatOpen = 1.0;
// The word for an openness ("open", "half", "closed"; "" for another value).
const char *hihat_openness_word(double openness);

// Grace strokes (docs/score.md, "Flams, drags and rolls"): a flam's one
// grace stroke of the other hand kFlamGraceLead_s before its note; a drag's
// two, the second kFlamGraceLead_s before the note and the first
// kDragGraceSpacing_s before that (a double of the other hand, above the
// body's 40 ms same-hand limit). Played at kGraceDynamics, or half the
// note's dynamics if that is less, legato, on the hand's default spot.
constexpr double kFlamGraceLead_s = 0.030;
constexpr double kDragGraceSpacing_s = 0.040;
constexpr double kGraceDynamics = 0.15;
// Meters (`meter N/D`): N 1..kMaxMeterNumerator, D a power of two 1..kMaxMeterDenominator.
constexpr int kMaxMeterNumerator = 64;
constexpr int kMaxMeterDenominator = 64;

// What a note is: a written stroke, or a grace stroke of a flam or a drag.
enum class Grace { none, flam, drag };
const char *to_string(Grace grace);

// One stroke of the score, in beats (times come from the tempo map).
struct ScoreNote {
    double beat = 0.0;  // onset (the strike), beats from the start of the score
    double beats = 1.0; // duration: the next statement starts this much later
    Side hand = Side::right;
    // Played by the foot of `hand`'s side (`RF`: the right foot on the kick's
    // pedal, docs/pedal.md), not by the hand.
    bool foot = false;
    Nuance nuance = Nuance::legato;
    Grip grip = Grip::french;
    double dynamics = kDefaultDynamics; // 0 (softest) .. 1 (loudest)
    double r_over_a = kDefaultRadiusFraction;
    double theta_deg = 180.0; // membrane frame, in (-180, 180]
    bool spot_given = false;  // by `at` (else the hand's default spot, or a cymbal's)
    int spot_column = 0;      // its `at` word's column, 0 when not written (a MIDI note's)
    // The grip's firmness for this stroke, 0 (loose) .. 1 (clamped); < 0:
    // the performance's own (its default, or /ictus/grip/firmness).
    double firmness = -1.0;
    int line = 0; // where the note was written
    int column = 0;
    // The drum of a kit it is played on (`drum NAME`, `on NAME`; lower
    // case), "" for the kit's first (or the one drum); where the name was
    // written (the note's line, or the `drum` statement's), for the
    // planner's error when the kit has no such drum.
    std::string drum;
    int drum_line = 0, drum_column = 0;
    // The hi-hat's pedal for this note (`open` 1, `half` 0.5, `closed` 0:
    // kHihatOpen ...), < 0 when the note names none (closed on a hi-hat);
    // the word's column, for the planner's error when the drum is not a hi-hat.
    double openness = -1.0;
    int openness_column = 0;
    // A grace stroke (its ornament; none: a written note) is played
    // grace_lead_s before `beat`, the beat of the note it ornaments.
    Grace grace = Grace::none;
    double grace_lead_s = 0.0;
};

// A `meter N/D` statement: from `beat` on (carried to MIDI; the beat stays
// the tempo's beat).
struct ScoreMeter {
    double beat = 0.0;
    int numerator = 4;
    int denominator = 4;
    int line = 0;
};

// Tempo as a function of score position: a list of changes, each setting the
// tempo at a beat and optionally ramping it linearly (in beats) to another
// tempo over some beats, then holding it until the next change. Time is the
// integral of 60 / tempo(beat) d(beat) (closed form per piece).
class TempoMap
{
  public:
    struct Change {
        double beat = 0.0;         // where the change starts
        double start_bpm = 120.0;  // tempo at `beat`
        double end_bpm = 120.0;    // tempo at beat + ramp_beats and after
        double ramp_beats = 0.0;   // 0: instant change
        double start_time_s = 0.0; // time_at_beat(beat), filled in by add()
    };

    explicit TempoMap(double initial_bpm = kDefaultTempoBpm);
    // Changes must come in non-decreasing beat order; a change cuts short a
    // ramp still running at its beat. Throws std::invalid_argument otherwise.
    void add(double beat, double start_bpm, double end_bpm, double ramp_beats);

    double tempo_at_beat(double beat) const; // bpm
    double time_at_beat(double beat) const;  // s from beat 0; beats < 0 at the first tempo
    double beat_at_time(double time_s) const;
    const std::vector<Change> &changes() const { return changes_; }

  private:
    std::vector<Change> changes_; // changes_[0] at beat 0
    const Change &change_at(double beat) const;
};

// A whole parsed score.
struct Score {
    std::string source;             // file name or "osc", for messages
    std::vector<ScoreNote> notes;   // in onset time order (ties: in the order written)
    TempoMap tempo;                 // beat -> time
    std::vector<ScoreMeter> meters; // in beat order; none: 4/4
    double length_beats = 0.0;      // end of the last statement (note or rest)
    // `humanize AMOUNT` (docs/humanize.md); < 0: not written
    // (the performance's amount, 0 by default). The last statement wins.
    double humanize = -1.0;
    double duration_s() const { return tempo.time_at_beat(length_beats); }
    double note_time_s(const ScoreNote &note) const
    {
        return tempo.time_at_beat(note.beat) - note.grace_lead_s;
    }
};

// The live tempo scale (docs/osc.md, /ictus/tempo in score mode): the tempo
// map with every tempo from `from_beat` on multiplied by `factor`, the beats
// before it (and so every time up to it) as they were. A ramp running at
// `from_beat` goes on, scaled, to its end. Throws std::invalid_argument when a
// scaled tempo leaves the score's range (kMinTempoBpm..kMaxTempoBpm).
TempoMap scale_tempo_from(const TempoMap &map, double from_beat, double factor);
// The score with its tempo map scaled so (scale_tempo_from).
Score scale_score_from(const Score &score, double from_beat, double factor);

// Builds a score one statement at a time, as statements arrive from Pd
// (`/ictus/score ,s "L accent 0.8"`). Each add_statement() counts as one line
// for error positions. A statement that throws changes nothing; once one has
// thrown, finish() refuses the score (throws the first error again) so a
// score with a fault is never played, even in part.
class ScoreBuilder
{
  public:
    explicit ScoreBuilder(std::string source_name = "osc");
    ~ScoreBuilder();
    ScoreBuilder(ScoreBuilder &&) noexcept;
    // A copy, e.g. to finish and plan elsewhere while statements keep arriving.
    ScoreBuilder(const ScoreBuilder &other);
    ScoreBuilder &operator=(ScoreBuilder &&) noexcept;

    // Parses one statement (it may hold several separated by ',' or ';',
    // and a '#' comment). Throws ScoreError.
    void add_statement(const std::string &text);
    // The statements so far as a score; throws ScoreError when a statement
    // failed or a `repeat` is still open. The builder is left as it was.
    Score finish() const;
    // The nuance of the notes that follow and name none, as the statement
    // `nuance N` would set it, but not counted as a statement (statements()
    // and error positions stay those of the statements received): what
    // /ictus/nuance does in score mode.
    void set_default_nuance(Nuance nuance);
    // The tempo the score starts at until its own first `tempo` statement
    // (ictusd --tempo), as a `tempo BPM` before the first statement would set
    // it, not counted as a statement. Throws ScoreError outside 20..400 bpm.
    void set_start_tempo(double bpm);
    int statements() const; // how many add_statement() calls so far
    // The tempo the statements so far start at (their beat 0): that of the
    // last `tempo` before the first note, roll or rest; the default (120 bpm)
    // without one. What finish() would give as tempo.tempo_at_beat(0).
    double first_tempo_bpm() const;
    // How many statements they held (a line may hold several; comments none).
    std::size_t parsed_statements() const;
    bool failed() const;
    void reset(); // back to an empty score, errors forgotten

  private:
    friend Score parse_score(const std::string &, const std::string &, double);
    struct State;
    std::unique_ptr<State> state_;
    // Parses `text` as line `line` and appends its statements (all or none).
    void add_line(const std::string &text, int line);
};

// Parses a whole score (a file's contents): statements separated by
// newlines, ';' or ','; '#' starts a comment. Throws ScoreError at the first
// fault, naming `source_name`, the line and the column. The score starts at
// start_bpm until its first `tempo` statement.
Score parse_score(const std::string &text, const std::string &source_name,
                  double start_bpm = kDefaultTempoBpm);
// Whether a score's text holds a statement, faulty or not: false for an empty text or one
// of blank lines and comments only (a score file with no notes, refused as one).
bool score_text_has_statements(const std::string &text);
// Reads and parses a file; throws ScoreError (line 0) when it cannot be read.
Score load_score(const std::string &path);

// The built-in score the main job plays (the paper's Figure 5: legato and
// accent beats of both hands under a tempo change, ~15 s).
const char *default_score_text();

// Dynamics words and their values (pp .. ff), for docs and tests.
struct DynamicsWord {
    const char *word;
    double value;
};
const std::vector<DynamicsWord> &dynamics_words();

} // namespace ictus
