// bvh_export.hpp -- the simulated performance as motion of the mocap skeleton
// the character was built from (CharacterModel::from_skeleton), for BVH export
// (write_bvh, bvh.hpp): any 3D tool then shows the performance without Gem.
#pragma once

#include <array>

#include "ictus/mocap/bvh.hpp"
#include "ictus/character/character.hpp"
#include "ictus/mocap/motion.hpp"

#include <string>
#include <vector>

namespace ictus
{

// The inverse of CharacterModel::pose_from_motion. Each body's frame is its
// source mocap joint's frame, and its joint rotation is the product of the
// local rotations along its source path (parent-most first): the body's
// rotation goes on the source joint itself, the joints merged into the path
// (e.g. Spine1 between thorax and neck, LHipJoint) keep the identity, and so
// does every joint the character leaves out (fingers, toes, end sites), which
// then moves rigidly with its parent. With those identities the source joint
// lands exactly where the character puts the body (the body's offset is the
// sum of the path's OFFSETs), so forward_kinematics of the result at each
// body's source joint equals CharacterModel::forward. Joints appended to the
// skeleton after the source ones (e.g. by skeleton_with_sticks) get identity.
// Throws CharacterError when a pose has the wrong number of joints, a source
// joint is out of the skeleton, or rate_hz is not finite and > 0.
Motion motion_from_poses(const CharacterModel &model, const Skeleton &skeleton,
                         const std::vector<CharacterPose> &poses, double rate_hz);

// The pose whose forward kinematics gives these body orientations (the
// inverse of CharacterModel::forward for rotations): pelvis frame as given,
// local[j] = rotation(parent)^-1 * rotation(body j + 1). For recording the
// physics' bodies (Scene) as poses. Body origins other than the pelvis's are
// not used: the exported skeleton places each body at its joint offset, so a
// physics joint's drift (a few tenths of a mm at most) does not show.
CharacterPose pose_from_frames(const CharacterModel &model, const BodyFrames &frames);

// The skeleton plus the two drumsticks, so that a BVH shows them: per hand a
// joint "<Hand>Stick" (LeftHandStick / RightHandStick) below the hand's source
// joint at the stick's grip point, with an end site at the tip. At identity
// the stick lies as the hand holds it at rest (CharacterModel::tip_position);
// BvhRecorder turns it about its fulcrum. Appended after the existing joints.
Skeleton skeleton_with_sticks(const CharacterModel &model, const Skeleton &skeleton);

// Records a performance frame by frame and writes it as BVH: the source
// skeleton with the sticks, metres, Z Y X channels. Keeps copies of the model
// and skeleton (no references to objects that may die first). Offline use:
// record() appends (allocates); not for the real-time loop. Frame f of the
// file is the f-th recorded frame at time f / rate_hz: record at t = 0 and
// then every 1 / rate_hz.
class BvhRecorder
{
  public:
    BvhRecorder(const CharacterModel &model, const Skeleton &source, double rate_hz);
    // The physics' body frames (Scene::body_frames) of one frame, and the
    // sticks' rotations in their hands' frames [side] (Scene::stick_in_hand;
    // identity: the stick as the hand holds it at rest).
    void record(const BodyFrames &frames,
                const std::array<Eigen::Quaterniond, 2> &sticks = {Eigen::Quaterniond::Identity(),
                                                                   Eigen::Quaterniond::Identity()});
    int frames() const { return static_cast<int>(poses_.size()); }
    // Throws MocapError naming the path when it cannot be written.
    void write(const std::string &path, const BvhWriteOptions &options = {}) const;

  private:
    CharacterModel model_;
    Skeleton skeleton_; // with the sticks
    double rate_hz_;
    std::vector<CharacterPose> poses_;
    std::vector<std::array<Eigen::Quaterniond, 2>> sticks_;
};

} // namespace ictus
