// Stick-only captures: tip trajectories, default body, placement, drum fit.
#include "ictus/character/stick_capture.hpp"
#include "ictus/mocap/bvh.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace ictus
{

namespace
{
std::string lower(std::string s)
{
    for (char &c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}
} // namespace

Eigen::Vector3d TipTrajectory::sample(int side, double t) const
{
    const std::vector<Eigen::Vector3d> &p = tip_m[side];
    const double at = time_s.front() + t;
    if (at <= time_s.front())
        return p.front();
    if (at >= time_s.back())
        return p.back();
    const auto it = std::upper_bound(time_s.begin(), time_s.end(), at);
    const size_t i = static_cast<size_t>(it - time_s.begin());
    const double w = (at - time_s[i - 1]) / (time_s[i] - time_s[i - 1]);
    return (1.0 - w) * p[i - 1] + w * p[i];
}

std::array<int, 2> find_stick_tracks(const MarkerCapture &capture, const std::string &left,
                                     const std::string &right)
{
    std::string names;
    for (const MarkerTrack &t : capture.tracks)
        names += (names.empty() ? "" : ", ") + t.name;
    std::array<int, 2> found = {-1, -1};
    const std::string given[2] = {left, right};
    const char *exact[2] = {"stick_l", "stick_r"};
    const char *part[2] = {"left", "right"};
    for (int s = 0; s < 2; ++s) {
        if (!given[s].empty()) {
            found[s] = capture.find(given[s]);
            if (found[s] < 0)
                throw CharacterError(std::string(s == 0 ? "--left-stick" : "--right-stick") +
                                     ": no object '" + given[s] +
                                     "' in the capture (objects: " + names + ")");
            continue;
        }
        for (size_t i = 0; i < capture.tracks.size() && found[s] < 0; ++i)
            if (lower(capture.tracks[i].name) == exact[s])
                found[s] = static_cast<int>(i);
        for (size_t i = 0; i < capture.tracks.size() && found[s] < 0; ++i)
            if (lower(capture.tracks[i].name).find(part[s]) != std::string::npos)
                found[s] = static_cast<int>(i);
        if (found[s] < 0)
            throw CharacterError(std::string("no ") + (s == 0 ? "left" : "right") +
                                 " stick in the capture (expected an object named " + exact[s] +
                                 " or containing '" + part[s] + "', or give --" +
                                 (s == 0 ? "left" : "right") + "-stick NAME; objects: " + names +
                                 ")");
    }
    if (found[0] == found[1])
        throw CharacterError("the left and right sticks are the same object '" +
                             capture.tracks[found[0]].name + "'");
    return found;
}

Skeleton default_skeleton()
{
    struct Row {
        const char *name;
        const char *parent;
        double x, y, z; // CMU BVH units (kCmuBvhScale_m)
        bool end_site;
    };
    // The CMU hierarchy with offsets rounded from subject 80's (1.75 m).
    static const Row rows[] = {
        {"Hips", "", 0, 0, 0, false},
        {"LHipJoint", "Hips", 0, 0, 0, false},
        {"LeftUpLeg", "LHipJoint", 1.8, -1.7, 0.7, false},
        {"LeftLeg", "LeftUpLeg", 2.3, -6.2, 0, false},
        {"LeftFoot", "LeftLeg", 2.6, -7.0, 0, false},
        {"LeftToeBase", "LeftFoot", 0.2, -0.6, 1.7, false},
        {"LeftToeBase_end", "LeftToeBase", 0, 0, 0.9, true},
        {"RHipJoint", "Hips", 0, 0, 0, false},
        {"RightUpLeg", "RHipJoint", -1.8, -1.7, 0.7, false},
        {"RightLeg", "RightUpLeg", -2.3, -6.2, 0, false},
        {"RightFoot", "RightLeg", -2.6, -7.0, 0, false},
        {"RightToeBase", "RightFoot", -0.2, -0.6, 1.7, false},
        {"RightToeBase_end", "RightToeBase", 0, 0, 0.9, true},
        {"LowerBack", "Hips", 0, 0, 0, false},
        {"Spine", "LowerBack", 0, 1.7, -0.2, false},
        {"Spine1", "Spine", 0, 1.7, 0.2, false},
        {"Neck", "Spine1", 0, 0, 0, false},
        {"Neck1", "Neck", 0, 1.65, 0.1, false},
        {"Head", "Neck1", 0, 1.6, -0.3, false},
        {"Head_end", "Head", 0, 1.7, -0.1, true},
        {"LeftShoulder", "Spine1", 0, 0, 0, false},
        {"LeftArm", "LeftShoulder", 3.1, 1.4, 0.3, false},
        {"LeftForeArm", "LeftArm", 5.1, 0, 0, false},
        {"LeftHand", "LeftForeArm", 3.6, 0, 0, false},
        {"LeftFingerBase", "LeftHand", 0, 0, 0, false},
        {"LeftHandIndex1", "LeftFingerBase", 0.6, 0, 0, false},
        {"LeftHandIndex1_end", "LeftHandIndex1", 0.5, 0, 0, true},
        {"LThumb", "LeftHand", 0, 0, 0, false},
        {"LThumb_end", "LThumb", 0.5, 0, 0.5, true},
        {"RightShoulder", "Spine1", 0, 0, 0, false},
        {"RightArm", "RightShoulder", -3.1, 1.4, 0.3, false},
        {"RightForeArm", "RightArm", -5.1, 0, 0, false},
        {"RightHand", "RightForeArm", -3.6, 0, 0, false},
        {"RightFingerBase", "RightHand", 0, 0, 0, false},
        {"RightHandIndex1", "RightFingerBase", -0.6, 0, 0, false},
        {"RightHandIndex1_end", "RightHandIndex1", -0.5, 0, 0, true},
        {"RThumb", "RightHand", 0, 0, 0, false},
        {"RThumb_end", "RThumb", -0.5, 0, 0.5, true},
    };
    Skeleton s;
    for (const Row &r : rows) {
        SkeletonJoint j;
        j.name = r.name;
        j.parent = *r.parent ? s.find(r.parent) : -1;
        j.offset_m = Eigen::Vector3d(r.x, r.y, r.z) * kCmuBvhScale_m;
        j.end_site = r.end_site;
        s.joints.push_back(j);
    }
    return s;
}

TipTrajectory place_behind_sticks(const CharacterModel &model, const CharacterPose &pose,
                                  const MarkerCapture &capture, const std::array<int, 2> &tracks)
{
    BodyFrames frames;
    model.forward(pose, frames);
    const Eigen::Vector3d shoulder[2] = {frames.origin_m[model.body_index("l_upper_arm")],
                                         frames.origin_m[model.body_index("r_upper_arm")]};
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    Eigen::Vector3d body_lateral = shoulder[0] - shoulder[1];
    body_lateral.y() = 0.0;
    body_lateral.normalize();
    const Eigen::Vector3d forward = body_lateral.cross(up); // left x up = forward
    const Eigen::Vector3d goal =
        0.5 * (shoulder[0] + shoulder[1]) + kStickForward_m * forward - kStickBelow_m * up;

    Eigen::Vector3d mean[2], lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (int s = 0; s < 2; ++s) {
        mean[s].setZero();
        for (const Eigen::Vector3d &p : capture.tracks[tracks[s]].position_m) {
            mean[s] += p;
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        mean[s] /= std::max<size_t>(1, capture.tracks[tracks[s]].position_m.size());
    }
    Eigen::Vector3d capture_lateral = mean[0] - mean[1];
    capture_lateral.y() = 0.0;
    if (capture_lateral.norm() < 1e-6)
        throw CharacterError("stick capture: the left and right sticks have the same mean "
                             "position; cannot tell left from right");
    capture_lateral.normalize();
    // The rotation about the vertical taking the capture's lateral axis onto the body's.
    const double angle =
        std::atan2(capture_lateral.cross(body_lateral).dot(up), capture_lateral.dot(body_lateral));
    const Eigen::AngleAxisd turn(angle, up);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);

    TipTrajectory tips;
    tips.time_s = capture.time_s;
    for (int s = 0; s < 2; ++s)
        for (const Eigen::Vector3d &p : capture.tracks[tracks[s]].position_m)
            tips.tip_m[s].push_back(goal + turn * (p - centre));
    return tips;
}

Eigen::Vector3d fit_drum_to_strokes(const TipTrajectory &tips, double tip_radius_m)
{
    std::vector<double> heights;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    int sticks_with_strokes = 0;
    for (int s = 0; s < 2; ++s) {
        const std::vector<Eigen::Vector3d> &p = tips.tip_m[s];
        double lo = 1e300, hi = -1e300;
        for (const Eigen::Vector3d &x : p) {
            lo = std::min(lo, x.y());
            hi = std::max(hi, x.y());
        }
        const double threshold = lo + 0.25 * (hi - lo);
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int strokes = 0;
        for (size_t i = 1; i + 1 < p.size(); ++i)
            if (p[i].y() <= p[i - 1].y() && p[i].y() < p[i + 1].y() && p[i].y() <= threshold) {
                sum += p[i];
                heights.push_back(p[i].y());
                ++strokes;
            }
        if (strokes > 0) {
            centre += sum / strokes;
            ++sticks_with_strokes;
        }
    }
    if (sticks_with_strokes == 0)
        throw CharacterError("--drum auto: no strokes in the stick capture (no minima of tip "
                             "height)");
    // Each stick counts once, however many strokes it played.
    centre /= sticks_with_strokes;
    std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
    centre.y() = heights[heights.size() / 2] - tip_radius_m;
    return centre;
}

} // namespace ictus
