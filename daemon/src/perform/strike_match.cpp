// How the strikes of a performance met its planned notes (strike_match.hpp).
#include "ictus/perform/strike_match.hpp"

#include <cmath>
#include <limits>

namespace ictus
{

MatchSummary match_strikes(const std::vector<PlannedNote> &notes,
                           const std::vector<StrikeEvent> &strikes, double origin_s)
{
    MatchSummary m;
    m.notes.assign(notes.size(), NoteMatch{});
    std::vector<double> best(notes.size(), std::numeric_limits<double>::infinity());
    for (const StrikeEvent &e : strikes) {
        if (e.bounce) {
            ++m.bounces;
            continue;
        }
        ++m.primary_strikes;
        // The nearest note of the strike's hand on the strike's drum.
        long nearest = -1;
        double nearest_d = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < notes.size(); ++i) {
            if (static_cast<int>(notes[i].hand) != e.hand || notes[i].drum != e.drum)
                continue;
            const double d = std::abs(e.time_s - (origin_s + notes[i].time_s));
            if (d < nearest_d) {
                nearest_d = d;
                nearest = static_cast<long>(i);
            }
        }
        if (nearest < 0) {
            ++m.extra_strikes;
            continue;
        }
        const size_t i = static_cast<size_t>(nearest);
        if (m.notes[i].strike_seq >= 0)
            ++m.extra_strikes; // the note already has one: one of the two is extra
        if (nearest_d < best[i]) {
            best[i] = nearest_d;
            m.notes[i].strike_seq = e.seq;
            m.notes[i].strike_time_s = e.time_s;
            m.notes[i].error_ms = 1e3 * (e.time_s - (origin_s + notes[i].time_s));
            m.notes[i].normal_velocity_mps = e.normal_velocity_mps;
            m.notes[i].duration_ms = e.duration_ms;
        }
    }
    double sum = 0.0;
    for (const NoteMatch &n : m.notes) {
        if (n.strike_seq < 0)
            continue;
        ++m.matched_notes;
        sum += std::abs(n.error_ms);
        m.max_abs_error_ms = std::max(m.max_abs_error_ms, std::abs(n.error_ms));
    }
    m.mean_abs_error_ms = m.matched_notes > 0 ? sum / m.matched_notes : 0.0;
    return m;
}

} // namespace ictus
