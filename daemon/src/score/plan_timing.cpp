// plan_timing.cpp -- a plan's length and its sample times (plan_timing.hpp).
#include "plan_timing.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace ictus
{
namespace score_detail
{

double plan_duration(const Score &score, const PlanOptions &opt, double last_motion_end)
{
    const double duration_s =
        std::max(opt.lead_in_s + score.duration_s() + opt.tail_s, last_motion_end + 0.1);
    if (duration_s > opt.max_duration_s) {
        const int line = score.notes.empty() ? 0 : score.notes.back().line;
        const int column = score.notes.empty() ? 0 : score.notes.back().column;
        std::ostringstream m;
        m << "the performance lasts " << duration_s << " s, longer than the planner's limit ("
          << opt.max_duration_s << " s)";
        throw ScoreError(score.source, line, column, m.str());
    }
    return duration_s;
}

void sample_times(const PlanOptions &opt, GesturePlan &plan)
{
    std::vector<double> strikes;
    for (const PlannedNote &p : plan.notes)
        strikes.push_back(p.time_s);
    std::sort(strikes.begin(), strikes.end());
    const long grid = static_cast<long>(std::ceil(plan.duration_s * opt.rate_hz));
    std::vector<double> &times = plan.tips.time_s;
    times.reserve(static_cast<size_t>(grid) + 1 + strikes.size());
    size_t next_strike = 0;
    for (long i = 0; i <= grid; ++i) {
        const double t = static_cast<double>(i) / opt.rate_hz;
        while (next_strike < strikes.size() && strikes[next_strike] <= t + 1e-6) {
            if (times.empty() || strikes[next_strike] > times.back() + 1e-9)
                times.push_back(strikes[next_strike]);
            ++next_strike;
        }
        if (times.empty() || t > times.back() + 1e-6)
            times.push_back(t);
    }
}

} // namespace score_detail
} // namespace ictus
