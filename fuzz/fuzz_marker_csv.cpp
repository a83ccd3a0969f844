// fuzz_marker_csv.cpp -- libFuzzer harness of the marker/rigid-body CSV reader
// (mocap/marker_csv.hpp) and of the stick-only capture that track and
// gestures build on it (character/stick_capture.hpp): the two sticks found
// by name, placed in front of the default body, the drum fitted under them.
//
// Each input is read twice, as the verbs' option sets do: seconds, metres,
// y up, gaps filled; and frames at 120 Hz, millimetres, z up, no gaps.
// A file out of a capture's physical bounds (MocapBoundError) is read again
// as `--force` reads it (accept_out_of_bounds). A refusal (MocapError,
// CharacterError) is a pass; a crash, a sanitizer report, a run over the
// -timeout or a broken promise of the reader (strictly increasing finite
// times, finite positions, unit orientations, one sample per frame) is a
// finding. See docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/character/character.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/mocap/marker_csv.hpp"

#include <sstream>

using namespace ictus;

namespace
{

constexpr std::size_t kMaxInputBytes = 64 * 1024;

void check_capture(const MarkerCapture &capture)
{
    const std::size_t frames = capture.time_s.size();
    ICTUS_FUZZ_CHECK(frames > 0, "accepted a file without rows");
    ICTUS_FUZZ_CHECK(!capture.tracks.empty(), "accepted a file without objects");
    for (std::size_t f = 0; f < frames; ++f) {
        ICTUS_FUZZ_CHECK(std::isfinite(capture.time_s[f]), "non-finite time");
        ICTUS_FUZZ_CHECK(f == 0 || capture.time_s[f] > capture.time_s[f - 1],
                         "times not strictly increasing");
    }
    for (const MarkerTrack &track : capture.tracks) {
        ICTUS_FUZZ_CHECK(!track.name.empty(), "an object without a name");
        ICTUS_FUZZ_CHECK(capture.find(track.name) >= 0, "find() misses an object");
        ICTUS_FUZZ_CHECK(track.position_m.size() == frames, "positions not one per frame");
        ICTUS_FUZZ_CHECK(track.orientation.empty() || track.orientation.size() == frames,
                         "orientations not one per frame");
        for (const Eigen::Vector3d &p : track.position_m)
            ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p), "a gap or non-finite position left");
        for (const Eigen::Quaterniond &q : track.orientation)
            ICTUS_FUZZ_CHECK(ictus_fuzz::unit(q), "an orientation that is not a unit quaternion");
    }
}

// The default body at rest, as track builds it for a stick-only capture.
struct DefaultBody {
    CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    CharacterPose pose;
    DefaultBody()
    {
        Motion motion;
        motion.frame_rate_hz = 100.0;
        motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
        motion.local_rotation.emplace_back(default_skeleton().joints.size(),
                                           Eigen::Quaterniond::Identity());
        pose = model.pose_from_motion(motion, 0);
    }
};

void check_sticks(const MarkerCapture &capture)
{
    static const DefaultBody body;
    try {
        const std::array<int, 2> tracks = find_stick_tracks(capture, "", "");
        ICTUS_FUZZ_CHECK(tracks[0] != tracks[1], "one object for both sticks");
        const TipTrajectory tips = place_behind_sticks(body.model, body.pose, capture, tracks);
        for (int s = 0; s < 2; ++s) {
            ICTUS_FUZZ_CHECK(tips.tip_m[s].size() == tips.time_s.size(), "tips not one per time");
            for (const Eigen::Vector3d &p : tips.tip_m[s])
                ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p), "placed tip not finite");
            for (double t : {-1.0, 0.0, 0.5 * tips.duration_s(), tips.duration_s() + 1.0})
                ICTUS_FUZZ_CHECK(ictus_fuzz::finite(tips.sample(s, t)), "tip sample not finite");
        }
        const Eigen::Vector3d drum =
            fit_drum_to_strokes(tips, body.model.options().stick.tip_radius_m);
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(drum), "drum centre not finite");
    } catch (const CharacterError &) {
        // No sticks, sticks at one place, no strokes: refused by name.
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    const std::string text = ictus_fuzz::text_of(data, size);

    MarkerCsvOptions seconds; // the defaults: time (s), m, y up, gaps of <= 20 frames filled
    MarkerCsvOptions frames;
    frames.rate_hz = 120.0;
    frames.units = MarkerCsvOptions::Units::mm;
    frames.up = MarkerCsvOptions::Up::z;
    frames.interpolate_gaps = false;
    frames.max_frames = 5000;

    bool sticks_checked = false;
    for (const MarkerCsvOptions &options : {seconds, frames}) {
        MocapWarnings warnings;
        MarkerCapture capture;
        try {
            try {
                std::istringstream in(text);
                capture = parse_marker_csv(in, "fuzz.csv", options, &warnings);
            } catch (const MocapBoundError &) {
                // Out of a capture's physical bounds: read it as `--force` does.
                MarkerCsvOptions forced = options;
                forced.accept_out_of_bounds = true;
                std::istringstream in(text);
                capture = parse_marker_csv(in, "fuzz.csv", forced, &warnings);
            }
        } catch (const MocapError &) {
            continue;
        }
        check_capture(capture);
        if (!sticks_checked) {
            check_sticks(capture);
            sticks_checked = true;
        }
    }
    return 0;
}
