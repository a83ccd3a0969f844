// options.cpp -- the option groups several verbs share (options.hpp): how a
// BVH clip is read, how a stick-only CSV is read, the performance options of
// run and render, the grip and the mode; and the output files of a verb.
#include "ictus/cli/options.hpp"
#include "ictus/base/input_file.hpp"
#include "ictus/score/midi_score.hpp"

#include <algorithm>
#include <iterator>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

extern "C" {
#include "membrane_presets.h"
}

namespace ictus
{
namespace cli
{

namespace
{
// "grip: expected ..." -> ": expected ...": the model's message under the option's name.
std::string after_name(const std::string &message)
{
    const size_t colon = message.find(':');
    return colon == std::string::npos ? ": " + message : message.substr(colon);
}

constexpr int kGivenRadius = 1, kGivenTension = 2, kGivenDensity = 4, kGivenPreset = 8;

// --drum-preset NAME: the head of a preset (membrane_presets.h) in the physics and the
// sound; a --drum-radius, --drum-tension or --drum-density given too wins over it.
void apply_drum_preset(const std::string &option, const std::string &name, PerformanceOptions &o)
{
    const membrane_preset *p = membrane_preset_find(name.c_str());
    if (!p)
        throw UsageError(option + ": unknown preset '" + name + "'; the presets are " +
                         membrane_preset_drum_names());
    if (p->plate)
        throw UsageError(option + ": '" + name +
                         "' is a cymbal (a plate, membrane~'s preset for the sound), not a drum "
                         "the physics can play; the drum presets are " +
                         membrane_preset_drum_names());
    o.drum_preset = p->name;
    if (!(o.drum_given & kGivenRadius))
        o.scene.drum.radius_m = p->radius_m;
    if (!(o.drum_given & kGivenTension))
        o.scene.drum.tension_n_per_m = p->tension_n_per_m;
    if (!(o.drum_given & kGivenDensity))
        o.drum_density_kg_per_m2 = p->density_kg_per_m2;
}
} // namespace

bool parse_bvh_option(const std::string &a, Args &args, double &scale_m_per_unit, int &skip_frames)
{
    if (a == "--scale")
        scale_m_per_unit = parse_positive(a, args.value(a));
    else if (a == "--skip-frames")
        skip_frames = parse_int(a, args.value(a), 0, 100000000);
    else
        return false;
    return true;
}

bool parse_stick_csv_option(const std::string &a, Args &args, StickCsvOptions &o)
{
    if (a == "--left-stick") {
        o.left_stick = args.value(a);
    } else if (a == "--right-stick") {
        o.right_stick = args.value(a);
    } else if (a == "--units") {
        const std::string v = args.word(a);
        if (v != "mm" && v != "m")
            throw UsageError("--units: expected mm or m, got '" + v + "'");
        o.csv.units = v == "mm" ? MarkerCsvOptions::Units::mm : MarkerCsvOptions::Units::m;
    } else if (a == "--up") {
        const std::string v = args.word(a);
        if (v != "y" && v != "z")
            throw UsageError("--up: expected y or z, got '" + v + "'");
        o.csv.up = v == "z" ? MarkerCsvOptions::Up::z : MarkerCsvOptions::Up::y;
    } else if (a == "--rate") {
        o.csv.rate_hz = parse_positive(a, args.value(a));
    } else {
        return false;
    }
    o.given = true;
    return true;
}

Grip parse_grip(const std::string &option, const std::string &text)
{
    try {
        return grip_from_string(text);
    } catch (const CharacterError &e) {
        throw UsageError(option + after_name(e.what()));
    }
}

TrackMode parse_track_mode(const std::string &option, const std::string &text)
{
    try {
        return track_mode_from_string(text);
    } catch (const PerformError &e) {
        throw UsageError(option + after_name(e.what()));
    }
}

bool parse_clip_option(const std::string &a, Args &args, ClipOptions &clip)
{
    if (parse_bvh_option(a, args, clip.scale, clip.skip)) {
    } else if (a == "--smooth-hz") {
        clip.filter.smooth_cutoff_hz = parse_number(a, args.value(a));
        if (clip.filter.smooth_cutoff_hz < 0.0)
            throw UsageError("--smooth-hz: expected a number >= 0 (0: off)");
    } else if (a == "--smooth-kernel") {
        try {
            clip.filter.kernel = reference_kernel_from_string(args.word(a));
        } catch (const CharacterError &e) {
            throw UsageError(a + after_name(e.what()));
        }
    } else if (a == "--despike-deg") {
        clip.filter.spike_threshold_rad = parse_number(a, args.value(a)) * M_PI / 180.0;
        if (clip.filter.spike_threshold_rad < 0.0)
            throw UsageError("--despike-deg: expected a number >= 0 (0: off)");
    } else if (a == "--force") {
        clip.force = true;
    } else {
        return false;
    }
    return true;
}

double parse_min_half_width_deg(const std::string &option, const std::string &text)
{
    const double w = parse_number(option, text);
    if (w < 0.0 || w >= 180.0)
        throw UsageError(option + ": expected 0 <= deg < 180, got '" + text + "'");
    return w;
}

std::string force_help(std::size_t column)
{
    const std::string pad(column, ' ');
    std::string name = "  --force";
    name.resize(std::max(column, name.size() + 1), ' ');
    return name + "read a capture out of the physical bounds (docs/mocap.md)\n" + pad +
           "with a warning, not an error: a frame time or median\n" + pad +
           "time step outside 0.0005..0.5 s (2 kHz..2 Hz; a time\n" + pad +
           "column in ms?), a take longer than 3 h, a coordinate\n" + pad +
           "beyond 100 m (after --scale or --units)\n";
}

namespace
{
// "1 note", "3 notes": a count and its noun, for the --midi lines on stderr.
std::string counted(long n, const char *one, const char *many)
{
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

// A reader's out-of-bounds error, with the way to insist.
MocapBoundError with_force_hint(const MocapBoundError &e)
{
    return MocapBoundError(e.file(), e.line(), e.message() + " (--force reads it anyway)");
}

// What `read(&warnings)` reads, its warnings printed to stderr; an
// out-of-bounds error says that --force would read it.
template <typename Read> auto read_capture(const Read &read)
{
    MocapWarnings warnings;
    try {
        auto capture = read(&warnings);
        for (const std::string &w : warnings)
            std::cerr << "ictusd: warning: " << w << "\n";
        return capture;
    } catch (const MocapBoundError &e) {
        throw with_force_hint(e);
    }
}
} // namespace

BvhFile load_bvh(const std::string &path, double scale, int skip, bool force)
{
    BvhOptions o;
    o.scale = scale;
    o.skip_frames = skip;
    o.accept_out_of_bounds = force;
    return read_capture([&](MocapWarnings *warnings) { return read_bvh(path, o, warnings); });
}

MarkerCapture load_marker_csv(const std::string &path, const MarkerCsvOptions &o)
{
    return read_capture(
        [&](MocapWarnings *warnings) { return read_marker_csv(path, o, warnings); });
}

// A --score file: at most kMaxScoreFileBytes, and a byte more read to know
// it is more (/dev/zero, a FIFO: no size to ask for first).
std::string read_score_file(const std::string &path)
{
    InputFile file = open_input_file(path);
    if (file.is_folder) // it would open, and read as empty
        throw std::runtime_error("--score: '" + path + "' is a folder, not a score file");
    if (!file.opened)
        throw std::runtime_error("--score: cannot read '" + path + "'" + file.reason_suffix());
    std::ifstream &in = file.stream;
    std::string text;
    char buf[65536];
    while (text.size() <= kMaxScoreFileBytes && in.read(buf, sizeof buf).gcount() > 0)
        text.append(buf, static_cast<size_t>(in.gcount()));
    if (in.bad())
        throw std::runtime_error("--score: read error in '" + path + "'");
    if (text.size() > kMaxScoreFileBytes)
        throw std::runtime_error("--score: '" + path + "' is larger than " +
                                 std::to_string(kMaxScoreFileBytes >> 20) +
                                 " MiB, the bound of a score file");
    return text;
}

// The drum's and the kit's options (parse_performance_option's).
static bool parse_drum_option(const std::string &a, Args &args, PerformanceOptions &o)
{
    auto value = [&]() { return args.value(a); };
    auto word = [&]() { return args.word(a); };
    if (a == "--drum-pos") {
        o.scene.drum.center_m = parse_vec3(a, value(), -kMaxDrumDistance_m, kMaxDrumDistance_m);
        o.drum_auto = false;
    } else if (a == "--drum-radius") {
        o.scene.drum.radius_m = parse_number(a, value(), 0.05, 1.0);
        o.drum_given |= kGivenRadius;
    } else if (a == "--drum-tension") {
        o.scene.drum.tension_n_per_m = parse_number(a, value(), 10, 1e5);
        o.drum_given |= kGivenTension;
    } else if (a == "--drum-density") {
        o.drum_density_kg_per_m2 = parse_number(a, value(), 0.01, 10);
        o.drum_given |= kGivenDensity;
    } else if (a == "--drum-preset") {
        apply_drum_preset(a, word(), o);
        o.drum_given |= kGivenPreset;
    } else if (a == "--stick-tip") {
        const std::string v = word();
        if (!is_stick_tip(v))
            throw UsageError("--stick-tip: expected wood, nylon or felt, got '" + v + "'");
        o.scene.drum.stick_tip = v;
    } else if (a == "--kit") {
        const std::string v = word();
        try {
            o.kit = kit_named(v);
        } catch (const PerformError &e) {
            throw UsageError("--kit: " + std::string(e.what()));
        }
        // The first drum's head and sound are its preset's (as --drum-preset).
        apply_drum_preset(a, o.kit.drums.front().preset, o);
    } else {
        return false;
    }
    return true;
}

// Options shared by run and render. Returns false when `a` is not one of them.
bool parse_performance_option(const std::string &a, Args &args, PerformanceOptions &o,
                              double &duration)
{
    static const char *const score_options[] = {"--gestures",
                                                "--strike-depth",
                                                "--strike-aim",
                                                "--move-margins",
                                                "--strike-aim-from",
                                                "--strike-aim-max",
                                                "--advance",
                                                "--ik-gain",
                                                "--ik-velocity-gain",
                                                "--ik-rotation-weight",
                                                "--ik-max-joint-speed",
                                                "--ik-limit-margin",
                                                "--humanize",
                                                "--seed",
                                                "--rebound",
                                                "--lead-in"};
    if (o.score_option_given.empty() &&
        std::find(std::begin(score_options), std::end(score_options), a) != std::end(score_options))
        o.score_option_given = a;
    auto value = [&]() { return args.value(a); };
    auto word = [&]() { return args.word(a); };
    if (a == "--mocap") {
        o.mocap = value();
        std::string ext = std::filesystem::path(o.mocap).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (ext == ".csv")
            throw UsageError("--mocap " + o.mocap +
                             ": run and render play a BVH capture of the whole body; a "
                             "stick-only .csv capture is played by `ictusd track --mode "
                             "cartesian --mocap " +
                             o.mocap + "` (docs/mocap.md)");
    } else if (parse_bvh_option(a, args, o.scale_m_per_unit, o.skip_frames))
        ;
    else if (a == "--duration")
        duration = parse_number(a, value(), 1e-3, 1e7);
    else if (a == "--step")
        o.scene.step_s = parse_number(a, value(), 1e-5, 0.01);
    else if (a == "--grip") {
        o.character.grip = parse_grip(a, word());
        o.score.grip_given = true;
    } else if (a == "--score") {
        // A score that cannot be read is a file error (exit 1), not a usage error.
        const std::string path = value();
        o.score.score_text = read_score_file(path);
        o.score.score_name = path;
        // Empty, or blank lines and comments only: no notes, said alike.
        if (!score_text_has_statements(o.score.score_text))
            throw std::runtime_error("--score: '" + path + "' has no notes (" +
                                     (o.score.score_text.empty()
                                          ? "the file is empty"
                                          : "nothing but blank lines and comments") +
                                     ")");
    } else if (a == "--midi") {
        o.score.midi_path = value();
        o.score.score_name = o.score.midi_path;
    } else if (a == "--gestures")
        o.score.gestures = value();
    else if (a == "--mode") {
        o.score.mode = parse_track_mode(a, word());
        // `--mode joint` is what a clip plays in: said of cartesian alone
        if (o.score.mode != TrackMode::joint && o.score_option_given.empty())
            o.score_option_given = a;
    } else if (a == "--strike-depth")
        o.score.plan.strike_depth_m = parse_number(a, value(), -0.05, 0.05);
    else if (a == "--strike-aim")
        o.score.plan.strike_aim_s = parse_number(a, value(), 0.0, 0.01);
    else if (a == "--move-margins") {
        const std::string v = value();
        const auto comma = v.find(',');
        if (comma == std::string::npos)
            throw UsageError("--move-margins: expected AFTER,BEFORE (fractions of the gap)");
        o.score.plan.move_margin_after = parse_number(a, v.substr(0, comma), 0.0, 0.45);
        o.score.plan.move_margin_before = parse_number(a, v.substr(comma + 1), 0.0, 0.45);
    } else if (a == "--strike-aim-from")
        o.score.plan.strike_aim_from_mps = parse_number(a, value(), 0.0, 20.0);
    else if (a == "--strike-aim-max")
        o.score.plan.strike_aim_max_m = parse_number(a, value(), 0.0, 0.05);
    else if (a == "--advance")
        o.score.time_advance_s = parse_number(a, value(), 0, 0.1);
    else if (a == "--ik-gain")
        o.score.cartesian.gain = parse_number(a, value(), 0.1, 100);
    else if (a == "--ik-velocity-gain")
        o.score.cartesian.velocity_gain_s = parse_number(a, value(), 0, 1);
    else if (a == "--ik-rotation-weight")
        o.score.cartesian.rotation_weight = parse_number(a, value(), 0, 1);
    else if (a == "--iterations")
        o.scene.quickstep_iterations = static_cast<int>(parse_number(a, value(), 1, 1000));
    else if (a == "--sor-w")
        o.scene.quickstep_w = parse_number(a, value(), 0.01, 1.99);
    else if (a == "--ik-max-joint-speed")
        o.score.cartesian.max_joint_speed_rad_s = parse_number(a, value(), 0, 1000);
    else if (a == "--ik-limit-margin")
        o.score.ik_limit_margin_deg = parse_number(a, value(), 0, 10);
    else if (a == "--humanize")
        o.score.plan.humanize = parse_number(a, value(), 0, kMaxHumanize);
    else if (a == "--seed") {
        const std::string value_text = value();
        const double seed = parse_number(a, value_text, 0, 9007199254740992.0); // 2^53
        if (seed != std::floor(seed))
            throw UsageError("--seed: expected a whole number, got '" + value_text + "'");
        o.score.plan.seed = static_cast<std::uint64_t>(seed);
    } else if (a == "--rebound")
        o.score.rebound_s = parse_number(a, value(), 0, 0.5);
    else if (a == "--lead-in")
        o.score.plan.lead_in_s = parse_number(a, value(), 0.2, 60);
    else if (a == "--tempo") {
        // a clip's playback tempo; a score's until its own first `tempo`
        o.tempo_bpm = parse_number(a, value(), 20, 400);
        o.score.start_tempo_bpm = o.tempo_bpm;
    } else if (a == "--clip-bpm")
        o.clip_bpm = parse_number(a, value(), 20, 400);
    else if (parse_drum_option(a, args, o)) {
        // the drum or the kit
    } else if (a == "--sticks") {
        const std::string v = word();
        if (v == "fulcrum")
            o.scene.sticks = StickMount::fulcrum;
        else if (v == "rigid")
            o.scene.sticks = StickMount::rigid;
        else
            throw UsageError("--sticks: expected fulcrum or rigid, got '" + v + "'");
    } else if (a == "--grip-firmness")
        o.grip_firmness = parse_number(a, value(), 0, 1);
    else if (a == "--grip-damping")
        o.scene.grip_damping_ratio = parse_number(a, value(), 0, 10);
    else if (a == "--bounce-height")
        o.strikes.bounce_height_m = parse_number(a, value(), 0, 1);
    else if (a == "--bounce-window")
        o.strikes.bounce_window_s = parse_number(a, value(), 0, 10);
    else
        return false;
    return true;
}

OutputFile::OutputFile(const std::string &path) : path_(path), out_(path, std::ios::binary)
{
    if (!out_)
        throw std::runtime_error("--out: cannot write '" + path_ + "'");
}

void OutputFile::close()
{
    out_.close();
    if (!out_)
        throw std::runtime_error("--out: error writing '" + path_ + "' (disk full?)");
}

// A kit's first drum has the kit's head and sound (docs/kit.md, "Playing it"): the one
// drum's options would be dropped, or half kept, by their place before or after --kit.
static void check_kit_drum_options(const PerformanceOptions &o)
{
    if (o.kit.empty())
        return;
    const char *option = (o.drum_given & kGivenPreset)    ? "--drum-preset"
                         : (o.drum_given & kGivenRadius)  ? "--drum-radius"
                         : (o.drum_given & kGivenTension) ? "--drum-tension"
                                                          : nullptr;
    if (option)
        throw UsageError(std::string(option) +
                         ": the kit's drums have their own heads and sounds (its first, '" +
                         o.kit.drums.front().name + "', the " + o.kit.drums.front().preset +
                         " preset's; docs/kit.md): give " + option + " without --kit");
}

void check_performance_options(const PerformanceOptions &o)
{
    check_kit_drum_options(o);
    if (!o.mocap.empty() && !o.score.score_text.empty())
        throw UsageError("--score and --mocap are two motion sources: give one");
    if (!o.mocap.empty() && !o.kit.empty())
        throw UsageError("--kit: a kit is played from a score (--score, --midi or the default "
                         "score), not with --mocap");
    if (!o.mocap.empty() && !o.score_option_given.empty())
        throw UsageError(o.score_option_given +
                         ": a score's option (score mode: --score, --midi or the default "
                         "score): with --mocap the clip plays in joint space without it");
}

void load_midi_score(PerformanceOptions &o)
{
    check_performance_options(o);
    const std::string &path = o.score.midi_path;
    if (path.empty())
        return;
    if (!o.score.score_text.empty() || !o.mocap.empty())
        throw UsageError("--midi is a score: give one of --midi, --score, --mocap");
    std::vector<MidiDrum> drums;
    for (const KitDrum &d : o.kit.drums)
        drums.push_back({d.name, d.midi_note, true, {d.place_m.x(), d.place_m.y(), d.place_m.z()}});
    MidiDrumPart part = load_midi_drum_part(path, drums, o.score.start_tempo_bpm);
    std::ostringstream line;
    long skipped = 0;
    for (const auto &[note, count] : part.skipped) {
        line << (skipped ? ", " : "") << "note " << note << " x" << count;
        skipped += count;
    }
    if (skipped > 0)
        std::cerr << "ictusd: warning: --midi " << path << ": " << counted(skipped, "note", "notes")
                  << " the " << (drums.empty() ? "drum" : "kit") << " cannot play left out ("
                  << line.str() << ")\n";
    if (part.too_fast > 0)
        std::cerr << "ictusd: warning: --midi " << path << ": "
                  << counted(part.too_fast, "note", "notes")
                  << " left out: no hand free (a third note at once, or under "
                  << kMidiSameHandMin_s * 1e3 << " ms after both hands' last)\n";
    if (part.feet_too_fast > 0)
        std::cerr << "ictusd: warning: --midi " << path << ": "
                  << counted(part.feet_too_fast, "note", "notes")
                  << " left out: a foot plays again no sooner than " << kMidiFootMin_s * 1e3
                  << " ms (kick) or " << kMidiChickMin_s * 1e3
                  << " ms (hi-hat pedal) after its last\n";
    if (part.hihats_pedalled > 0)
        std::cerr << "ictusd: note: --midi " << path << ": " << part.hihats_pedalled
                  << (part.hihats_pedalled == 1 ? " closed hi-hat" : " closed hi-hats")
                  << " played by the left foot's pedal, a chick (both hands taken on the tick, "
                     "the right's move over "
                  << kMidiPedalHihatAbove_mps << " m/s; docs/midi.md)\n";
    if (part.hihats_lent > 0)
        std::cerr << "ictusd: note: --midi " << path << ": " << part.hihats_lent
                  << (part.hihats_lent == 1 ? " hi-hat note" : " hi-hat notes")
                  << " of the time-keeper played by the left hand while the right crosses the kit "
                     "(its move over "
                  << kMidiLendHihatAbove_mps << " m/s; docs/midi.md)\n";
    if (part.hihats_opened > 0)
        std::cerr << "ictusd: warning: --midi " << path << ": "
                  << counted(part.hihats_opened, "closed hi-hat", "closed hi-hats")
                  << " (42) left out for the open one (46) on the same tick (one pedal: the open "
                     "one wins; docs/midi.md)\n";
    if (part.other_channels > 0)
        std::cerr << "ictusd: note: --midi " << path << ": " << part.other_channels
                  << (part.other_channels == 1 ? " note on a channel" : " notes on channels")
                  << " other than 10 left out (channel 10 is the drum part's; "
                     "docs/midi.md)\n";
    if (part.crashes_given > 0)
        std::cerr << "ictusd: note: --midi " << path << ": " << part.crashes_given
                  << (part.crashes_given == 1 ? " crash note" : " crash notes")
                  << " played by the right hand, free beside it (the left's move over "
                  << kMidiLendHihatAbove_mps << " m/s; docs/midi.md)\n";
    if (part.tempo_clamped > 0)
        std::cerr << "ictusd: warning: --midi " << path << ": "
                  << counted(part.tempo_clamped, "tempo", "tempi") << " kept within "
                  << kMinTempoBpm << ".." << kMaxTempoBpm << " bpm\n";
    std::cerr << "ictusd: --midi " << path << ": "
              << counted(static_cast<long>(part.score.notes.size()), "note", "notes") << " from "
              << (part.channel < 0 ? "every channel" : "channel 10") << "\n";
    o.score.score = std::make_shared<const Score>(std::move(part.score));
}

} // namespace cli
} // namespace ictus
