// How a rendered pass met its notes, and the next pass's leads (rehearsal.hpp).
#include "rehearsal.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{
namespace cli
{

PassScore pass_score(const MatchSummary &m)
{
    PassScore p;
    for (const std::vector<NoteMatch> *v : {&m.notes, &m.foot_notes})
        for (const NoteMatch &k : *v) {
            if (k.strike_seq < 0 || std::abs(k.error_ms) > kOffTime_ms)
                ++p.wrong;
            if (k.strike_seq < 0)
                ++p.lost;
            if (k.strike_seq >= 0)
                p.worst_ms = std::max(p.worst_ms, std::abs(k.error_ms));
        }
    return p;
}

bool next_leads(const GesturePlan &plan, const MatchSummary &m, std::vector<double> &lead)
{
    bool moved = false;
    for (size_t i = 0; i < plan.notes.size(); ++i) {
        const PlannedNote &n = plan.notes[i];
        const double e = m.notes[i].error_ms;
        if (n.score_note < 0 || m.notes[i].strike_seq < 0 || std::abs(e) <= kRehearseAbove_ms ||
            std::abs(e) > kRehearseUpTo_ms)
            continue;
        const size_t k = static_cast<size_t>(n.score_note);
        if (lead.size() <= k)
            lead.resize(k + 1, 0.0);
        const double next = std::clamp(n.lead_s + 1e-3 * e, -kMaxNoteLead_s, kMaxNoteLead_s);
        moved = moved || std::abs(next - lead[k]) > 1e-6;
        lead[k] = next;
    }
    return moved;
}

} // namespace cli
} // namespace ictus
