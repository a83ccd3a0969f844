// bvh_export.cpp -- character poses back onto the source mocap skeleton
// (the inverse of CharacterModel::pose_from_motion), for BVH export.
#include "ictus/character/bvh_export.hpp"

#include <cmath>

namespace ictus
{

namespace
{

// The mocap joint whose frame is body b's frame: the last of its source path.
int source_joint(const BodySpec &body)
{
    return body.source_path.empty() ? -1 : body.source_path.back();
}

} // namespace

Motion motion_from_poses(const CharacterModel &model, const Skeleton &skeleton,
                         const std::vector<CharacterPose> &poses, double rate_hz)
{
    if (!(std::isfinite(rate_hz) && rate_hz > 0.0))
        throw CharacterError("BVH export: frame rate must be finite and > 0, got " +
                             std::to_string(rate_hz));
    const int n = static_cast<int>(skeleton.joints.size());
    const auto &bodies = model.bodies();
    for (const BodySpec &body : bodies) {
        const int j = source_joint(body);
        if (j < 0 || j >= n)
            throw CharacterError("BVH export: body " + body.name + " has source joint " +
                                 std::to_string(j) + ", outside the skeleton's " +
                                 std::to_string(n) +
                                 " joints (not the skeleton it was built from?)");
    }
    if (source_joint(bodies[0]) != 0)
        throw CharacterError("BVH export: the pelvis's source joint must be the skeleton's root");

    Motion motion;
    motion.frame_rate_hz = rate_hz;
    motion.root_position_m.reserve(poses.size());
    motion.local_rotation.reserve(poses.size());
    for (std::size_t f = 0; f < poses.size(); ++f) {
        const CharacterPose &pose = poses[f];
        if (static_cast<int>(pose.local.size()) != CharacterModel::kJoints)
            throw CharacterError("BVH export: pose " + std::to_string(f) + " has " +
                                 std::to_string(pose.local.size()) + " joint rotations, expected " +
                                 std::to_string(CharacterModel::kJoints));
        std::vector<Eigen::Quaterniond> local(static_cast<std::size_t>(n),
                                              Eigen::Quaterniond::Identity());
        local[0] = pose.pelvis_rotation.normalized();
        for (int b = 1; b < CharacterModel::kBodies; ++b)
            local[static_cast<std::size_t>(source_joint(bodies[static_cast<std::size_t>(b)]))] =
                pose.local[static_cast<std::size_t>(b - 1)].normalized();
        // The pelvis frame is the root's: its world position is the root's.
        motion.root_position_m.push_back(pose.pelvis_position_m);
        motion.local_rotation.push_back(std::move(local));
    }
    return motion;
}

CharacterPose pose_from_frames(const CharacterModel &model, const BodyFrames &frames)
{
    if (static_cast<int>(frames.origin_m.size()) != CharacterModel::kBodies ||
        static_cast<int>(frames.rotation.size()) != CharacterModel::kBodies)
        throw CharacterError("BVH export: body frames for " +
                             std::to_string(frames.rotation.size()) + " bodies, expected " +
                             std::to_string(CharacterModel::kBodies));
    CharacterPose pose;
    pose.pelvis_position_m = frames.origin_m[0];
    pose.pelvis_rotation = frames.rotation[0].normalized();
    pose.local.resize(CharacterModel::kJoints);
    for (int b = 1; b < CharacterModel::kBodies; ++b) {
        const int p = model.bodies()[static_cast<std::size_t>(b)].parent;
        pose.local[static_cast<std::size_t>(b - 1)] =
            (frames.rotation[static_cast<std::size_t>(p)].conjugate() *
             frames.rotation[static_cast<std::size_t>(b)])
                .normalized();
    }
    return pose;
}

Skeleton skeleton_with_sticks(const CharacterModel &model, const Skeleton &skeleton)
{
    Skeleton out = skeleton;
    const int n = static_cast<int>(skeleton.joints.size());
    for (Side side : {Side::left, Side::right}) {
        const BodySpec &hand = model.bodies()[static_cast<std::size_t>(model.hand_body(side))];
        const int parent = source_joint(hand);
        if (parent < 0 || parent >= n)
            throw CharacterError("BVH export: hand " + hand.name +
                                 " has no source joint in the skeleton");
        const StickInHand &stick = model.stick(side);
        SkeletonJoint grip;
        grip.name = skeleton.joints[static_cast<std::size_t>(parent)].name + "Stick";
        grip.parent = parent;
        grip.offset_m = stick.grip_m;
        out.joints.push_back(grip);
        SkeletonJoint tip;
        tip.name = grip.name + "_End";
        tip.parent = static_cast<int>(out.joints.size()) - 1;
        tip.offset_m = stick.tip_m - stick.grip_m;
        tip.end_site = true;
        out.joints.push_back(tip);
    }
    return out;
}

BvhRecorder::BvhRecorder(const CharacterModel &model, const Skeleton &source, double rate_hz)
    : model_(model), skeleton_(skeleton_with_sticks(model, source)), rate_hz_(rate_hz)
{
    if (!(std::isfinite(rate_hz) && rate_hz > 0.0))
        throw CharacterError("BVH export: frame rate must be finite and > 0, got " +
                             std::to_string(rate_hz));
}

void BvhRecorder::record(const BodyFrames &frames, const std::array<Eigen::Quaterniond, 2> &sticks)
{
    poses_.push_back(pose_from_frames(model_, frames));
    sticks_.push_back(sticks);
}

void BvhRecorder::write(const std::string &path, const BvhWriteOptions &options) const
{
    Motion motion = motion_from_poses(model_, skeleton_, poses_, rate_hz_);
    // The sticks turned about their fulcrums (the stick joint sits at the grip
    // point in the hand's frame).
    for (int side = 0; side < 2; ++side) {
        const int joint = skeleton_.find(side == 0 ? "LeftHandStick" : "RightHandStick");
        if (joint < 0)
            continue;
        for (size_t f = 0; f < motion.local_rotation.size() && f < sticks_.size(); ++f)
            motion.local_rotation[f][joint] = sticks_[f][side];
    }
    write_bvh(path, skeleton_, motion, options);
}

} // namespace ictus
