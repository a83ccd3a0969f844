// strike_event.cpp -- the strike's fields and the files made of them
// (strike_event.hpp, docs/osc.md).
#include "ictus/sim/strike_event.hpp"

#include "stick_tip.h"

#include <cmath>
#include <cstdio>
#include <ostream>

namespace ictus
{

namespace
{
// name, integer, decimals, in /ictus/strike, in /ictus/strike/end
constexpr StrikeFieldInfo kInfo[kStrikeFieldCount] = {
    {"seq", true, 0, true, true},
    {"hand", true, 0, true, true},
    {"drum", true, 0, true, false},
    {"bounce", true, 0, true, false},
    {"stroke", true, 0, false, false}, // per hand; the OSC messages have none (docs/osc.md)
    {"time_s", false, 6, true, false},
    {"x_m", false, 5, true, false},
    {"y_m", false, 5, true, false},
    {"r_over_a", false, 5, true, false},
    {"theta_deg", false, 2, true, false},
    {"normal_velocity_mps", false, 4, true, false},
    {"tangential_velocity_mps", false, 4, true, false},
    {"peak_force_n", false, 3, true, true},
    {"impulse_n_s", false, 6, true, true},
    {"duration_ms", false, 3, true, true},
    {"force_dir_x", false, 4, true, true},
    {"force_dir_y", false, 4, true, true},
    {"force_dir_z", false, 4, true, true},
    {"stick_mass_kg", false, 5, true, false},
    {"stick_tip", true, 0, true, false},
    // Known at the release only (the stick reaches the rim after the bead's
    // onset): in /ictus/strike/end, not /ictus/strike (docs/osc.md).
    {"zone", true, 0, false, true},
};

// Fixed notation with a given number of decimals; -0 printed as 0 so that
// equal physics gives equal bytes.
void put(std::ostream &out, double v, int decimals)
{
    char buf[64];
    if (!std::isfinite(v))
        v = 0.0; // never NaN in a file (the inputs are checked upstream)
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    if (buf[0] == '-') {
        bool zero = true;
        for (const char *c = buf + 1; *c; ++c)
            if (*c != '0' && *c != '.')
                zero = false;
        if (zero) {
            out << (buf + 1);
            return;
        }
    }
    out << buf;
}

void put_field(std::ostream &out, const StrikeEvent &e, StrikeField f)
{
    const StrikeFieldInfo &info = strike_field_info(f);
    if (info.integer)
        out << strike_field_integer(e, f);
    else
        put(out, strike_field(e, f), info.decimals);
}
} // namespace

// A hit line: what a drum patch needs first (patches/ictus-render.pd plays them).
const StrikeField kEventsStrikeFields[13] = {
    StrikeField::hand,         StrikeField::drum,
    StrikeField::bounce,       StrikeField::normal_velocity_mps,
    StrikeField::r_over_a,     StrikeField::theta_deg,
    StrikeField::peak_force_n, StrikeField::impulse_n_s,
    StrikeField::duration_ms,  StrikeField::tangential_velocity_mps,
    StrikeField::time_s,       StrikeField::stick_mass_kg,
    StrikeField::zone,
};

const StrikeFieldInfo &strike_field_info(StrikeField field)
{
    return kInfo[static_cast<int>(field)];
}

long strike_field_integer(const StrikeEvent &e, StrikeField field)
{
    switch (field) {
    case StrikeField::seq:
        return e.seq;
    case StrikeField::hand:
        return e.hand;
    case StrikeField::drum:
        return e.drum;
    case StrikeField::bounce:
        return e.bounce ? 1 : 0;
    case StrikeField::stroke:
        return e.stroke;
    case StrikeField::stick_tip:
        return e.stick_tip;
    case StrikeField::zone:
        return e.zone;
    default:
        return std::lround(strike_field(e, field));
    }
}

double strike_field(const StrikeEvent &e, StrikeField field)
{
    switch (field) {
    case StrikeField::seq:
    case StrikeField::hand:
    case StrikeField::drum:
    case StrikeField::bounce:
    case StrikeField::stroke:
    case StrikeField::stick_tip:
    case StrikeField::zone:
        return static_cast<double>(strike_field_integer(e, field));
    case StrikeField::time_s:
        return e.time_s;
    case StrikeField::x_m:
        return e.x_m;
    case StrikeField::y_m:
        return e.y_m;
    case StrikeField::r_over_a:
        return e.r_over_a;
    case StrikeField::theta_deg:
        return e.theta_deg;
    case StrikeField::normal_velocity_mps:
        return e.normal_velocity_mps;
    case StrikeField::tangential_velocity_mps:
        return e.tangential_velocity_mps;
    case StrikeField::peak_force_n:
        return e.peak_force_n;
    case StrikeField::impulse_n_s:
        return e.impulse_n_s;
    case StrikeField::duration_ms:
        return e.duration_ms;
    case StrikeField::force_dir_x:
        return e.force_dir.x();
    case StrikeField::force_dir_y:
        return e.force_dir.y();
    case StrikeField::force_dir_z:
        return e.force_dir.z();
    case StrikeField::stick_mass_kg:
        return e.stick_mass_kg;
    }
    return 0.0;
}

int stick_tip_code(const std::string &name)
{
    const stick_tip *tip = stick_tip_find(name.c_str());
    return tip ? static_cast<int>(tip - stick_tips) + 1 : 0;
}

std::string stick_tip_name(int code)
{
    return code >= 1 && code <= STICK_TIP_COUNT ? stick_tips[code - 1].name : "";
}

void write_strikes_csv_header(std::ostream &out)
{
    for (int i = 0; i < kStrikeFieldCount; ++i)
        out << (i ? "," : "") << kInfo[i].name;
    out << '\n';
}

void write_strike_csv_row(std::ostream &out, const StrikeEvent &e)
{
    for (int i = 0; i < kStrikeFieldCount; ++i) {
        if (i)
            out << ',';
        put_field(out, e, static_cast<StrikeField>(i));
    }
    out << '\n';
}

void write_events_line(std::ostream &out, const StrikeEvent &e, double previous_time_s)
{
    // Delays from whole microseconds, so that the delays add up to the onset times exactly.
    const long long t_us = std::llround(e.time_s * 1e6);
    const long long prev_us = std::llround(previous_time_s * 1e6);
    put(out, static_cast<double>(t_us - prev_us) * 1e-3, 3);
    out << " hit";
    for (StrikeField f : kEventsStrikeFields) {
        out << ' ';
        put_field(out, e, f);
    }
    out << ";\n";
}

void write_pedal_line(std::ostream &out, int drum, double openness, double time_s,
                      double previous_time_s)
{
    const long long t_us = std::llround(time_s * 1e6);
    const long long prev_us = std::llround(previous_time_s * 1e6);
    put(out, static_cast<double>(t_us - prev_us) * 1e-3, 3);
    out << " pedal " << drum << ' ';
    put(out, openness, 3);
    out << ";\n";
}

} // namespace ictus
