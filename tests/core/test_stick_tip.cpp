// The stick tips and their law (stick_tip.h): the table against its material
// constants, the law's contact time against Hertz's on a rigid target
// (integrated here, independently of contact.c), the speed exponent, and the
// tips on the default membrane.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "contact.h"
#include "ictus_param.h"
#include "membrane.h"
#include "stick_tip.h"

namespace
{
// Contact time (s) of a mass m landing at v on a rigid target through the law,
// by RK4 on m x'' = -F(x, x') with step dt; the release instant interpolated.
double law_contact_time(const stick_tip &tip, double lambda, double m, double v, double dt)
{
    auto acc = [&](double x, double xd) {
        return -stick_tip_force(tip.stiffness, tip.alpha, lambda, x, xd) / m;
    };
    double x = 0.0, xd = v, t = 0.0;
    for (long i = 0; i < 100000000L; i++) {
        double k1x = xd, k1v = acc(x, xd);
        double k2x = xd + 0.5 * dt * k1v, k2v = acc(x + 0.5 * dt * k1x, xd + 0.5 * dt * k1v);
        double k3x = xd + 0.5 * dt * k2v, k3v = acc(x + 0.5 * dt * k2x, xd + 0.5 * dt * k2v);
        double k4x = xd + dt * k3v, k4v = acc(x + dt * k3x, xd + dt * k3v);
        double x1 = x + dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
        double v1 = xd + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
        if (x1 < 0.0 && i > 0)
            return t + dt * x / (x - x1);
        x = x1;
        xd = v1;
        t += dt;
    }
    return -1.0;
}

// Hertz's contact time: tau = 2 (x_max / v) int_0^1 du / sqrt(1 - u^(a+1)),
// x_max = ((a+1) m v^2 / (2k))^(1/(a+1)); the integral by the Beta function,
// int_0^1 (1 - u^n)^(-1/2) du = Gamma(1/n) Gamma(1/2) / (n Gamma(1/n + 1/2)), n = a+1.
double hertz_tau(double m, double k, double a, double v)
{
    double n = a + 1.0;
    double xmax = std::pow(n * m * v * v / (2.0 * k), 1.0 / n);
    double integral = std::tgamma(1.0 / n) * std::tgamma(0.5) / (n * std::tgamma(1.0 / n + 0.5));
    return 2.0 * xmax / v * integral;
}

double loglog_slope(const std::vector<double> &x, const std::vector<double> &y)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, n = (double)x.size();
    for (size_t i = 0; i < x.size(); i++) {
        double lx = std::log(x[i]), ly = std::log(y[i]);
        sx += lx;
        sy += ly;
        sxx += lx * lx;
        sxy += lx * ly;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

const std::vector<double> kSpeeds = {0.5, 1.0, 2.0, 5.0, 10.0};
} // namespace

TEST_CASE("Stick tips: the table follows its sources", "[core][stick_tip]")
{
    const stick_tip *wood = stick_tip_find("wood"), *nylon = stick_tip_find("nylon"),
                    *felt = stick_tip_find("felt");
    REQUIRE(wood);
    REQUIRE(nylon);
    REQUIRE(felt);
    CHECK(stick_tip_find("steel") == nullptr);
    CHECK(stick_tip_find("Wood") == wood); // any casing
    CHECK(stick_tip_find("NYLON") == nylon);
    CHECK(stick_tip_find("fElT") == felt);
    CHECK(stick_tip_find("woo") == nullptr);
    CHECK(stick_tip_find(nullptr) == nullptr);
    // Hertz, sphere of 7 mm on a Mylar half-space: 4.73e8 and 2.34e8 N/m^1.5
    // (Johnson eq. 4.22, computed by hand in docs/sound.md).
    CHECK(wood->alpha == 1.5);
    CHECK(nylon->alpha == 1.5);
    CHECK(wood->stiffness == Approx(4.733e8).epsilon(0.005));
    CHECK(nylon->stiffness == Approx(2.337e8).epsilon(0.005));
    CHECK(wood->stiffness ==
          Approx(stick_tip_hertz_k(STICK_TIP_HICKORY_E, STICK_TIP_HICKORY_NU, STICK_TIP_MYLAR_E,
                                   STICK_TIP_MYLAR_NU, STICK_TIP_RADIUS_M))
              .epsilon(0.005));
    // Chaigne & Askenfelt (1994), hammer felt: p 2.5, K 4.5e9 N/m^2.5.
    CHECK(felt->alpha == 2.5);
    CHECK(felt->stiffness == 4.5e9);
}

TEST_CASE("Stick tip law on a rigid target: Hertz's contact time and exponent", "[core][stick_tip]")
{
    // alpha 1.5: tau = 3.218 (m/k)^(2/5) v^(-1/5) (the Beta-function constant,
    // 2 (5/4)^(2/5) sqrt(pi) Gamma(2/5) / (5/2 Gamma(9/10)) = 3.2180).
    CHECK(hertz_tau(1.0, 1.0, 1.5, 1.0) == Approx(3.218).epsilon(2e-4));
    for (const stick_tip &tip : stick_tips) {
        std::vector<double> tau;
        for (double v : kSpeeds) {
            double m = tip.mass_kg;
            double theory = hertz_tau(m, tip.stiffness, tip.alpha, v);
            double t = law_contact_time(tip, 0.0, m, v, theory / 20000.0);
            INFO(tip.name << " at " << v << " m/s: law " << t * 1e3 << " ms, Hertz " << theory * 1e3
                          << " ms");
            CHECK(t == Approx(theory).epsilon(1e-4));
            tau.push_back(t);
        }
        // tau ~ v^(-(alpha-1)/(alpha+1)): -0.2 for alpha 1.5, -0.43 for 2.5.
        CHECK(loglog_slope(kSpeeds, tau) ==
              Approx(-(tip.alpha - 1.0) / (tip.alpha + 1.0)).margin(1e-3));
    }
}

TEST_CASE("contact~'s core plays the same law as stick_tip_force", "[core][stick_tip]")
{
    // The rigid-target stroke of contact.c (its energy-consistent discretisation at
    // 384 kHz) against the law integrated here, damping included.
    for (const stick_tip &tip : stick_tips) {
        contact *c = contact_new();
        REQUIRE(contact_set_tip(c, tip.name) == ICTUS_OK);
        ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, tip.mass_kg);
        CHECK(ictus_param_get(&contact_params, c, CONTACT_PARAM_ALPHA) == tip.alpha);
        CHECK(ictus_param_get(&contact_params, c, CONTACT_PARAM_STIFFNESS) == tip.stiffness);
        for (double v : {0.5, 2.0}) {
            double law = law_contact_time(tip, tip.mu * tip.stiffness, tip.mass_kg, v, 1e-8);
            contact_report r{};
            REQUIRE(contact_simulate_rigid(c, v, 384000.0, 1.0, &r) == 1);
            INFO(tip.name << " at " << v << " m/s");
            CHECK(r.duration_ms == Approx(law * 1e3).epsilon(0.01));
        }
        CHECK(contact_set_tip(c, "granite") == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&contact_params, c, CONTACT_PARAM_ALPHA) == tip.alpha);
        contact_free(c);
    }
}

TEST_CASE("Stick tips on the default head: a softer tip lasts longer", "[core][stick_tip]")
{
    // Two springs in series, the head and the tip: the tip's compliance adds to the
    // head's, so felt > nylon > wood at every speed, and the duration never
    // rises with speed (the tip stiffens with force, the head is linear: no
    // tension modulation here, and the contact's stretching is off in the core).
    membrane *m = membrane_new(48000.0);
    REQUIRE(m);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION_MOD, 0.0);
    std::vector<float> o0(64), o1(64);
    float *outs[2] = {o0.data(), o1.data()};
    std::vector<std::vector<double>> d(STICK_TIP_COUNT);
    for (int t = 0; t < STICK_TIP_COUNT; t++) {
        contact *c = contact_new();
        REQUIRE(membrane_attach_contact(m, c) == ICTUS_OK);
        REQUIRE(contact_set_tip(c, stick_tips[t].name) == ICTUS_OK);
        for (double v : kSpeeds) {
            membrane_clear(m);
            contact_hit(c, v, 0.34, 0.0, 0);
            contact_report r{};
            bool done = false;
            for (int b = 0; b < 400 && !done; b++) {
                membrane_process(m, nullptr, outs, 64);
                done = contact_take_report(c, &r) == 1;
            }
            REQUIRE(done);
            d[t].push_back(r.duration_ms);
        }
        membrane_detach_contact(m, c);
        contact_free(c);
        double slope = loglog_slope(kSpeeds, d[t]);
        WARN(stick_tips[t].name << ": duration " << d[t].front() << " .. " << d[t].back()
                                << " ms over 0.5..10 m/s, log-log slope " << slope);
        for (size_t i = 1; i < d[t].size(); i++)
            CHECK(d[t][i] <= d[t][i - 1] * (1.0 + 1e-6));
    }
    for (size_t i = 0; i < kSpeeds.size(); i++) {
        CHECK(d[2][i] > d[1][i]);
        CHECK(d[1][i] > d[0][i]);
    }
    membrane_free(m);
}
