// A human-like drummer's arm for the kinematics tests: torso base, clavicle 0.15 m, upper arm
// 0.29 m, forearm 0.27 m, hand 0.08 m + stick 0.40 m held forward. y is up, +x to the right.
#pragma once

#include "ictus/control/kinematic_chain.hpp"

#include <atomic>
#include <cmath>
#include <random>

extern std::atomic<long> g_operator_new_calls;

namespace arm
{

constexpr double kClavicle = 0.15, kUpperArm = 0.29, kForearm = 0.27, kHand = 0.08, kStick = 0.40;
inline const Eigen::Vector3d kBase(0.0, 1.2, 0.0);            // torso body centre, world
inline const Eigen::Vector3d kSternum(0.0, 0.2, 0.0);         // clavicle joint, in torso frame
inline const Eigen::Vector3d kTipOffset(0.0, -kHand, kStick); // in the hand (wrist) frame
// |kTipOffset| = sqrt(0.08^2 + 0.4^2): the tip is that far from the wrist at most.
inline double reach()
{
    return kClavicle + kUpperArm + kForearm + std::hypot(kHand, kStick);
}

// Joint order: clavicle, shoulder, elbow, wrist.
inline ictus::KinematicChain make(const ictus::JointLimitRef *limits = nullptr)
{
    ictus::KinematicChain chain;
    const Eigen::Vector3d offsets[4] = {kSternum, Eigen::Vector3d(kClavicle, 0.0, 0.0),
                                        Eigen::Vector3d(0.0, -kUpperArm, 0.0),
                                        Eigen::Vector3d(0.0, -kForearm, 0.0)};
    for (int j = 0; j < 4; ++j)
        chain.add_joint(offsets[j], Eigen::Quaterniond::Identity(),
                        limits ? limits[j] : ictus::JointLimitRef());
    chain.set_base(kBase, Eigen::Quaterniond::Identity());
    chain.set_tip(kTipOffset, Eigen::Vector3d::UnitZ());
    return chain;
}

// Random rotation of angle uniform in [0, max_angle] about a uniformly random axis.
inline Eigen::Quaterniond random_rotation(std::mt19937 &rng, double max_angle)
{
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> uniform(0.0, max_angle);
    Eigen::Vector3d axis(gauss(rng), gauss(rng), gauss(rng));
    return Eigen::Quaterniond(Eigen::AngleAxisd(uniform(rng), axis.normalized()));
}

// Typical ranges of a drummer's joints (rad): clavicle, shoulder, elbow, wrist.
constexpr double kRange[4] = {0.3, 1.5, 1.5, 1.0};

inline void random_pose(std::mt19937 &rng, Eigen::Quaterniond *rotations, double scale = 1.0)
{
    for (int j = 0; j < 4; ++j)
        rotations[j] = random_rotation(rng, scale * kRange[j]);
}

// A test limit: the joint's rotation angle from its rest pose at most max_angle_rad
// (a ball-shaped region of the rotation group), clamped along the geodesic to the rest pose.
struct AngleLimit {
    double max_angle_rad;
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const
    {
        const Eigen::Quaterniond c = q.w() < 0.0 ? Eigen::Quaterniond(-q.coeffs()) : q;
        const double angle = 2.0 * std::atan2(c.vec().norm(), c.w());
        if (angle <= max_angle_rad)
            return q;
        return Eigen::Quaterniond(Eigen::AngleAxisd(max_angle_rad, c.vec().normalized()));
    }
    static double angle_of(const Eigen::Quaterniond &q)
    {
        return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
    }
};

} // namespace arm
