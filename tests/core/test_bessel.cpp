// Bessel zeros and values against an independent table (scipy.special 1.10,
// jn_zeros / jv, pasted here; not computed by the code under test).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

extern "C" {
#include "bessel_internal.h"
#include "membrane.h"
}

namespace
{
struct zero_row {
    int m, n;
    double j;
};
const zero_row scipy_zeros[] = {
    {0, 1, 2.404825557695773},   {0, 2, 5.520078110286311},    {0, 3, 8.653727912911013},
    {0, 4, 11.791534439014281},  {0, 5, 14.930917708487787},   {1, 1, 3.8317059702075125},
    {50, 3, 67.69740841076478},  {120, 2, 136.64311236744743}, {10, 40, 140.23046526883238},
    {200, 1, 211.0291665105547}, {3, 300, 946.400164112479},
};
struct value_row {
    int m;
    double x, j;
};
const value_row scipy_values[] = {
    {0, 1.0, 0.7651976865579666},        {5, 10.0, -0.23406152818679354},
    {100, 50.0, 1.1159273690838103e-21}, {100, 120.0, 0.0757371791300129},
    {30, 1000.0, -0.020271896981075847}, {200, 300.0, -0.019369872600835406},
    {150, 140.0, 0.0043110999456729086},
};
} // namespace

TEST_CASE("Bessel zeros match scipy to 1e-12 relative", "[core][bessel]")
{
    for (const auto &row : scipy_zeros) {
        INFO("j_{" << row.m << "," << row.n << "}");
        double j = ictus_bessel_zero(row.m, row.n);
        CHECK(std::fabs(j - row.j) <= 1e-12 * row.j);
    }
}

TEST_CASE("Bessel J_m(x) matches scipy", "[core][bessel]")
{
    for (const auto &row : scipy_values) {
        INFO("J_" << row.m << "(" << row.x << ")");
        double v = ictus_bessel_j(row.m, row.x);
        // Relative accuracy where J is O(1/sqrt(x)); deep in the evanescent region
        // (J ~ 1e-21) relative accuracy of the tiny value itself.
        CHECK(std::fabs(v - row.j) <= 1e-11 * std::fabs(row.j) + 1e-14 / std::sqrt(row.x));
    }
}

TEST_CASE("the integral of J_m from 0 matches quadrature and the closed form for m = 1",
          "[core][bessel]")
{
    // Independent of the recurrence: composite Simpson on std::cyl_bessel_j (C++17),
    // 40 panels per unit of x, and int_0^x J_1 = 1 - J_0(x) (Abramowitz & Stegun
    // 11.1.6 with nu = 0). Seeded draws of m and x, either sign.
    std::mt19937 rng(20261201);
    std::uniform_int_distribution<int> pick_m(0, 60);
    std::uniform_real_distribution<double> pick_x(-120.0, 120.0);
    for (int i = 0; i < 60; i++) {
        const int m = i < 5 ? 1 : pick_m(rng);
        const double x = pick_x(rng);
        const int panels = 2 * (int)(20.0 * std::fabs(x) + 10.0);
        const double h = std::fabs(x) / panels;
        double simpson = 0.0;
        for (int k = 0; k <= panels; k++) {
            const double f = std::cyl_bessel_j((double)m, k * h);
            simpson += (k == 0 || k == panels ? 1.0 : (k % 2 ? 4.0 : 2.0)) * f;
        }
        simpson *= h / 3.0;
        if (x < 0.0 && m % 2 == 0) // J_m even: its integral from 0 is odd in x
            simpson = -simpson;
        const double got = ictus_bessel_j_integral(m, x);
        INFO("m " << m << ", x " << x << ": recurrence " << got << ", Simpson " << simpson);
        CHECK(std::fabs(got - simpson) <= 1e-9);
        if (m == 1)
            CHECK(std::fabs(got - (1.0 - std::cyl_bessel_j(0.0, std::fabs(x)))) <= 1e-12);
    }
    CHECK(ictus_bessel_j_integral(3, 0.0) == 0.0);
    CHECK(ictus_bessel_j_integral(0, 1e-8) == Approx(1e-8).epsilon(1e-12));
}
