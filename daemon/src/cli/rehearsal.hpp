// rehearsal.hpp -- how a rendered pass met its notes, and the leads the next
// pass asks for (private to src/cli; docs/score.md, "Rehearsal").
#pragma once

#include "render_report.hpp"

#include <vector>

namespace ictus
{
namespace cli
{

// Rehearsal (docs/score.md, "Rehearsal"): when a note was struck more than
// kOffTime_ms off its time, each note more than kRehearseAbove_ms off moves
// its stroke's plan by its error, and the score is played again; again while
// a note is more than kRehearseAbove_ms off, up to r.rehearse passes after the
// first. A pass is kept when it strikes more notes within kOffTime_ms (then:
// loses fewer, then: a smaller worst error) than the best before it; else the
// next pass tries half of its change.
constexpr double kRehearseAbove_ms = 2.5;
constexpr double kRehearseUpTo_ms = 25.0; // further off: not a lag to correct

// A pass's notes: how many went wrong, how many were lost, the worst error.
struct PassScore {
    long wrong = 0; // notes not struck, or struck more than kOffTime_ms off
    long lost = 0;  // of those, not struck: a note played late is not traded for none
    double worst_ms = 0.0;
    bool better_than(const PassScore &o) const
    {
        if (wrong != o.wrong)
            return wrong < o.wrong;
        if (lost != o.lost)
            return lost < o.lost;
        return worst_ms < o.worst_ms - 1e-6;
    }
};

PassScore pass_score(const MatchSummary &m);

// The leads (s, per score note) a pass asks for: the plan's, plus each note's
// error when it is more than kRehearseAbove_ms and at most kRehearseUpTo_ms
// off, each held to +-kMaxNoteLead_s; false when no note moves.
bool next_leads(const GesturePlan &plan, const MatchSummary &m, std::vector<double> &lead);

} // namespace cli
} // namespace ictus
