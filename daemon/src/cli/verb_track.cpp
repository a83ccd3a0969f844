// `ictusd track`: tracking of a mocap clip by the simulated character, in
// joint space (eq. 1) or Cartesian space (Algorithm 2); errors, speed and the
// strikes on the drum (docs/character.md, docs/ik.md). Four steps: parse the
// command line, load the capture and build the character, run, report.
#include "ictus/character/character_limits.hpp"
#include "ictus/character/range_of_motion.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/mocap/marker_csv.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/perform/strike_log.hpp"
#include "ictus/perform/track.hpp"

#include <unistd.h>

#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

namespace ictus
{
namespace cli
{

namespace
{

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
           "  --drum auto|X,Y,Z      membrane centre (auto, default: at the strokes'\n"
           "                         turnarounds, or under the lowest tips when the tips\n"
           "                         pass through a drum there, e.g. a kit; docs/mocap.md)\n"
           "  --ik-gain G            eq. 2's gain on the tip error (default 10)\n"
           "  --ik-velocity-gain S   tip velocity error term, s (default 0.1; < 0: automatic)\n"
           "  --ik-accel-ff S2       tip acceleration feedforward, s^2 (default 0)\n"
           "  --ik-integral PER_S    integral of the tip error (default 0)\n"
           "  --ik-correction-limit M   cap on the IK target's correction (default 0.3)\n"
           "  --ik-start simulated|kinematic   where the feedback IK starts: simulated, the\n"
           "                         simulated arm (Algorithm 2, default); kinematic, the\n"
           "                         capture-seeded IK solution (docs/ik.md)\n"
           "  --ik-posture-weight W  null-space posture task, 0..1 per step (default 0.005)\n"
           "  --out DIR              write DIR/track.csv, DIR/strikes.csv and DIR/summary.json\n"
           "  --scale M              metres per BVH unit (default 0.056444, the CMU files)\n"
           "  --skip-frames N        frames dropped at the start (default 1: the CMU\n"
           "                         converter's reference pose)\n"
           "  --duration S           simulated seconds (default: the clip; longer runs play\n"
           "                         it forwards and backwards)\n"
           "  --step S               physics step, s (default 0.001)\n"
           "  --stepper quick|direct dWorldQuickStep (default) or dWorldStep\n"
           "  --iterations N         QuickStep iterations (default 13)\n"
           "  --sor-w W              QuickStep's over-relaxation (default 1.3, ODE's)\n"
           "  --body-mass KG         body mass for de Leva's table (default 70)\n"
           "  --grip french|german   hand-stick orientation (default french)\n"
           "  --stick-length M       (default 0.406)   --stick-mass KG (default 0.05)\n"
           "  --stick-tip-radius M   (default 0.007)\n"
           "  --drum-pos X,Y,Z       membrane centre, m (default: --drum auto)\n"
           "  --drum-radius M        (default 0.178)   --drum-tension N/m (default 3000)\n"
           "  --gain-hz HZ           PD natural frequency (default 30)\n"
           "  --damping-ratio Z      (default 1)       --torque-scale S (default 1)\n"
           "  --gains FILE.json      per-joint overrides, e.g. {\"l_wrist\": {\"kp_nm_per_rad\":\n"
           "                         40, \"kd_nm_s_per_rad\": 0.5, \"torque_limit_nm\": 20}}\n"
           "  --limits none|euler|quaternion   limits enforced (default quaternion; a\n"
           "                         stick-only capture: the human range of motion)\n"
           "  --limit-k K            limit width in standard deviations (default 3)\n"
           "  --limit-min-deg DEG    minimum half-width of a limit per axis (default 6)\n"
           "  --no-stops             clamp targets only, no safety-net stops\n"
           "  --ramp S               blend targets in over S seconds (default 0.25)\n"
           "  --smooth-hz HZ         low-pass the reference (default 10; 0: off)\n"
           "  --smooth-kernel butterworth|gaussian   its kernel (default butterworth: the\n"
           "                         zero-phase 2nd-order Butterworth, docs/mocap.md)\n"
           "  --despike-deg DEG      replace one-frame spikes larger than DEG (default 5;\n"
           "                         0: off; below 120 Hz, DEG x (120 / rate)^2)\n"
           "  --tip-smooth-hz HZ     low-pass of the stick tips (X^T and the errors; default:\n"
           "                         --smooth-hz; 0: de-spiked only)\n"
           "  --ik-iterations N      feedback IK iterations per step (default 2; 0: to\n"
           "                         convergence; 1: eq. 2's single step)\n"
           "  --ik-kinematic-iterations N   the kinematic IK's (target rates; default 1)\n"
           "  --quiet                no progress output\n"
        << force_help(25)
        << "\n"
           "Refused (exit 1, FILE:LINE: naming the joint): a limb (upper arm, forearm, thigh,\n"
           "shank) shorter than 0.05 m or any segment longer than 1 m after --scale: no human\n"
           "body has one (docs/character.md). Joint limits learned from fewer than 30 frames\n"
           "are noise: a warning (use --limits none).\n"
           "\n"
           "examples:\n"
           "  ictusd track --mode joint --mocap ../shared/data/cmu/80_13.bvh --out run1\n"
           "  ictusd track --mode cartesian --mocap ../shared/data/cmu/80_13.bvh\n"
           "  ictusd track --mode cartesian --mocap sticks.csv --units mm --up z --drum auto\n";
}

// The command line of a track run.
struct TrackArgs {
    bool help = false;
    std::string mode, mocap, out_dir, limits_mode = "quaternion", gains_file;
    double limit_k = 3.0, limit_width_deg = 6.0;
    double tip_smooth_hz = -1.0; // < 0: the reference's (--smooth-hz)
    ClipOptions clip;
    bool quiet = false;
    CharacterOptions character;
    TrackOptions options;
    bool drum_pos_given = false;
    StickCsvOptions sticks;
    bool stick_only = false; // a .csv capture: stick tips only (Cartesian mode)
};

bool is_csv(const std::string &path)
{
    if (path.size() < 4)
        return false;
    std::string ext = path.substr(path.size() - 4);
    for (char &c : ext)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".csv";
}

// The inverse kinematics of Cartesian mode (docs/ik.md).
OptionTable ik_options(TrackArgs &t)
{
    CartesianOptions &ik = t.options.cartesian;
    return {
        {"--mode",
         [&t](const std::string &a, Args &args) {
             t.mode = args.word(a);
             t.options.mode = parse_track_mode(a, t.mode);
         }},
        {"--ik-gain", store(ik.gain, parse_positive)},
        {"--ik-velocity-gain", store(ik.velocity_gain_s, parse_number)},
        {"--ik-accel-ff", store(ik.acceleration_feedforward_s2, parse_number)},
        {"--ik-correction-limit", store(ik.correction_limit_m, parse_number)},
        {"--ik-start",
         [&ik](const std::string &a, Args &args) {
             const std::string v = args.word(a);
             if (v != "simulated" && v != "kinematic")
                 throw UsageError("--ik-start: expected simulated or kinematic, got '" + v + "'");
             ik.start_from_simulated = v == "simulated";
         }},
        {"--tip-smooth-hz",
         [&t](const std::string &a, Args &args) {
             const std::string text = args.value(a);
             t.tip_smooth_hz = parse_number(a, text);
             if (!(t.tip_smooth_hz >= 0.0 && t.tip_smooth_hz <= 1000.0))
                 throw UsageError("--tip-smooth-hz: expected 0 <= HZ <= 1000, got " + text);
         }},
        {"--ik-iterations", store(ik.feedback_iterations, parse_int, 0, 10000)},
        {"--ik-kinematic-iterations", store(ik.kinematic_iterations, parse_int, 0, 10000)},
        {"--ik-posture-weight", store(ik.posture_weight, parse_number)},
        {"--ik-integral", store(ik.integral_per_s, parse_number)},
    };
}

// The simulation: the step, the solver, the drum, the stops, the ramp.
OptionTable scene_options(TrackArgs &t)
{
    SceneOptions &scene = t.options.scene;
    return {
        {"--drum",
         [&t](const std::string &a, Args &args) {
             const std::string v = args.word(a);
             if (v == "auto")
                 return;
             try {
                 t.options.scene.drum.center_m =
                     parse_vec3(a, v, -kMaxDrumDistance_m, kMaxDrumDistance_m);
             } catch (const UsageError &) {
                 throw UsageError("--drum: expected auto or X,Y,Z (m), got '" + v + "'");
             }
             t.drum_pos_given = true;
         }},
        {"--drum-pos",
         [&t](const std::string &a, Args &args) {
             t.options.scene.drum.center_m =
                 parse_vec3(a, args.value(a), -kMaxDrumDistance_m, kMaxDrumDistance_m);
             t.drum_pos_given = true;
         }},
        {"--drum-radius", store(scene.drum.radius_m, parse_positive)},
        {"--drum-tension", store(scene.drum.tension_n_per_m, parse_positive)},
        {"--duration", store(t.options.duration_s, parse_positive)},
        {"--step", store(scene.step_s, parse_positive)},
        {"--stepper",
         [&scene](const std::string &a, Args &args) {
             const std::string s = args.word(a);
             if (s == "quick")
                 scene.stepper = Stepper::quick;
             else if (s == "direct")
                 scene.stepper = Stepper::direct;
             else
                 throw UsageError("--stepper: expected quick or direct, got '" + s + "'");
         }},
        {"--iterations", store(scene.quickstep_iterations, parse_int, 1, 1000)},
        {"--sor-w", store(scene.quickstep_w, parse_number, 0.01, 1.99)},
        {"--no-stops", [&scene](const std::string &, Args &) { scene.limit_stops = false; }},
        {"--ramp",
         [&t](const std::string &a, Args &args) {
             t.options.ramp_s = parse_number(a, args.value(a));
             if (t.options.ramp_s < 0.0)
                 throw UsageError("--ramp: expected a number >= 0, got " +
                                  std::to_string(t.options.ramp_s));
         }},
    };
}

// The body: mass, grip, sticks, joint gains and limits.
OptionTable body_options(TrackArgs &t)
{
    CharacterOptions &body = t.character;
    GainOptions &gains = t.options.gains;
    return {
        {"--body-mass", store(body.body_mass_kg, parse_positive)},
        {"--grip", store(body.grip, parse_grip)},
        {"--stick-length", store(body.stick.length_m, parse_positive)},
        {"--stick-mass", store(body.stick.mass_kg, parse_positive)},
        {"--stick-tip-radius", store(body.stick.tip_radius_m, parse_positive)},
        {"--gain-hz", store(gains.natural_frequency_hz, parse_positive)},
        {"--damping-ratio", store(gains.damping_ratio, parse_positive)},
        {"--torque-scale", store(gains.torque_scale, parse_positive)},
        {"--gains", store_text(t.gains_file)},
        {"--limits",
         [&t](const std::string &a, Args &args) {
             t.limits_mode = args.word(a);
             if (t.limits_mode != "none" && t.limits_mode != "euler" &&
                 t.limits_mode != "quaternion")
                 throw UsageError("--limits: expected none, euler or quaternion, got '" +
                                  t.limits_mode + "'");
         }},
        {"--limit-k", store(t.limit_k, parse_positive)},
        {"--limit-min-deg", store(t.limit_width_deg, parse_min_half_width_deg)},
    };
}

// The capture, the output folder, the chatter.
OptionTable io_options(TrackArgs &t)
{
    return {
        {"--mocap", store_text(t.mocap)},
        {"--out", store_text(t.out_dir)},
        {"--quiet", store_flag(t.quiet)},
        {"-q", store_flag(t.quiet)},
    };
}

// What the options mean together, checked before any file is read.
void check_track_args(TrackArgs &t)
{
    if (t.mode.empty())
        throw UsageError("--mode is required (--mode joint or --mode cartesian)");
    if (t.mocap.empty())
        throw UsageError("--mocap FILE is required");
    t.sticks.csv.accept_out_of_bounds = t.clip.force;
    t.options.drum_auto = !t.drum_pos_given;
    // Option values that only the model can judge (e.g. a too-long step) are
    // usage errors too: check them before reading the file.
    try {
        validate(t.options);
    } catch (const PerformError &e) {
        throw UsageError(e.what());
    } catch (const CharacterError &e) { // the scene's options
        throw UsageError(e.what());
    } catch (const SimError &e) {
        throw UsageError(e.what());
    }
    // A .csv capture is stick-only (Cartesian mode): the default body holds a
    // neutral pose and its arms follow the two stick tips.
    t.stick_only = is_csv(t.mocap);
    if (t.stick_only && t.options.mode != TrackMode::cartesian)
        throw UsageError("a stick-only capture (" + t.mocap + ") needs --mode cartesian");
    if (!t.stick_only && t.sticks.given)
        throw UsageError("--left-stick, --right-stick, --units, --up and --rate apply "
                         "to stick-only .csv captures");
    if (t.stick_only && t.limits_mode != "none") {
        // No capture to learn them from: a person's (RangeOfMotion, as the score
        // performer's body). Without limits fast strokes' impacts pumped the arms'
        // null space until a clavicle turned 150 degrees (docs/ik.md).
        if (!t.quiet)
            std::cerr << "ictusd: note: stick-only capture: joint limits from the normal human "
                         "range of motion (no capture to learn them from; --limits none: "
                         "none)\n";
        t.limits_mode = "range_of_motion";
    }
}

TrackArgs parse_track_args(Args &args)
{
    TrackArgs t;
    const OptionTable tables[] = {ik_options(t), scene_options(t), body_options(t), io_options(t)};
    const bool go_on = walk_args(args, track_usage, [&](const std::string &a) {
        for (const OptionTable &table : tables)
            if (dispatch_option(table, a, args))
                return;
        if (!parse_stick_csv_option(a, args, t.sticks) && !parse_clip_option(a, args, t.clip))
            throw UsageError("unknown option '" + a + "' (see ictusd track --help)");
    });
    if (!go_on) {
        t.help = true;
        return t;
    }
    check_track_args(t);
    return t;
}

// What a track run needs, built from the files: the character, its reference
// motion (cleaned, and raw for the errors), limits, gains, the stick tips of a
// stick-only capture. Members refer to one another: built in place, never moved.
struct TrackInput {
    TrackInput() = default;
    TrackInput(const TrackInput &) = delete;
    TrackInput &operator=(const TrackInput &) = delete;
    BvhFile bvh;
    std::unique_ptr<CharacterModel> model;
    std::unique_ptr<ReferenceMotion> raw, reference, tips_cleaned;
    TipTrajectory tips;
    std::unique_ptr<CharacterLimits> limits;
    std::unique_ptr<RangeOfMotion> rom; // a stick-only capture's limits
    std::vector<JointLimitRef> limit_refs;
    std::vector<JointGains> gains;
};

// Joint limits learned from the (cleaned) capture (Algorithm 1, CharacterLimits).
void load_learned_limits(const TrackArgs &t, TrackInput &in)
{
    const CharacterModel &model = *in.model;
    if (t.limits_mode != "none" && in.reference->frames() < kMinLimitFrames)
        std::cerr << "ictusd: warning: " << t.mocap << ": joint limits learned from "
                  << in.reference->frames() << " frame(s), fewer than " << kMinLimitFrames
                  << ": their spreads are noise (--limits none to run without them)\n";
    CharacterLimitOptions lim;
    lim.kind = limit_kind_from_string(t.limits_mode);
    lim.k = t.limit_k;
    lim.min_half_width_rad = t.limit_width_deg * M_PI / 180.0;
    in.limits = std::make_unique<CharacterLimits>(model, *in.reference, lim);
    in.limit_refs = in.limits->refs();
}

// --gains FILE passes the stability check /ictus/gains applies
// (Performance::check_gains, docs/perform.md "Stability of the controller"),
// joint by joint against its default: the damping ratio zeta0 * (kd/kd0) /
// sqrt(kp/kp0) at least min(1/sqrt 2, zeta0), and kp/kd times the step at most
// kMaxPdRateStep. Else std::runtime_error naming the file and the joint.
void check_gain_overrides(const CharacterModel &model, const std::vector<JointGains> &defaults,
                          const std::vector<JointGains> &gains, const TrackArgs &t)
{
    const double zeta0 = t.options.gains.damping_ratio, h = t.options.scene.step_s;
    const double zeta_min = std::min(Performance::kMinDampingRatio, zeta0);
    for (size_t j = 0; j < gains.size() && j < defaults.size(); ++j) {
        const JointGains &g = gains[j], &d = defaults[j];
        const double zeta = zeta0 * (g.kd_nm_s_per_rad / d.kd_nm_s_per_rad) /
                            std::sqrt(g.kp_nm_per_rad / d.kp_nm_per_rad);
        const double rate = g.kp_nm_per_rad / g.kd_nm_s_per_rad;
        char why[256] = "";
        if (zeta < zeta_min * (1.0 - 1e-9))
            std::snprintf(why, sizeof why,
                          "leaves a damping ratio of %.2f, under %.2f (the joint would ring): "
                          "kd_nm_s_per_rad %.4g or more",
                          zeta, zeta_min,
                          d.kd_nm_s_per_rad * zeta_min / zeta0 *
                              std::sqrt(g.kp_nm_per_rad / d.kp_nm_per_rad));
        else if (rate * h > Performance::kMaxPdRateStep)
            std::snprintf(why, sizeof why,
                          "gives a PD rate kp/kd of %.0f/s, unstable at the %g ms step (at most "
                          "%.0f/s)",
                          rate, 1e3 * h, Performance::kMaxPdRateStep / h);
        if (why[0])
            throw std::runtime_error(t.gains_file + ": joint '" +
                                     model.joint_name(static_cast<int>(j)) + "': kp_nm_per_rad " +
                                     std::to_string(g.kp_nm_per_rad) + " with kd_nm_s_per_rad " +
                                     std::to_string(g.kd_nm_s_per_rad) + " " + why);
    }
}

void load_track_input(TrackArgs &t, TrackInput &in)
{
    MarkerCapture capture;
    std::array<int, 2> stick_tracks = {-1, -1};
    if (t.stick_only) {
        capture = load_marker_csv(t.mocap, t.sticks.csv);
        if (capture.time_s.size() < 2) // no motion to track, nor a rate
            throw MocapError(t.mocap, 0,
                             "expected at least two frames (data rows) of the sticks, got " +
                                 std::to_string(capture.time_s.size()));
        try {
            stick_tracks = find_stick_tracks(capture, t.sticks.left_stick, t.sticks.right_stick);
        } catch (const CharacterError &e) {
            throw UsageError(e.what());
        }
        in.bvh.skeleton = default_skeleton();
        in.bvh.motion.frame_rate_hz = 100.0;
        for (int f = 0; f < 2; ++f) {
            // Standing height of the default body's hips (legs straight).
            in.bvh.motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
            in.bvh.motion.local_rotation.emplace_back(in.bvh.skeleton.joints.size(),
                                                      Eigen::Quaterniond::Identity());
        }
    } else {
        in.bvh = load_bvh(t.mocap, t.clip.scale, t.clip.skip, t.clip.force);
    }
    in.model = std::make_unique<CharacterModel>(
        CharacterModel::from_skeleton(in.bvh.skeleton, t.character));
    const CharacterModel &model = *in.model;
    in.raw = std::make_unique<ReferenceMotion>(model, in.bvh.motion);
    in.reference = std::make_unique<ReferenceMotion>(
        model, in.bvh.motion, t.stick_only ? ReferenceFilter{0.0, 0.0} : t.clip.filter);
    if (t.stick_only) {
        in.tips = place_behind_sticks(model, in.reference->frame(0), capture, stick_tracks);
        t.options.tip_reference = &in.tips;
        if (t.options.drum_auto) {
            // A capture with no stroke (sticks held still) has nowhere to put
            // the drum: say which file, and what to give instead.
            try {
                fit_drum_to_turnarounds(in.tips, t.character.stick.tip_radius_m);
            } catch (const CharacterError &e) {
                throw MocapError(t.mocap, 0,
                                 std::string(e.what()) +
                                     "; give the drum's place instead: --drum X,Y,Z (m)");
            }
        }
    } else if (t.tip_smooth_hz >= 0.0 && t.tip_smooth_hz != t.clip.filter.smooth_cutoff_hz) {
        // The stick tips' own clean-up (docs/mocap.md): de-spiked as the joints,
        // low-passed at --tip-smooth-hz.
        ReferenceFilter tip_filter = t.clip.filter;
        tip_filter.smooth_cutoff_hz = t.tip_smooth_hz;
        in.tips_cleaned = std::make_unique<ReferenceMotion>(model, in.bvh.motion, tip_filter);
        t.options.tip_motion = in.tips_cleaned.get();
    }
    if (t.limits_mode == "range_of_motion") {
        in.rom = std::make_unique<RangeOfMotion>(model);
        in.limit_refs = in.rom->refs();
    } else {
        load_learned_limits(t, in);
    }
    // Gains: inertia-scaled defaults at the first pose, then per-joint overrides.
    in.gains = default_gains(model, in.reference->frame(0), t.options.gains);
    if (!t.gains_file.empty()) {
        std::ifstream file(t.gains_file);
        if (!file)
            throw std::runtime_error("--gains: cannot read '" + t.gains_file + "'");
        nlohmann::json overrides;
        try {
            overrides = nlohmann::json::parse(file);
        } catch (const nlohmann::json::parse_error &e) {
            throw std::runtime_error(t.gains_file + ": not valid JSON (" + e.what() + ")");
        }
        const std::vector<JointGains> defaults = in.gains;
        apply_gain_overrides(model, overrides, t.gains_file, in.gains);
        check_gain_overrides(model, defaults, in.gains, t);
    }
}

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

// The simulation: track.csv streamed as it runs, strikes kept in order.
TrackSummary run_tracking(TrackArgs &t, const TrackInput &in, std::ostream *csv, StrikeLog &log)
{
    t.options.interrupt = &g_interrupted;
    // strikes.csv: every verb that simulates writes it (docs/osc.md), through
    // the interaction manager on the scene's beads, fed after each physics step.
    StrikeDetector detector;
    if (!t.out_dir.empty())
        t.options.on_step = [&](const Scene &scene) {
            detector.set_membrane(membrane_of(scene));
            StrikeEvent out[2];
            const int n = detect_strikes(detector, scene, out);
            log.add(out, n);
        };
    Progress progress(!t.quiet);
    TrackSummary summary = track_joint_space(
        *in.model, *in.reference, t.options, in.limit_refs, csv, [&](double f) { progress(f); },
        &in.gains, in.raw.get());
    if (t.options.drum_auto && summary.drum_rule == "lowest_tips" && !t.quiet)
        std::cerr << "ictusd: note: --drum auto: the drum goes under the lowest tips: "
                  << 100.0 * summary.drum_through_fraction
                  << " % of a stick's samples pass through a drum at the strokes' turnarounds "
                     "(docs/mocap.md, \"Drum placement\")\n";
    StrikeEvent e;
    while (detector.flush(e))
        log.add(&e, 1);
    log.finish();
    t.options.on_step = nullptr;
    return summary;
}

// summary.json, strikes.csv and the lines on stdout; the exit status.
int report(const TrackArgs &t, const TrackInput &in, const TrackSummary &summary,
           const StrikeLog &log)
{
    const TrackOptions &options = t.options;
    nlohmann::json j = summary.to_json();
    j["mocap"] = t.mocap;
    // A stick-only .csv capture has no BVH scale, skipped frames or joint clean-up: null.
    const nlohmann::json not_used;
    j["scale_m_per_unit"] = t.stick_only ? not_used : nlohmann::json(t.clip.scale);
    j["skip_frames"] = t.stick_only ? not_used : nlohmann::json(t.clip.skip);
    j["step_s"] = options.scene.step_s;
    j["stepper"] = options.scene.stepper == Stepper::quick ? "quick" : "direct";
    j["quickstep_iterations"] = options.scene.quickstep_iterations;
    j["quickstep_w"] = options.scene.quickstep_w;
    j["grip"] = to_string(t.character.grip);
    j["body_mass_kg"] = t.character.body_mass_kg;
    j["limits"] = t.limits_mode;
    j["limit_k"] = t.limit_k;
    j["limit_min_deg"] = t.limit_width_deg;
    j["limit_stops"] = options.scene.limit_stops;
    j["gain_hz"] = options.gains.natural_frequency_hz;
    j["damping_ratio"] = options.gains.damping_ratio;
    j["drum_radius_m"] = options.scene.drum.radius_m;
    j["smooth_hz"] = t.stick_only ? not_used : nlohmann::json(t.clip.filter.smooth_cutoff_hz);
    j["despike_deg"] =
        t.stick_only ? not_used : nlohmann::json(t.clip.filter.spike_threshold_rad * 180.0 / M_PI);
    j["smooth_kernel"] = t.stick_only ? not_used : nlohmann::json(to_string(t.clip.filter.kernel));
    j["spikes_removed"] = t.stick_only ? not_used : nlohmann::json(in.reference->spikes_removed());
    j["tip_smooth_hz"] = t.stick_only           ? 0.0
                         : t.options.tip_motion ? t.tip_smooth_hz
                                                : t.clip.filter.smooth_cutoff_hz;
    j["drum_auto"] = options.drum_auto;
    j["interrupted"] = summary.interrupted;
    j["gains"] = gains_to_json(*in.model, in.gains);
    if (options.mode == TrackMode::cartesian) {
        j["ik"]["gain"] = options.cartesian.gain;
        j["ik"]["velocity_gain_s"] = options.cartesian.velocity_gain_s;
        j["ik"]["correction_limit_m"] = options.cartesian.correction_limit_m;
        j["ik"]["integral_per_s"] = options.cartesian.integral_per_s;
        j["ik"]["start"] = options.cartesian.start_from_simulated ? "simulated" : "kinematic";
        j["ik"]["posture_weight"] = options.cartesian.posture_weight;
        j["ik"]["feedback_iterations"] = options.cartesian.feedback_iterations;
        j["ik"]["kinematic_iterations"] = options.cartesian.kinematic_iterations;
    }
    if (!t.out_dir.empty()) {
        OutputFile strikes(t.out_dir + "/strikes.csv");
        log.write_csv(strikes.stream());
        strikes.close();
        j["strikes"] = static_cast<long>(log.strikes().size());
        OutputFile js(t.out_dir + "/summary.json");
        js.stream() << j.dump(2) << "\n";
        js.close();
    }
    std::cout << "mode " << summary.mode << ", " << summary.duration_s
              << " s simulated, realtime factor " << summary.realtime_factor << "\n"
              << "tip rms (mm): left " << summary.tip_rms_mm[0] << ", right "
              << summary.tip_rms_mm[1] << "\n"
              << "joint rms (deg), all joints: " << j["joint_rms_deg_all"].get<double>() << "\n"
              << "divergences: " << summary.divergences << "\n";
    if (options.mode == TrackMode::cartesian) {
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

} // namespace

int cmd_track(Args &args)
{
    TrackArgs t = parse_track_args(args);
    if (t.help)
        return 0;
    TrackInput in;
    load_track_input(t, in);
    std::ofstream csv;
    if (!t.out_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(t.out_dir, ec);
        if (ec)
            throw std::runtime_error("--out: cannot create directory '" + t.out_dir +
                                     "': " + ec.message());
        csv.open(t.out_dir + "/track.csv");
        if (!csv)
            throw std::runtime_error("--out: cannot write '" + t.out_dir + "/track.csv'");
        csv.precision(9);
    }
    StrikeLog log;
    const TrackSummary summary = run_tracking(t, in, t.out_dir.empty() ? nullptr : &csv, log);
    if (!t.out_dir.empty()) {
        csv.close();
        if (!csv)
            throw std::runtime_error("--out: error writing '" + t.out_dir + "/track.csv'");
    }
    return report(t, in, summary, log);
}

} // namespace cli
} // namespace ictus
