// fuzz_bvh.cpp -- libFuzzer harness of the BVH reader (mocap/bvh.hpp) and of
// what every verb does next with a clip: forward kinematics and, for a
// CMU-named skeleton, the character and its cleaned reference motion.
//
// A file out of a capture's physical bounds (MocapBoundError) is read again
// as `--force` reads it (BvhOptions::accept_out_of_bounds), so that what
// follows the reader sees it too. A refusal (MocapError, CharacterError) is a
// pass. A crash, a sanitizer
// report, a run over the -timeout, or a result that breaks the reader's
// promises (bvh.hpp, motion.hpp: unit rotations, finite positions, one
// rotation per joint per frame) is a finding. See docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/character/character.hpp"
#include "ictus/mocap/bvh.hpp"

#include <algorithm>
#include <sstream>

using namespace ictus;

namespace
{

// Larger inputs only make slower runs of the same code: the reader is line
// by line, and 64 KiB hold a CMU hierarchy and hundreds of frames.
constexpr std::size_t kMaxInputBytes = 64 * 1024;
// The character's clean-up is linear in frames times its smoothing window:
// keep it to clips short enough for the -timeout.
constexpr int kMaxCharacterFrames = 500;

void check_file(const BvhFile &bvh, const BvhOptions &options)
{
    const std::size_t joints = bvh.skeleton.joints.size();
    ICTUS_FUZZ_CHECK(joints > 0, "no joints in an accepted file");
    ICTUS_FUZZ_CHECK(bvh.channels.size() == joints, "channels not one list per joint");
    ICTUS_FUZZ_CHECK(bvh.skeleton.joints[0].parent == -1, "joint 0 is not the root");
    int channels = 0;
    for (std::size_t j = 0; j < joints; ++j) {
        const SkeletonJoint &joint = bvh.skeleton.joints[j];
        ICTUS_FUZZ_CHECK(j == 0 || (joint.parent >= 0 && joint.parent < static_cast<int>(j)),
                         "a parent after its child");
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(joint.offset_m), "non-finite OFFSET");
        ICTUS_FUZZ_CHECK(!joint.end_site || bvh.channels[j].empty(), "an end site with channels");
        channels += static_cast<int>(bvh.channels[j].size());
    }
    ICTUS_FUZZ_CHECK(channels == bvh.channel_count, "channel_count is not the sum of channels");
    ICTUS_FUZZ_CHECK(bvh.channel_count > 0, "accepted a file without channels");

    const Motion &m = bvh.motion;
    ICTUS_FUZZ_CHECK(m.frames() >= 1, "accepted a file without frames");
    ICTUS_FUZZ_CHECK(m.frames() <= options.max_frames, "more frames than max_frames");
    ICTUS_FUZZ_CHECK(std::isfinite(m.frame_rate_hz) && m.frame_rate_hz > 0.0,
                     "frame rate not finite and > 0");
    ICTUS_FUZZ_CHECK(std::fabs(bvh.frame_time_s * m.frame_rate_hz - 1.0) < 1e-9,
                     "frame_time_s is not 1 / frame_rate_hz");
    ICTUS_FUZZ_CHECK(m.local_rotation.size() == m.root_position_m.size(),
                     "rotation frames != root positions");
    ICTUS_FUZZ_CHECK(bvh.joint_translation_m.empty() ||
                         bvh.joint_translation_m.size() == m.root_position_m.size(),
                     "joint translations not one per frame");
    for (int f = 0; f < m.frames(); ++f) {
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(m.root_position_m[f]), "non-finite root position");
        ICTUS_FUZZ_CHECK(m.local_rotation[f].size() == joints, "not one rotation per joint");
        for (const Eigen::Quaterniond &q : m.local_rotation[f])
            ICTUS_FUZZ_CHECK(ictus_fuzz::unit(q), "a rotation that is not a unit quaternion");
    }
    for (int f : {0, m.frames() - 1}) {
        const std::vector<Eigen::Vector3d> positions = bvh_forward_kinematics(bvh, f);
        ICTUS_FUZZ_CHECK(positions.size() == joints, "forward kinematics: not one per joint");
        for (const Eigen::Vector3d &p : positions)
            ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p), "forward kinematics: non-finite position");
    }
}

// What track, limits, run and render do with a clip (cli/verb_track.cpp).
void check_character(const BvhFile &bvh)
{
    if (bvh.motion.frames() > kMaxCharacterFrames)
        return;
    try {
        const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
        const ReferenceMotion reference(model, bvh.motion, ReferenceFilter{});
        CharacterPose pose;
        BodyFrames frames;
        for (double t : {0.0, 0.5 * reference.duration_s(), reference.duration_s() + 0.25}) {
            reference.sample(t, pose);
            model.forward(pose, frames);
            for (const Eigen::Vector3d &origin : frames.origin_m)
                ICTUS_FUZZ_CHECK(ictus_fuzz::finite(origin), "character: non-finite body origin");
            for (const Eigen::Quaterniond &q : frames.rotation)
                ICTUS_FUZZ_CHECK(ictus_fuzz::unit(q), "character: body rotation not unit");
        }
    } catch (const CharacterError &) {
        // Not a CMU skeleton, or one the character refuses: a clean refusal.
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    // CMU units (what the verbs read by default), a limit on frames that a
    // 64 KiB file can reach, and the reference pose kept.
    BvhOptions options;
    options.scale = kCmuBvhScale_m;
    options.max_frames = 100000;
    const std::string text = ictus_fuzz::text_of(data, size);
    MocapWarnings warnings;
    BvhFile bvh;
    try {
        try {
            std::istringstream in(text);
            bvh = parse_bvh(in, "fuzz.bvh", options, &warnings);
        } catch (const MocapBoundError &) {
            // Out of a capture's physical bounds: read it as `--force` does.
            options.accept_out_of_bounds = true;
            std::istringstream in(text);
            bvh = parse_bvh(in, "fuzz.bvh", options, &warnings);
        }
    } catch (const MocapError &) {
        return 0;
    }
    check_file(bvh, options);
    check_character(bvh);
    return 0;
}
