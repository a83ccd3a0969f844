// kit_notes.hpp -- a note's piece of a kit as the planner finds it (private
// to src/score): its drum by name, a hi-hat's pedal, and the right foot's
// notes on the kick (docs/score.md, docs/kit.md, docs/pedal.md).
#pragma once

#include "ictus/score/gesture_score.hpp"

#include <cstddef>

namespace ictus
{
namespace score_detail
{

// The index of the note's drum in the frame's kit (0 for none named); a
// ScoreError where the drum was named when the kit has none of that name.
int drum_index(const Score &score, const ScoreNote &n, const PerformerFrame &frame);
// The note's pedal on a hi-hat (closed when it names none), -1 on another
// drum; a ScoreError at the word when it names one on a drum without a pedal.
double note_openness(const Score &score, const ScoreNote &n, const PerformerFrame &frame, int drum);
// A foot's note (score note k): its time (with the motor noise of `humanize`,
// as a hand's) and its drum, the kit's foot piece (the first, or the one it
// names); a ScoreError where the kit has none or it names a piece of the hands.
PlannedFootNote foot_note(const Score &score, const ScoreNote &n, size_t k,
                          const PerformerFrame &frame, const PlanOptions &opt);

} // namespace score_detail
} // namespace ictus
