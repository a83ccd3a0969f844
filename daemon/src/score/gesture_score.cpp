// gesture_score.cpp -- a score into stick-tip targets (docs/score.md, "From
// score to motion"). Per hand, the notes' gesture units are
//  1. made C1 curves: cubic Hermite through the unit's samples, in two pieces
//     split at the strike (the impact reverses the velocity there);
//  2. time-warped around their strike: unit time u = P + sigma(tau), tau the
//     plan time from the note's beat, sigma(0) = 0 and sigma'(0) = 1, so the
//     strike lands on the beat with the unit's own impact velocity; the
//     preparation and the lift are compressed (quadratic sigma) only when the
//     time to the neighbouring strikes is shorter than they are;
//  3. placed: rotated from the performer frame into the world and moved onto
//     the note's spot of the head;
//  4. co-articulated: consecutive units (and the rest tip, when the hand is
//     idle) are cross-faded with a quintic smoothstep weight over a window
//     strictly between two strikes. Both curves are C1 and the weight has zero
//     slope at the window's ends, so the blend is C1; outside the windows a
//     single unit rules, so the strikes are untouched.
// The paper plans Figure 5 this way in spirit ("co-articulation between
// successive motion units" in the Cartesian space); the warping and blending
// are the classic motion-editing tools (Witkin & Popovic 1995 motion warping,
// Kovar & Gleicher 2003 registration curves, cross-fades with ease curves).
// Steps 1 and 4, the moves between spots and pieces and the lift over the kit
// are in hand_timeline.cpp.
#include "ictus/score/gesture_score.hpp"

#include "ictus/base/motor_noise.hpp"
#include "hand_timeline.hpp"
#include "kit_notes.hpp"
#include "plan_inputs.hpp"
#include "plan_timing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace ictus
{

namespace
{

using score_detail::build_timeline;
using score_detail::foot_note;
using score_detail::HandStrokes;
using score_detail::HandTimeline;
using score_detail::Item;
using score_detail::note_openness;
using score_detail::plan_duration;
using score_detail::sample_hand;
using score_detail::sample_times;
using score_detail::UnitCurve;

// A stroke's period when nothing sets it: gesture.hpp's nominal 0.5 s (120 bpm).
constexpr double kNominalPeriod_s = 0.5;

// The rebound aim (warp_units): none for a stroke kReboundAimFrom_s or more
// after the hand's previous strike (the doubles of docs/score.md, "Rebound
// strokes", 60 ms and slower), the whole from kReboundAimFull_s in.
constexpr double kReboundAimFrom_s = 0.060;
constexpr double kReboundAimFull_s = 0.045;
constexpr double kReboundAimSpeed_mps = 0.8;

// Units are shared by notes with the same grip, nuance, hand, dynamics
// and periods. The parametric model's units are made at the hand's own
// periods (the downswing for the time since its previous strike, the lift
// for the time to its next one: gesture.hpp's stroke_model), so the warp
// has little to do; imported units come from instantiate() and are warped.
class UnitCache
{
  public:
    explicit UnitCache(const GestureDatabase &db) : db_(db) {}

    const UnitCurve &unit_for(Grip g, Nuance n, Side s, double dynamics, double prep_period_s,
                              double lift_period_s)
    {
        const long prep_us = std::lround(prep_period_s * 1e6);
        const long lift_us = std::lround(lift_period_s * 1e6);
        const auto key = std::make_tuple(static_cast<int>(g), static_cast<int>(n),
                                         static_cast<int>(s), dynamics, prep_us, lift_us);
        auto it = units_.find(key);
        if (it == units_.end()) {
            const GestureUnit *stored = db_.find(g, n, s);
            const GestureUnit unit =
                !stored || stored->source == "model"
                    ? stroke_model(g, n, s, dynamics, prep_us * 1e-6, lift_us * 1e-6)
                    : db_.instantiate(g, n, s, dynamics);
            it = units_.emplace(key, std::make_unique<UnitCurve>(unit)).first;
        }
        return *it->second;
    }

  private:
    const GestureDatabase &db_;
    std::map<std::tuple<int, int, int, double, long, long>, std::unique_ptr<UnitCurve>> units_;
};

using HandNotes = std::array<std::vector<size_t>, 2>; // each hand's notes, indices into plan.notes

// The notes, timed by the tempo map, into plan.notes (score order); a score that
// asks a hand to play faster than one hand plays is a ScoreError. The timing noise
// of `humanize` never does: it is clipped where it would bring a stroke closer
// than that to the hand's previous one (a hand cannot play faster when it errs).
HandNotes time_notes(const Score &score, const PerformerFrame &frame, const PlanOptions &opt,
                     GesturePlan &plan)
{
    HandNotes by_hand;
    const double amount = humanize_amount(score, opt);
    std::array<double, 2> score_time_prev = {0.0, 0.0};   // each hand's last note, without noise
    std::array<double, 2> foot_written_prev = {0.0, 0.0}; // each foot's, likewise
    std::array<long, 2> foot_prev = {-1, -1};             // each foot's last, in plan.foot_notes
    for (size_t k = 0; k < score.notes.size(); ++k) {
        const ScoreNote &n = score.notes[k];
        if (n.foot) {
            // As a hand's: a kick (a chick) closer to the foot's last than its
            // pedal plays is refused; the noise of `humanize` never brings it closer.
            PlannedFootNote f = foot_note(score, n, k, frame, opt);
            const double written = opt.lead_in_s + score.note_time_s(n);
            const size_t s = f.side == Side::right ? 0 : 1;
            const double min_s = s == 0 ? opt.min_foot_interval_s : opt.min_chick_interval_s;
            if (foot_prev[s] >= 0) {
                const PlannedFootNote &prev = plan.foot_notes[static_cast<size_t>(foot_prev[s])];
                if (written - foot_written_prev[s] < min_s - 1e-9) {
                    std::ostringstream m;
                    m << "this " << (s == 0 ? "kick" : "chick") << " comes "
                      << (written - foot_written_prev[s]) * 1000.0
                      << " ms after the previous one (line " << prev.line << "), faster than the "
                      << (s == 0 ? "right foot plays its pedal"
                                 : "left foot plays the hi-hat's pedal")
                      << " (minimum " << min_s * 1000.0 << " ms)";
                    throw ScoreError(score.source, n.line, n.column, m.str());
                }
                f.time_s = std::max(f.time_s, prev.time_s + min_s);
            }
            foot_written_prev[s] = written;
            foot_prev[s] = static_cast<long>(plan.foot_notes.size());
            plan.foot_notes.push_back(f);
            continue;
        }
        PlannedNote p;
        const double score_time = opt.lead_in_s + score.note_time_s(n);
        p.time_s = score_time;
        p.hand = n.hand;
        p.nuance = n.nuance;
        p.grip = n.grip;
        p.dynamics = n.dynamics;
        if (amount > 0.0) {
            // Note k's own stream: a replan (a tempo change) draws the same.
            MotorNoise noise(opt.seed, k + 1);
            p.time_s += amount * kHumanizeTimingSd_s * noise.normal();
            const double scale = 1.0 + amount * kHumanizeForceCv * noise.normal();
            p.dynamics = std::clamp(n.dynamics * scale, 0.0, 1.0);
        }
        p.score_note = static_cast<int>(k);
        if (k < opt.note_lead_s.size() && std::isfinite(opt.note_lead_s[k])) {
            p.lead_s = std::clamp(opt.note_lead_s[k], -kMaxNoteLead_s, kMaxNoteLead_s);
            p.time_s -= p.lead_s;
        }
        p.beats = n.beats;
        p.tempo_bpm = score.tempo.tempo_at_beat(n.beat);
        p.r_over_a = n.r_over_a;
        p.theta_deg = n.theta_deg;
        p.firmness = n.firmness;
        p.drum = score_detail::note_drum_spot(score, n, frame, p.r_over_a, p.theta_deg);
        const bool cymbal = !n.spot_given && p.drum >= 0 &&
                            p.drum < static_cast<int>(frame.drums.size()) &&
                            frame.drums[static_cast<size_t>(p.drum)].cymbal;
        if (cymbal && n.hand == Side::right && !by_hand[static_cast<int>(n.hand)].empty()) {
            // A cymbal the right hand reaches fast from another piece: its spot turned toward
            // where the hand comes from (a fast arm overshoots along its way: over the plate,
            // not past its far edge). Not the left's: its way to the crash passes over the
            // hi-hat's rod, which the planner clears from the spot toward the performer.
            const PlannedNote &q = plan.notes[by_hand[static_cast<int>(n.hand)].back()];
            const double dt = score_time - score_time_prev[static_cast<int>(n.hand)];
            const Eigen::Vector3d here = membrane_point(frame, p.r_over_a, p.theta_deg, p.drum);
            if (q.drum != p.drum &&
                ((here - q.strike_point_m).norm() + kStrokeTravel_m) >
                    kCymbalFaceAbove_mps * std::max(dt, 1e-9)) {
                p.r_over_a = n.r_over_a;
                p.theta_deg = n.theta_deg;
                score_detail::note_drum_spot(score, n, frame, p.r_over_a, p.theta_deg,
                                             &q.strike_point_m);
            }
        }
        if (p.drum < static_cast<int>(frame.drums.size()) &&
            frame.drums[static_cast<size_t>(p.drum)].foot)
            throw ScoreError(score.source, n.drum_line, n.drum_column,
                             "drum '" + frame.drums[static_cast<size_t>(p.drum)].name +
                                 "' is played by the right foot on its pedal: write 'RF'");
        p.openness = note_openness(score, n, frame, p.drum);
        const std::vector<size_t> &other = by_hand[1 - static_cast<int>(n.hand)];
        if (p.openness >= 0.0 && !other.empty())
            score_detail::check_one_pedal(score, n, p, plan.notes[other.back()], frame);
        p.strike_point_m = membrane_point(frame, p.r_over_a, p.theta_deg, p.drum);
        p.tip_target_m = p.strike_point_m - opt.strike_depth_m * frame.up;
        p.line = n.line;
        p.column = n.column;
        p.grace = n.grace;
        const std::vector<size_t> &same = by_hand[static_cast<int>(n.hand)];
        if (!same.empty()) {
            const PlannedNote &prev = plan.notes[same.back()];
            const double written = score_time - score_time_prev[static_cast<int>(n.hand)];
            if ((amount > 0.0 || p.lead_s != 0.0) && written >= opt.min_stroke_interval_s - 1e-9) {
                const double w = p.written_time_s();
                const double t = std::max(p.time_s, prev.time_s + opt.min_stroke_interval_s);
                if (t > p.time_s && p.lead_s > 0.0)
                    p.lead_s = std::max(0.0, w - t); // what the interval leaves of it
                p.time_s = t;
            }
            if (written < opt.min_stroke_interval_s - 1e-9) {
                auto what = [](const PlannedNote &q) {
                    return q.grace == Grace::none
                               ? std::string()
                               : std::string(", a ") + to_string(q.grace) + "'s grace stroke";
                };
                std::ostringstream m;
                m << "this " << (n.hand == Side::right ? "right" : "left") << "-hand stroke"
                  << (n.grace == Grace::none
                          ? std::string()
                          : std::string(" (the ") + to_string(n.grace) + "'s grace stroke)")
                  << " comes " << written * 1000.0 << " ms after the previous one (line "
                  << prev.line << what(prev) << "), faster than one hand plays (minimum "
                  << opt.min_stroke_interval_s * 1000.0
                  << " ms): give it to the other hand or slow down";
                throw ScoreError(score.source, n.line, n.column, m.str());
            }
        }
        score_time_prev[static_cast<int>(n.hand)] = score_time;
        by_hand[static_cast<int>(n.hand)].push_back(plan.notes.size());
        plan.notes.push_back(p);
    }
    return by_hand;
}

// The units at their notes' targets and strikes. A long gap goes through the
// rest tip: when it is longer than idle_return_s and leaves room for a
// nominal lift, two moves and a nominal preparation.
HandStrokes place_strokes(const std::vector<size_t> &idx, const GesturePlan &plan,
                          const PerformerFrame &frame, const PlanOptions &opt,
                          const Eigen::Matrix3d &to_world)
{
    const size_t n = idx.size();
    HandStrokes h{std::vector<Item>(n), std::vector<bool>(n, false)};
    for (size_t k = 0; k < n; ++k) {
        const PlannedNote &p = plan.notes[idx[k]];
        Item &it = h.placed[k];
        it.rest = false;
        it.yaw_rad = piece_yaw_rad(frame, static_cast<int>(p.hand), p.strike_point_m, p.drum);
        it.to_world = Eigen::AngleAxisd(it.yaw_rad, frame.up).toRotationMatrix() * to_world;
        it.origin = p.tip_target_m;
        it.strike_t = p.time_s;
        it.drum = p.drum;
    }
    const double tr = opt.return_time_s;
    for (size_t k = 0; k + 1 < n; ++k) {
        const double gap = h.placed[k + 1].strike_t - h.placed[k].strike_t;
        h.via_rest[k] = gap > opt.idle_return_s && gap > 2.0 * kNominalPeriod_s + 2.0 * tr + 0.2;
    }
    return h;
}

// The unit of each stroke, made at its periods: the downswing's from the
// hand's previous strike, else nominal (the first stroke, or one after a
// rest, is a whole stroke); the lift's to its next strike, else from the
// previous one, else nominal (a lone stroke).
void choose_units(HandStrokes &h, const std::vector<size_t> &idx, const GesturePlan &plan,
                  UnitCache &units)
{
    std::vector<Item> &placed = h.placed;
    const size_t n = placed.size();
    for (size_t k = 0; k < n; ++k) {
        const bool has_prev = k > 0 && !h.via_rest[k - 1];
        const bool has_next = k + 1 < n && !h.via_rest[k];
        const double before =
            has_prev ? placed[k].strike_t - placed[k - 1].strike_t : kNominalPeriod_s;
        const double after = has_next ? placed[k + 1].strike_t - placed[k].strike_t
                                      : (has_prev ? before : kNominalPeriod_s);
        const PlannedNote &p = plan.notes[idx[k]];
        placed[k].curve = &units.unit_for(p.grip, p.nuance, p.hand, p.dynamics, before, after);
    }
}

// Each unit placed later by the contact lead over its downward impact speed
// (PlanOptions::contact_lead_m), keeping the hand's strokes in order.
void delay_for_contact(HandStrokes &h, const PlanOptions &opt, const PerformerFrame &frame,
                       const Eigen::Matrix3d &to_world)
{
    if (opt.contact_lead_m <= 0.0)
        return;
    for (Item &it : h.placed) {
        const double down = -(to_world * it.curve->impact_velocity()).dot(frame.up);
        it.strike_t += std::min(opt.contact_lead_m / std::max(down, 0.05), 0.02);
    }
}

// Each unit's warp: its preparation and lift fit the time to the
// neighbouring strikes; the target aimed below the head by the impact speed.
void warp_units(HandStrokes &h, const std::vector<size_t> &idx, const PerformerFrame &frame,
                const PlanOptions &opt, const Eigen::Matrix3d &to_world, GesturePlan &plan)
{
    std::vector<Item> &placed = h.placed;
    const size_t n = placed.size();
    const double beta = opt.blend_margin;
    for (size_t k = 0; k < n; ++k) {
        Item &it = placed[k];
        // Time before the strike: back to the previous strike (direct
        // link) or to the plan's start (first note); unlimited after a rest.
        double before = std::numeric_limits<double>::infinity();
        if (k == 0)
            before = it.strike_t;
        else if (!h.via_rest[k - 1])
            before = it.strike_t - placed[k - 1].strike_t;
        double after = std::numeric_limits<double>::infinity();
        if (k + 1 < n && !h.via_rest[k])
            after = placed[k + 1].strike_t - it.strike_t;
        it.prep_t = std::min(it.curve->prep_s, (1.0 - beta) * before);
        it.lift_t = std::min(it.curve->lift_s, (1.0 - beta) * after);
        const Eigen::Vector3d impact = to_world * it.curve->impact_velocity();
        // A stroke closer than kReboundAimFrom_s to the hand's previous one (a
        // drag's second grace) turns twice within that time, and the arm
        // tracks it later than its lag: it aims as deep as a stroke
        // kReboundAimSpeed_mps past strike_aim_from_mps (reached at
        // kReboundAimFull_s), whatever its own speed.
        const double rebound = std::clamp(
            (kReboundAimFrom_s - before) / (kReboundAimFrom_s - kReboundAimFull_s), 0.0, 1.0);
        const double aim =
            opt.strike_aim_s * std::max({0.0, -impact.dot(frame.up) - opt.strike_aim_from_mps,
                                         rebound * kReboundAimSpeed_mps});
        it.origin -= std::min(aim, opt.strike_aim_max_m) * frame.up;
        plan.notes[idx[k]].tip_target_m = it.origin;
        it.prepare();
        plan.notes[idx[k]].impact_velocity_mps = to_world * it.curve->impact_velocity();
    }
}
} // namespace

double humanize_amount(const Score &score, const PlanOptions &options)
{
    return options.humanize >= 0.0 ? options.humanize : std::max(0.0, score.humanize);
}

GesturePlan plan_performance(const Score &score, const GestureDatabase &db,
                             const PerformerFrame &frame, const PlanOptions &opt)
{
    score_detail::validate_plan_inputs(frame, opt);
    Eigen::Matrix3d to_world;
    to_world.col(0) = frame.right;
    to_world.col(1) = frame.up;
    to_world.col(2) = frame.forward;

    GesturePlan plan;
    plan.score_start_s = opt.lead_in_s;
    UnitCache units(db); // the timelines' items point into it
    const HandNotes by_hand = time_notes(score, frame, opt, plan);
    for (const ScoreMeter &m : score.meters)
        plan.meters.push_back(
            {opt.lead_in_s + score.tempo.time_at_beat(m.beat), m.beat, m.numerator, m.denominator});

    std::array<HandTimeline, 2> timelines;
    double last_motion_end = 0.0;
    for (int s = 0; s < 2; ++s) {
        const std::vector<size_t> &idx = by_hand[s];
        if (idx.empty()) {
            // A hand with nothing to play holds its stick at rest.
            Item rest;
            rest.rest_pos = frame.rest_tip_m[s];
            rest.rest_dir = rest_stick_direction(frame, s);
            timelines[s].items.push_back(rest);
            continue;
        }
        HandStrokes strokes = place_strokes(idx, plan, frame, opt, to_world);
        choose_units(strokes, idx, plan, units);
        delay_for_contact(strokes, opt, frame, to_world);
        warp_units(strokes, idx, frame, opt, to_world, plan);
        last_motion_end =
            std::max(last_motion_end, build_timeline(strokes, frame, s, opt, timelines[s]));
    }

    plan.duration_s = plan_duration(score, opt, last_motion_end);
    sample_times(opt, plan);
    for (int s = 0; s < 2; ++s)
        sample_hand(plan.tips.time_s, timelines[s], plan.tips.tip_m[s], plan.stick_dir[s]);
    std::stable_sort(
        plan.notes.begin(), plan.notes.end(),
        [](const PlannedNote &a, const PlannedNote &b) { return a.time_s < b.time_s; });
    std::stable_sort(
        plan.foot_notes.begin(), plan.foot_notes.end(),
        [](const PlannedFootNote &a, const PlannedFootNote &b) { return a.time_s < b.time_s; });
    return plan;
}

} // namespace ictus
