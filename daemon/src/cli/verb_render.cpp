// `ictusd render`: the performance offline, as fast as possible and
// deterministic (same input, same bytes): strikes.csv, events.txt for Pd's
// batch render, render.json, and in score mode tips.csv, notes.csv; the
// performance as BVH and the strikes as a Standard MIDI File. Also the options run and render share
// (verbs.hpp). Nothing is written while the physics runs: every output is kept in memory and
// written at the end, each write checked. --out is a new or empty folder
// (--force: render's own files in a used one are replaced). docs/osc.md,
// docs/perform.md.
#include "ictus/character/bvh_export.hpp"
#include "ictus/cli/midi_file.hpp"
#include "ictus/cli/pd_render.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/perform/strike_log.hpp"

#include "rehearsal.hpp"
#include "render_report.hpp"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ictus
{
namespace cli
{

namespace
{

void render_usage(std::ostream &out)
{
    out << "usage: ictusd render [--mocap FILE | --score FILE] --out DIR [options]\n"
           "\n"
           "Plays offline, as fast as possible and deterministically (same input, same\n"
           "bytes), and writes DIR/strikes.csv, DIR/events.txt (qlist lines for a Pd batch\n"
           "patch), DIR/render.json (drum parameters for membrane~, summary) and\n"
           "DIR/performance.mid (the strikes as MIDI notes, docs/midi.md). docs/osc.md.\n"
           "With --mocap the clip plays in joint space; otherwise the score (--score FILE, or\n"
           "the built-in default score) is performed and DIR/tips.csv (stick-tip targets and\n"
           "simulated tips) and DIR/notes.csv (each note and its strike) are written too\n"
           "(docs/perform.md).\n"
           "\n"
           "  --out DIR           a new or empty folder (a used one is refused, exit 1, so\n"
           "                      that no earlier render's file passes for this one's)\n"
           "  --force             write into a used folder: render's own files there\n"
           "                      (strikes.csv, events.txt, render.json, tips.csv, notes.csv,\n"
           "                      performance.bvh, performance.mid, pd.log,\n"
           "                      performance.wav) are removed\n"
           "                      first, no other file\n"
           "  --tips-rate HZ      tips.csv rows per second (default 250; 0: none)\n"
           "  --bvh-rate HZ       performance.bvh frames per second (default 250; 0: none)\n"
           "  --midi-channel N    MIDI channel 1..16 of DIR/performance.mid, the strikes as\n"
           "                      notes (docs/midi.md; default 1)\n"
           "  --progress-every S  a progress line on stderr every S s of wall time (default 2;\n"
           "                      0: none)\n"
           "  --rehearse N        a score's notes struck more than 5 ms off their time: their\n"
           "                      strokes planned earlier or later by their errors and the\n"
           "                      score played again, up to N times (0..5, default 2; 0: none;\n"
           "                      docs/score.md, \"Rehearsal\")\n"
           "\n"
           "the sound (Pd in batch mode, as scripts/main.sh: patches/ictus-render.pd on the\n"
           "drum of render.json; docs/main-job.md; the options after --wav need it):\n"
           "  --wav FILE          render the strikes to FILE (Pd's log: DIR/pd.log)\n"
           "  --wav-mix M         stereo (default: the drum in the middle, the hands panned)\n"
           "                      | pickups (the membrane's two pickups)\n"
           "  --wav-bits N        16 | 24 (integer PCM) | 32 (float, default)\n"
           "  --wav-gain DB       output gain before the soft limiter (default 0)\n"
           "  --wav-rate HZ       sample rate (default 48000)\n"
           "  --pd BINARY         the pd program (default: pd on PATH)\n"
           "  --pd-lib DIR        the ictus Pd library (default: ictusd's own folder, as in\n"
           "                      the deken package, ictus/ beside ictusd, or\n"
           "                      ../lib/pd-externals/ictus from it)\n"
           "\n"
           "score mode (run and render; refused with --mocap):\n"
           "  --score FILE        score file (docs/score.md; default: the built-in score)\n"
           "  --midi FILE         a Standard MIDI File's drum part as the score: the General\n"
           "                      MIDI drum map's notes the kit has (docs/midi.md, MIDI in)\n"
           "  --gestures DB.json  gesture database (default: the built-in one)\n"
           "  --mode M            cartesian (default, Algorithm 2) | joint (eq. 1, joint\n"
           "                      targets from the IK of the tip targets)\n"
           "  --strike-depth M    the target dips this far below the first contact (0)\n"
           "  --strike-aim S      and further by S times the planned impact speed above\n"
           "                      --strike-aim-from V (defaults 0.0025 s, 1.5 m/s)\n"
           "  --strike-aim-max M  but at most M deeper (default 0.004)\n"
           "  --move-margins A,B  a move to another spot spans the gap between the two\n"
           "                      strikes but these fractions after and before (0.05,0.1)\n"
           "  --advance S         tip targets sampled S ahead: the tracking lag (default 0)\n"
           "  --humanize A        motor noise, 0..4 (0: none; 1: a drummer's hand); given,\n"
           "                      it replaces the score's `humanize` statement\n"
           "  --seed N            the noise's seed, a whole number (default 1)\n"
           "  --rebound S         a scripted rebound of the target after each beat, time\n"
           "                      constant (default 0: off, the stick rebounds by itself)\n"
           "  --ik-gain G         Algorithm 2's gain on the tip error (default 4)\n"
           "  --ik-velocity-gain S  tip velocity error term, s (default 0.03)\n"
           "  --ik-rotation-weight W  weight of the hands' rotation task (1; 0: off)\n"
           "  --iterations N      ODE QuickStep iterations (default 13)\n"
           "  --sor-w W           QuickStep's over-relaxation (default 1.3, ODE's)\n"
           "  --ik-max-joint-speed R  the kinematic IK turns no arm joint faster than R\n"
           "                      rad/s (default 35; 0: no cap)\n"
           "  --ik-limit-margin D the IK keeps the arms D degrees inside their range of\n"
           "                      motion (default 3; stops and checks use the range)\n"
           "  --lead-in S         time before the score's first beat (default 1)\n"
           "\n"
           "common options (run and render):\n"
           "  --mocap FILE        BVH file with CMU joint names (clip mode)\n"
           "  --scale M           metres per BVH unit (default 0.056444)\n"
           "  --skip-frames N     frames dropped at the start (default 1)\n"
           "  --duration S        simulated seconds (render default: the clip's or plan's length)\n"
           "  --step S            physics step (default 0.001)\n"
           "  --grip G            french | german (default: a score's first note's, else\n"
           "                      french)\n"
           "  --tempo BPM         a clip's tempo; a score's until its own tempo (120)\n"
           "  --clip-bpm BPM      tempo at which the clip plays at its own speed (default 120)\n"
           "  --drum-pos X,Y,Z    membrane centre, m (default: a clip's, where its fast strokes\n"
           "                      turn around (median); a score's, in front of the shoulders)\n"
           "  --drum-radius M     (default 0.178)\n"
           "  --drum-tension N/M  (default 3000)\n"
           "  --drum-density KG/M2  for the sound (default 0.26)\n"
           "  --drum-preset NAME  a drum modelled on a measured instrument: paper (the\n"
           "                      defaults), snare, tom, floor-tom, timpani, frame, kick;\n"
           "                      sets radius, tension, density (unless given) and, in Pd,\n"
           "                      the head's T60, modes, pickups and tuning (docs/sound.md)\n"
           "  --kit NAME          several drums (score mode): standard (snare, tom1, tom2,\n"
           "                      floor), standard-cymbals (and crash, ride, hihat),\n"
           "                      full (and kick: the right foot's RF; the left foot's\n"
           "                      LF on the hihat's pedal, docs/pedal.md),\n"
           "                      standard-timpani (and timpani), timpani (timpani1,\n"
           "                      timpani2); the first where the drum goes, the score's\n"
           "                      'drum NAME' and 'on NAME' choose (docs/perform.md)\n"
           "  --stick-tip NAME    wood, nylon or felt: the tip's law in series with the head\n"
           "                      (default: none, the head's spring alone; docs/sound.md)\n"
           "  --bounce-height M   bounce rule height (default 0.01)\n"
           "  --bounce-window S   bounce rule window (default 0.15)\n"
           "\n"
           "examples:\n"
           "  ictusd render --mocap ../shared/data/cmu/80_13.bvh --duration 10 --out out/r1\n"
           "  ictusd render --out out/fig5                  (the built-in score)\n"
           "  ictusd render --out out/fig5 --wav out/fig5/performance.wav\n"
           "  ictusd render --score examples/scores/nuances.txt --grip german --mode joint --out "
           "out/r2\n";
}

// An output of render: tried before the run (created and removed again: an
// unwritable folder shows at once, and a render killed while it simulates
// leaves no empty file), written whole at the end. A failed or short write,
// or a failed close, names the file and the system's reason (ENOSPC, EIO,
// EFBIG under a file-size limit): exit 1, and what was written is cut back to
// its last whole line (`lines`: a text of lines) or removed.
class RenderOutput
{
  public:
    RenderOutput(const std::string &path, bool lines) : path_(path), lines_(lines)
    {
        const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0)
            throw std::runtime_error(message(errno));
        ::close(fd);
        ::unlink(path_.c_str());
    }
    RenderOutput(const RenderOutput &) = delete;
    RenderOutput &operator=(const RenderOutput &) = delete;
    // The whole content, then the file is closed.
    void write_and_close(const std::string &content)
    {
        const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0)
            throw std::runtime_error(message(errno));
        std::size_t done = 0;
        while (done < content.size()) {
            const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
            if (n > 0) {
                done += static_cast<std::size_t>(n);
            } else if (!(n < 0 && errno == EINTR)) {
                const int error = n < 0 ? errno : EIO;
                ::close(fd);
                fail(error, content, done);
            }
        }
        if (::close(fd) != 0)
            fail(errno, content, done);
    }

  private:
    std::string message(int error) const
    {
        return "--out: cannot write '" + path_ + "': " + std::strerror(error);
    }
    // What was written is cut back to its whole lines, or removed when it
    // has none or is not lines.
    [[noreturn]] void fail(int error, const std::string &content, std::size_t done) const
    {
        const std::size_t last =
            lines_ && done > 0 ? content.rfind('\n', done - 1) : std::string::npos;
        const bool keep = last != std::string::npos &&
                          ::truncate(path_.c_str(), static_cast<off_t>(last + 1)) == 0;
        if (!keep) {
            ::unlink(path_.c_str());
            throw std::runtime_error(message(error) + " (removed)");
        }
        const auto lines = std::count(content.begin(), content.begin() + (last + 1), '\n');
        throw std::runtime_error(message(error) + " (cut to its first " + std::to_string(lines) +
                                 " whole lines)");
    }
    std::string path_;
    bool lines_;
};

// tips.csv: the stick-tip targets X^T and the simulated tips, both hands.
void write_tips_header(std::ostream &out)
{
    out << "time_s";
    for (const char *hand : {"left", "right"})
        for (const char *what : {"target", "sim"})
            for (const char *axis : {"x", "y", "z"})
                out << ',' << hand << '_' << what << '_' << axis << "_m";
    // Per hand, the tip's height where the hand holds it (the stick at its
    // fulcrum's rest angle) and the fulcrum's angle.
    for (const char *hand : {"left", "right"})
        out << ',' << hand << "_held_y_m," << hand << "_fulcrum_rad";
    out << '\n';
}

void write_tips_row(std::ostream &out, const Performance &perf)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4f", perf.time_s());
    out << buf;
    for (int hand = 0; hand < 2; ++hand)
        for (const Eigen::Vector3d &p : {perf.tip_target(hand), perf.tip_position(hand)}) {
            std::snprintf(buf, sizeof buf, ",%.5f,%.5f,%.5f", p.x(), p.y(), p.z());
            out << buf;
        }
    for (int hand = 0; hand < 2; ++hand) {
        const Side side = static_cast<Side>(hand);
        std::snprintf(buf, sizeof buf, ",%.5f,%.5f", perf.scene().held_tip_position(side).y(),
                      perf.scene().fulcrum_angle_rad(side));
        out << buf;
    }
    out << '\n';
}

// The command line of a render.
// The longest render: its outputs are kept in memory until the end, about
// 0.6 MB a simulated second (tips.csv and performance.bvh at 250 Hz), some
// 0.5 GB here; a score's performance is bounded by 900 s too (docs/score.md).
constexpr double kMaxRenderSeconds = 900.0;

struct RenderArgs {
    PerformanceOptions o;
    double duration = 0.0, tips_rate = 250.0, bvh_rate = 250.0, midi_channel = 1.0;
    bool midi_channel_given = false; // else 1, or 10 with a kit (General MIDI's drums)
    std::string out_dir;
    bool force = false;
    double progress_every = 2.0;
    int rehearse = 2; // rehearsal passes at most (docs/score.md, "Rehearsal")
    std::string wav;
    std::string sound_option; // the first of --wav-mix .. --pd-lib given: they need --wav
    PdRenderOptions pd;
};

// A whole number in lo..hi for option `a`, else a UsageError naming it.
int parse_whole(const std::string &a, const std::string &text, double lo, double hi,
                const char *what)
{
    const double v = parse_number(a, text, lo, hi);
    if (v != std::floor(v))
        throw UsageError(a + ": expected a whole number " + what + ", got '" + text + "'");
    return static_cast<int>(v);
}

// render's own options (parse_performance_option has the shared ones).
OptionTable render_options(RenderArgs &r)
{
    PdRenderOptions &pd = r.pd;
    return {
        {"--out", store_text(r.out_dir)},
        {"--force", store_flag(r.force)},
        {"--bvh-rate", store(r.bvh_rate, parse_number, 0.0, 1000.0)},
        {"--midi-channel",
         [&r](const std::string &a, Args &args) {
             r.midi_channel = parse_whole(a, args.value(a), 1, 16, "1..16");
             r.midi_channel_given = true;
         }},
        {"--progress-every", store(r.progress_every, parse_number, 0.0, 3600.0)},
        {"--rehearse",
         [&r](const std::string &a, Args &args) {
             r.rehearse = parse_whole(a, args.value(a), 0, 5, "0..5");
         }},
        {"--wav", store_text(r.wav)},
        {"--wav-mix",
         [&pd](const std::string &a, Args &args) {
             pd.mix = args.word(a);
             if (pd.mix != "stereo" && pd.mix != "pickups")
                 throw UsageError("--wav-mix: expected stereo or pickups, got '" + pd.mix + "'");
         }},
        {"--wav-bits",
         [&pd](const std::string &a, Args &args) {
             const std::string text = args.value(a);
             const double bits = parse_number(a, text);
             if (bits != 16 && bits != 24 && bits != 32)
                 throw UsageError("--wav-bits: expected 16, 24 or 32, got '" + text + "'");
             pd.bits = static_cast<int>(bits);
         }},
        {"--wav-gain", store(pd.gain_db, parse_number, -120.0, 40.0)},
        {"--wav-rate",
         [&pd](const std::string &a, Args &args) {
             pd.sample_rate = parse_whole(a, args.value(a), 8000, 192000, "of Hz");
         }},
        {"--pd", store_text(pd.pd)},
        {"--pd-lib", store_text(pd.library)},
        {"--tips-rate", store(r.tips_rate, parse_number, 0.0, 1000.0)},
    };
}

// The command line; false when --help was printed (exit 0). What the options
// mean together is checked here, and Pd and its library are looked for now,
// not after the physics.
bool parse_render_args(Args &args, RenderArgs &r)
{
    const OptionTable options = render_options(r);
    const bool go_on = walk_args(args, render_usage, [&](const std::string &a) {
        if (r.sound_option.empty() && (a.rfind("--wav-", 0) == 0 || a == "--pd" || a == "--pd-lib"))
            r.sound_option = a;
        if (a == "--rehearse" && r.o.score_option_given.empty())
            r.o.score_option_given = a; // a score's notes: refused with --mocap
        if (!dispatch_option(options, a, args) &&
            !parse_performance_option(a, args, r.o, r.duration))
            throw UsageError("unknown option '" + a + "' (see ictusd render --help)");
    });
    if (!go_on)
        return false;
    load_midi_score(r.o);
    if (r.out_dir.empty())
        throw UsageError("--out DIR is required");
    if (r.wav.empty() && !r.sound_option.empty())
        throw UsageError(r.sound_option +
                         ": sets the WAV that --wav FILE writes; give --wav FILE too (e.g. "
                         "--wav DIR/performance.wav)");
    if (r.duration > kMaxRenderSeconds) {
        std::ostringstream m;
        m << "--duration: render keeps its outputs in memory (about 0.6 MB a simulated second): "
             "at most "
          << kMaxRenderSeconds << " s, got " << r.duration;
        throw UsageError(m.str());
    }
    if (!r.wav.empty()) {
        find_pd_binary(r.pd.pd);
        r.pd.library = find_pd_library(r.pd.library);
        r.wav = std::filesystem::absolute(r.wav).lexically_normal().string();
        const std::string out = std::filesystem::absolute(r.out_dir).lexically_normal().string();
        check_wav_path(r.wav, out);
        check_pd_path("--out", out);
        check_pd_path("--pd-lib", r.pd.library);
    }
    return true;
}

// Every output but the sound, opened before the run (an unwritable folder is
// found at once) and written at the end.
struct RenderFiles {
    RenderFiles(const std::string &dir, bool score_mode)
        : strikes_csv(dir + "/strikes.csv", true), events_txt(dir + "/events.txt", true),
          render_json(dir + "/render.json", false), performance_mid(dir + "/performance.mid", false)
    {
        if (score_mode) {
            tips_csv = std::make_unique<RenderOutput>(dir + "/tips.csv", true);
            notes_csv = std::make_unique<RenderOutput>(dir + "/notes.csv", true);
        }
    }
    RenderOutput strikes_csv, events_txt, render_json, performance_mid;
    std::unique_ptr<RenderOutput> tips_csv, notes_csv; // score mode
};

// What the physics of a render leaves, kept in memory.
struct RenderRecording {
    StrikeLog log;
    std::ostringstream tips; // tips.csv, about 100 bytes a row
    std::unique_ptr<BvhRecorder> bvh;
    bool interrupted = false;
    double wall_s = 0.0;
    // Rehearsal: the passes simulated after the first, whose plan was kept
    // (0: the first), and the leads it gave (PlannedNote::lead_s).
    int passes = 0, kept_pass = 0;
    long leads = 0;
    double max_lead_ms = 0.0;
};

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Every how many steps a row of a file `rate_hz` rows a second (0: none) is taken.
long every_steps(double rate_hz, double step_s)
{
    return rate_hz > 0.0 ? std::max(1L, std::lround(1.0 / (rate_hz * step_s))) : 0;
}

// One frame of performance.bvh: the simulated bodies and the sticks.
void record_bvh_frame(Performance &perf, BodyFrames &frames, BvhRecorder &bvh)
{
    perf.scene().body_frames(frames);
    bvh.record(frames,
               {perf.scene().stick_in_hand(Side::left), perf.scene().stick_in_hand(Side::right)});
}

// The physics, `duration_s` of it as fast as it goes: the strikes, tips.csv's
// rows (score mode) and performance.bvh's frames, f at f / bvh_rate s from t = 0.
void simulate(Performance &perf, const RenderArgs &r, bool score_mode, RenderRecording &rec)
{
    if (score_mode)
        write_tips_header(rec.tips);
    const auto wall0 = std::chrono::steady_clock::now();
    const double h = perf.step_s();
    const long steps = std::max(1L, std::lround(r.duration / h));
    const long tips_every = score_mode ? every_steps(r.tips_rate, h) : 0;
    const long bvh_every = every_steps(r.bvh_rate, h);
    BodyFrames frames;
    if (bvh_every) {
        rec.bvh =
            std::make_unique<BvhRecorder>(perf.model(), perf.skeleton(), 1.0 / (bvh_every * h));
        record_bvh_frame(perf, frames, *rec.bvh);
    }
    StrikeEvent ev[kStepStrikes];
    double next_progress = r.progress_every;
    for (long n = 0; n < steps; ++n) {
        if (g_interrupted) {
            rec.interrupted = true;
            break;
        }
        if (r.progress_every > 0.0 && (n & 63) == 0) {
            const double w = seconds_since(wall0);
            if (w >= next_progress) {
                std::fprintf(stderr, "render: %.1f of %.1f s simulated (%.0f s)\n", perf.time_s(),
                             steps * h, w);
                next_progress = w + r.progress_every;
            }
        }
        const int k = perf.step(ev);
        rec.log.add(ev, k);
        if (tips_every && (n + 1) % tips_every == 0)
            write_tips_row(rec.tips, perf);
        if (rec.bvh && (n + 1) % bvh_every == 0)
            record_bvh_frame(perf, frames, *rec.bvh);
    }
    StrikeEvent last;
    while (perf.flush(last))
        rec.log.add(&last, 1);
    rec.log.finish();
    rec.wall_s = seconds_since(wall0);
}

// The MIDI channel, 1..16: --midi-channel, else 1, or with a kit 10 (the
// General MIDI drum channel its notes are for, docs/midi.md).
int midi_channel(const RenderArgs &r, const Performance &perf)
{
    if (!r.midi_channel_given && !perf.options().kit.empty())
        return 10;
    return static_cast<int>(r.midi_channel);
}

// The clock of performance.mid (docs/midi.md): a score's beats on the
// file's quarters, its beat 0 on a bar line after a pickup bar (a clip:
// --tempo from render time 0).
MidiTimeline midi_timeline_of(const Performance &perf, const RenderArgs &r, bool score_mode,
                              const StrikeLog &log)
{
    if (!score_mode || !perf.plan())
        return midi_timeline(score_mode ? kDefaultTempoBpm : r.o.tempo_bpm);
    const ScorePerformOptions &so = perf.options().score;
    const Score score =
        so.score ? *so.score
                 : parse_score(so.score_text.empty() ? default_score_text() : so.score_text,
                               so.score_name, so.start_tempo_bpm);
    const double beat0_s = perf.plan_origin_s() + perf.plan()->score_start_s;
    double earliest_s = beat0_s;
    for (const StrikeEvent &e : log.strikes())
        earliest_s = std::min(earliest_s, e.time_s);
    return midi_timeline(score.tempo, score.meters, beat0_s, earliest_s);
}

// performance.mid: the strikes as notes on the score's grid.
std::string render_midi(const Performance &perf, const RenderArgs &r, bool score_mode,
                        const StrikeLog &log)
{
    std::vector<int> drum_notes;
    for (const KitDrum &d : perf.options().kit.drums)
        drum_notes.push_back(d.midi_note);
    return standard_midi_file(log.strikes(), midi_timeline_of(perf, r, score_mode, log),
                              midi_channel(r, perf) - 1,
                              drum_notes.empty() ? nullptr : &drum_notes);
}

// render.json but its "performance" (score mode).
nlohmann::json render_summary(const Performance &perf, const RenderArgs &r, bool score_mode,
                              const StrikeLog &log)
{
    const long strikes = static_cast<long>(log.strikes().size());
    nlohmann::json j;
    if (score_mode)
        j["score"] =
            r.o.score.score_text.empty() && !r.o.score.score ? "default" : r.o.score.score_name;
    else
        j["mocap"] = r.o.mocap;
    j["duration_s"] = perf.time_s();
    j["step_s"] = perf.step_s();
    j["strikes"] = strikes;
    j["bounces"] = log.bounces();
    j["divergences"] = perf.divergences();
    j["side_entries"] = perf.detector().side_entries();
    j["grip"] = to_string(perf.options().character.grip);
    if (!score_mode)
        j["tempo_bpm"] = r.o.tempo_bpm;
    j["drum"] = drum_json(perf);
    if (!perf.options().kit.empty())
        j["kit"] = kit_json(perf);
    const MidiTimeline timeline = midi_timeline_of(perf, r, score_mode, log);
    j["midi"] = {{"file", "performance.mid"},
                 {"channel", midi_channel(r, perf)},
                 {"tick0_time_s", timeline.start_s},
                 {"first_beat_tick", timeline.first_beat_tick},
                 {"notes", strikes},
                 {"ticks_per_quarter", kMidiTicksPerQuarter}};
    return j;
}

// The notes of the score, how many of them were not struck and how many were
// struck more than kOffTime_ms from their time.
struct NoteCount {
    long notes = 0, missed = 0, off_time = 0;
    std::string first_missed, first_off_time; // where the first few were written
    // Notes at or after the render's end (--duration, Ctrl-C): not played, not missed.
    long after_end = 0;
    std::string first_after_end;
    // The strikes (bounces aside) and those of no note: how many, the first few.
    long primary_strikes = 0, extra = 0;
    std::string first_extra;
};
MatchSummary match_of(const Performance &perf, const RenderRecording &rec)
{
    const GesturePlan &plan = *perf.plan();
    return match_strikes(plan.notes, rec.log.strikes(), perf.plan_origin_s(), plan.foot_notes);
}

// Rehearsal (docs/score.md, "Rehearsal"; rehearsal.hpp): the performance
// played again, each off note led by its error, while that helps.
void rehearse(std::unique_ptr<Performance> &perf, std::unique_ptr<RenderRecording> &rec,
              RenderArgs &r)
{
    MatchSummary kept_match = match_of(*perf, *rec);
    PassScore best = pass_score(kept_match);
    std::vector<double> step; // the last pass's change of the leads, when it was not kept
    for (int pass = 1; pass <= r.rehearse && !rec->interrupted; ++pass) {
        const std::vector<double> &kept = r.o.score.plan.note_lead_s;
        std::vector<double> lead = kept;
        if (step.empty()) {
            // The first pass when a note is off; the next ones while any is
            // further off than kRehearseAbove_ms.
            const MatchSummary &m = kept_match;
            const double above_ms = pass == 1 ? kOffTime_ms : kRehearseAbove_ms;
            bool off = false;
            for (const NoteMatch &k : m.notes)
                off = off || (k.strike_seq >= 0 && std::abs(k.error_ms) > above_ms &&
                              std::abs(k.error_ms) <= kRehearseUpTo_ms);
            if (!off || !next_leads(*perf->plan(), m, lead))
                break;
        } else {
            // The last step overshot (a stroke planned earlier moves faster and
            // lags more): half of it.
            lead.resize(std::max(lead.size(), step.size()), 0.0);
            for (size_t k = 0; k < step.size(); ++k)
                lead[k] += 0.5 * step[k];
        }
        RenderArgs again = r;
        again.o.score.plan.note_lead_s = lead;
        auto p = std::make_unique<Performance>(again.o);
        p->start_score();
        auto q = std::make_unique<RenderRecording>();
        simulate(*p, again, true, *q);
        const double wall_s = rec->wall_s + q->wall_s;
        rec->wall_s = wall_s;
        rec->passes = pass;
        if (q->interrupted) { // Ctrl-C: the last whole pass is written, exit 130
            rec->interrupted = true;
            break;
        }
        MatchSummary match = match_of(*p, *q);
        const PassScore score = pass_score(match);
        if (!score.better_than(best)) {
            step.assign(lead.size(), 0.0);
            for (size_t k = 0; k < lead.size(); ++k)
                step[k] = lead[k] - (k < kept.size() ? kept[k] : 0.0);
            continue;
        }
        best = score;
        kept_match = std::move(match);
        step.clear();
        r.o.score.plan.note_lead_s = lead;
        perf = std::move(p);
        rec = std::move(q);
        rec->passes = pass;
        rec->kept_pass = pass;
        rec->wall_s = wall_s;
    }
    for (const PlannedNote &n : perf->plan()->notes)
        if (n.lead_s != 0.0) {
            ++rec->leads;
            rec->max_lead_ms = std::max(rec->max_lead_ms, 1e3 * std::abs(n.lead_s));
        }
}

// Every output but the sound, from memory; in score mode the notes matched
// with the strikes (notes.csv, render.json's "performance").
NoteCount write_render_files(RenderFiles &files, const Performance &perf, const RenderArgs &r,
                             bool score_mode, const RenderRecording &rec)
{
    std::ostringstream text;
    rec.log.write_csv(text);
    files.strikes_csv.write_and_close(text.str());
    text.str("");
    rec.log.write_events(text);
    files.events_txt.write_and_close(text.str());
    if (rec.bvh)
        rec.bvh->write(r.out_dir + "/performance.bvh");
    files.performance_mid.write_and_close(render_midi(perf, r, score_mode, rec.log));
    nlohmann::json j = render_summary(perf, r, score_mode, rec.log);
    NoteCount count;
    if (score_mode) {
        const GesturePlan &plan = *perf.plan();
        const MatchSummary m =
            match_strikes(plan.notes, rec.log.strikes(), perf.plan_origin_s(), plan.foot_notes);
        count.notes = static_cast<long>(plan.notes.size() + plan.foot_notes.size());
        // A MIDI part's notes are numbered as the file's note-ons, in time order.
        const char *unit = perf.options().score.midi_path.empty() ? "line" : "note";
        const Kit &kit = perf.options().kit;
        const double end_s = perf.time_s() - perf.plan_origin_s();
        const ListedNotes missed = notes_text(plan, m, kit, NoteList::missed, end_s, unit);
        count.missed = missed.count;
        count.first_missed = missed.text;
        const ListedNotes after = notes_text(plan, m, kit, NoteList::after_end, end_s, unit);
        count.after_end = after.count;
        count.first_after_end = after.text;
        const ListedNotes off = notes_text(plan, m, kit, NoteList::off_time, end_s, unit);
        count.off_time = off.count;
        count.first_off_time = off.text;
        count.primary_strikes = m.primary_strikes;
        count.extra = m.extra_strikes;
        count.first_extra = extra_strikes_text(m, rec.log.strikes(), perf.options().kit);
        text.str("");
        write_notes_csv(text, plan, m, perf.plan_origin_s(), perf.options().kit);
        files.notes_csv->write_and_close(text.str());
        files.tips_csv->write_and_close(rec.tips.str());
        j["performance"] = performance_json(r.o, perf, m);
        j["performance"]["rehearsal"] = {{"passes", rec.passes},
                                         {"kept_pass", rec.kept_pass},
                                         {"notes_led", rec.leads},
                                         {"max_lead_ms", rec.max_lead_ms}};
    }
    files.render_json.write_and_close(j.dump(2) + "\n");
    return count;
}

// The summary line on stdout, and on stderr what render.json says in
// missed_notes, said where it is seen: a drum out of the sticks' reach
// (--drum-pos) plays nothing and still exits 0 (a divergence exits 3).
void print_render_summary(const Performance &perf, const RenderArgs &r, bool score_mode,
                          const RenderRecording &rec, const NoteCount &count)
{
    const double wall = rec.wall_s;
    std::cout << "render: " << perf.time_s() << " s simulated in " << wall << " s ("
              << perf.time_s() / std::max(wall, 1e-9) << "x real time), "
              << static_cast<long>(rec.log.strikes().size()) << " strikes (" << rec.log.bounces()
              << " bounces), wrote " << r.out_dir
              << (score_mode ? "/{strikes.csv,events.txt,render.json,performance.mid,tips.csv,"
                               "notes.csv"
                             : "/{strikes.csv,events.txt,render.json,performance.mid")
              << (rec.bvh ? ",performance.bvh}\n" : "}\n");
    if (perf.whips() > 0)
        std::cerr << "ictusd render: warning: " << perf.whips() << " stick(s) thrown faster than "
                  << Performance::kRunawayTipSpeed_mps
                  << " m/s by a move (a whip): that hand's strikes held back while it flew and "
                  << Performance::kWhipSettle_s << " s after (render.json's performance.whips)\n";
    if (perf.runaways() > 0)
        std::cerr << "ictusd render: warning: the runaway guard fired " << perf.runaways()
                  << " time(s) (a stick tip over " << Performance::kRunawayTipSpeed_mps
                  << " m/s): the sticks' strikes of the next " << Performance::kRunawayQuiet_s
                  << " s held back (render.json's performance.runaways)\n";
    if (perf.withheld_strikes() > 0)
        std::cerr << "ictusd render: warning: " << perf.withheld_strikes()
                  << " strike(s) held back by the guard (render.json's "
                     "performance.withheld_strikes)\n";
    if (perf.divergences() > 0)
        std::cerr << "ictusd render: warning: the simulation diverged " << perf.divergences()
                  << " time(s) and was reset (render.json's divergences; exit status 3)\n";
    if (score_mode && count.notes == 0)
        std::cerr << "ictusd render: warning: the score has no notes: nothing was played\n";
    else if (!score_mode && rec.log.strikes().empty() && perf.withheld_strikes() == 0 &&
             !rec.interrupted)
        std::cerr << "ictusd render: warning: no stick struck the drum: nothing was played "
                     "(is the drum within the sticks' reach? --drum-pos)\n";
    else if (count.missed > 0)
        std::cerr << "ictusd render: warning: " << count.missed << " of " << count.notes
                  << " notes of the score were not struck: " << count.first_missed
                  << " (strike_seq -1 in notes.csv"
                  << (count.missed == count.notes - count.after_end
                          ? "; is the drum within the sticks' reach? --drum-pos"
                          : "")
                  << ")\n";
    if (score_mode && count.after_end > 0)
        std::cerr << "ictusd render: warning: " << count.after_end << " of " << count.notes
                  << " notes of the score come after the end of the render ("
                  << (rec.interrupted ? "interrupted at " : "--duration ") << perf.time_s()
                  << " s): " << count.first_after_end
                  << " (not played: strike_seq -1 in notes.csv)\n";
    if (rec.passes > 0)
        std::cerr << "ictusd render: rehearsed " << rec.passes << " time(s), kept pass "
                  << rec.kept_pass << ": " << rec.leads
                  << " note(s) planned earlier or later, by up to " << rec.max_lead_ms
                  << " ms, to land on their time (--rehearse 0: none; render.json's "
                     "performance.rehearsal)\n";
    if (count.off_time > 0)
        std::cerr << "ictusd render: warning: " << count.off_time << " of " << count.notes
                  << " notes of the score were struck more than " << kOffTime_ms
                  << " ms from their time: " << count.first_off_time
                  << " (error_ms in notes.csv)\n";
    if (count.extra > 0)
        std::cerr << "ictusd render: warning: " << count.extra << " of " << count.primary_strikes
                  << " strikes (bounces aside) were of no note of the score: " << count.first_extra
                  << " (seq in strikes.csv; render.json's "
                  << "performance.extra_strikes)\n";
}

// --wav: events.txt played by Pd on the same drum. Returns the exit status.
int render_wav(RenderArgs &r, const Performance &perf)
{
    PdRenderOptions &pd = r.pd;
    const DrumParams &d = perf.scene().options().drum;
    pd.events = std::filesystem::absolute(r.out_dir + "/events.txt").lexically_normal().string();
    pd.log = r.out_dir + "/pd.log";
    pd.wav = r.wav;
    pd.seconds = perf.time_s() + 1.5; // the last strike rings out (as scripts/main.sh)
    pd.radius_m = d.radius_m;
    pd.tension_n_per_m = d.tension_n_per_m;
    pd.density_kg_per_m2 = perf.options().drum_density_kg_per_m2;
    pd.preset = perf.options().drum_preset;
    const Kit &kit = perf.options().kit;
    pd.kit.clear();
    for (int i = 1; i < static_cast<int>(kit.drums.size()); ++i) {
        const KitDrum &k = kit.drums[static_cast<size_t>(i)];
        if (i < perf.scene().drum_count()) {
            const DrumParams &kd = perf.scene().drum(i);
            pd.kit.push_back({k.preset, kd.radius_m, kd.tension_n_per_m, kit_drum_pan(k), ""});
        } else if (k.foot) { // the kick: not in the sticks' scene
            pd.kit.push_back({k.preset, k.radius_m, k.tension_n_per_m, kit_drum_pan(k), "felt"});
        }
    }
    pd.stick_tip = d.stick_tip;
    pd.stretch_n_per_m3 = d.stretch_n_per_m3();
    if (g_interrupted)
        return 130; // the files are written; no sound is started
    std::cout << "render: pd: " << pd.seconds << " s of sound into " << r.wav << " ..."
              << std::endl;
    const PdRenderResult result = run_pd_render(pd, [&](double s) {
        if (r.progress_every > 0.0)
            std::fprintf(stderr, "render: pd still rendering (%.0f s)\n", s);
    });
    if (result.interrupted) {
        // pd stopped before it said anything: an empty log is no output
        std::error_code ec;
        if (std::filesystem::exists(pd.log, ec) && std::filesystem::file_size(pd.log, ec) == 0 &&
            !ec) {
            std::filesystem::remove(pd.log, ec);
            std::cerr << "ictusd render: interrupted: pd stopped, no " << r.wav << "\n";
        } else {
            std::cerr << "ictusd render: interrupted: pd stopped, no " << r.wav
                      << " (log: " << pd.log << ")\n";
        }
        return 130;
    }
    if (!result.errors.empty()) {
        std::cerr << "ictusd render: pd reported errors (log: " << pd.log << "):\n"
                  << result.errors;
        return 1;
    }
    char line[512];
    std::snprintf(line, sizeof line,
                  "render: wrote %s in %.1f s (%s, %d-bit%s, %d Hz): peak %.2f dBFS, %.2f "
                  "dBFS before the limiter\n",
                  r.wav.c_str(), result.wall_s, pd.mix.c_str(), pd.bits,
                  pd.bits == 32 ? " float" : "", pd.sample_rate, result.peak_out_dbfs,
                  result.peak_in_dbfs);
    std::cout << line;
    return 0;
}

} // namespace

int cmd_render(Args &args)
{
    RenderArgs r;
    if (!parse_render_args(args, r))
        return 0;
    const bool score_mode = r.o.mocap.empty();
    std::error_code ec;
    const bool made = !std::filesystem::exists(r.out_dir, ec);
    prepare_render_out_dir(r.out_dir, r.force);
    std::unique_ptr<Performance> perf;
    try {
        perf = std::make_unique<Performance>(r.o);
        if (score_mode)
            perf->start_score();
    } catch (...) {
        if (made) // a refused score or clip leaves no empty folder behind
            std::filesystem::remove(r.out_dir, ec);
        throw;
    }
    if (r.duration <= 0.0)
        r.duration = perf->clip_duration_s();
    if (r.duration > kMaxRenderSeconds)
        throw std::runtime_error("--duration: the clip is " + std::to_string(r.duration) +
                                 " s long; render takes at most " +
                                 std::to_string(static_cast<int>(kMaxRenderSeconds)) +
                                 " s (give --duration to render its start)");
    RenderFiles files(r.out_dir, score_mode);
    auto rec = std::make_unique<RenderRecording>();
    simulate(*perf, r, score_mode, *rec);
    if (score_mode)
        rehearse(perf, rec, r);
    const NoteCount count = write_render_files(files, *perf, r, score_mode, *rec);
    print_render_summary(*perf, r, score_mode, *rec, count);
    if (rec->interrupted)
        return 130;
    // A divergence (exit status 3, as track) still renders the sound of what was played.
    const int wav_status = r.wav.empty() ? 0 : render_wav(r, *perf);
    if (wav_status != 0)
        return wav_status;
    return perf->divergences() > 0 ? 3 : 0;
}

} // namespace cli
} // namespace ictus
