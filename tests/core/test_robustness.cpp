// Bad and extreme input: setters clamp (and say so), nothing is ever NaN.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "signal_tools.hpp"

namespace
{
bool all_finite(const std::vector<float> &x)
{
    for (float v : x)
        if (!std::isfinite(v))
            return false;
    return true;
}
} // namespace

TEST_CASE("Extreme legal corners stay finite", "[core][robust]")
{
    const double radius[2] = {MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX};
    const double tension[2] = {MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX};
    const double density[2] = {MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX};
    const double t60[2] = {MEMBRANE_T60_MIN, MEMBRANE_T60_MAX};
    const double hf[2] = {0.0, 1000.0};
    const double sr[2] = {MEMBRANE_SR_MIN, MEMBRANE_SR_MAX};
    int corner = 0;
    for (int bits = 0; bits < 64; bits++, corner++) {
        membrane *m = membrane_new(sr[(bits >> 5) & 1]);
        REQUIRE(m);
        membrane_set_modes(m, 12);
        CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, radius[bits & 1]) ==
              ICTUS_OK);
        CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION,
                              tension[(bits >> 1) & 1]) == ICTUS_OK);
        CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_DENSITY,
                              density[(bits >> 2) & 1]) == ICTUS_OK);
        CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, t60[(bits >> 3) & 1]) ==
              ICTUS_OK);
        CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_HF_DAMPING,
                              hf[(bits >> 4) & 1]) == ICTUS_OK);
        contact *c = contact_new();
        membrane_attach_contact(m, c);
        ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS,
                        (bits & 1) ? CONTACT_MASS_MAX : CONTACT_MASS_MIN);
        ictus_param_set(&contact_params, c, CONTACT_PARAM_STIFFNESS,
                        (bits & 2) ? CONTACT_STIFFNESS_MAX : CONTACT_STIFFNESS_MIN);
        ictus_param_set(&contact_params, c, CONTACT_PARAM_ALPHA,
                        (bits & 4) ? CONTACT_ALPHA_MAX : CONTACT_ALPHA_MIN);
        ictus_param_set(&contact_params, c, CONTACT_PARAM_DAMPING,
                        (bits & 8) ? CONTACT_DAMPING_MAX : CONTACT_DAMPING_MIN);
        contact_hit(c, (bits & 16) ? CONTACT_VELOCITY_MAX : 0.01, (bits & 8) ? 1.0 : 0.0, 0.0, 3);
        membrane_strike(m, 0.5, 0.0, 1e3, 5);
        std::vector<float> fin(256, 1e6f);
        std::vector<float> o0(256), o1(256);
        float *outs[2] = {o0.data(), o1.data()};
        for (int b = 0; b < 8; b++) {
            membrane_process(m, fin.data(), outs, 256);
            INFO("corner " << bits << " block " << b);
            REQUIRE(all_finite(o0));
            REQUIRE(all_finite(o1));
        }
        CHECK(std::isfinite(membrane_energy(m)));
        CHECK(std::isfinite(contact_stick_velocity(c)));
        membrane_free(m);
        contact_free(c);
    }
}

TEST_CASE("Mode count clamps to [1, 4096]", "[core][robust]")
{
    membrane *m = membrane_new(48000.0);
    CHECK(membrane_set_modes(m, 0) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 1);
    CHECK(membrane_set_modes(m, 1000000) == ICTUS_CLAMPED);
    CHECK(membrane_get_modes(m) == 4096);
    // 4096 modes sorted by frequency and ringing correctly at the top end too.
    double f_prev = 0.0;
    const double hz_per_j =
        std::sqrt(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_TENSION) /
                  ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY)) /
        (2.0 * M_PI * ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_RADIUS));
    int found = 0;
    for (int k = 0; k < 4096; k++) {
        double f;
        int mm, nn, s;
        REQUIRE(membrane_get_mode(m, k, &f, nullptr, &mm, &nn, &s));
        REQUIRE(f >= f_prev);
        f_prev = f;
        // A high-order mode of the table against scipy's jn_zeros(50, 3)[-1].
        if (mm == 50 && nn == 3) {
            CHECK(f / hz_per_j == Approx(67.69740841076478).epsilon(1e-12));
            found++;
        }
    }
    CHECK(found == 2); // cos and sin partner
    membrane_strike(m, 0.3, 0.0, 0.01, 0);
    REQUIRE(all_finite(tools::render(m, 1024)));
    membrane_free(m);
}

TEST_CASE("Setter fuzz: random doubles clamp and never produce NaN", "[core][robust]")
{
    std::mt19937_64 rng(99);
    const double specials[] = {std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(),
                               -std::numeric_limits<double>::infinity(),
                               1e308,
                               -1e308,
                               0.0,
                               -0.0,
                               -1.0,
                               1e-308};
    std::uniform_int_distribution<int> pick(0, 12);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto value = [&]() {
        if (u01(rng) < 0.4)
            return specials[rng() % (sizeof specials / sizeof specials[0])];
        return (u01(rng) < 0.5 ? -1.0 : 1.0) * std::pow(10.0, -12.0 + 24.0 * u01(rng));
    };
    auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
    membrane *m = membrane_new(48000.0);
    membrane_set_modes(m, 16);
    contact *c = contact_new();
    membrane_attach_contact(m, c);
    std::vector<float> o0(64), o1(64);
    float *outs[2] = {o0.data(), o1.data()};
    for (int i = 0; i < 3000; i++) {
        double v = value();
        ictus_status s = ICTUS_OK;
        bool legal = false;
        switch (pick(rng)) {
        case 0:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, v);
            legal = in(v, MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX);
            CHECK(in(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_RADIUS),
                     MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX));
            break;
        case 1:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION, v);
            legal = in(v, MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX);
            CHECK(in(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_TENSION),
                     MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX));
            break;
        case 2:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_DENSITY, v);
            legal = in(v, MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX);
            CHECK(in(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY),
                     MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX));
            break;
        case 3:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, v);
            legal = in(v, MEMBRANE_T60_MIN, MEMBRANE_T60_MAX);
            CHECK(in(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_T60), MEMBRANE_T60_MIN,
                     MEMBRANE_T60_MAX));
            break;
        case 4:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_HF_DAMPING, v);
            legal = in(v, 0.0, 1000.0);
            break;
        case 5:
            s = membrane_set_sample_rate(m, v);
            legal = in(v, MEMBRANE_SR_MIN, MEMBRANE_SR_MAX);
            break;
        case 6:
            s = ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_MASS, v);
            legal = true; // legal iff the implied density is: checked below
            CHECK(in(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY),
                     MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX));
            break;
        case 7:
            s = membrane_set_pickup(m, 0, v, value());
            legal = true;
            break;
        case 8:
            s = membrane_strike(m, value(), value(), v, 0);
            legal = true;
            break;
        case 9:
            s = ictus_param_set(&contact_params, c, CONTACT_PARAM_STIFFNESS, v);
            legal = in(v, CONTACT_STIFFNESS_MIN, CONTACT_STIFFNESS_MAX);
            break;
        case 10:
            s = ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, v);
            legal = in(v, CONTACT_MASS_MIN, CONTACT_MASS_MAX);
            break;
        case 11:
            s = ictus_param_set(&contact_params, c, CONTACT_PARAM_ALPHA, v);
            legal = in(v, CONTACT_ALPHA_MIN, CONTACT_ALPHA_MAX);
            break;
        case 12:
            s = contact_hit(c, v, value(), value(), 0);
            legal = true;
            break;
        }
        if (!legal)
            CHECK(s == ICTUS_CLAMPED);
        if (std::isnan(v) || std::isinf(v))
            CHECK(s == ICTUS_CLAMPED);
        membrane_process(m, nullptr, outs, 64);
        INFO("step " << i);
        REQUIRE(all_finite(o0));
        REQUIRE(all_finite(o1));
    }
    CHECK(std::isfinite(membrane_energy(m)));
    membrane_free(m);
    contact_free(c);
}

extern "C" void membrane_use_generic_kernel_(membrane *m); // membrane_internal.h

TEST_CASE("A force beyond MEMBRANE_FORCE_MAX is clamped to it, in either kernel", "[core][robust]")
{
    // On a linear head (tensionmod 0) the force input is linear in the force: fed
    // +-1e30 N (finite, absurd) for 10 ms, the pickups must be those of 1 N times the
    // cap (1e12 N, a contact's cap) with its sign, not 1e30 times, from the portable
    // kernel as from the selected one. On the default (Mylar) head, whose pitch
    // follows its energy, 1e30 N must sound as 1e12 N does, sample for sample.
    REQUIRE(MEMBRANE_FORCE_MAX == 1.0e12);
    auto run = [](float force, bool generic, bool linear = true) {
        membrane *m = membrane_new(48000.0);
        if (generic)
            membrane_use_generic_kernel_(m);
        membrane_set_modes(m, 100);
        if (linear)
            ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION_MOD, 0.0);
        membrane_set_strike_point(m, 0.42, 75.0);
        std::vector<float> fin(64), o0(64), o1(64), x;
        float *outs[2] = {o0.data(), o1.data()};
        for (int b = 0; b < 60; b++) { // 80 ms: 10 ms pushed, then ringing
            for (int j = 0; j < 64; j++)
                fin[j] = b * 64 + j < 480 ? force : 0.0f; // 480 samples: 10 ms
            membrane_process(m, fin.data(), outs, 64);
            x.insert(x.end(), o0.begin(), o0.end());
            x.insert(x.end(), o1.begin(), o1.end());
        }
        membrane_free(m);
        return x;
    };
    for (bool generic : {false, true}) {
        const std::vector<float> unit = run(1.0f, generic);
        double unit_peak = 0.0;
        for (float v : unit)
            unit_peak = std::max(unit_peak, (double)std::fabs(v));
        REQUIRE(unit_peak > 0.0);
        for (float sign : {1.0f, -1.0f}) {
            const std::vector<float> huge = run(sign * 1e30f, generic);
            REQUIRE(all_finite(huge));
            double diff = 0.0, peak = 0.0;
            for (size_t i = 0; i < huge.size(); i++) {
                const double want = sign * MEMBRANE_FORCE_MAX * (double)unit[i];
                diff = std::max(diff, std::fabs((double)huge[i] - want));
                peak = std::max(peak, std::fabs((double)huge[i]));
            }
            INFO((generic ? "portable" : "selected")
                 << " kernel, force " << sign * 1e30 << " N: peak " << peak
                 << ", 1 N's peak x 1e12 " << unit_peak * MEMBRANE_FORCE_MAX
                 << ", largest difference " << diff);
            CHECK(diff <= 1e-4 * unit_peak * MEMBRANE_FORCE_MAX);
            CHECK(peak <= 1.0001 * unit_peak * MEMBRANE_FORCE_MAX);
            const std::vector<float> mylar = run(sign * 1e30f, generic, false);
            const std::vector<float> at_cap = run(sign * 1e12f, generic, false);
            REQUIRE(all_finite(mylar));
            CHECK(mylar == at_cap);
        }
    }
}
