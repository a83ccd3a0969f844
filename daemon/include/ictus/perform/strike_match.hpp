// strike_match.hpp -- how the strikes of a performance met its planned notes
// (what `ictusd render` reports for a score: notes.csv, performance.json).
#pragma once

#include "ictus/score/gesture_score.hpp"
#include "ictus/sim/strike_event.hpp"

#include <vector>

namespace ictus
{

// Per hand, each primary (non-bounce) strike is given to the nearest note of
// that hand; a note keeps the nearest of the strikes given to it (the others
// are extra).
struct NoteMatch {
    long strike_seq = -1; // -1: no strike for this note
    double strike_time_s = 0.0;
    double error_ms = 0.0; // strike - beat
    double normal_velocity_mps = 0.0;
    double duration_ms = 0.0;
};
struct MatchSummary {
    std::vector<NoteMatch> notes;      // [note], as the plan's notes
    std::vector<NoteMatch> foot_notes; // [note], as the plan's foot notes
    long primary_strikes = 0, bounces = 0;
    long matched_notes = 0;
    long extra_strikes = 0; // primary strikes not matched to a note
    std::vector<size_t> extra; // those, as indices into the strikes, in their order
    double mean_abs_error_ms = 0.0, max_abs_error_ms = 0.0;
};
// `origin_s`: simulation time of the plan's time 0. The feet's strikes
// (StrikeEvent::hand kFootRight, kFootLeft) meet their foot's notes likewise;
// the counts and errors are over all.
MatchSummary match_strikes(const std::vector<PlannedNote> &notes,
                           const std::vector<StrikeEvent> &strikes, double origin_s,
                           const std::vector<PlannedFootNote> &foot_notes = {});

// The hi-hat's pedal for a strike (StrikeEvent::pedal_openness): the
// openness of the note it plays, the nearest note in time on its drum that
// carries one (PlannedNote::openness), of its hand if it has any there, else
// of the other's; -1 when its drum has none (not a hi-hat). `notes` in time
// order; no allocation (the physics thread asks it at each onset).
double strike_pedal_openness(const std::vector<PlannedNote> &notes, const StrikeEvent &strike,
                             double origin_s);

} // namespace ictus
