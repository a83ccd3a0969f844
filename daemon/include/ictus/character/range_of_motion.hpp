// range_of_motion.hpp -- joint limits for a body without a capture to learn
// them from (the score performer): each joint's normal human range of motion,
// from published goniometry (docs/character.md, "Range of motion", lists the
// sources), as swing-twist limits about the joint's rest axes. The limits the
// mocap learns (character_limits.hpp) fit a capture's own motion; these fit a
// person.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/character/joint_limit_ref.hpp"

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace ictus
{

// A joint's rotation q (local, rest = identity) split as q = swing * twist:
// the twist turns about the segment's long axis (its rest direction), the
// swing tilts that axis, as the rotation vector swing_u u + swing_w w (u, w
// unit, normal to the long axis). Each of the three is kept in a range.
struct SwingTwistLimit {
    Eigen::Vector3d twist_axis = Eigen::Vector3d::UnitY(); // unit, the segment at rest
    Eigen::Vector3d u = Eigen::Vector3d::UnitX();          // unit, normal to twist_axis
    Eigen::Vector3d w = Eigen::Vector3d::UnitZ();          // unit, twist_axis x u or its opposite
    double twist_lo_rad = -0.5, twist_hi_rad = 0.5;
    double u_lo_rad = -0.5, u_hi_rad = 0.5;
    double w_lo_rad = -0.5, w_hi_rad = 0.5;

    // (swing_u, swing_w, twist) of q, rad.
    Eigen::Vector3d coordinates(const Eigen::Quaterniond &q) const;
    bool contains(const Eigen::Quaterniond &q, double tolerance_rad = 1e-9) const;
    // Inside: q. Outside: each coordinate clamped into its range, recomposed.
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const;
    // The angle between q and clamp(q), rad: how far q is outside.
    double excursion_rad(const Eigen::Quaterniond &q) const;
};

// One limit per joint of the model, from its rest geometry (the long axes)
// and the table of ranges in range_of_motion.cpp (degrees, with sources).
// Throws CharacterError when a joint of the table is missing from the model.
class RangeOfMotion
{
  public:
    explicit RangeOfMotion(const CharacterModel &model);
    // The same ranges narrowed by inner_margin_rad on every side (each range
    // keeps at least its middle): the IK's limits, so that the tracking's
    // overshoot of a solution on the boundary stays inside the true one.
    RangeOfMotion(const CharacterModel &model, double inner_margin_rad);
    const SwingTwistLimit &limit(int joint) const { return limits_[joint]; }
    // For Scene::set_joint_limits and the IK; refer to this object.
    std::vector<JointLimitRef> refs() const;
    // The joint furthest outside its range in `local` (19 rotations), and
    // how far, rad.
    double max_excursion_rad(const std::vector<Eigen::Quaterniond> &local, int *joint) const;

  private:
    std::vector<SwingTwistLimit> limits_;
};

} // namespace ictus
