// rotation.cpp -- quaternion log/exp maps (rotation.hpp).
#include "ictus/base/rotation.hpp"

#include <cmath>

namespace ictus
{

Eigen::Vector3d log_map(const Eigen::Quaterniond &q)
{
    // q and -q are the same rotation: take the one with w >= 0 so the angle is in [0, pi].
    const double sign = q.w() < 0.0 ? -1.0 : 1.0;
    const Eigen::Vector3d v = sign * q.vec();
    const double sin_half = v.norm();
    if (sin_half < 1e-12)
        return 2.0 * v; // angle ~ 2 sin(angle/2)
    const double angle = 2.0 * std::atan2(sin_half, sign * q.w());
    return (angle / sin_half) * v;
}

Eigen::Quaterniond exp_map(const Eigen::Vector3d &rotation_vector_rad)
{
    const double angle = rotation_vector_rad.norm();
    const double half_sinc =
        angle < 1e-6 ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle;
    const Eigen::Vector3d v = half_sinc * rotation_vector_rad;
    return Eigen::Quaterniond(std::cos(0.5 * angle), v.x(), v.y(), v.z());
}

double rotation_angle_between(const Eigen::Quaterniond &from, const Eigen::Quaterniond &to)
{
    return log_map(to * from.conjugate()).norm();
}

} // namespace ictus
