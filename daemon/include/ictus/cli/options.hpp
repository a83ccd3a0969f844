// options.hpp -- the option groups several of ictusd's verbs share, parsed
// once (options.cpp): how a BVH clip is read (track, limits, run, render,
// gestures), how a stick-only CSV is read (track, gestures), the performance
// options of run and render; and a verb's output file, checked when closed.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/cli/args.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/marker_csv.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/perform/track.hpp"
#include "ictus/perform/tracker.hpp"

#include <cstddef>
#include <fstream>
#include <string>

namespace ictus
{
namespace cli
{

// The drum may stand this far from the origin at most (--drum-pos), m.
constexpr double kMaxDrumDistance_m = 100.0;

// The largest --score file read: 16 MiB (a score of the 100000-note bound,
// one note a line, is about 1 MiB; docs/score.md).
constexpr std::size_t kMaxScoreFileBytes = std::size_t{16} << 20;
// A --score file's text; std::runtime_error (exit 1) naming the path when it
// cannot be read or is larger than kMaxScoreFileBytes.
std::string read_score_file(const std::string &path);

// --scale M, --skip-frames N. Returns false when `option` is neither (nothing consumed).
bool parse_bvh_option(const std::string &option, Args &args, double &scale_m_per_unit,
                      int &skip_frames);

// track and limits: how a BVH clip is read and its reference motion cleaned.
struct ClipOptions {
    double scale = kCmuBvhScale_m;
    int skip = 1;
    ReferenceFilter filter =
        track_reference_filter(); // --smooth-hz, --smooth-kernel, --despike-deg
    // --force: values out of the physical bounds of a capture
    // (mocap/capture_bounds.hpp) and, for limits, too few frames are warnings.
    bool force = false;
};
// The BVH options, --smooth-hz, --smooth-kernel, --despike-deg and --force.
bool parse_clip_option(const std::string &option, Args &args, ClipOptions &clip);

// A stick-only capture (.csv): --units, --up, --rate, --left-stick, --right-stick.
struct StickCsvOptions {
    MarkerCsvOptions csv;
    std::string left_stick, right_stick; // "" = found by name
    bool given = false;                  // any of them was given
};
bool parse_stick_csv_option(const std::string &option, Args &args, StickCsvOptions &o);

Grip parse_grip(const std::string &option, const std::string &text);
TrackMode parse_track_mode(const std::string &option, const std::string &text);
// A limit's minimum half-width per axis, degrees (track --limit-min-deg, limits --min-deg).
double parse_min_half_width_deg(const std::string &option, const std::string &text);

// The --help lines of --force and the bounds it lifts (track, limits), the
// text starting at `column` as the verb's other options.
std::string force_help(std::size_t column);

// A BVH file, its warnings printed to stderr. `force`: values out of the
// physical bounds are read with a warning; without it their error says
// that --force would read them.
BvhFile load_bvh(const std::string &path, double scale, int skip, bool force = false);
// A marker CSV (a stick-only capture) the same way; o.accept_out_of_bounds is --force.
MarkerCapture load_marker_csv(const std::string &path, const MarkerCsvOptions &o);

// run and render: the motion source, the character, the drum, score mode.
// Returns false when `option` is not one of them.
// The options that do not go together (UsageError): --mocap with --score, --midi, --kit or
// a score's option (--mode cartesian, --humanize, ...); --kit with --drum-preset,
// --drum-radius or --drum-tension (the kit's drums have their own).
void check_performance_options(const PerformanceOptions &options);

// check_performance_options(), then
// --midi FILE (options.score.midi_path): the file's drum part as the score
// (score/midi_score.hpp), on the kit given (--kit) or the one drum; a line on
// stderr counts the notes left out. Throws UsageError with --score or
// --mocap, MidiFileError for a malformed file. Nothing else without --midi.
void load_midi_score(PerformanceOptions &options);

bool parse_performance_option(const std::string &option, Args &args, PerformanceOptions &o,
                              double &duration_s);

// An output file of a verb: opened (and so checked) before the work, written
// at the end, and checked again when closed (a full disk shows there).
class OutputFile
{
  public:
    explicit OutputFile(const std::string &path); // throws naming the path
    std::ostream &stream() { return out_; }
    void close(); // throws naming the path on a write error

  private:
    std::string path_;
    std::ofstream out_;
};

} // namespace cli
} // namespace ictus
