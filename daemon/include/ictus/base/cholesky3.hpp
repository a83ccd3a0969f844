// cholesky3.hpp -- Eigen::LLT<Matrix3d> written out for 3x3, bit for bit.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

namespace ictus
{

// The Cholesky factorisation of a symmetric positive-definite 3x3 matrix and its
// solves, with exactly the operations (and so the rounding) of
// Eigen::LLT<Eigen::Matrix3d> (Eigen 3.4): the factor is Eigen's unblocked
// llt_inplace, a vector right-hand side Eigen's unrolled substitutions (a
// division by the diagonal), a matrix right-hand side its triangular_solve_matrix
// (a product with the diagonal's reciprocal). Written out, without Eigen's
// runtime-sized blocks, L1 norm and packed triangular solve, which took ~5 % of
// `ictusd render` in the IK's three 3x3 solves per iteration (docs/benchmarks.md,
// "Performer"). A matrix Eigen would find not positive definite (a diagonal pivot
// <= 0 or NaN) goes to Eigen's own LLT, so the results are Eigen's in every case
// (checked against it on random matrices: tests/base/test_cholesky3.cpp).
class Cholesky3
{
  public:
    void compute(const Eigen::Matrix3d &a)
    {
        ok_ = false;
        double x = a(0, 0);
        if (x > 0.0) {
            l00_ = std::sqrt(x);
            l10_ = a(1, 0) / l00_;
            l20_ = a(2, 0) / l00_;
            x = a(1, 1) - l10_ * l10_;
            if (x > 0.0) {
                l11_ = std::sqrt(x);
                l21_ = (a(2, 1) - l20_ * l10_) / l11_;
                x = a(2, 2) - (l20_ * l20_ + l21_ * l21_);
                if (x > 0.0) {
                    l22_ = std::sqrt(x);
                    ok_ = true;
                }
            }
        }
        if (!ok_)
            fallback_.compute(a);
    }

    // A^-1 b.
    Eigen::Vector3d solve(const Eigen::Vector3d &b) const
    {
        if (!ok_)
            return fallback_.solve(b);
        const double y0 = b[0] / l00_;
        const double y1 = (b[1] - l10_ * y0) / l11_;
        const double y2 = (b[2] - (l20_ * y0 + l21_ * y1)) / l22_;
        const double x2 = y2 / l22_;
        const double x1 = (y1 - l21_ * x2) / l11_;
        const double x0 = (y0 - (l10_ * x1 + l20_ * x2)) / l00_;
        return Eigen::Vector3d(x0, x1, x2);
    }

    // out = A^-1 b, column by column, for a 3 x n b.
    template <typename In, typename Out> void solve(const In &b, Out &out) const
    {
        if (!ok_) {
            out = fallback_.solve(b);
            return;
        }
        out.resize(3, b.cols());
        const double r00 = 1.0 / l00_, r11 = 1.0 / l11_, r22 = 1.0 / l22_;
        for (Eigen::Index c = 0; c < b.cols(); ++c) {
            const double y0 = b(0, c) * r00;
            const double b1 = b(1, c) - y0 * l10_;
            double b2 = b(2, c) - y0 * l20_;
            const double y1 = b1 * r11;
            b2 -= y1 * l21_;
            const double y2 = b2 * r22;
            // Eigen's row sums start from 0 (which keeps a -0 product's sign out).
            const double x2 = (y2 - 0.0) * r22;
            const double x1 = (y1 - (0.0 + l21_ * x2)) * r11;
            const double x0 = (y0 - ((0.0 + l10_ * x1) + l20_ * x2)) * r00;
            out(0, c) = x0;
            out(1, c) = x1;
            out(2, c) = x2;
        }
    }

  private:
    bool ok_ = false;
    double l00_ = 1.0, l10_ = 0.0, l20_ = 0.0, l11_ = 1.0, l21_ = 0.0, l22_ = 1.0;
    Eigen::LLT<Eigen::Matrix3d> fallback_;
};

} // namespace ictus
