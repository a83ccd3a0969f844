// How the strikes of a performance met its planned notes (strike_match.hpp).
#include "ictus/perform/strike_match.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ictus
{

MatchSummary match_strikes(const std::vector<PlannedNote> &notes,
                           const std::vector<StrikeEvent> &strikes, double origin_s,
                           const std::vector<PlannedFootNote> &foot_notes)
{
    // Every note as (time, limb, drum): the hands' first, then the feet's.
    struct Target {
        double time_s;
        int limb, drum;
    };
    std::vector<Target> all;
    all.reserve(notes.size() + foot_notes.size());
    for (const PlannedNote &n : notes)
        all.push_back({n.written_time_s(), static_cast<int>(n.hand), n.drum});
    for (const PlannedFootNote &n : foot_notes)
        all.push_back({n.time_s, n.side == Side::right ? kFootRight : kFootLeft, n.drum});
    MatchSummary m;
    std::vector<NoteMatch> matched(all.size(), NoteMatch{});
    std::vector<double> best(all.size(), std::numeric_limits<double>::infinity());
    for (const StrikeEvent &e : strikes) {
        if (e.bounce) {
            ++m.bounces;
            continue;
        }
        ++m.primary_strikes;
        // The nearest note of the strike's limb on the strike's drum.
        long nearest = -1;
        double nearest_d = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < all.size(); ++i) {
            if (all[i].limb != e.hand || all[i].drum != e.drum)
                continue;
            const double d = std::abs(e.time_s - (origin_s + all[i].time_s));
            if (d < nearest_d) {
                nearest_d = d;
                nearest = static_cast<long>(i);
            }
        }
        if (nearest < 0)
            continue; // extra: no note of its limb on its drum
        // A note given a second strike keeps the nearer; the other is extra.
        const size_t i = static_cast<size_t>(nearest);
        if (nearest_d < best[i]) {
            best[i] = nearest_d;
            matched[i].strike_seq = e.seq;
            matched[i].strike_time_s = e.time_s;
            matched[i].error_ms = 1e3 * (e.time_s - (origin_s + all[i].time_s));
            matched[i].normal_velocity_mps = e.normal_velocity_mps;
            matched[i].duration_ms = e.duration_ms;
        }
    }
    // The extra ones: the primary strikes no note kept.
    std::vector<long> kept;
    for (const NoteMatch &n : matched)
        if (n.strike_seq >= 0)
            kept.push_back(n.strike_seq);
    std::sort(kept.begin(), kept.end());
    for (size_t k = 0; k < strikes.size(); ++k)
        if (!strikes[k].bounce && !std::binary_search(kept.begin(), kept.end(), strikes[k].seq))
            m.extra.push_back(k);
    m.extra_strikes = static_cast<long>(m.extra.size());
    double sum = 0.0;
    for (const NoteMatch &n : matched) {
        if (n.strike_seq < 0)
            continue;
        ++m.matched_notes;
        sum += std::abs(n.error_ms);
        m.max_abs_error_ms = std::max(m.max_abs_error_ms, std::abs(n.error_ms));
    }
    m.mean_abs_error_ms = m.matched_notes > 0 ? sum / m.matched_notes : 0.0;
    m.notes.assign(matched.begin(), matched.begin() + static_cast<long>(notes.size()));
    m.foot_notes.assign(matched.begin() + static_cast<long>(notes.size()), matched.end());
    return m;
}

double strike_pedal_openness(const std::vector<PlannedNote> &notes, const StrikeEvent &strike,
                             double origin_s)
{
    const double t = strike.time_s - origin_s; // the plan's clock
    // Outward from the strike's time: the first note of the strike's hand
    // on its drum each way, and of either hand for want of one.
    const auto at = std::lower_bound(notes.begin(), notes.end(), t,
                                     [](const PlannedNote &n, double s) { return n.time_s < s; });
    const PlannedNote *best[2] = {nullptr, nullptr}; // [0] its hand, [1] either
    double best_d[2] = {std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
    auto consider = [&](const PlannedNote &n) {
        if (n.drum != strike.drum || n.openness < 0.0)
            return false;
        const double d = std::abs(n.time_s - t);
        const int k = static_cast<int>(n.hand) == strike.hand ? 0 : 1;
        for (int j = k; j < 2; ++j)
            if (d < best_d[j]) {
                best_d[j] = d;
                best[j] = &n;
            }
        return k == 0; // found its hand's nearest this way
    };
    for (auto it = at; it != notes.end(); ++it)
        if (consider(*it))
            break;
    for (auto it = at; it != notes.begin();)
        if (consider(*--it))
            break;
    const PlannedNote *n = best[0] ? best[0] : best[1];
    return n ? n->openness : -1.0;
}

} // namespace ictus
