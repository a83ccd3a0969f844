// kinematic_chain.cpp -- forward kinematics of ball-joint chains (see kinematics.hpp).
#include "ictus/kinematics.hpp"

#include <cmath>

namespace ictus
{

Eigen::Quaterniond quaternion_exp(const Eigen::Vector3d &rotation_vector_rad)
{
    const double angle = rotation_vector_rad.norm();
    // sin(a/2)/a by its Taylor series near 0, where the quotient loses precision.
    const double half_sinc =
        angle < 1e-6 ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle;
    const Eigen::Vector3d v = half_sinc * rotation_vector_rad;
    return Eigen::Quaterniond(std::cos(0.5 * angle), v.x(), v.y(), v.z());
}

Eigen::Vector3d quaternion_log(const Eigen::Quaterniond &rotation)
{
    // q and -q are the same rotation: take the one with w >= 0 so the angle is in [0, pi].
    const double sign = rotation.w() < 0.0 ? -1.0 : 1.0;
    const Eigen::Vector3d v = sign * rotation.vec();
    const double sin_half = v.norm();
    const double angle = 2.0 * std::atan2(sin_half, sign * rotation.w());
    if (sin_half < 1e-12)
        return 2.0 * v; // angle ~ 2 sin(angle/2)
    return (angle / sin_half) * v;
}

double rotation_angle_between(const Eigen::Quaterniond &from, const Eigen::Quaterniond &to)
{
    return quaternion_log(to * from.conjugate()).norm();
}

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
