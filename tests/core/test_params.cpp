// The exported ranges and the table-driven setters (ictus_param_range, ictus_param_set
// on membrane_params and contact_params): the numbers are those documented in
// docs/externals.md, written out here rather than taken from the headers, and every
// setter follows the one clamp rule.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "signal_tools.hpp"

namespace
{
struct expected_range {
    int id;
    double min, max, def;
};

// docs/externals.md, the message tables of membrane~ and contact~.
const expected_range membrane_expected[] = {
    {MEMBRANE_PARAM_RADIUS, 0.01, 2.0, 0.178},   {MEMBRANE_PARAM_TENSION, 1.0, 1e5, 3000.0},
    {MEMBRANE_PARAM_DENSITY, 0.01, 20.0, 0.262}, {MEMBRANE_PARAM_MODES, 1.0, 4096.0, 128.0},
    {MEMBRANE_PARAM_T60, 0.005, 60.0, 1.0},      {MEMBRANE_PARAM_HF_DAMPING, 0.0, 1000.0, 1.0},
    {MEMBRANE_PARAM_GAIN, -1e6, 1e6, 0.16},      {MEMBRANE_PARAM_OPENNESS, 0.0, 1.0, 1.0},
    {MEMBRANE_PARAM_EDGE_DAMP, 0.0, 1e4, 0.0},   {MEMBRANE_PARAM_CASCADE, 0.0, 100.0, 0.0},
    {MEMBRANE_PARAM_VON_KARMAN, 0.0, 10.0, 0.0},
};
const expected_range contact_expected[] = {
    {CONTACT_PARAM_MASS, 1e-4, 10.0, 0.05},
    {CONTACT_PARAM_STIFFNESS, 1.0, 1e12, 1e7},
    {CONTACT_PARAM_ALPHA, 1.0, 4.0, 1.5},
    {CONTACT_PARAM_DAMPING, 0.0, 1e13, 5e6},
};
} // namespace

TEST_CASE("Exported ranges are the documented ones and new objects start at the defaults",
          "[core][params]")
{
    membrane *m = membrane_new(48000.0);
    contact *c = contact_new();
    REQUIRE(m);
    REQUIRE(c);
    for (const expected_range &e : membrane_expected) {
        INFO("membrane parameter " << e.id);
        ictus_range r = ictus_param_range(&membrane_params, m, (membrane_param)e.id);
        CHECK(r.min == Approx(e.min));
        CHECK(r.max == Approx(e.max));
        CHECK(r.def == Approx(e.def));
        CHECK(ictus_param_get(&membrane_params, m, (membrane_param)e.id) == Approx(e.def));
    }
    for (const expected_range &e : contact_expected) {
        INFO("contact parameter " << e.id);
        ictus_range r = ictus_param_range(&contact_params, nullptr, (contact_param)e.id);
        CHECK(r.min == Approx(e.min));
        CHECK(r.max == Approx(e.max));
        CHECK(r.def == Approx(e.def));
        CHECK(ictus_param_get(&contact_params, c, (contact_param)e.id) == Approx(e.def));
    }
    // The mass range is the density range times the area pi a^2, for the current radius.
    for (double a : {0.05, 0.178, 0.4}) {
        REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, a) == ICTUS_OK);
        ictus_range r = ictus_param_range(&membrane_params, m, MEMBRANE_PARAM_MASS);
        const double area = 3.141592653589793 * a * a;
        CHECK(r.min == Approx(0.01 * area));
        CHECK(r.max == Approx(20.0 * area));
        CHECK(r.def == Approx(0.262 * area));
    }
    // Unknown parameters: nothing set, an empty range.
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_COUNT, 1.0) == ICTUS_CLAMPED);
    CHECK(ictus_param_set(&contact_params, c, CONTACT_PARAM_COUNT, 1.0) == ICTUS_CLAMPED);
    ictus_range none = ictus_param_range(&membrane_params, m, MEMBRANE_PARAM_COUNT);
    CHECK((none.min == 0.0 && none.max == 0.0));
    membrane_free(m);
    contact_free(c);
}

TEST_CASE("Setters report clamping and keep the bound", "[core][params]")
{
    membrane *m = membrane_new(48000.0);
    contact *c = contact_new();
    REQUIRE(m);
    REQUIRE(c);
    for (const expected_range &e : membrane_expected) {
        const membrane_param p = (membrane_param)e.id;
        INFO("membrane parameter " << e.id);
        CHECK(ictus_param_set(&membrane_params, m, p, e.max * 10.0 + 10.0) == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&membrane_params, m, p) == Approx(e.max));
        CHECK(ictus_param_set(&membrane_params, m, p, e.min - 1.0) == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&membrane_params, m, p) == Approx(e.min));
        CHECK(ictus_param_set(&membrane_params, m, p, e.def) == ICTUS_OK);
        CHECK(ictus_param_get(&membrane_params, m, p) == Approx(e.def));
    }
    for (const expected_range &e : contact_expected) {
        const contact_param p = (contact_param)e.id;
        INFO("contact parameter " << e.id);
        CHECK(ictus_param_set(&contact_params, c, p, e.max * 10.0 + 10.0) == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&contact_params, c, p) == Approx(e.max));
        CHECK(ictus_param_set(&contact_params, c, p, e.min - 1.0) == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&contact_params, c, p) == Approx(e.min));
        CHECK(ictus_param_set(&contact_params, c, p, e.def) == ICTUS_OK);
    }
    // A mass out of range lands on the density limits; a mass in range is kept.
    REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, 0.2) == ICTUS_OK);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MASS, -2.0) == ICTUS_CLAMPED);
    CHECK(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY) == Approx(0.01));
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MASS, 1e3) == ICTUS_CLAMPED);
    CHECK(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY) == Approx(20.0));
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MASS, 0.05) == ICTUS_OK);
    CHECK(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_MASS) == Approx(0.05));
    // A fractional mode count in the range rounds to the nearest; one outside it (0.5
    // modes) is clamped and said so, as 0 is.
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 2.6) == ICTUS_OK);
    CHECK(membrane_get_modes(m) == 3);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 1.4) == ICTUS_OK);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 0.5) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 4096.4) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 4096);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 0.4) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, 1e30) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 4096);
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MODES, NAN) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 128);
    membrane_free(m);
    contact_free(c);
}

TEST_CASE("Setters follow the clamp rule on random values", "[core][params]")
{
    // Every entry of both tables: a value in range is kept and said OK; out of range it
    // becomes the nearer limit, NaN the default, and the status says ICTUS_CLAMPED.
    // The mode count is clamped, then rounds; the mass is kept through the density.
    std::mt19937_64 rng(20240611);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto value = [&]() {
        if (u01(rng) < 0.1)
            return std::nan("");
        return (u01(rng) < 0.3 ? -1.0 : 1.0) * std::pow(10.0, -6.0 + 14.0 * u01(rng));
    };
    membrane *m = membrane_new(48000.0);
    contact *c = contact_new();
    REQUIRE((m && c));
    membrane_set_modes(m, 16);
    for (int i = 0; i < 400; i++) {
        const double v = value();
        const int which = (int)(u01(rng) * 12.0);
        const bool is_membrane = which < 8;
        const ictus_param_table *t = is_membrane ? &membrane_params : &contact_params;
        void *obj = is_membrane ? (void *)m : (void *)c;
        const int id = is_membrane ? which : which - 8;
        const ictus_range r = ictus_param_range(t, obj, id);
        const bool clamped = std::isnan(v) || v < r.min || v > r.max;
        double want = std::isnan(v) ? r.def : std::fmin(std::fmax(v, r.min), r.max);
        if (id == MEMBRANE_PARAM_MODES && is_membrane)
            want = std::floor(want + 0.5);
        INFO("step " << i << " parameter " << which << " value " << v);
        REQUIRE(ictus_param_set(t, obj, id, v) == (clamped ? ICTUS_CLAMPED : ICTUS_OK));
        REQUIRE(ictus_param_get(t, obj, id) == Approx(want).epsilon(1e-12));
    }
    membrane_free(m);
    contact_free(c);
}

TEST_CASE("The mass's limits are taken as given at any radius", "[core][params]")
{
    // The mass range is the density range times pi a^2; the density a limit gives,
    // mass / (pi a^2), could round an ulp past the density's limit, and setting the
    // quoted limit then said ICTUS_CLAMPED (1 radius in 9, both ends).
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    membrane *m = membrane_new(48000.0);
    REQUIRE(m);
    membrane_set_modes(m, 4);
    int refused = 0;
    double first_radius = 0.0;
    for (int i = 0; i < 2000; i++) {
        const double a = i == 0 ? 0.01 : i == 1 ? 2.0 : 0.01 * std::pow(200.0, u01(rng));
        REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, a) == ICTUS_OK);
        const ictus_range r = ictus_param_range(&membrane_params, m, MEMBRANE_PARAM_MASS);
        for (double limit : {r.min, r.max}) {
            if (ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MASS, limit) != ICTUS_OK &&
                refused++ == 0)
                first_radius = a;
            INFO("radius " << a << " mass " << limit);
            REQUIRE(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY) >= 0.01);
            REQUIRE(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY) <= 20.0);
            REQUIRE(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_MASS) ==
                    Approx(limit).epsilon(1e-12));
        }
    }
    INFO("first refused at radius " << first_radius);
    CHECK(refused == 0);
    membrane_free(m);
}
