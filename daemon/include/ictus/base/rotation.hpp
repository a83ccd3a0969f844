// rotation.hpp -- the rotation toolkit every area shares: the quaternion log
// and exp maps between unit quaternions and rotation vectors (axis * angle,
// radians), and the angle between two rotations. One implementation of each;
// see docs/architecture.md ("base").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace ictus
{

// log map: the rotation vector (axis * angle, angle in [0, pi]) of a unit
// quaternion; of q and -q (the same rotation) the one with w >= 0 is taken.
// The input is not normalised: pass q.normalized() when it may have drifted.
Eigen::Vector3d log_map(const Eigen::Quaterniond &q);

// exp map: the unit quaternion of a rotation vector (axis * angle, rad).
// Near 0, sin(a/2)/a comes from its Taylor series, where the quotient loses precision.
Eigen::Quaterniond exp_map(const Eigen::Vector3d &rotation_vector_rad);

// Angle in [0, pi] of the rotation taking `from` to `to`.
double rotation_angle_between(const Eigen::Quaterniond &from, const Eigen::Quaterniond &to);

// The rotation by angle_rad about axis 0 (x), 1 (y) or 2 (z).
Eigen::Quaterniond axis_rotation(int axis, double angle_rad);

// Tait-Bryan angles (rad) of a rotation about the axes `axes` (a permutation
// of {0, 1, 2}), intrinsic: q = R_axes[0](a[0]) * R_axes[1](a[1]) * R_axes[2](a[2]),
// a[0], a[2] in (-pi, pi], a[1] in [-pi/2, pi/2]. At gimbal lock (a[1] = +-pi/2)
// a[0] and a[2] are not unique; the pair returned still composes to q to rounding.
Eigen::Vector3d euler_angles(const Eigen::Quaterniond &q, const std::array<int, 3> &axes);
// The rotation of Tait-Bryan angles (rad) about `axes`, as above.
Eigen::Quaterniond from_euler(const Eigen::Vector3d &angles_rad, const std::array<int, 3> &axes);

} // namespace ictus
