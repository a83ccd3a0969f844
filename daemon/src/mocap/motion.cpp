// motion.cpp -- lookups, forward kinematics and resampling of captured motion.
#include "ictus/mocap/mocap_error.hpp"
#include "ictus/mocap/motion.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace ictus
{

int Skeleton::find(const std::string &name) const
{
    for (std::size_t i = 0; i < joints.size(); ++i)
        if (joints[i].name == name)
            return static_cast<int>(i);
    return -1;
}

int MarkerCapture::find(const std::string &name) const
{
    for (std::size_t i = 0; i < tracks.size(); ++i)
        if (tracks[i].name == name)
            return static_cast<int>(i);
    return -1;
}

namespace
{

void check_frame(const Skeleton &skeleton, const Motion &motion, int frame)
{
    if (frame < 0 || frame >= motion.frames())
        throw MocapError("motion", 0,
                         "expected a frame in [0, " + std::to_string(motion.frames()) + "), got " +
                             std::to_string(frame));
    const std::size_t got = frame < static_cast<int>(motion.local_rotation.size())
                                ? motion.local_rotation[static_cast<std::size_t>(frame)].size()
                                : 0;
    if (got != skeleton.joints.size())
        throw MocapError("motion", 0,
                         "expected one local rotation per skeleton joint (" +
                             std::to_string(skeleton.joints.size()) + ") at frame " +
                             std::to_string(frame) + ", got " + std::to_string(got));
    // Parents must come before children (BVH depth-first order), so one pass
    // over the joints in order sees every parent's world pose first.
    for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
        const int parent = skeleton.joints[j].parent;
        if (parent >= static_cast<int>(j) || parent < -1)
            throw MocapError("skeleton", 0,
                             "expected joint " + skeleton.joints[j].name +
                                 " to have its parent listed before it, got parent index " +
                                 std::to_string(parent));
    }
}

} // namespace

std::vector<Eigen::Quaterniond> world_rotations(const Skeleton &skeleton, const Motion &motion,
                                                int frame)
{
    check_frame(skeleton, motion, frame);
    const auto &local = motion.local_rotation[static_cast<std::size_t>(frame)];
    std::vector<Eigen::Quaterniond> world(skeleton.joints.size());
    for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
        const int parent = skeleton.joints[j].parent;
        world[j] = parent < 0 ? local[j] : world[static_cast<std::size_t>(parent)] * local[j];
        world[j].normalize();
    }
    return world;
}

std::vector<Eigen::Vector3d> forward_kinematics(const Skeleton &skeleton, const Motion &motion,
                                                int frame)
{
    const std::vector<Eigen::Quaterniond> world = world_rotations(skeleton, motion, frame);
    std::vector<Eigen::Vector3d> position(skeleton.joints.size());
    bool first_root = true;
    for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
        const SkeletonJoint &joint = skeleton.joints[j];
        if (joint.parent < 0) {
            // The first root moves with the captured root position; any further
            // root (unusual) stays at its offset.
            position[j] = first_root ? motion.root_position_m[static_cast<std::size_t>(frame)]
                                     : joint.offset_m;
            first_root = false;
        } else {
            const auto parent = static_cast<std::size_t>(joint.parent);
            position[j] = position[parent] + world[parent] * joint.offset_m;
        }
    }
    return position;
}

namespace
{

void check_rate(double rate_hz)
{
    if (!std::isfinite(rate_hz) || rate_hz <= 0.0 || rate_hz > 1e6)
        throw MocapError("resample", 0,
                         "expected a rate in (0, 1e6] Hz, got " + std::to_string(rate_hz));
}

// Output sample times 0, 1/rate, ... up to `duration_s` (inclusive, with a
// little slack so that a duration that is an exact multiple is not lost to rounding).
std::size_t output_count(double duration_s, double rate_hz)
{
    const double count = std::floor(duration_s * rate_hz + 1e-9) + 1.0;
    if (count > 1e7)
        throw MocapError("resample", 0,
                         "expected at most 1e7 output frames, got " + std::to_string(count));
    return static_cast<std::size_t>(count);
}

} // namespace

Motion resample(const Motion &motion, double rate_hz)
{
    check_rate(rate_hz);
    if (!std::isfinite(motion.frame_rate_hz) || motion.frame_rate_hz <= 0.0)
        throw MocapError("resample", 0,
                         "expected a motion with a frame rate > 0, got " +
                             std::to_string(motion.frame_rate_hz));
    if (motion.local_rotation.size() != motion.root_position_m.size())
        throw MocapError("resample", 0, "expected as many rotation frames as root positions");
    Motion out;
    out.frame_rate_hz = rate_hz;
    const int frames = motion.frames();
    if (frames == 0)
        return out;
    const double duration_s = (frames - 1) / motion.frame_rate_hz;
    const std::size_t count = output_count(duration_s, rate_hz);
    out.root_position_m.reserve(count);
    out.local_rotation.reserve(count);
    for (std::size_t n = 0; n < count; ++n) {
        // Position in input frames; i and i + 1 bracket it.
        const double x = std::min(static_cast<double>(n) / rate_hz * motion.frame_rate_hz,
                                  static_cast<double>(frames - 1));
        const auto i = static_cast<std::size_t>(std::min<double>(std::floor(x), frames - 1));
        const std::size_t i1 = std::min<std::size_t>(i + 1, static_cast<std::size_t>(frames - 1));
        const double u = x - static_cast<double>(i);
        out.root_position_m.push_back((1.0 - u) * motion.root_position_m[i] +
                                      u * motion.root_position_m[i1]);
        const auto &a = motion.local_rotation[i];
        const auto &b = motion.local_rotation[i1];
        if (a.size() != b.size())
            throw MocapError("resample", 0,
                             "expected the same joint count in every frame, frame " +
                                 std::to_string(i) + " differs from frame " + std::to_string(i1));
        std::vector<Eigen::Quaterniond> rotations(a.size());
        for (std::size_t j = 0; j < a.size(); ++j)
            rotations[j] = a[j].slerp(u, b[j]).normalized(); // Eigen: shortest arc
        out.local_rotation.push_back(std::move(rotations));
    }
    return out;
}

MarkerCapture resample(const MarkerCapture &capture, double rate_hz)
{
    check_rate(rate_hz);
    MarkerCapture out;
    const std::size_t frames = capture.time_s.size();
    for (const MarkerTrack &track : capture.tracks)
        if (track.position_m.size() != frames ||
            (!track.orientation.empty() && track.orientation.size() != frames))
            throw MocapError("resample", 0,
                             "expected track " + track.name + " to have " + std::to_string(frames) +
                                 " samples");
    for (std::size_t i = 1; i < frames; ++i)
        if (!(capture.time_s[i] > capture.time_s[i - 1]))
            throw MocapError("resample", 0,
                             "expected strictly increasing times, frame " + std::to_string(i));
    for (const MarkerTrack &track : capture.tracks) {
        MarkerTrack empty;
        empty.name = track.name;
        out.tracks.push_back(empty);
    }
    if (frames == 0)
        return out;
    const double start = capture.time_s.front();
    const std::size_t count = output_count(capture.time_s.back() - start, rate_hz);
    out.time_s.reserve(count);
    std::size_t i = 0; // input segment [i, i + 1] holding t; t only grows
    for (std::size_t n = 0; n < count; ++n) {
        const double t = std::min(start + static_cast<double>(n) / rate_hz, capture.time_s.back());
        while (i + 1 < frames - 1 && capture.time_s[i + 1] < t)
            ++i;
        const std::size_t i1 = std::min(i + 1, frames - 1);
        const double span = capture.time_s[i1] - capture.time_s[i];
        const double u = span > 0.0 ? std::clamp((t - capture.time_s[i]) / span, 0.0, 1.0) : 0.0;
        out.time_s.push_back(t);
        for (std::size_t k = 0; k < capture.tracks.size(); ++k) {
            const MarkerTrack &in = capture.tracks[k];
            MarkerTrack &track = out.tracks[k];
            track.position_m.push_back((1.0 - u) * in.position_m[i] + u * in.position_m[i1]);
            if (!in.orientation.empty())
                track.orientation.push_back(
                    in.orientation[i].slerp(u, in.orientation[i1]).normalized());
        }
    }
    return out;
}

} // namespace ictus
