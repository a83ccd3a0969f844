// verb_gestures.cpp -- `ictusd gestures`: list, export and import gesture
// units (docs/gestures.md).
#include "ictus/cli/verbs.hpp"
#include "ictus/gesture/gesture.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

namespace ictus
{
namespace cli
{

namespace
{

void gestures_usage(std::ostream &out)
{
    out << "usage: ictusd gestures --list [--db FILE.json]\n"
           "       ictusd gestures --export FILE.json\n"
           "       ictusd gestures --import CAPTURE --grip french|german --nuance N\n"
           "                       --hand left|right [--db IN.json] --out FILE.json\n"
           "\n"
           "The gesture database: one unit (a stroke of one stick tip, 250 Hz, strike\n"
           "marked) per grip x nuance x hand. Nuances: legato, tenuto, accent,\n"
           "vertical_accent, staccato, buzz. Without --db the built-in units of the\n"
           "parametric stroke model are used (docs/gestures.md).\n"
           "\n"
           "  --list             print the units: samples, strike time, preparation height,\n"
           "                     impact speed\n"
           "  --export FILE      write the built-in database as JSON\n"
           "  --import CAPTURE   segment a capture (.bvh with CMU joint names: the\n"
           "                     character's stick tip; .csv: stick-only, both sticks) into\n"
           "                     strokes at the tip-height minima, add the stroke with the\n"
           "                     median impact speed to the database (IN, else the built-in)\n"
           "                     and write it to --out\n"
           "  --stroke K         import stroke K (0-based) instead of the median one\n"
           "  --dynamics D       the level the captured strokes represent, 0 (ppp) .. 1 (fff)\n"
           "                     (default 0.6)\n"
           "  --scale M, --skip-frames N   BVH reading (default 0.056444, 1)\n"
           "  --units mm|m, --up y|z, --rate HZ, --left-stick NAME, --right-stick NAME\n"
           "                     CSV reading (as ictusd track)\n"
           "\n"
           "examples:\n"
           "  ictusd gestures --list\n"
           "  ictusd gestures --export gestures.json\n"
           "  ictusd gestures --import ../shared/data/cmu/80_13.bvh --grip french \\\n"
           "      --nuance legato --hand right --out mine.json\n"
           "  ictusd gestures --list --db mine.json\n";
}

void print_units(const GestureDatabase &db)
{
    std::printf("%-7s %-16s %-6s %-12s %8s %8s %9s %9s %9s\n", "grip", "nuance", "hand", "source",
                "samples", "strike_s", "period_s", "height_m", "impact_mps");
    for (const GestureUnit &u : db.units())
        std::printf("%-7s %-16s %-6s %-12s %8d %8.3f %9.3f %9.3f %9.2f\n", to_string(u.grip),
                    to_string(u.nuance), to_string(u.hand), u.source.c_str(), u.samples(),
                    u.strike_time_s(), u.period_s, u.preparation_height_m(), u.impact_speed_mps());
}

} // namespace

int cmd_gestures(Args &args)
{
    bool list = false;
    std::string export_path, import_path, db_path, out_path;
    std::string grip, nuance, hand;
    int stroke = -1;
    double dynamics = 0.6;
    ImportOptions io;
    StickCsvOptions sticks;
    const OptionTable options = {{"--list", store_flag(list)},
                                 {"--export", store_text(export_path)},
                                 {"--import", store_text(import_path)},
                                 {"--db", store_text(db_path)},
                                 {"--out", store_text(out_path)},
                                 {"--grip", store_word(grip)},
                                 {"--nuance", store_word(nuance)},
                                 {"--hand", store_word(hand)},
                                 {"--stroke", store(stroke, parse_int, 0, 1000000)},
                                 {"--dynamics", store(dynamics, parse_number, 0.0, 1.0)}};
    const bool go_on = walk_args(args, gestures_usage, [&](const std::string &a) {
        if (!dispatch_option(options, a, args) &&
            !parse_bvh_option(a, args, io.bvh_scale, io.bvh_skip_frames) &&
            !parse_stick_csv_option(a, args, sticks))
            throw UsageError("unknown option '" + a + "' (see ictusd gestures --help)");
    });
    if (!go_on)
        return 0;
    const int actions = list + !export_path.empty() + !import_path.empty();
    if (actions != 1)
        throw UsageError("give exactly one of --list, --export FILE, --import CAPTURE");

    if (!export_path.empty()) {
        const GestureDatabase db = GestureDatabase::builtin();
        db.save_json(export_path);
        std::cout << "wrote " << db.units().size() << " units to " << export_path << "\n";
        return 0;
    }
    if (list) {
        const GestureDatabase db =
            db_path.empty() ? GestureDatabase::builtin() : GestureDatabase::load_json(db_path);
        print_units(db);
        return 0;
    }
    // --import
    if (grip.empty() || nuance.empty() || hand.empty() || out_path.empty())
        throw UsageError("--import needs --grip, --nuance, --hand and --out");
    Grip g;
    Nuance n;
    Side h;
    try {
        g = grip_from_string(grip);
        n = nuance_from_string(nuance);
        h = side_from_string(hand);
    } catch (const std::runtime_error &e) {
        throw UsageError(e.what());
    }
    GestureDatabase db =
        db_path.empty() ? GestureDatabase::builtin() : GestureDatabase::load_json(db_path);
    io.csv = sticks.csv;
    io.left_stick = sticks.left_stick;
    io.right_stick = sticks.right_stick;
    const std::vector<GestureUnit> units = import_capture(import_path, g, n, h, io);
    const std::string strokes =
        std::to_string(units.size()) + (units.size() == 1 ? " stroke" : " strokes");
    if (stroke >= static_cast<int>(units.size()))
        throw UsageError("--stroke " + std::to_string(stroke) + ": the capture has " + strokes);
    const GestureUnit &picked = stroke >= 0 ? units[stroke] : representative_unit(units);
    GestureUnit chosen = picked;
    chosen.dynamics = dynamics;
    std::cout << import_path << ": " << strokes << "; importing stroke " << (&picked - units.data())
              << " (strike at " << chosen.capture_time_s + chosen.strike_time_s() << " s, impact "
              << chosen.impact_speed_mps() << " m/s, preparation " << chosen.preparation_height_m()
              << " m)\n";
    // The unit's heights scale from --dynamics (docs/gestures.md, "Dynamics rule"): a level
    // far from the model's for a stroke of that height is said, with what mf will make of it.
    const double model_m = stroke_model(g, n, h, dynamics, chosen.period_s).preparation_height_m();
    const double ratio = chosen.preparation_height_m() / model_m;
    if (ratio > 3.0 || ratio < 1.0 / 3.0)
        std::cerr << "ictusd gestures: warning: --dynamics " << dynamics << ": the stroke rises "
                  << chosen.preparation_height_m() << " m, the model's " << to_string(n)
                  << " at that level " << model_m << " m (" << ratio
                  << "x); played at mf (0.6) it will rise "
                  << chosen.preparation_height_m() * dynamics_height_level(0.6) /
                         dynamics_height_level(dynamics)
                  << " m\n";
    db.add(chosen);
    db.save_json(out_path);
    std::cout << "wrote " << db.units().size() << " units to " << out_path << "\n";
    return 0;
}

} // namespace cli
} // namespace ictus
