// strike_log.cpp -- strikes in onset order, to strikes.csv and events.txt
// (strike_log.hpp).
#include "ictus/perform/strike_log.hpp"

#include <ostream>

namespace ictus
{

void StrikeLog::add(const StrikeEvent *events, int n, long first_open_seq)
{
    auto keep = [this](const StrikeEvent &e) { strikes_.push_back(e); };
    for (int i = 0; i < n; ++i)
        order_.push(events[i], keep);
    order_.release(first_open_seq, keep);
}

void StrikeLog::add_flushed(const StrikeEvent &event)
{
    order_.push(event, [this](const StrikeEvent &e) { strikes_.push_back(e); });
}

void StrikeLog::finish()
{
    order_.flush([this](const StrikeEvent &e) { strikes_.push_back(e); });
}

long StrikeLog::bounces() const
{
    long n = 0;
    for (const StrikeEvent &e : strikes_)
        n += e.bounce ? 1 : 0;
    return n;
}

bool StrikeLog::write_csv(std::ostream &out) const
{
    write_strikes_csv_header(out);
    for (const StrikeEvent &e : strikes_)
        write_strike_csv_row(out, e);
    return static_cast<bool>(out);
}

bool StrikeLog::write_events(std::ostream &out) const
{
    double previous_s = 0.0;
    for (const StrikeEvent &e : strikes_) {
        write_events_line(out, e, previous_s);
        previous_s = e.time_s;
    }
    return static_cast<bool>(out);
}

} // namespace ictus
