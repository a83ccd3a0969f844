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

// The note's piece of the frame's kit: its index (0 for none named), and
// whether the name is a cymbal's bell (`ride-bell`: the cymbal `ride`, struck
// on its bell where the note gives no spot). A name the kit does not use is
// also found as the common spelling of a standard piece (`floor-tom` for
// `floor`, `hi-hat` for `hihat`, `bass-drum` for `kick`: docs/score.md). A
// ScoreError where the drum was named when the kit has no such piece.
struct NoteDrum {
    int index = 0;
    bool bell = false;
    bool rim = false; // `snare-rim`: the drum `snare`, struck on its rim
};
NoteDrum note_drum(const Score &score, const ScoreNote &n, const PerformerFrame &frame);
int drum_index(const Score &score, const ScoreNote &n, const PerformerFrame &frame);
// The note's drum (note_drum) and, where the note gives no spot on a cymbal,
// the cymbal's toward the performer, at kCymbalThetaDeg: its bell's
// (kBellRadiusFraction, as General MIDI's 53) or its bow's
// (kCymbalRadiusFraction); where it gives none on a drum's rim (`snare-rim`),
// the edge where it faces the hand's shoulder in plan (kRimInset_m inside it);
// r_over_a and theta_deg are left as they are elsewhere. With arriving_from (the
// point the hand comes from, fast: kCymbalFaceAbove_mps) a cymbal's bow spot is
// turned toward it by at most kCymbalFaceMostDeg.
int note_drum_spot(const Score &score, const ScoreNote &n, const PerformerFrame &frame,
                   double &r_over_a, double &theta_deg,
                   const Eigen::Vector3d *arriving_from = nullptr);
// The note's pedal on a hi-hat (closed when it names none), -1 on another
// drum; a ScoreError at the word when it names one on a drum without a pedal.
double note_openness(const Score &score, const ScoreNote &n, const PerformerFrame &frame, int drum);
// One hi-hat, one pedal: a ScoreError at `n`'s pedal word (at the note where it writes
// none) when `other`, the other hand's last planned note, is on the same hi-hat at the
// same written instant (a chord's) with another openness (`p`: n planned so far).
void check_one_pedal(const Score &score, const ScoreNote &n, const PlannedNote &p,
                     const PlannedNote &other, const PerformerFrame &frame);
// A foot's note (score note k): its time (with the motor noise of `humanize`,
// as a hand's) and its drum, the kit's foot piece (the first, or the one it
// names); a ScoreError where the kit has none or it names a piece of the hands.
PlannedFootNote foot_note(const Score &score, const ScoreNote &n, size_t k,
                          const PerformerFrame &frame, const PlanOptions &opt);

} // namespace score_detail
} // namespace ictus
