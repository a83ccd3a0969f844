// plan_timing.hpp -- a plan's length and its sample times (private to
// src/score; docs/score.md, "From score to motion").
#pragma once

#include "ictus/score/gesture_score.hpp"

namespace ictus
{
namespace score_detail
{

// The plan's length: the score's and the tail, or the last motion's end; a
// ScoreError beyond the planner's limit.
double plan_duration(const Score &score, const PlanOptions &opt, double last_motion_end);
// Sample times: the grid plus each strike exactly (plan.tips.time_s).
void sample_times(const PlanOptions &opt, GesturePlan &plan);

} // namespace score_detail
} // namespace ictus
