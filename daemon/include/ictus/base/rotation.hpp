// rotation.hpp -- the rotation toolkit every area shares: the quaternion log
// and exp maps between unit quaternions and rotation vectors (axis * angle,
// radians), and the angle between two rotations. One implementation of each;
// see docs/architecture.md ("base").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

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

} // namespace ictus
