// `ictusd limits`: joint limits learned from a clip (Euler statistics and
// Algorithm 1), printed and written as JSON.
#include "ictus/character/character_limits.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/mocap/joint_limits.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace ictus
{
namespace cli
{

namespace
{
void limits_usage(std::ostream &out)
{
    out << "usage: ictusd limits FILE [options]\n"
           "\n"
           "Learns the limits of the character's 19 joints from a BVH clip: Euler angles\n"
           "(ZYX, mean -/+ k std) and quaternions (Algorithm 1: mean, log map, SVD,\n"
           "ellipsoid of k std). Prints a table and writes JSON.\n"
           "\n"
           "  --out FILE      JSON output (default limits.json; '-' prints JSON instead)\n"
           "  --scale M       metres per BVH unit (default 0.056444)\n"
           "  --skip-frames N frames dropped at the start (default 1)\n"
           "  --k K           limits at mean -/+ k std (Euler) and ellipsoid half-axes of\n"
           "                  k std (quaternion; default 3)\n"
           "  --min-deg DEG   minimum half-width per axis (default 6)\n"
           "  --smooth-hz HZ, --smooth-kernel K, --despike-deg DEG   reference clean-up as\n"
           "                  in track\n"
        << force_help(18)
        << "                  (limits: also learn from fewer than 30 frames)\n"
           "\n"
           "Refused (exit 1): fewer than 30 frames after --skip-frames (a spread per axis\n"
           "estimated from n frames is off by about 1/sqrt(2(n-1)): 13 % at 30, 50 % at 3;\n"
           "--force learns anyway, with a warning); a limb shorter than 0.05 m or a segment\n"
           "longer than 1 m (FILE:LINE: naming the joint; docs/character.md).\n"
           "\n"
           "example:\n"
           "  ictusd limits ../shared/data/cmu/80_13.bvh --out limits.json\n";
}
} // namespace

int cmd_limits(Args &args)
{
    std::string file, out = "limits.json";
    ClipOptions clip;
    CharacterLimitOptions lo;
    const OptionTable options = {{"--out", store_text(out)},
                                 {"--k", store(lo.k, parse_positive)},
                                 {"--min-deg", [&](const std::string &a, Args &args) {
                                      lo.min_half_width_rad =
                                          parse_min_half_width_deg(a, args.value(a)) * M_PI / 180.0;
                                  }}};
    const bool go_on = walk_args(args, limits_usage, [&](const std::string &a) {
        if (dispatch_option(options, a, args) || parse_clip_option(a, args, clip))
            return;
        if (!a.empty() && a[0] == '-' && a != "-")
            throw UsageError("unknown option '" + a + "' (see ictusd limits --help)");
        if (!file.empty())
            throw UsageError("one FILE expected, got also '" + a + "'");
        file = a;
    });
    if (!go_on)
        return 0;
    if (file.empty())
        throw UsageError("FILE is required (ictusd limits FILE)");
    std::string ext = std::filesystem::path(file).extension().string();
    for (char &c : ext)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".csv")
        throw UsageError(file + ": limits are learned from a BVH capture's joint rotations; a "
                                "marker or stick .csv capture has none (docs/mocap.md)");
    const BvhFile bvh = load_bvh(file, clip.scale, clip.skip, clip.force);
    if (bvh.motion.frames() < kMinLimitFrames) {
        const std::string what = file + ": " + std::to_string(bvh.motion.frames()) +
                                 " frame(s) after --skip-frames " + std::to_string(clip.skip) +
                                 ", fewer than the " + std::to_string(kMinLimitFrames) +
                                 " that limits are learned from (their spreads would be noise)";
        if (!clip.force)
            throw std::runtime_error(what + " (--force learns from them anyway)");
        std::cerr << "ictusd: warning: " << what << "; learning anyway (--force)\n";
    }
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
    const ReferenceMotion reference(model, bvh.motion, clip.filter);
    const CharacterLimits limits(model, reference, lo);
    nlohmann::json report = limits.report();
    report["mocap"] = file;
    if (out == "-") {
        std::cout << report.dump(2) << "\n";
        return 0;
    }
    std::vector<JointLimit> enforced = limits.learned();
    for (size_t j = 0; j < enforced.size(); ++j)
        enforced[j].euler = limits.euler(static_cast<int>(j)).limit;
    print_limits(std::cout, enforced);
    std::ofstream js(out);
    js << report.dump(2) << "\n";
    if (!js)
        throw std::runtime_error("--out: cannot write '" + out + "'");
    std::cout << "wrote " << out << "\n";
    return 0;
}

} // namespace cli
} // namespace ictus
