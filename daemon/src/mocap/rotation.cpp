// rotation.cpp -- sign-robust mean rotation and Tait-Bryan angles (joint_limits.hpp).
#include "ictus/mocap/joint_limits.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>

namespace ictus
{

Eigen::Quaterniond mean_rotation(const std::vector<Eigen::Quaterniond> &series)
{
    if (series.empty())
        throw MocapError("mean_rotation", 0, "expected at least one rotation, got none");
    // Markley, Cheng, Crassidis, Oshman (2007): the average maximising
    // sum (q_i . q)^2 is the top eigenvector of M = sum q_i q_i^T. q and -q
    // give the same outer product, so the sign of the samples does not matter.
    Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
    for (std::size_t i = 0; i < series.size(); ++i) {
        const Eigen::Vector4d q = series[i].coeffs(); // x y z w; any fixed order works
        const double norm = q.norm();
        if (!std::isfinite(norm) || norm < 1e-9)
            throw MocapError("mean_rotation", 0,
                             "expected finite non-zero quaternions, got norm " +
                                 std::to_string(norm) + " at sample " + std::to_string(i));
        m += (q / norm) * (q / norm).transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(m);
    const Eigen::Vector4d top = solver.eigenvectors().col(3); // eigenvalues ascending
    Eigen::Quaterniond mean(top(3), top(0), top(1), top(2));
    mean.normalize();
    if (mean.w() < 0.0)
        mean.coeffs() = -mean.coeffs();
    return mean;
}

const char *to_string(EulerOrder order)
{
    switch (order) {
    case EulerOrder::XYZ:
        return "XYZ";
    case EulerOrder::XZY:
        return "XZY";
    case EulerOrder::YXZ:
        return "YXZ";
    case EulerOrder::YZX:
        return "YZX";
    case EulerOrder::ZXY:
        return "ZXY";
    case EulerOrder::ZYX:
        return "ZYX";
    }
    return "?";
}

EulerOrder euler_order_from_string(const std::string &text)
{
    std::string upper;
    for (char c : text)
        upper.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    for (EulerOrder order : {EulerOrder::XYZ, EulerOrder::XZY, EulerOrder::YXZ, EulerOrder::YZX,
                             EulerOrder::ZXY, EulerOrder::ZYX})
        if (upper == to_string(order))
            return order;
    throw MocapError("euler order", 0,
                     "expected one of XYZ XZY YXZ YZX ZXY ZYX, got '" + text + "'");
}

namespace
{

// Axis indices (i, j, k) of an order; `cyclic` when (i, j, k) is an even
// permutation of (0, 1, 2).
void order_axes(EulerOrder order, int &i, int &j, int &k, bool &cyclic)
{
    const char *name = to_string(order);
    i = name[0] - 'X';
    j = name[1] - 'X';
    k = name[2] - 'X';
    cyclic = ((j - i + 3) % 3) == 1;
}

} // namespace

Eigen::Vector3d euler_angles(const Eigen::Quaterniond &q, EulerOrder order)
{
    int i, j, k;
    bool cyclic;
    order_axes(order, i, j, k, cyclic);
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    // R = R_i(a0) R_j(a1) R_k(a2). For a cyclic order R(i,k) = sin a1,
    // R(j,k) = -sin a0 cos a1, R(k,k) = cos a0 cos a1, R(i,j) = -cos a1 sin a2,
    // R(i,i) = cos a1 cos a2; an anti-cyclic order flips the off-diagonal signs.
    const double s = cyclic ? 1.0 : -1.0;
    const double sin_a1 = std::clamp(s * r(i, k), -1.0, 1.0);
    Eigen::Vector3d a;
    a[1] = std::asin(sin_a1);
    if (std::fabs(sin_a1) < 1.0 - 1e-12) {
        a[0] = std::atan2(-s * r(j, k), r(k, k));
        a[2] = std::atan2(-s * r(i, j), r(i, i));
    } else {
        // Gimbal lock: only a0 +/- a2 is defined; put it all in a0.
        a[2] = 0.0;
        a[0] = std::atan2(s * r(k, j), r(j, j));
    }
    return a;
}

Eigen::Quaterniond from_euler(const Eigen::Vector3d &angles_rad, EulerOrder order)
{
    int i, j, k;
    bool cyclic;
    order_axes(order, i, j, k, cyclic);
    const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                     Eigen::Vector3d::UnitZ()};
    return (Eigen::Quaterniond(Eigen::AngleAxisd(angles_rad[0], axes[i])) *
            Eigen::Quaterniond(Eigen::AngleAxisd(angles_rad[1], axes[j])) *
            Eigen::Quaterniond(Eigen::AngleAxisd(angles_rad[2], axes[k])))
        .normalized();
}

} // namespace ictus
