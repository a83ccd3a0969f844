// score_plan.hpp -- a gesture plan ready to perform (private to src/perform):
// per hand and note the beats, the targets' leads and approach speeds, the
// grips; the tip targets and stick directions the controller follows; where a
// live tempo change may start (docs/perform.md).
#pragma once

#include "ictus/perform/performance.hpp"

#include <array>
#include <memory>
#include <vector>

namespace ictus
{

// The score it came from, the plan, and per hand and note the plan time of
// the beat, the lead of the target's first contact before it and the
// approach speed there (target_at).
struct ScorePlan {
    std::shared_ptr<const Score> score;
    GesturePlan plan;
    std::array<std::vector<double>, 2> beats, lead_s, approach_mps;
    std::array<std::vector<double>, 2> firmness; // < 0: the performance's
    std::array<std::vector<bool>, 2> press;      // a buzz: loose from its beat on
    std::array<std::vector<bool>, 2> down;       // a down stroke: firm until the next beat
    // A stroke soon after a much louder one of the hand (as a down stroke's
    // next, whatever the two notes' grips): its downswing is held firm.
    std::array<std::vector<bool>, 2> after_loud;
    std::array<size_t, 2> grip_note = {0, 0};    // the note whose grip is applied
    std::vector<double> planned_speed_mps;       // [note of plan]

    // The tip target of hand `s` at plan time t: the plan's, each note's
    // delayed by its lead; with a scripted rebound (rebound_s > 0) lifted
    // along `up` after each beat.
    Eigen::Vector3d target_at(int s, double t, double rebound_s, const Eigen::Vector3d &up) const;
    // The stick's direction at plan time t (the frame's rest direction
    // when the plan has none).
    Eigen::Vector3d direction_at(int s, double t, const PerformerFrame &frame) const;
    // The plan time whose target the hand follows at plan time t (target_at's delay).
    double plan_time_of(int s, double t) const;
};

// Plans `score` on `frame` (allocates the whole trajectory at 1 kHz: the
// worker's job in `ictusd run`, inline in render). Throws GestureError.
std::unique_ptr<ScorePlan> make_score_plan(std::shared_ptr<const Score> score,
                                           const GestureDatabase &db, const PerformerFrame &frame,
                                           const PlanOptions &options);

// Where a live tempo change can start in a plan under way: the first beat
// such that every stroke the hands have begun by plan time `now_s` keeps its
// shape and time. A hand's stroke toward its note j is planned on the times
// of notes j - 1, j and j + 1 (its unit is made for its period and warped
// into the gaps, docs/score.md) and enters the hand's trajectory at the
// start of the cross-fade window t_{j-1} + m (t_j - t_{j-1}); so a note j
// whose window has not started can move its successors. Returns the beat
// of the latest such first unstarted note over the hands (infinity: a hand
// has begun its last stroke) and, in `until_s`, the earliest of those
// windows: up to that plan time the plan with the new tempo equals the old.
double tempo_split_beat(const Score &score, double score_start_s, double blend_margin, double now_s,
                        double &until_s);

} // namespace ictus
