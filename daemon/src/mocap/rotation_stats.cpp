// rotation_stats.cpp -- the sign-robust mean rotation and the named Tait-Bryan orders
// (rotation_stats.hpp) over base/rotation.hpp.
#include "ictus/mocap/rotation_stats.hpp"
#include "ictus/base/enum_names.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
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

namespace
{
const EnumNames<6> kEulerOrderNames = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
} // namespace

const char *to_string(EulerOrder order)
{
    return enum_name(kEulerOrderNames, order, "?");
}

EulerOrder euler_order_from_string(const std::string &text)
{
    std::string upper;
    for (char c : text)
        upper.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    EulerOrder order;
    if (enum_from_name(kEulerOrderNames, upper, order))
        return order;
    throw MocapError("euler order", 0,
                     "expected one of XYZ XZY YXZ YZX ZXY ZYX, got '" + text + "'");
}

namespace
{
// The axes (i, j, k) of an order, 0 = x.
std::array<int, 3> order_axes(EulerOrder order)
{
    const char *name = to_string(order);
    return {name[0] - 'X', name[1] - 'X', name[2] - 'X'};
}
} // namespace

Eigen::Vector3d euler_angles(const Eigen::Quaterniond &q, EulerOrder order)
{
    return euler_angles(q, order_axes(order));
}

Eigen::Quaterniond from_euler(const Eigen::Vector3d &angles_rad, EulerOrder order)
{
    return from_euler(angles_rad, order_axes(order));
}

} // namespace ictus
