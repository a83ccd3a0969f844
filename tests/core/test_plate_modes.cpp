// The free-edge circular plate's modes (plate_modes.h) against independent numbers:
// the published frequency parameters (A. W. Leissa, Vibration of Plates, NASA SP-160,
// 1969, table 2.5 for nu = 0.33, lambda^2 to 3-4 digits; also in R. D. Blevins,
// Formulas for Natural Frequency and Mode Shape, table 11-1), a second solver of the
// same conditions (scipy.special jv/iv/jvp/ivp and brentq, values pasted here), and
// the orthogonality that only the right edge conditions give.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <random>

extern "C" {
#include "plate_modes.h"
}

namespace
{
struct table_row {
    int m, s;
    double lambda2;
};
// Leissa's table (m nodal diameters, s nodal circles), nu = 0.33.
const table_row leissa[] = {
    {2, 0, 5.253}, {0, 1, 9.084}, {3, 0, 12.23}, {1, 1, 20.52}, {4, 0, 21.6},
    {5, 0, 33.1},  {2, 1, 35.25}, {0, 2, 38.55}, {3, 1, 52.91},
};
struct root_row {
    int m, s;
    double lambda;
};
// scipy: brentq on the determinant of the two free-edge conditions, to 1e-15.
const root_row scipy_roots[] = {
    {2, 0, 2.29391302369926}, {0, 1, 3.01146121704833}, {3, 0, 3.49912764242092},
    {1, 1, 4.52913754545791}, {4, 0, 4.63974322730695}, {2, 1, 5.93654113120492},
    {0, 2, 6.20539834049313}, {10, 3, 23.051143197066}, {25, 5, 48.5899854558155},
    {0, 12, 37.684897726518},
};
struct ive_row {
    int m;
    double x, value;
};
const ive_row scipy_ive[] = {
    {0, 1.0, 0.46575960759364038},      {3, 10.0, 0.079830361029840521},
    {20, 50.0, 0.0010496272879428204},  {1, 0.3, 0.11237756063983882},
    {40, 69.0, 5.5428299376450871e-07}, {0, 69.0, 0.048114732441320335},
};

double simpson(const plate_mode &a, const plate_mode &b, int n)
{
    double sum = 0.0;
    for (int k = 0; k <= n; k++) {
        const double r = double(k) / n, w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        sum += w * plate_mode_radial(&a, r) * plate_mode_radial(&b, r) * r;
    }
    return sum / (3.0 * n);
}
} // namespace

TEST_CASE("plate: e^-x I_m(x) matches scipy's ive", "[core][plate]")
{
    for (const auto &row : scipy_ive) {
        INFO("I_" << row.m << "(" << row.x << ")");
        CHECK(std::fabs(ictus_bessel_i_scaled(row.m, row.x) - row.value) <= 1e-12 * row.value);
    }
}

TEST_CASE("plate: free-edge frequency parameters match Leissa's table and a second solver",
          "[core][plate]")
{
    for (const auto &row : leissa) {
        INFO("(" << row.m << "," << row.s << ")");
        const double l = plate_free_lambda(row.m, row.s, 0.33);
        // the table's own precision: 3-4 digits (its sources predate exact roots)
        CHECK(std::fabs(l * l - row.lambda2) <= 0.005 * row.lambda2);
    }
    for (const auto &row : scipy_roots) {
        INFO("(" << row.m << "," << row.s << ")");
        CHECK(std::fabs(plate_free_lambda(row.m, row.s, 0.33) - row.lambda) <= 1e-10 * row.lambda);
    }
    CHECK(plate_free_lambda(0, 0, 0.33) == 0.0); // rigid-body: not a mode
    CHECK(plate_free_lambda(1, 0, 0.33) == 0.0);
    CHECK(plate_free_lambda(2, 0, 0.7) == 0.0); // nu out of range
}

TEST_CASE("plate: the mode list is sorted, complete and its shapes orthonormal", "[core][plate]")
{
    plate_mode *modes = nullptr;
    const int n = plate_free_modes_below(40.0, 0.33, &modes);
    REQUIRE(n > 50);
    for (int k = 1; k < n; k++)
        CHECK(modes[k].lambda >= modes[k - 1].lambda);
    // each listed (m, s) is the one plate_free_lambda finds, and the next root of that
    // order lies above the limit (nothing skipped)
    for (int k = 0; k < n; k++) {
        INFO("mode " << k << " (" << modes[k].m << "," << modes[k].s << ")");
        CHECK(std::fabs(modes[k].lambda - plate_free_lambda(modes[k].m, modes[k].s, 0.33)) <=
              1e-12 * modes[k].lambda);
    }
    for (int m = 0; m < 40; m++) {
        int top = -1;
        for (int k = 0; k < n; k++)
            if (modes[k].m == m && modes[k].s > top)
                top = modes[k].s;
        const int next = top < 0 ? (m <= 1 ? 1 : 0) : top + 1;
        INFO("order " << m);
        CHECK(plate_free_lambda(m, next, 0.33) >= 40.0);
    }
    // Orthonormal over the disc (radial integral times pi, or 2 pi for m = 0), for
    // seeded random pairs of one order: eigenfunctions of the free plate are
    // orthogonal only with the right edge conditions.
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pick(0, n - 1);
    int pairs = 0;
    for (int tries = 0; tries < 4000 && pairs < 40; tries++) {
        const plate_mode &a = modes[pick(rng)], &b = modes[pick(rng)];
        if (a.m != b.m)
            continue;
        pairs++;
        const double ang = a.m ? M_PI : 2.0 * M_PI;
        const double ip = ang * simpson(a, b, 40000);
        INFO("(" << a.m << "," << a.s << ") . (" << b.m << "," << b.s << ") = " << ip);
        CHECK(std::fabs(ip - (a.s == b.s ? 1.0 : 0.0)) <= 1e-7);
    }
    CHECK(pairs >= 20);
    std::free(modes);
}
