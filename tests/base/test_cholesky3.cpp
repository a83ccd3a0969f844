// Cholesky3 (the IK's 3x3 solves written out) against Eigen::LLT<Matrix3d> itself: the same
// bits for the factor, a vector solve and a 3 x n solve, on well- and ill-conditioned
// matrices of the kinds the IK forms (J J^T plus a damping or a 1e-12 regulariser), and
// Eigen's own answer where the matrix is not positive definite.
#include <catch2/catch.hpp>

#include "ictus/base/cholesky3.hpp"

#include <cmath>
#include <limits>
#include <random>

namespace
{
using Jacobian = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 24>;

bool same_bits(double a, double b)
{
    return (std::isnan(a) && std::isnan(b)) || (a == b && std::signbit(a) == std::signbit(b));
}

template <typename A, typename B> bool same_bits(const A &a, const B &b)
{
    if (a.rows() != b.rows() || a.cols() != b.cols())
        return false;
    for (Eigen::Index r = 0; r < a.rows(); ++r)
        for (Eigen::Index c = 0; c < a.cols(); ++c)
            if (!same_bits(a(r, c), b(r, c)))
                return false;
    return true;
}
} // namespace

TEST_CASE("Cholesky3 solves bit for bit as Eigen::LLT<Matrix3d>", "[base]")
{
    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal(0.0, 1.0);
    long vector_mismatches = 0, matrix_mismatches = 0, cases = 0;
    for (int i = 0; i < 20000; ++i) {
        // J: 3 x 12, rows of scales 1e-3 .. 1e2 m, sometimes nearly rank-deficient.
        const int cols = 3 * (1 + i % 4);
        Jacobian j(3, cols);
        const double scale = std::pow(10.0, (i % 6) - 3);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < cols; ++c)
                j(r, c) = normal(rng) * scale;
        if (i % 5 == 0)
            j.row(2) = j.row(0) * 0.5 + j.row(1) * 1e-9; // near-singular J J^T
        Eigen::Matrix3d a = j * j.transpose();
        a.diagonal().array() += (i % 2 == 0) ? 1e-12 : 1e-4;
        Eigen::LLT<Eigen::Matrix3d> llt(a);
        ictus::Cholesky3 c3;
        c3.compute(a);
        const Eigen::Vector3d b(normal(rng), normal(rng), normal(rng));
        vector_mismatches += !same_bits(Eigen::Vector3d(llt.solve(b)), c3.solve(b));
        Jacobian expected = llt.solve(j), got;
        c3.solve(j, got);
        matrix_mismatches += !same_bits(expected, got);
        ++cases;
    }
    INFO(cases << " matrices");
    CHECK(vector_mismatches == 0);
    CHECK(matrix_mismatches == 0);
}

TEST_CASE("Cholesky3 gives Eigen's answer for matrices that are not positive definite",
          "[base]")
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Eigen::Matrix3d zero = Eigen::Matrix3d::Zero(), indefinite,
                    with_nan = Eigen::Matrix3d::Identity();
    indefinite << 1, 2, 0, 2, 1, 0, 0, 0, 1; // eigenvalues 3, -1, 1
    with_nan(1, 1) = nan;
    Jacobian j(3, 6);
    j << 1, 2, 3, 4, 5, 6, -1, 0.5, 2, 0, 1, -2, 3, 1, 0, 2, -1, 1;
    for (const Eigen::Matrix3d &a : {zero, indefinite, with_nan}) {
        Eigen::LLT<Eigen::Matrix3d> llt(a);
        ictus::Cholesky3 c3;
        c3.compute(a);
        const Eigen::Vector3d b(1.0, -2.0, 0.5);
        CHECK(same_bits(Eigen::Vector3d(llt.solve(b)), c3.solve(b)));
        Jacobian expected = llt.solve(j), got;
        c3.solve(j, got);
        CHECK(same_bits(expected, got));
    }
}
