// statement.hpp -- a parsed statement of the score language (private to
// src/score): what score.cpp's parser makes of one statement, and the
// executor (score_execute.cpp) that runs a balanced list of them into a
// Score. The language: docs/score.md.
#pragma once

#include "ictus/score/score.hpp"

#include <optional>
#include <string>
#include <vector>

namespace ictus
{
namespace score_detail
{

enum class Kind {
    note,
    rest,
    tempo,
    grip,
    default_beats,
    default_dynamics,
    default_firmness,
    default_nuance,
    roll,
    meter,
    drum,
    humanize,
    repeat,
    end
};

enum class Roll { single, double_stroke, buzz };

struct Statement {
    Kind kind = Kind::note;
    int line = 0;
    int column = 0;
    // note
    Side hand = Side::right;
    bool foot = false;       // RF: the right foot's (the kick's pedal), not a hand's
    bool both_hands = false; // R+L: one stroke of each hand on the same beat
    // `R ... + L ... + RF`: the next statement is another limb's note on the same beat
    // (the beat advances after the chord's last, by the longest of its durations)
    bool with_next = false;
    std::optional<Nuance> nuance;   // note, default_nuance
    std::optional<double> beats;    // note, rest, default_beats
    std::optional<double> dynamics; // note, default_dynamics
    std::optional<double> r_over_a, theta_deg;
    std::optional<double> firmness; // note, default_firmness
    // tempo: start_bpm absent means "from the current tempo"
    std::optional<double> start_bpm;
    double end_bpm = 0.0;
    double ramp_beats = 0.0;
    Grip grip = Grip::french;
    int count = 0; // repeat
    // note: a flam or a drag (its word's column, for errors)
    Grace ornament = Grace::none;
    int ornament_column = 0;
    // default_dynamics: a hairpin to dynamics_end over ramp_beats (dynamics
    // absent: from the current dynamics)
    std::optional<double> dynamics_end;
    Roll roll = Roll::single;           // roll: its kind, and its length in ramp_beats
    int numerator = 4, denominator = 4; // meter
    // drum (the current drum) and a note's `on NAME`: the name, lower case,
    // and its column
    std::optional<std::string> drum;
    int drum_column = 0;
    int spot_column = 0; // note: its 'at' word's column, for errors (r_over_a, theta_deg)
    // note: the hi-hat's pedal (`open`, `half`, `closed`) and its word's column
    std::optional<double> openness;
    int openness_column = 0;
    double humanize = 0.0; // humanize
};

// Runs `statements` (parsed, repeat/end balanced) into a score: repeats
// expanded, defaults and hairpins applied, flams, drags and rolls made into
// their strokes, the notes in time order. Throws ScoreError.
Score execute_statements(const std::string &source, const std::vector<Statement> &statements);

} // namespace score_detail
} // namespace ictus
