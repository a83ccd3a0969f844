// plan_inputs.hpp -- the planner's inputs checked (private to src/score;
// docs/score.md, "From score to motion").
#pragma once

#include "ictus/score/gesture_score.hpp"

namespace ictus
{
namespace score_detail
{

// Throws std::invalid_argument naming the field when the frame (unit,
// orthogonal axes; finite positions; the kit's drums) or an option is out of
// its range.
void validate_plan_inputs(const PerformerFrame &f, const PlanOptions &o);

} // namespace score_detail
} // namespace ictus
