// rotation_stats.hpp -- rotations of captured joints as data: their
// sign-robust mean (Algorithm 1's first step) and the named Tait-Bryan orders
// of BVH channels and Euler limits, over base/rotation.hpp.
#pragma once

#include "ictus/base/rotation.hpp"
#include "ictus/mocap/mocap_error.hpp"

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace ictus
{

// Sign-robust mean rotation (Markley et al. 2007): the eigenvector of the
// largest eigenvalue of sum q q^T (q as 4-vectors). Returned with w >= 0.
// Throws MocapError on an empty series.
Eigen::Quaterniond mean_rotation(const std::vector<Eigen::Quaterniond> &series);

// Tait-Bryan orders, intrinsic: XYZ means R = Rx(a0) * Ry(a1) * Rz(a2) (the
// BVH composition for channels "Xrotation Yrotation Zrotation").
enum class EulerOrder { XYZ, XZY, YXZ, YZX, ZXY, ZYX };
const char *to_string(EulerOrder order);
// Parses "XYZ".."ZYX" (case-insensitive); throws MocapError otherwise.
EulerOrder euler_order_from_string(const std::string &text);
// Angles (rad) a0, a1, a2 with a0, a2 in (-pi, pi], a1 in [-pi/2, pi/2]
// (base/rotation.hpp's euler_angles about the order's axes).
Eigen::Vector3d euler_angles(const Eigen::Quaterniond &q, EulerOrder order);
Eigen::Quaterniond from_euler(const Eigen::Vector3d &angles_rad, EulerOrder order);

} // namespace ictus
