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

Eigen::Quaterniond axis_rotation(int axis, double angle_rad)
{
    const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                     Eigen::Vector3d::UnitZ()};
    return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axes[axis < 0 || axis > 2 ? 0 : axis]));
}

Eigen::Vector3d euler_angles(const Eigen::Quaterniond &q, const std::array<int, 3> &axes)
{
    // R = R_i(a) R_j(b) R_k(c). With s = +1 for the cyclic orders (XYZ, YZX,
    // ZXY) and -1 for the others: R(i,k) = s sin b, and a from the j and k rows
    // of the third column. c is taken from M = R_i(a)^T R = R_j(b) R_k(c),
    // whose row j is that of R_k(c) alone: stable at gimbal lock, where the
    // textbook atan2(R(i,j), R(i,i)) loses c (Shoemake's method, as in Eigen).
    const int i = axes[0], j = axes[1], k = axes[2];
    const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    Eigen::Vector3d angles;
    angles[1] = std::atan2(s * r(i, k), std::hypot(r(i, i), r(i, j)));
    angles[0] = std::atan2(-s * r(j, k), r(k, k));
    const Eigen::Matrix3d m = axis_rotation(i, angles[0]).toRotationMatrix().transpose() * r;
    angles[2] = std::atan2(s * m(j, i), m(j, j));
    return angles;
}

Eigen::Quaterniond from_euler(const Eigen::Vector3d &angles_rad, const std::array<int, 3> &axes)
{
    return (axis_rotation(axes[0], angles_rad[0]) * axis_rotation(axes[1], angles_rad[1]) *
            axis_rotation(axes[2], angles_rad[2]))
        .normalized();
}

} // namespace ictus
