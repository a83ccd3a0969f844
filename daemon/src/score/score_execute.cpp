// score_execute.cpp -- the score language's executor (docs/score.md):
// parsed statements into notes, with repeats expanded, defaults and
// hairpins applied and flams, drags and rolls made into their strokes.
#include "statement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ictus
{
namespace score_detail
{

namespace
{

// Runs the parsed statements into notes: repeats expanded, defaults and
// hairpins applied, flams, drags and rolls made into their strokes.
class Executor
{
  public:
    explicit Executor(const std::string &source) { score_.source = source; }

    Score run(const std::vector<Statement> &statements)
    {
        struct Loop {
            size_t body; // first statement of the body
            int left;    // passes still to play after this one
        };
        std::vector<Loop> loops;
        long steps = 0;
        for (size_t pc = 0; pc < statements.size(); ++pc) {
            const Statement &st = statements[pc];
            if (++steps > kMaxScoreSteps)
                fail(st, "the score executes more than 1000000 statements (check the repeat "
                         "counts: repeats nested around no note or rest)");
            if (st.kind == Kind::repeat) {
                loops.push_back({pc + 1, st.count - 1});
            } else if (st.kind == Kind::end) {
                if (loops.back().left > 0) {
                    --loops.back().left;
                    pc = loops.back().body - 1;
                } else {
                    loops.pop_back();
                }
            } else {
                execute(st);
            }
        }
        score_.length_beats = beat_;
        // Grace strokes come before their note's beat, maybe before notes
        // written earlier: the notes in time order, ties as written.
        std::vector<double> time(score_.notes.size());
        std::vector<size_t> order(score_.notes.size());
        for (size_t i = 0; i < order.size(); ++i) {
            order[i] = i;
            time[i] = score_.note_time_s(score_.notes[i]);
        }
        std::stable_sort(order.begin(), order.end(),
                         [&](size_t a, size_t b) { return time[a] < time[b]; });
        std::vector<ScoreNote> sorted;
        sorted.reserve(order.size());
        for (size_t i : order)
            sorted.push_back(score_.notes[i]);
        score_.notes = std::move(sorted);
        return std::move(score_);
    }

  private:
    Score score_;
    double beat_ = 0.0;
    double chord_beats_ = 0.0;            // the longest note of a chord so far (`R ... + L ...`)
    double chord_written_ = 0.0;          // its longest written duration (0: none written)
    std::vector<size_t> chord_unwritten_; // its notes without one (indices into the score's)
    Grip grip_ = Grip::french;
    double default_beats_ = kDefaultNoteBeats;
    double default_firmness_ = -1.0; // the performance's
    Nuance default_nuance_ = Nuance::legato;
    std::string drum_; // the current drum ("": the kit's first)
    int drum_line_ = 0, drum_column_ = 0;
    // Dynamics: d0 at beat0, linearly to d1 at beat0 + ramp, then d1.
    double dyn_beat0_ = 0.0, dyn0_ = kDefaultDynamics, dyn1_ = kDefaultDynamics, dyn_ramp_ = 0.0;

    [[noreturn]] void fail(const Statement &st, const std::string &message) const
    {
        throw ScoreError(score_.source, st.line, st.column, message);
    }

    // The default dynamics at `beat` (the hairpin running there, or the last `dynamics D`).
    double dynamics_at(double beat) const
    {
        const double in = beat - dyn_beat0_;
        if (dyn_ramp_ <= 0.0 || in >= dyn_ramp_)
            return dyn1_;
        return in <= 0.0 ? dyn0_ : dyn0_ + (dyn1_ - dyn0_) * in / dyn_ramp_;
    }

    void advance(const Statement &st, double beats)
    {
        beat_ += beats;
        if (beat_ > kMaxScoreBeats)
            fail(st, "the score is longer than 100000 beats (check the repeat counts)");
    }

    void add(const Statement &st, const ScoreNote &n)
    {
        if (score_.notes.size() >= static_cast<size_t>(kMaxScoreNotes))
            fail(st, "the score has more than 100000 notes (check the repeat counts)");
        score_.notes.push_back(n);
    }

    // A stroke of `hand` at the current beat with the defaults.
    ScoreNote stroke(const Statement &st, Side hand) const
    {
        ScoreNote n;
        n.beat = beat_;
        n.beats = default_beats_;
        n.nuance = default_nuance_;
        n.grip = grip_;
        n.dynamics = dynamics_at(beat_);
        n.firmness = default_firmness_;
        n.hand = hand;
        n.foot = st.foot;
        n.theta_deg = kDefaultThetaDeg[static_cast<int>(hand)];
        n.line = st.line;
        n.column = st.column;
        n.drum = drum_;
        n.drum_line = drum_line_;
        n.drum_column = drum_column_;
        return n;
    }

    void note(const Statement &st)
    {
        ScoreNote n = stroke(st, st.hand);
        n.beats = st.beats.value_or(default_beats_);
        n.nuance = st.nuance.value_or(default_nuance_);
        n.dynamics = st.dynamics.value_or(n.dynamics);
        n.r_over_a = st.r_over_a.value_or(kDefaultRadiusFraction);
        n.spot_given = st.r_over_a.has_value() || st.theta_deg.has_value();
        n.spot_column = n.spot_given ? st.spot_column : 0;
        n.firmness = st.firmness.value_or(default_firmness_);
        if (n.foot) {
            // The foot plays its pedal's drum (the planner finds the kit's
            // kick), not the hands' current drum.
            n.drum.clear();
            n.drum_line = st.line;
            n.drum_column = st.column;
        }
        if (st.drum) {
            n.drum = *st.drum;
            n.drum_line = st.line;
            n.drum_column = st.drum_column;
        }
        if (st.openness) {
            // The kit's first drum is never a cymbal (validate_kit): the
            // pedal needs a note on a named drum, a hi-hat (the planner,
            // which knows the kit, checks that it is one).
            if (n.drum.empty())
                throw ScoreError(score_.source, st.line, st.openness_column,
                                 std::string("'") + hihat_openness_word(*st.openness) +
                                     "' is a hi-hat's pedal, and this note is on the kit's "
                                     "first drum (write 'on hihat', or 'drum hihat' before it)");
            n.openness = *st.openness;
            n.openness_column = st.openness_column;
        }
        if (st.ornament != Grace::none) {
            // The grace strokes: the other hand's, soft, before the beat, on the note's drum.
            ScoreNote g = stroke(st, st.hand == Side::right ? Side::left : Side::right);
            g.drum = n.drum;
            g.drum_line = n.drum_line;
            g.drum_column = n.drum_column;
            g.openness = n.openness; // one pedal for the note and its graces
            g.openness_column = n.openness_column;
            g.beats = 0.0;
            g.nuance = Nuance::legato;
            g.dynamics = std::min(kGraceDynamics, 0.5 * n.dynamics);
            g.grace = st.ornament;
            g.column = st.ornament_column;
            if (st.ornament == Grace::drag) {
                g.grace_lead_s = kFlamGraceLead_s + kDragGraceSpacing_s;
                add(st, g);
            }
            g.grace_lead_s = kFlamGraceLead_s;
            add(st, g);
        }
        for (Side hand : {Side::right, Side::left}) {
            if (!st.both_hands && hand != st.hand)
                continue;
            n.hand = hand;
            n.theta_deg = st.theta_deg.value_or(kDefaultThetaDeg[static_cast<int>(hand)]);
            if (!st.beats)
                chord_unwritten_.push_back(score_.notes.size());
            add(st, n);
        }
        // A chord's notes but its last (`R ... + L ... + RF`): the next starts on the same
        // beat. The chord lasts its longest written duration (`R on hihat 1/2 + RF` lasts
        // half a beat), the default when none is written.
        chord_beats_ = std::max(chord_beats_, n.beats);
        if (st.beats)
            chord_written_ = std::max(chord_written_, *st.beats);
        if (st.with_next)
            return;
        const double beats = chord_written_ > 0.0 ? chord_written_ : chord_beats_;
        for (size_t i : chord_unwritten_) // its notes without a written duration last as long
            score_.notes[i].beats = beats;
        chord_unwritten_.clear();
        advance(st, beats);
        chord_beats_ = 0.0;
        chord_written_ = 0.0;
    }

    // A roll: strokes at the `beats` default for its length, alternating
    // (single R L, double R R L L, buzz R L as buzz strokes).
    void roll(const Statement &st)
    {
        const double sub = default_beats_;
        const double strokes = st.ramp_beats / sub;
        const long count = std::lround(strokes);
        if (count < 1 || std::abs(strokes - static_cast<double>(count)) > 1e-9 * strokes) {
            char buf[240];
            std::snprintf(buf, sizeof buf,
                          "a roll of %g beats is not a whole number of strokes at 'beats' %g (a "
                          "roll plays strokes at the 'beats' default: make its length a multiple "
                          "of it)",
                          st.ramp_beats, sub);
            fail(st, buf);
        }
        for (long k = 0; k < count; ++k) {
            const long pair = st.roll == Roll::double_stroke ? k / 2 : k;
            ScoreNote n = stroke(st, pair % 2 == 0 ? Side::right : Side::left);
            if (st.roll == Roll::buzz)
                n.nuance = Nuance::buzz;
            add(st, n);
            advance(st, sub);
        }
    }

    void execute(const Statement &st)
    {
        switch (st.kind) {
        case Kind::note:
            note(st);
            break;
        case Kind::roll:
            roll(st);
            break;
        case Kind::rest:
            advance(st, st.beats.value_or(default_beats_));
            break;
        case Kind::tempo: {
            const double start = st.start_bpm.value_or(score_.tempo.tempo_at_beat(beat_));
            score_.tempo.add(beat_, start, st.end_bpm, st.ramp_beats);
            break;
        }
        case Kind::grip:
            grip_ = st.grip;
            break;
        case Kind::humanize:
            score_.humanize = st.humanize;
            break;
        case Kind::drum:
            drum_ = *st.drum;
            drum_line_ = st.line;
            drum_column_ = st.drum_column;
            break;
        case Kind::meter: {
            std::vector<ScoreMeter> &m = score_.meters;
            if (!m.empty() && m.back().beat == beat_)
                m.pop_back(); // two at one beat: the later one
            m.push_back({beat_, st.numerator, st.denominator, st.line});
            break;
        }
        case Kind::default_dynamics: {
            // `dynamics D` holds D; a hairpin starts at D (or where the
            // dynamics are) and cuts a hairpin still running.
            const double from = st.dynamics.value_or(dynamics_at(beat_));
            dyn_beat0_ = beat_;
            dyn0_ = from;
            dyn1_ = st.dynamics_end.value_or(from);
            dyn_ramp_ = st.dynamics_end ? st.ramp_beats : 0.0;
            break;
        }
        case Kind::default_beats:
        case Kind::default_firmness:
        case Kind::default_nuance:
            // A default statement carries its one value; the others stay.
            default_beats_ = st.beats.value_or(default_beats_);
            default_firmness_ = st.firmness.value_or(default_firmness_);
            default_nuance_ = st.nuance.value_or(default_nuance_);
            break;
        case Kind::repeat:
        case Kind::end:
            break;
        }
    }
};

} // namespace

Score execute_statements(const std::string &source, const std::vector<Statement> &statements)
{
    return Executor(source).run(statements);
}

} // namespace score_detail
} // namespace ictus
