// The exported ranges and the table-driven setters (membrane_param_range,
// membrane_set_param, contact_param_range, ...): the numbers are those documented in
// docs/externals.md, written out here rather than taken from the headers, and the
// table-driven path behaves exactly like the named setters.
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
    {MEMBRANE_PARAM_GAIN, -1e6, 1e6, 0.16},
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
        ictus_range r = membrane_param_range(m, (membrane_param)e.id);
        CHECK(r.min == Approx(e.min));
        CHECK(r.max == Approx(e.max));
        CHECK(r.def == Approx(e.def));
        CHECK(membrane_get_param(m, (membrane_param)e.id) == Approx(e.def));
    }
    for (const expected_range &e : contact_expected) {
        INFO("contact parameter " << e.id);
        ictus_range r = contact_param_range((contact_param)e.id);
        CHECK(r.min == Approx(e.min));
        CHECK(r.max == Approx(e.max));
        CHECK(r.def == Approx(e.def));
        CHECK(contact_get_param(c, (contact_param)e.id) == Approx(e.def));
    }
    // The mass range is the density range times the area pi a^2, for the current radius.
    for (double a : {0.05, 0.178, 0.4}) {
        REQUIRE(membrane_set_radius(m, a) == ICTUS_OK);
        ictus_range r = membrane_param_range(m, MEMBRANE_PARAM_MASS);
        const double area = 3.141592653589793 * a * a;
        CHECK(r.min == Approx(0.01 * area));
        CHECK(r.max == Approx(20.0 * area));
        CHECK(r.def == Approx(0.262 * area));
    }
    // Unknown parameters: nothing set, an empty range.
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_COUNT, 1.0) == ICTUS_CLAMPED);
    CHECK(contact_set_param(c, CONTACT_PARAM_COUNT, 1.0) == ICTUS_CLAMPED);
    ictus_range none = membrane_param_range(m, MEMBRANE_PARAM_COUNT);
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
        CHECK(membrane_set_param(m, p, e.max * 10.0 + 10.0) == ICTUS_CLAMPED);
        CHECK(membrane_get_param(m, p) == Approx(e.max));
        CHECK(membrane_set_param(m, p, e.min - 1.0) == ICTUS_CLAMPED);
        CHECK(membrane_get_param(m, p) == Approx(e.min));
        CHECK(membrane_set_param(m, p, e.def) == ICTUS_OK);
        CHECK(membrane_get_param(m, p) == Approx(e.def));
    }
    for (const expected_range &e : contact_expected) {
        const contact_param p = (contact_param)e.id;
        INFO("contact parameter " << e.id);
        CHECK(contact_set_param(c, p, e.max * 10.0 + 10.0) == ICTUS_CLAMPED);
        CHECK(contact_get_param(c, p) == Approx(e.max));
        CHECK(contact_set_param(c, p, e.min - 1.0) == ICTUS_CLAMPED);
        CHECK(contact_get_param(c, p) == Approx(e.min));
        CHECK(contact_set_param(c, p, e.def) == ICTUS_OK);
    }
    // A mass out of range lands on the density limits; a mass in range is kept.
    REQUIRE(membrane_set_radius(m, 0.2) == ICTUS_OK);
    CHECK(membrane_set_mass(m, -2.0) == ICTUS_CLAMPED);
    CHECK(membrane_get_density(m) == Approx(0.01));
    CHECK(membrane_set_mass(m, 1e3) == ICTUS_CLAMPED);
    CHECK(membrane_get_density(m) == Approx(20.0));
    CHECK(membrane_set_mass(m, 0.05) == ICTUS_OK);
    CHECK(membrane_get_mass(m) == Approx(0.05));
    // A fractional mode count rounds to the nearest; clamping is judged after rounding.
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_MODES, 2.6) == ICTUS_OK);
    CHECK(membrane_get_modes(m) == 3);
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_MODES, 0.5) == ICTUS_OK);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_MODES, 0.4) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_MODES, 1e30) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 4096);
    CHECK(membrane_set_param(m, MEMBRANE_PARAM_MODES, NAN) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 128);
    membrane_free(m);
    contact_free(c);
}

TEST_CASE("Table-driven and named setters agree on random values", "[core][params]")
{
    std::mt19937_64 rng(20240611);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto value = [&]() {
        if (u01(rng) < 0.1)
            return std::nan("");
        return (u01(rng) < 0.3 ? -1.0 : 1.0) * std::pow(10.0, -6.0 + 14.0 * u01(rng));
    };
    membrane *a = membrane_new(48000.0), *b = membrane_new(48000.0);
    contact *ca = contact_new(), *cb = contact_new();
    REQUIRE((a && b && ca && cb));
    membrane_set_modes(a, 16);
    membrane_set_modes(b, 16);
    for (int i = 0; i < 400; i++) {
        const double v = value();
        const int which = (int)(u01(rng) * 12.0);
        ictus_status sa, sb;
        double ga, gb;
        if (which < 8) {
            const membrane_param p = (membrane_param)which;
            sa = membrane_set_param(a, p, v);
            switch (p) {
            case MEMBRANE_PARAM_RADIUS:
                sb = membrane_set_radius(b, v);
                break;
            case MEMBRANE_PARAM_TENSION:
                sb = membrane_set_tension(b, v);
                break;
            case MEMBRANE_PARAM_DENSITY:
                sb = membrane_set_density(b, v);
                break;
            case MEMBRANE_PARAM_MASS:
                sb = membrane_set_mass(b, v);
                break;
            case MEMBRANE_PARAM_T60:
                sb = membrane_set_t60(b, v);
                break;
            case MEMBRANE_PARAM_HF_DAMPING:
                sb = membrane_set_hf_damping(b, v);
                break;
            case MEMBRANE_PARAM_GAIN:
                sb = membrane_set_output_gain(b, v);
                break;
            default: { // modes: the nearest count, clamped like the named setter's int
                double n = std::isnan(v) ? 128.0 : std::floor(v + 0.5);
                n = std::fmin(std::fmax(n, 1.0), 4096.0);
                sb = membrane_set_modes(b, (int)n);
                if (std::isnan(v) || n != std::floor(v + 0.5))
                    sb = ICTUS_CLAMPED;
                break;
            }
            }
            ga = membrane_get_param(a, p);
            gb = membrane_get_param(b, p);
        } else {
            const contact_param p = (contact_param)(which - 8);
            sa = contact_set_param(ca, p, v);
            switch (p) {
            case CONTACT_PARAM_MASS:
                sb = contact_set_mass(cb, v);
                break;
            case CONTACT_PARAM_STIFFNESS:
                sb = contact_set_stiffness(cb, v);
                break;
            case CONTACT_PARAM_ALPHA:
                sb = contact_set_alpha(cb, v);
                break;
            default:
                sb = contact_set_damping(cb, v);
                break;
            }
            ga = contact_get_param(ca, p);
            gb = contact_get_param(cb, p);
        }
        INFO("step " << i << " parameter " << which << " value " << v);
        REQUIRE(sa == sb);
        REQUIRE(ga == gb);
    }
    membrane_free(a);
    membrane_free(b);
    contact_free(ca);
    contact_free(cb);
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
        REQUIRE(membrane_set_radius(m, a) == ICTUS_OK);
        const ictus_range r = membrane_param_range(m, MEMBRANE_PARAM_MASS);
        for (double limit : {r.min, r.max}) {
            if (membrane_set_mass(m, limit) != ICTUS_OK && refused++ == 0)
                first_radius = a;
            INFO("radius " << a << " mass " << limit);
            REQUIRE(membrane_get_density(m) >= 0.01);
            REQUIRE(membrane_get_density(m) <= 20.0);
            REQUIRE(membrane_get_mass(m) == Approx(limit).epsilon(1e-12));
        }
    }
    INFO("first refused at radius " << first_radius);
    CHECK(refused == 0);
    membrane_free(m);
}
