// A gesture plan ready to perform (score_plan.hpp).
#include "score_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace ictus
{

double tempo_split_beat(const Score &score, double score_start_s, double blend_margin, double now_s,
                        double &until_s)
{
    double split = 0.0;
    until_s = std::numeric_limits<double>::infinity();
    for (Side hand : {Side::left, Side::right}) {
        bool any = false, found = false;
        double previous_s = 0.0;
        for (const ScoreNote &n : score.notes) {
            if (n.hand != hand)
                continue;
            const double t = score_start_s + score.note_time_s(n);
            // The first stroke's window is the plan's start: always begun.
            if (any) {
                const double window_s = previous_s + blend_margin * (t - previous_s);
                if (window_s > now_s) {
                    split = std::max(split, n.beat);
                    until_s = std::min(until_s, window_s);
                    found = true;
                    break;
                }
            }
            any = true;
            previous_s = t;
        }
        if (any && !found)
            return std::numeric_limits<double>::infinity();
    }
    return split;
}

std::unique_ptr<ScorePlan> make_score_plan(std::shared_ptr<const Score> score,
                                           const GestureDatabase &db, const PerformerFrame &frame,
                                           const PlanOptions &options)
{
    // Planning allocates (the whole trajectory at 1 kHz): the worker's job
    // in `ictusd run`, inline in render.
    auto ps = std::make_unique<ScorePlan>();
    ps->plan = plan_performance(*score, db, frame, options);
    ps->score = std::move(score);
    const GesturePlan &plan = ps->plan;
    // Per note: its beat, how long before it the target reaches the contact
    // (the lead that target_at removes) and its approach speed there.
    ps->planned_speed_mps.assign(plan.notes.size(), 0.0);
    for (int s = 0; s < 2; ++s) {
        for (size_t i = 0; i < plan.notes.size(); ++i) {
            const PlannedNote &n = plan.notes[i];
            if (static_cast<int>(n.hand) != s)
                continue;
            auto height = [&](double t) {
                return (plan.tips.sample(s, t) - frame.membrane_center_m).dot(frame.up);
            };
            double lead = 0.0;
            constexpr double kSearch_s = 0.05, kStep_s = 1e-4;
            if (height(n.time_s) < 0.0)
                for (double back = kStep_s; back <= kSearch_s; back += kStep_s) {
                    const double h0 = height(n.time_s - back),
                                 h1 = height(n.time_s - back + kStep_s);
                    if (h0 >= 0.0) {
                        lead = back - kStep_s * h0 / (h0 - h1); // linear between the two
                        break;
                    }
                }
            constexpr double kApproach_s = 0.002;
            const double t_contact = n.time_s - lead;
            const double v =
                std::max(0.0, (height(t_contact - kApproach_s) - height(t_contact)) / kApproach_s);
            ps->beats[s].push_back(n.time_s);
            ps->lead_s[s].push_back(lead);
            ps->approach_mps[s].push_back(v);
            // A buzz's press is played with the loosest grip from its strike on
            // (the downswing keeps the performance's grip: a loose stick lags a
            // fast hand), unless the note gives its own.
            const bool press = n.firmness < 0.0 && n.nuance == Nuance::buzz;
            ps->firmness[s].push_back(press ? Performance::kBuzzGripFirmness : n.firmness);
            ps->press[s].push_back(press);
            ps->planned_speed_mps[i] = v;
        }
        // Down strokes: a stroke followed soon by a much softer one of the
        // same hand, neither with a grip of its own.
        const size_t count = ps->beats[s].size();
        ps->down[s].assign(count, false);
        ps->after_loud[s].assign(count, false);
        for (size_t k = 0; k + 1 < count; ++k) {
            ps->after_loud[s][k + 1] =
                !ps->press[s][k + 1] &&
                ps->beats[s][k + 1] - ps->beats[s][k] <= Performance::kDownStrokeGap_s &&
                ps->approach_mps[s][k + 1] < Performance::kDownStrokeRatio * ps->approach_mps[s][k];
            ps->down[s][k] = ps->firmness[s][k] < 0.0 && ps->firmness[s][k + 1] < 0.0 &&
                             ps->after_loud[s][k + 1];
        }
    }
    return ps;
}

Eigen::Vector3d ScorePlan::direction_at(int s, double t, const PerformerFrame &frame) const
{
    const std::vector<double> &times = plan.tips.time_s;
    const std::vector<Eigen::Vector3d> &dir = plan.stick_dir[s];
    if (times.empty() || dir.size() != times.size())
        return rest_stick_direction(frame, s);
    const double tp = times.front() + std::clamp(plan_time_of(s, t), 0.0, plan.tips.duration_s());
    const size_t k = static_cast<size_t>(
        std::min<std::ptrdiff_t>(std::upper_bound(times.begin(), times.end(), tp) - times.begin(),
                                 static_cast<std::ptrdiff_t>(times.size()) - 1));
    if (k == 0)
        return dir.front();
    const double w = (tp - times[k - 1]) / std::max(times[k] - times[k - 1], 1e-12);
    const Eigen::Vector3d d = (1.0 - w) * dir[k - 1] + w * dir[k];
    return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : dir[k];
}

// The plan time whose target the hand follows at plan time t (target_at's delay).
double ScorePlan::plan_time_of(int s, double t) const
{
    const std::vector<double> &hand_beats = beats[s];
    if (hand_beats.empty())
        return t;
    auto it = std::upper_bound(hand_beats.begin(), hand_beats.end(), t);
    const size_t k = static_cast<size_t>(it - hand_beats.begin()); // beats k-1 <= t < beat k
    const std::vector<double> &lead = lead_s[s];
    double delay;
    if (k == 0)
        delay = lead.front();
    else if (k == hand_beats.size())
        delay = lead.back();
    else {
        const double w = (t - hand_beats[k - 1]) / (hand_beats[k] - hand_beats[k - 1]);
        delay = (1.0 - w) * lead[k - 1] + w * lead[k];
    }
    return t - delay;
}

Eigen::Vector3d ScorePlan::target_at(int s, double t, double rebound_s,
                                     const Eigen::Vector3d &up) const
{
    const std::vector<double> &hand_beats = beats[s];
    if (hand_beats.empty())
        return plan.tips.sample(s, t);
    // The contact on the beat: the plan's target passes strike_depth_m below
    // the first contact at the beat, so it reaches the contact a little
    // before (depth / speed: 4 ms for a soft 1 m/s stroke). Each note's
    // target is delayed by that lead, the delay interpolated linearly in
    // time between the hand's beats (a rate change of well under 2 %).
    const double tp = plan_time_of(s, t);
    const Eigen::Vector3d p = plan.tips.sample(s, tp);
    double tc = rebound_s;
    if (tc <= 0.0)
        return p;
    // The scripted rebound (off by default, --rebound: the stick on its
    // fulcrum rebounds by itself). The units of the database lift slowly
    // after the strike, so an arm driven down at the impact speed toward a
    // target that barely rises presses into the head for 30-70 ms
    // (docs/perform.md). After each beat the target gets an upward offset
    //     r(tau) = v tau exp(-tau / tc),
    // v the target's approach speed at the beat: it leaves the head at the
    // impact speed, peaks v tc / e above the unit at tau = tc and fades
    // smoothly (never faster downward than 0.14 v), so the hand does not
    // strike again.
    auto it = std::upper_bound(hand_beats.begin(), hand_beats.end(), tp);
    if (it == hand_beats.begin())
        return p;
    const size_t j = static_cast<size_t>(it - hand_beats.begin()) - 1;
    const double beat = hand_beats[j];
    if (it != hand_beats.end())
        tc = std::min(tc, 0.1 * (*it - beat)); // faded out (< 5e-4 v tc) by the next beat
    const double tau = tp - beat;
    if (tau >= 20.0 * tc)
        return p;
    return p + approach_mps[s][j] * tau * std::exp(-tau / tc) * up;
}

} // namespace ictus
