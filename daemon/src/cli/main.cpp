// ictusd -- the ictus simulation daemon: a physically simulated percussionist.
// Verbs: track (joint-space PD tracking of a mocap clip, paper eq. 1),
// limits (joint limits learned from a clip, paper Algorithm 1), run and
// render (docs/osc.md), gestures (the gesture database, issue 6). See
// docs/character.md. Exit status: 0 ok, 1 runtime error (file, data), 2 usage
// error (unknown verb or option, bad value), 3 the simulation diverged (and
// was reset) at least once, 130 interrupted.
#include "ictus/bvh.hpp"
#include "ictus/character.hpp"
#include "ictus/character_limits.hpp"
#include "ictus/gesture.hpp"
#include "ictus/joint_limits.hpp"
#include "ictus/marker_csv.hpp"
#include "ictus/stick_capture.hpp"
#include "ictus/strike.hpp"
#include "ictus/track.hpp"
#include "ictus/verbs_osc.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace
{

volatile std::sig_atomic_t g_interrupted = 0;
void on_sigint(int)
{
    g_interrupted = 1;
}

constexpr double kCmuScale = 0.056444; // (1/0.45) inch per unit, cgspeed CMU BVH files

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

void usage(std::ostream &out)
{
    out << "ictusd -- the ictus simulation daemon (a physically simulated percussionist)\n"
           "\n"
           "usage: ictusd VERB [options]\n"
           "       ictusd --help | VERB --help\n"
           "\n"
           "verbs:\n"
           "  track    drive the character with a motion capture in joint space (PD, eq. 1)\n"
           "           and report tracking errors and speed\n"
           "  limits   learn joint limits from a motion capture (Euler statistics and\n"
           "           Algorithm 1), print them and write them as JSON\n"
           "  run      perform in real time: physics on the wall clock, strikes and poses\n"
           "           out over OSC, control in over OSC (docs/osc.md)\n"
           "  render   perform offline, as fast as possible and deterministic: strikes.csv\n"
           "           and an events file for Pd's batch render (docs/osc.md)\n"
           "  gestures the gesture database: list, export, or import units segmented\n"
           "           from a capture (ictusd gestures --help)\n"
           "\n"
           "examples:\n"
           "  ictusd track --mode joint --mocap ../shared/data/cmu/80_13.bvh --out run1\n"
           "  ictusd track --mode joint --mocap clip.bvh --duration 600 --grip german --quiet\n"
           "  ictusd limits ../shared/data/cmu/80_13.bvh --out limits.json\n"
           "  ictusd render --mocap ../shared/data/cmu/80_13.bvh --out perf\n"
           "  ictusd run --mocap ../shared/data/cmu/80_13.bvh --target osc.udp://127.0.0.1:9000\n"
           "  ictusd gestures --list\n"
           "\n"
           "exit status: 0 ok, 1 error in a file or the data, 2 usage error,\n"
           "             3 the simulation diverged (and was reset), 130 interrupted\n";
}

void track_usage(std::ostream &out)
{
    out << "usage: ictusd track --mode joint|cartesian --mocap FILE [options]\n"
           "\n"
           "Tracks the clip with per-joint PD controllers (eq. 1) on the 57-DoF character,\n"
           "pelvis anchored, sticks in the hands, a drum in front. joint: every joint follows\n"
           "the capture's rotations. cartesian (Algorithm 2): the arms' targets come from IK\n"
           "(eq. 2) toward the stick tips every step, the other joints follow the capture.\n"
           "\n"
           "  --mode joint|cartesian control mode\n"
           "  --mocap FILE           BVH file with CMU joint names, or (cartesian) a stick-only\n"
           "                         .csv capture (time,NAME.x,NAME.y,NAME.z,...; docs/mocap.md):\n"
           "                         the default body is placed behind the sticks\n"
           "  --left-stick NAME, --right-stick NAME   the capture's stick-tip objects (default:\n"
           "                         named stick_l / stick_r, else containing left / right)\n"
           "  --units mm|m, --up y|z, --rate HZ   how to read the .csv (default m, y, its time)\n"
           "  --drum auto|X,Y,Z      membrane centre (auto: under the lowest strokes)\n"
           "  --ik-gain G            eq. 2's gain on the tip error (default 10)\n"
           "  --ik-velocity-gain S   tip velocity error term, s (default 0.1; < 0: automatic)\n"
           "  --ik-accel-ff S2       tip acceleration feedforward, s^2 (default 0)\n"
           "  --ik-integral PER_S    integral of the tip error (default 0)\n"
           "  --ik-correction-limit M   cap on the IK target's correction (default 0.1)\n"
           "  --ik-start kinematic|simulated   IK warm start (default kinematic; docs/ik.md)\n"
           "  --out DIR              write DIR/track.csv, DIR/strikes.csv and DIR/summary.json\n"
           "  --scale M              metres per BVH unit (default 0.056444, the CMU files)\n"
           "  --skip-frames N        frames dropped at the start (default 1: the CMU\n"
           "                         converter's reference pose)\n"
           "  --duration S           simulated seconds (default: the clip; longer runs play\n"
           "                         it forwards and backwards)\n"
           "  --step S               physics step, s (default 0.001)\n"
           "  --stepper quick|direct dWorldQuickStep (default) or dWorldStep\n"
           "  --iterations N         QuickStep iterations (default 15)\n"
           "  --body-mass KG         body mass for de Leva's table (default 70)\n"
           "  --grip french|german   hand-stick orientation (default french)\n"
           "  --stick-length M       (default 0.406)   --stick-mass KG (default 0.05)\n"
           "  --stick-tip-radius M   (default 0.007)\n"
           "  --drum-pos X,Y,Z       membrane centre, m (default: under the lowest tips)\n"
           "  --drum-radius M        (default 0.178)   --drum-tension N/m (default 3000)\n"
           "  --gain-hz HZ           PD natural frequency (default 30)\n"
           "  --damping-ratio Z      (default 1)       --torque-scale S (default 1)\n"
           "  --gains FILE.json      per-joint overrides, e.g. {\"l_wrist\": {\"kp_nm_per_rad\":\n"
           "                         40, \"kd_nm_s_per_rad\": 0.5, \"torque_limit_nm\": 20}}\n"
           "  --limits none|euler|quaternion   limits enforced (default quaternion)\n"
           "  --limit-k K            limit width in standard deviations (default 3)\n"
           "  --limit-min-deg DEG    minimum half-width of a limit per axis (default 6)\n"
           "  --no-stops             clamp targets only, no safety-net stops\n"
           "  --ramp S               blend targets in over S seconds (default 0.25)\n"
           "  --smooth-hz HZ         low-pass the reference (Gaussian, default 10; 0: off)\n"
           "  --despike-deg DEG      replace one-frame spikes larger than DEG (default 5;\n"
           "                         0: off)\n"
           "  --quiet                no progress output\n"
           "\n"
           "examples:\n"
           "  ictusd track --mode joint --mocap ../shared/data/cmu/80_13.bvh --out run1\n"
           "  ictusd track --mode cartesian --mocap ../shared/data/cmu/80_13.bvh --limit-k 4\n"
           "  ictusd track --mode cartesian --mocap sticks.csv --units mm --up z --drum auto\n";
}

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
           "  --smooth-hz HZ, --despike-deg DEG   reference clean-up as in track\n"
           "\n"
           "example:\n"
           "  ictusd limits ../shared/data/cmu/80_13.bvh --out limits.json\n";
}

// Strict number parsing: the whole text must be a finite number.
double parse_double(const std::string &option, const std::string &text)
{
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        throw UsageError(option + ": expected a number, got '" + text + "'");
    return v;
}

double parse_positive(const std::string &option, const std::string &text)
{
    const double v = parse_double(option, text);
    if (!(v > 0.0))
        throw UsageError(option + ": expected a number > 0, got '" + text + "'");
    return v;
}

int parse_int(const std::string &option, const std::string &text, int lo, int hi)
{
    char *end = nullptr;
    errno = 0;
    const long v = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        throw UsageError(option + ": expected an integer in [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "], got '" + text + "'");
    return static_cast<int>(v);
}

Eigen::Vector3d parse_vec3(const std::string &option, const std::string &text)
{
    Eigen::Vector3d v;
    std::stringstream in(text);
    std::string part;
    int i = 0;
    while (std::getline(in, part, ',')) {
        if (i >= 3)
            throw UsageError(option + ": expected X,Y,Z, got '" + text + "'");
        v[i++] = parse_double(option, part);
    }
    if (i != 3)
        throw UsageError(option + ": expected X,Y,Z, got '" + text + "'");
    return v;
}

// argv walker: flags with one value, no value, or positional arguments.
struct Args {
    std::vector<std::string> items;
    size_t at = 0;
    bool done() const { return at >= items.size(); }
    const std::string &next() { return items[at++]; }
    std::string value(const std::string &option)
    {
        if (done())
            throw UsageError(option + ": missing value");
        return next();
    }
};

// The options track and limits share: how a BVH clip is read and how its
// reference motion is cleaned (ictusd track --help, ictusd limits --help).
struct ClipOptions {
    double scale = kCmuScale;
    int skip = 1;
    ictus::ReferenceFilter filter;
};

// When `a` is one of the clip options, reads its value into `clip` and
// returns true; false otherwise (nothing consumed).
bool parse_clip_option(const std::string &a, Args &args, ClipOptions &clip)
{
    if (a == "--scale") {
        clip.scale = parse_positive(a, args.value(a));
    } else if (a == "--skip-frames") {
        clip.skip = parse_int(a, args.value(a), 0, 100000000);
    } else if (a == "--smooth-hz") {
        clip.filter.smooth_cutoff_hz = parse_double(a, args.value(a));
        if (clip.filter.smooth_cutoff_hz < 0.0)
            throw UsageError("--smooth-hz: expected a number >= 0 (0: off)");
    } else if (a == "--despike-deg") {
        clip.filter.spike_threshold_rad = parse_double(a, args.value(a)) * M_PI / 180.0;
        if (clip.filter.spike_threshold_rad < 0.0)
            throw UsageError("--despike-deg: expected a number >= 0 (0: off)");
    } else {
        return false;
    }
    return true;
}

// A limit's minimum half-width per axis, degrees (track --limit-min-deg,
// limits --min-deg).
double parse_min_half_width_deg(const std::string &option, const std::string &text)
{
    const double w = parse_double(option, text);
    if (w < 0.0 || w >= 180.0)
        throw UsageError(option + ": expected 0 <= deg < 180, got '" + text + "'");
    return w;
}

bool is_csv(const std::string &path)
{
    if (path.size() < 4)
        return false;
    std::string ext = path.substr(path.size() - 4);
    for (char &c : ext)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".csv";
}

ictus::BvhFile load_bvh(const std::string &path, double scale, int skip)
{
    ictus::BvhOptions o;
    o.scale = scale;
    o.skip_frames = skip;
    ictus::MocapWarnings warnings;
    ictus::BvhFile bvh = ictus::read_bvh(path, o, &warnings);
    for (const std::string &w : warnings)
        std::cerr << "ictusd: warning: " << w << "\n";
    return bvh;
}

// strikes.csv of a verb that simulates (issue 5): the interaction manager on
// the scene's beads, fed once after each physics step; rows in onset order
// (seq), as render writes them. Strikes are few (a few per second): they are
// kept and written at close(), so that the physics loop never writes a file.
class StrikesCsv
{
  public:
    StrikesCsv(std::string path, const ictus::StrikeDetectorOptions &options = {})
        : path_(std::move(path)), detector_(ictus::MembraneGeometry{}, options)
    {
    }
    // After each step of `scene` (its drum is read every step: a scene whose
    // drum Scene::set_drum changed is watched on the new one).
    void after_step(const ictus::Scene &scene)
    {
        detector_.set_membrane(ictus::membrane_of(scene));
        ictus::StrikeEvent out[2];
        const int n = ictus::detect_strikes(detector_, scene, out);
        events_.insert(events_.end(), out, out + n);
    }
    // Ends open contacts and writes the file; throws naming it on error.
    void close()
    {
        ictus::StrikeEvent e;
        while (detector_.flush(e))
            events_.push_back(e);
        std::sort(
            events_.begin(), events_.end(),
            [](const ictus::StrikeEvent &a, const ictus::StrikeEvent &b) { return a.seq < b.seq; });
        std::ofstream out(path_);
        ictus::write_strikes_csv_header(out);
        for (const ictus::StrikeEvent &event : events_)
            ictus::write_strike_csv_row(out, event);
        out.close();
        if (!out)
            throw std::runtime_error("--out: cannot write '" + path_ + "'");
    }
    long strikes() const { return static_cast<long>(events_.size()); }

  private:
    std::string path_;
    ictus::StrikeDetector detector_;
    std::vector<ictus::StrikeEvent> events_;
};

class Progress
{
  public:
    explicit Progress(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
    void operator()(double fraction)
    {
        if (!enabled_)
            return;
        const int pct = static_cast<int>(fraction * 100.0 + 0.5);
        if (tty_) {
            const int width = 40, filled = pct * width / 100;
            std::cerr << "\rtrack [" << std::string(filled, '#') << std::string(width - filled, ' ')
                      << "] " << pct << "%" << std::flush;
            if (pct >= 100)
                std::cerr << "\n";
        } else if (pct / 10 != last_decile_) {
            last_decile_ = pct / 10;
            std::cerr << "track: " << pct << "%\n";
        }
    }

  private:
    bool enabled_, tty_;
    int last_decile_ = -1;
};

int run_track(Args &args)
{
    std::string mode, mocap, out_dir, limits_mode = "quaternion", gains_file;
    double limit_k = 3.0, limit_width_deg = 6.0;
    ClipOptions clip;
    bool quiet = false;
    ictus::CharacterOptions character;
    ictus::TrackOptions options;
    bool drum_pos_given = false;
    std::string left_stick, right_stick;
    ictus::MarkerCsvOptions csv_options;
    bool csv_options_given = false;
    while (!args.done()) {
        const std::string a = args.next();
        if (a == "--help" || a == "-h") {
            track_usage(std::cout);
            return 0;
        } else if (a == "--mode") {
            mode = args.value(a);
            try {
                options.mode = ictus::track_mode_from_string(mode);
            } catch (const ictus::CharacterError &e) {
                throw UsageError(std::string("--") + e.what());
            }
        } else if (a == "--ik-gain") {
            options.cartesian.gain = parse_positive(a, args.value(a));
        } else if (a == "--left-stick") {
            left_stick = args.value(a);
        } else if (a == "--right-stick") {
            right_stick = args.value(a);
        } else if (a == "--units") {
            const std::string v = args.value(a);
            if (v != "mm" && v != "m")
                throw UsageError("--units: expected mm or m, got '" + v + "'");
            csv_options.units =
                v == "mm" ? ictus::MarkerCsvOptions::Units::mm : ictus::MarkerCsvOptions::Units::m;
            csv_options_given = true;
        } else if (a == "--up") {
            const std::string v = args.value(a);
            if (v != "y" && v != "z")
                throw UsageError("--up: expected y or z, got '" + v + "'");
            csv_options.up =
                v == "z" ? ictus::MarkerCsvOptions::Up::z : ictus::MarkerCsvOptions::Up::y;
            csv_options_given = true;
        } else if (a == "--rate") {
            csv_options.rate_hz = parse_positive(a, args.value(a));
            csv_options_given = true;
        } else if (a == "--drum") {
            const std::string v = args.value(a);
            if (v != "auto") {
                try {
                    options.scene.drum.center_m = parse_vec3(a, v);
                } catch (const UsageError &) {
                    throw UsageError("--drum: expected auto or X,Y,Z (m), got '" + v + "'");
                }
                drum_pos_given = true;
            }
        } else if (a == "--ik-velocity-gain") {
            options.cartesian.velocity_gain_s = parse_double(a, args.value(a));
        } else if (a == "--ik-accel-ff") {
            options.cartesian.acceleration_feedforward_s2 = parse_double(a, args.value(a));
        } else if (a == "--ik-correction-limit") {
            options.cartesian.correction_limit_m = parse_double(a, args.value(a));
        } else if (a == "--ik-start") {
            const std::string v = args.value(a);
            if (v != "simulated" && v != "kinematic")
                throw UsageError("--ik-start: expected simulated or kinematic, got '" + v + "'");
            options.cartesian.start_from_simulated = v == "simulated";
        } else if (a == "--ik-integral") {
            options.cartesian.integral_per_s = parse_double(a, args.value(a));
        } else if (a == "--mocap") {
            mocap = args.value(a);
        } else if (a == "--out") {
            out_dir = args.value(a);
        } else if (parse_clip_option(a, args, clip)) {
        } else if (a == "--duration") {
            options.duration_s = parse_positive(a, args.value(a));
        } else if (a == "--step") {
            options.scene.step_s = parse_positive(a, args.value(a));
        } else if (a == "--stepper") {
            const std::string s = args.value(a);
            if (s == "quick")
                options.scene.stepper = ictus::Stepper::quick;
            else if (s == "direct")
                options.scene.stepper = ictus::Stepper::direct;
            else
                throw UsageError("--stepper: expected quick or direct, got '" + s + "'");
        } else if (a == "--iterations") {
            options.scene.quickstep_iterations = parse_int(a, args.value(a), 1, 1000);
        } else if (a == "--body-mass") {
            character.body_mass_kg = parse_positive(a, args.value(a));
        } else if (a == "--grip") {
            const std::string g = args.value(a);
            try {
                character.grip = ictus::grip_from_string(g);
            } catch (const ictus::CharacterError &e) {
                throw UsageError(std::string("--") + e.what());
            }
        } else if (a == "--stick-length") {
            character.stick.length_m = parse_positive(a, args.value(a));
        } else if (a == "--stick-mass") {
            character.stick.mass_kg = parse_positive(a, args.value(a));
        } else if (a == "--stick-tip-radius") {
            character.stick.tip_radius_m = parse_positive(a, args.value(a));
        } else if (a == "--drum-pos") {
            options.scene.drum.center_m = parse_vec3(a, args.value(a));
            drum_pos_given = true;
        } else if (a == "--drum-radius") {
            options.scene.drum.radius_m = parse_positive(a, args.value(a));
        } else if (a == "--drum-tension") {
            options.scene.drum.tension_n_per_m = parse_positive(a, args.value(a));
        } else if (a == "--gain-hz") {
            options.gains.natural_frequency_hz = parse_positive(a, args.value(a));
        } else if (a == "--damping-ratio") {
            options.gains.damping_ratio = parse_positive(a, args.value(a));
        } else if (a == "--torque-scale") {
            options.gains.torque_scale = parse_positive(a, args.value(a));
        } else if (a == "--gains") {
            gains_file = args.value(a);
        } else if (a == "--limits") {
            limits_mode = args.value(a);
            if (limits_mode != "none" && limits_mode != "euler" && limits_mode != "quaternion")
                throw UsageError("--limits: expected none, euler or quaternion, got '" +
                                 limits_mode + "'");
        } else if (a == "--limit-k") {
            limit_k = parse_positive(a, args.value(a));
        } else if (a == "--limit-min-deg") {
            limit_width_deg = parse_min_half_width_deg(a, args.value(a));
        } else if (a == "--no-stops") {
            options.scene.limit_stops = false;
        } else if (a == "--ramp") {
            options.ramp_s = parse_double(a, args.value(a));
            if (options.ramp_s < 0.0)
                throw UsageError("--ramp: expected a number >= 0, got " +
                                 std::to_string(options.ramp_s));
        } else if (a == "--quiet" || a == "-q") {
            quiet = true;
        } else {
            throw UsageError("track: unknown option '" + a + "' (see ictusd track --help)");
        }
    }
    if (mode.empty())
        throw UsageError("track: --mode is required (--mode joint or --mode cartesian)");
    if (mocap.empty())
        throw UsageError("track: --mocap FILE is required");
    options.drum_auto = !drum_pos_given;
    // Option values that only the model can judge (e.g. a too-long step) are
    // usage errors too: check them before reading the file.
    try {
        ictus::validate(options);
    } catch (const ictus::CharacterError &e) {
        throw UsageError(std::string("track: ") + e.what());
    }

    // A .csv capture is stick-only (Cartesian mode): the default body holds a
    // neutral pose and its arms follow the two stick tips.
    const bool stick_only = is_csv(mocap);
    if (stick_only && options.mode != ictus::TrackMode::cartesian)
        throw UsageError("track: a stick-only capture (" + mocap + ") needs --mode cartesian");
    if (!stick_only && (!left_stick.empty() || !right_stick.empty() || csv_options_given))
        throw UsageError("track: --left-stick, --right-stick, --units, --up and --rate apply "
                         "to stick-only .csv captures");
    ictus::BvhFile bvh;
    ictus::MarkerCapture capture;
    std::array<int, 2> stick_tracks = {-1, -1};
    if (stick_only) {
        ictus::MocapWarnings warnings;
        capture = ictus::read_marker_csv(mocap, csv_options, &warnings);
        for (const std::string &w : warnings)
            std::cerr << "ictusd: warning: " << w << "\n";
        try {
            stick_tracks = ictus::find_stick_tracks(capture, left_stick, right_stick);
        } catch (const ictus::CharacterError &e) {
            throw UsageError(std::string("track: ") + e.what());
        }
        bvh.skeleton = ictus::default_skeleton();
        bvh.motion.frame_rate_hz = 100.0;
        const ictus::Skeleton &sk = bvh.skeleton;
        for (int f = 0; f < 2; ++f) {
            // Standing height of the default body's hips (legs straight).
            bvh.motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
            bvh.motion.local_rotation.emplace_back(sk.joints.size(),
                                                   Eigen::Quaterniond::Identity());
        }
        if (limits_mode != "none") {
            std::cerr << "ictusd: note: stick-only capture: no joint limits (they are learned "
                         "from a full-body capture)\n";
            limits_mode = "none";
        }
    } else {
        bvh = load_bvh(mocap, clip.scale, clip.skip);
    }
    const ictus::CharacterModel model =
        ictus::CharacterModel::from_skeleton(bvh.skeleton, character);
    const ictus::ReferenceMotion raw(model, bvh.motion);
    const ictus::ReferenceMotion reference(
        model, bvh.motion, stick_only ? ictus::ReferenceFilter{0.0, 0.0} : clip.filter);
    ictus::TipTrajectory tips;
    if (stick_only) {
        tips = ictus::place_behind_sticks(model, reference.frame(0), capture, stick_tracks);
        options.tip_reference = &tips;
    }

    ictus::CharacterLimitOptions lim;
    lim.kind = ictus::limit_kind_from_string(limits_mode);
    lim.k = limit_k;
    lim.min_half_width_rad = limit_width_deg * M_PI / 180.0;
    const ictus::CharacterLimits limits(model, reference, lim);
    const std::vector<ictus::JointLimitRef> refs = limits.refs();

    std::ofstream csv;
    if (!out_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(out_dir, ec);
        if (ec)
            throw std::runtime_error("--out: cannot create directory '" + out_dir +
                                     "': " + ec.message());
        csv.open(out_dir + "/track.csv");
        if (!csv)
            throw std::runtime_error("--out: cannot write '" + out_dir + "/track.csv'");
        csv.precision(9);
    }
    // Gains: inertia-scaled defaults at the first pose, then per-joint overrides.
    std::vector<ictus::JointGains> gains =
        ictus::default_gains(model, reference.frame(0), options.gains);
    if (!gains_file.empty()) {
        std::ifstream in(gains_file);
        if (!in)
            throw std::runtime_error("--gains: cannot read '" + gains_file + "'");
        nlohmann::json overrides;
        try {
            overrides = nlohmann::json::parse(in);
        } catch (const nlohmann::json::parse_error &e) {
            throw std::runtime_error(gains_file + ": not valid JSON (" + e.what() + ")");
        }
        ictus::apply_gain_overrides(model, overrides, gains_file, gains);
    }

    options.interrupt = &g_interrupted;
    // strikes.csv: every verb that simulates writes it (docs/osc.md).
    std::unique_ptr<StrikesCsv> strikes;
    if (!out_dir.empty()) {
        strikes.reset(new StrikesCsv(out_dir + "/strikes.csv"));
        options.on_step = [&](const ictus::Scene &scene) { strikes->after_step(scene); };
    }
    Progress progress(!quiet);
    ictus::TrackSummary summary = ictus::track_joint_space(
        model, reference, options, refs, out_dir.empty() ? nullptr : &csv,
        [&](double f) { progress(f); }, &gains, &raw);

    nlohmann::json j = summary.to_json();
    j["mocap"] = mocap;
    j["scale_m_per_unit"] = clip.scale;
    j["skip_frames"] = clip.skip;
    j["step_s"] = options.scene.step_s;
    j["stepper"] = options.scene.stepper == ictus::Stepper::quick ? "quick" : "direct";
    j["quickstep_iterations"] = options.scene.quickstep_iterations;
    j["grip"] = ictus::to_string(character.grip);
    j["body_mass_kg"] = character.body_mass_kg;
    j["limits"] = limits_mode;
    j["limit_k"] = limit_k;
    j["limit_min_deg"] = limit_width_deg;
    j["limit_stops"] = options.scene.limit_stops;
    j["gain_hz"] = options.gains.natural_frequency_hz;
    j["damping_ratio"] = options.gains.damping_ratio;
    j["drum_radius_m"] = options.scene.drum.radius_m;
    j["smooth_hz"] = clip.filter.smooth_cutoff_hz;
    j["despike_deg"] = clip.filter.spike_threshold_rad * 180.0 / M_PI;
    j["spikes_removed"] = reference.spikes_removed();
    j["interrupted"] = summary.interrupted;
    j["gains"] = ictus::gains_to_json(model, gains);
    if (options.mode == ictus::TrackMode::cartesian) {
        j["ik"]["gain"] = options.cartesian.gain;
        j["ik"]["integral_per_s"] = options.cartesian.integral_per_s;
    }
    if (strikes) {
        strikes->close();
        j["strikes"] = strikes->strikes();
    }
    if (!out_dir.empty()) {
        csv.close();
        if (!csv)
            throw std::runtime_error("--out: error writing '" + out_dir + "/track.csv'");
        std::ofstream js(out_dir + "/summary.json");
        js << j.dump(2) << "\n";
        if (!js)
            throw std::runtime_error("--out: cannot write '" + out_dir + "/summary.json'");
    }
    std::cout << "mode " << summary.mode << ", " << summary.duration_s
              << " s simulated, realtime factor " << summary.realtime_factor << "\n"
              << "tip rms (mm): left " << summary.tip_rms_mm[0] << ", right "
              << summary.tip_rms_mm[1] << "\n"
              << "joint rms (deg), all joints: " << j["joint_rms_deg_all"].get<double>() << "\n"
              << "divergences: " << summary.divergences << "\n";
    if (options.mode == ictus::TrackMode::cartesian) {
        std::cout << "ik: " << summary.ik_mean_iterations << " iterations per solve (max "
                  << summary.ik_max_iterations << "), " << summary.ik_us_per_step << " us per step";
        if (summary.elbow_measured)
            std::cout << "; elbow flexion rms (deg) left " << summary.elbow_ik_rms_deg[0]
                      << ", right " << summary.elbow_ik_rms_deg[1];
        std::cout << "\n";
    }
    if (summary.interrupted)
        return 130;
    return summary.diverged ? 3 : 0;
}

int run_limits(Args &args)
{
    std::string file, out = "limits.json";
    ClipOptions clip;
    ictus::CharacterLimitOptions lo;
    while (!args.done()) {
        const std::string a = args.next();
        if (a == "--help" || a == "-h") {
            limits_usage(std::cout);
            return 0;
        } else if (a == "--out") {
            out = args.value(a);
        } else if (parse_clip_option(a, args, clip)) {
        } else if (a == "--k") {
            lo.k = parse_positive(a, args.value(a));
        } else if (a == "--min-deg") {
            lo.min_half_width_rad = parse_min_half_width_deg(a, args.value(a)) * M_PI / 180.0;
        } else if (!a.empty() && a[0] == '-' && a != "-") {
            throw UsageError("limits: unknown option '" + a + "' (see ictusd limits --help)");
        } else if (file.empty()) {
            file = a;
        } else {
            throw UsageError("limits: one FILE expected, got also '" + a + "'");
        }
    }
    if (file.empty())
        throw UsageError("limits: FILE is required (ictusd limits FILE)");
    const ictus::BvhFile bvh = load_bvh(file, clip.scale, clip.skip);
    const ictus::CharacterModel model = ictus::CharacterModel::from_skeleton(bvh.skeleton);
    const ictus::ReferenceMotion reference(model, bvh.motion, clip.filter);
    const ictus::CharacterLimits limits(model, reference, lo);
    nlohmann::json report = limits.report();
    report["mocap"] = file;
    if (out == "-") {
        std::cout << report.dump(2) << "\n";
        return 0;
    }
    std::vector<ictus::JointLimit> enforced = limits.learned();
    for (size_t j = 0; j < enforced.size(); ++j)
        enforced[j].euler = limits.euler(static_cast<int>(j)).limit;
    ictus::print_limits(std::cout, enforced);
    std::ofstream js(out);
    js << report.dump(2) << "\n";
    if (!js)
        throw std::runtime_error("--out: cannot write '" + out + "'");
    std::cout << "wrote " << out << "\n";
    return 0;
}

} // namespace

int main(int argc, char **argv)
{
    std::signal(SIGINT, on_sigint);
    Args args;
    for (int i = 1; i < argc; ++i)
        args.items.emplace_back(argv[i]);
    if (args.done()) {
        usage(std::cerr);
        return 2;
    }
    const std::string verb = args.next();
    try {
        if (verb == "--help" || verb == "-h" || verb == "help") {
            usage(std::cout);
            return 0;
        }
        if (verb == "track")
            return run_track(args);
        if (verb == "limits")
            return run_limits(args);
        // run and render parse their own options (argv[0] is the verb).
        if (verb == "run")
            return ictus::cmd_run(argc - 1, argv + 1);
        if (verb == "render")
            return ictus::cmd_render(argc - 1, argv + 1);
        if (verb == "gestures")
            return ictus::cmd_gestures(argc - 1, argv + 1);
        throw UsageError("unknown verb '" + verb +
                         "' (verbs: track, limits, run, render, gestures; see ictusd --help)");
    } catch (const UsageError &e) {
        std::cerr << "ictusd: " << e.what() << "\n";
        return 2;
    } catch (const ictus::MocapError &e) {
        std::cerr << "ictusd: " << e.what() << "\n";
        return 1;
    } catch (const ictus::CharacterError &e) {
        std::cerr << "ictusd: " << e.what() << "\n";
        return 1;
    } catch (const std::exception &e) {
        std::cerr << "ictusd: " << e.what() << "\n";
        return 1;
    }
}
