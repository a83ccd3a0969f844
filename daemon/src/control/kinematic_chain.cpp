// kinematic_chain.cpp -- forward kinematics of ball-joint chains (see kinematic_chain.hpp).
#include "ictus/control/kinematic_chain.hpp"

#include <cmath>

namespace ictus
{

int KinematicChain::add_joint(const Eigen::Vector3d &offset_m, const Eigen::Quaterniond &rotation,
                              JointLimitRef limit)
{
    const double norm = rotation.norm();
    if (joint_count_ >= kMaxJoints || !offset_m.allFinite() || !rotation.coeffs().allFinite() ||
        !(norm > 0.0))
        return -1;
    offset_m_[joint_count_] = offset_m;
    rotation_[joint_count_] = Eigen::Quaterniond(rotation.coeffs() / norm);
    limit_[joint_count_] = limit;
    return joint_count_++;
}

void KinematicChain::set_base(const Eigen::Vector3d &position_m, const Eigen::Quaterniond &rotation)
{
    base_position_m_ = position_m;
    base_rotation_ = rotation;
}

void KinematicChain::set_tip(const Eigen::Vector3d &tip_offset_m, const Eigen::Vector3d &stick_axis)
{
    tip_offset_m_ = tip_offset_m;
    const Eigen::Vector3d axis = stick_axis.squaredNorm() > 0.0 ? stick_axis : tip_offset_m;
    stick_axis_ = axis.squaredNorm() > 0.0 ? axis.normalized() : Eigen::Vector3d::UnitX();
}

void KinematicChain::set_rotations(const Eigen::Quaterniond *rotations)
{
    for (int j = 0; j < joint_count_; ++j)
        rotation_[j] = rotations[j];
}

double KinematicChain::reach_m() const
{
    double reach = tip_offset_m_.norm();
    for (int j = 1; j < joint_count_; ++j)
        reach += offset_m_[j].norm();
    return reach;
}

void KinematicChain::forward(ChainFrames *frames) const
{
    forward(rotation_.data(), frames);
}

void KinematicChain::forward(const Eigen::Quaterniond *rotations, ChainFrames *frames) const
{
    Eigen::Vector3d position = base_position_m_;
    Eigen::Quaterniond orientation = base_rotation_;
    for (int j = 0; j < joint_count_; ++j) {
        position += orientation * offset_m_[j];
        orientation = orientation * rotations[j];
        frames->joint_position_m[j] = position;
        frames->joint_rotation[j] = orientation;
    }
    frames->tip_position_m = position + orientation * tip_offset_m_;
    frames->stick_direction = orientation * stick_axis_;
}

Eigen::Vector3d KinematicChain::tip_position() const
{
    ChainFrames frames;
    forward(&frames);
    return frames.tip_position_m;
}

} // namespace ictus
