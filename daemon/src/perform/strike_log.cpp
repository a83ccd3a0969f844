// strike_log.cpp -- a run's strikes in onset order, to strikes.csv and
// events.txt (strike_log.hpp).
#include "ictus/perform/strike_log.hpp"

#include <algorithm>
#include <array>
#include <ostream>

namespace ictus
{

void StrikeLog::add(const StrikeEvent *events, int n)
{
    strikes_.insert(strikes_.end(), events, events + n);
}

void StrikeLog::finish()
{
    std::stable_sort(strikes_.begin(), strikes_.end(),
                     [](const StrikeEvent &a, const StrikeEvent &b) { return a.seq < b.seq; });
}

long StrikeLog::bounces() const
{
    return static_cast<long>(std::count_if(strikes_.begin(), strikes_.end(),
                                           [](const StrikeEvent &e) { return e.bounce; }));
}

void StrikeLog::write_csv(std::ostream &out) const
{
    write_strikes_csv_header(out);
    for (const StrikeEvent &e : strikes_)
        write_strike_csv_row(out, e);
}

void StrikeLog::write_events(std::ostream &out) const
{
    double previous_s = 0.0;
    // Each drum's pedal as last written: a hi-hat's pedal line goes before
    // the strike that plays it, when it changes (the first one always).
    std::array<double, kMaxDrums> pedal;
    pedal.fill(-1.0);
    for (const StrikeEvent &e : strikes_) {
        if (e.pedal_openness >= 0.0 && e.drum >= 0 && e.drum < kMaxDrums &&
            e.pedal_openness != pedal[static_cast<size_t>(e.drum)]) {
            write_pedal_line(out, e.drum, e.pedal_openness, e.time_s, previous_s);
            pedal[static_cast<size_t>(e.drum)] = e.pedal_openness;
            previous_s = e.time_s;
        }
        write_events_line(out, e, previous_s);
        previous_s = e.time_s;
    }
}

} // namespace ictus
