// The output bound of docs/externals.md ("Output bound"): the contact is passive, so
// the head never holds more energy than what went in, and a pickup can read no more
// than that energy allows. Tested on seeded random members of the whole parameter
// space (limits, values clamped to them, everything in between), and on the corners
// where the contact solve once broke passivity (a 10 kg stick on a 3 mg head peaked
// at 2.5e4 with lambda 0, at 1e13 with lambda 1e13).
//
// The bound, per combination: a mode k's energy-normalised state (q_k, p_k) holds
// E = sum (q_k^2 + p_k^2) / 2, a pickup reads
//     out = gain * sum psi_k(pickup) p_k / sqrt(sigma a^2)
// (psi_k: the mass-normalised shapes), so by Cauchy-Schwarz
//     |out| <= |gain| * ||psi(pickup)|| * sqrt(2 E / (sigma a^2)),
// ||psi||^2 = sum psi_k^2 over the modes that ring. A stick brings E = m v^2 / 2; a
// strike of impulse J moves the state by at most J ||psi(strike)|| / sqrt(sigma a^2)
// (the midpoint step's input gains are below 1), and energies add as norms:
//     |out| <= |gain| ||psi(pickup)|| (sqrt(m) v + J ||psi(strike)|| / sqrt(sigma a^2))
//              / sqrt(sigma a^2).
// The modes, their shapes and which of them ring are computed here from
// std::cyl_bessel_j, not taken from the core.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "signal_tools.hpp"

namespace
{
struct ref_mode {
    double j; // zero of J_m
    int m;
    bool sin;
    double norm; // sqrt(eps_m / pi) / |J_{m+1}(j)|: psi = J_m(j r/a) {cos, sin}(m theta) norm
};

// Every mode with j below 2 sqrt(count) + 8 (Weyl: about count of them, and more),
// sorted by j: zeros of J_m bracketed on a 0.1 grid (zeros of one order are more
// than 2.4 apart) and bisected to double precision.
std::vector<ref_mode> reference_modes(int count)
{
    const double x_max = 2.0 * std::sqrt((double)count) + 8.0;
    std::vector<ref_mode> modes;
    for (int m = 0; m < x_max; m++) {
        double x0 = m + 1e-9, f0 = std::cyl_bessel_j(m, x0);
        for (double x1 = x0 + 0.1; x1 < x_max; x0 = x1, x1 += 0.1) {
            double f1 = std::cyl_bessel_j(m, x1);
            if ((f0 < 0.0) != (f1 < 0.0)) {
                double lo = x0, hi = x1, flo = f0;
                for (int i = 0; i < 60; i++) {
                    double mid = 0.5 * (lo + hi), fm = std::cyl_bessel_j(m, mid);
                    if ((fm < 0.0) == (flo < 0.0))
                        lo = mid, flo = fm;
                    else
                        hi = mid;
                }
                const double j = 0.5 * (lo + hi);
                const double norm =
                    std::sqrt((m ? 2.0 : 1.0) / M_PI) / std::fabs(std::cyl_bessel_j(m + 1, j));
                modes.push_back({j, m, false, norm});
                if (m)
                    modes.push_back({j, m, true, norm});
            }
            f0 = f1;
        }
    }
    std::sort(modes.begin(), modes.end(),
              [](const ref_mode &a, const ref_mode &b) { return a.j < b.j; });
    return modes;
}

const std::vector<ref_mode> &table()
{
    static const std::vector<ref_mode> t = reference_modes(MEMBRANE_MODES_MAX);
    return t;
}

struct head {
    double sr, radius, tension, density;
    int modes;
};

// ||psi|| at a point over the modes that ring: the first `modes` by frequency, below
// the core's cutoff of 0.95 x Nyquist (docs/membrane.md). Both ends are taken
// inclusively, with a hair of slack, so that a rounding at the edge can only raise
// the bound.
double shape_norm(const head &h, double r_over_a, double theta_deg)
{
    const std::vector<ref_mode> &t = table();
    const double c = std::sqrt(h.tension / h.density);
    const double j_cut = 0.95 * 0.5 * h.sr * 2.0 * M_PI * h.radius / c * (1.0 + 1e-9);
    const double j_last = t[(size_t)h.modes - 1].j * (1.0 + 1e-9);
    const double theta = theta_deg * M_PI / 180.0;
    double sum = 0.0;
    for (const ref_mode &k : t) {
        if (k.j > j_last || k.j > j_cut)
            break;
        double psi = std::cyl_bessel_j(k.m, k.j * r_over_a) * k.norm *
                     (k.sin ? std::sin(k.m * theta) : std::cos(k.m * theta));
        sum += psi * psi;
    }
    return std::sqrt(sum);
}

struct stroke {
    head h;
    double t60, hf, gain;
    double stick_mass, stiffness, alpha, damping;
    double velocity, hit_r, hit_theta;
    double pick_r[2], pick_theta[2];
    double impulse, strike_r, strike_theta; // impulse 0: no strike
    int hit_offset, strike_offset;
};

// The bound above for one stroke. The gain starts at the default and glides to the
// new one: the larger of the two applies.
double output_bound(const stroke &s)
{
    const double inv_sqrt_mass = 1.0 / std::sqrt(s.h.density * s.h.radius * s.h.radius);
    const double pick = std::max(shape_norm(s.h, s.pick_r[0], s.pick_theta[0]),
                                 shape_norm(s.h, s.pick_r[1], s.pick_theta[1]));
    const double strike = s.impulse > 0.0 ? shape_norm(s.h, s.strike_r, s.strike_theta) : 0.0;
    const double gain = std::max(std::fabs(s.gain), MEMBRANE_DEFAULT_GAIN);
    return gain * pick * inv_sqrt_mass *
           (std::sqrt(s.stick_mass) * s.velocity + s.impulse * strike * inv_sqrt_mass);
}

struct result {
    double peak = 0.0;
    bool finite = true;
    double energy_peak = 0.0; // largest membrane_energy() seen at a block's end
};

// Plays one stroke; the parameters go through the setters (which clamp), the
// values in `s` are the ones the bound uses. Blocks of 64.
result play(const stroke &s, const stroke &ask, double seconds)
{
    membrane *m = membrane_new(ask.h.sr);
    contact *c = contact_new();
    REQUIRE((m && c));
    membrane_set_modes(m, ask.h.modes);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIUS, ask.h.radius);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION, ask.h.tension);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_DENSITY, ask.h.density);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, ask.t60);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_HF_DAMPING, ask.hf);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_GAIN, ask.gain);
    for (int j = 0; j < 2; j++)
        membrane_set_pickup(m, j, s.pick_r[j], s.pick_theta[j]);
    REQUIRE(membrane_attach_contact(m, c) == ICTUS_OK);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, ask.stick_mass);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_STIFFNESS, ask.stiffness);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_ALPHA, ask.alpha);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_DAMPING, ask.damping);
    contact_hit(c, ask.velocity, s.hit_r, s.hit_theta, s.hit_offset);
    if (s.impulse > 0.0)
        membrane_strike(m, s.strike_r, s.strike_theta, s.impulse, s.strike_offset);
    std::vector<float> o0(64), o1(64);
    float *outs[2] = {o0.data(), o1.data()};
    result r;
    const int blocks = (int)(seconds * s.h.sr / 64.0) + 1;
    for (int b = 0; b < blocks; b++) {
        membrane_process(m, nullptr, outs, 64);
        for (int i = 0; i < 64; i++) {
            r.finite = r.finite && std::isfinite(o0[(size_t)i]) && std::isfinite(o1[(size_t)i]);
            r.peak = std::max(r.peak,
                              (double)std::max(std::fabs(o0[(size_t)i]), std::fabs(o1[(size_t)i])));
        }
        r.energy_peak = std::max(r.energy_peak, membrane_energy(m));
    }
    membrane_free(m);
    contact_free(c);
    return r;
}

// The bound holds exactly for the discrete energy; the state is float, and its
// rounding (a few FLT_EPSILON of the energy per sample, < 10^4 samples here) may
// add at most this much.
constexpr double kRoundingMargin = 1e-3;

// docs/externals.md, the ranges of membrane~ and contact~ (written out, not taken
// from the headers).
struct range {
    double lo, hi;
};
const range kRadius{0.01, 2.0}, kTension{1.0, 1e5}, kDensity{0.01, 20.0}, kT60{0.005, 60.0},
    kHf{0.0, 1000.0}, kGain{-1e6, 1e6}, kStickMass{1e-4, 10.0}, kStiffness{1.0, 1e12},
    kAlpha{1.0, 4.0}, kDamping{0.0, 1e13};
constexpr double kVelocityMax = 50.0; // m/s, a hit
} // namespace

TEST_CASE("The reference mode table agrees with scipy", "[core][bound]")
{
    // ||psi(r/a = 0.5, theta = 0)|| over the first 128 and 4096 modes, from scipy's
    // jn_zeros and jv (tests/pd/test_extremes.py computes the same).
    head h{768000.0, 1.0, 1.0, 1.0, 128};
    CHECK(shape_norm(h, 0.5, 0.0) == Approx(6.771049490023098).epsilon(1e-9));
    h.modes = 4096;
    CHECK(shape_norm(h, 0.5, 0.0) == Approx(36.35014465339419).epsilon(1e-9));
}

TEST_CASE("A heavy stick on the lightest head stays passive (the reported 2.5e4 peak)",
          "[core][bound][contact]")
{
    // The tester's set-up: every parameter clamped to its limit (radius and density at
    // their minimum, a 3 mg head; a 10 kg stick, stiffness 1e12, alpha 1) and a hit at
    // 50 m/s. The solve stopped on a tolerance scaled by its first trial force (1e12 N)
    // and handed back forces of 1e7 N: the head gained energy, 20 % over what the stick
    // brought at tension 100, 1e17 times with lambda 1e13 at 96 kHz.
    struct {
        double sr, tension, damping;
    } corners[] = {{48000.0, 100.0, 0.0},
                   {48000.0, 1.0, 0.0},
                   {96000.0, 1.0, 1e13},
                   {44100.0, 1.0, 1e13},
                   {96000.0, 10.0, 1e13}};
    for (const auto &k : corners) {
        stroke s{};
        s.h = {k.sr, kRadius.lo, k.tension, kDensity.lo, 64};
        s.t60 = kT60.hi; // the least loss: nothing hides a gain of energy
        s.hf = 0.0;
        s.gain = MEMBRANE_DEFAULT_GAIN;
        s.stick_mass = kStickMass.hi;
        s.stiffness = kStiffness.hi;
        s.alpha = kAlpha.lo;
        s.damping = k.damping;
        s.velocity = 50.0;
        s.hit_r = 0.3;
        s.pick_r[0] = s.pick_r[1] = 0.5;
        s.pick_theta[1] = 90.0;
        result r = play(s, s, 0.4);
        const double e0 = 0.5 * s.stick_mass * s.velocity * s.velocity;
        INFO("sr " << k.sr << " tension " << k.tension << " lambda " << k.damping << ": peak "
                   << r.peak << ", head energy " << r.energy_peak / e0 << " x the stick's");
        REQUIRE(r.finite);
        CHECK(r.energy_peak <= e0 * (1.0 + kRoundingMargin));
        CHECK(r.peak <= output_bound(s) * (1.0 + kRoundingMargin));
    }
}

TEST_CASE("Random strokes over the whole legal range stay below the output bound",
          "[core][bound][robust]")
{
    std::mt19937_64 rng(20250611);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    // A value for a parameter with range [lo, hi]: the limits themselves, values out
    // of range that the setter clamps to them (and NaN, which becomes the default),
    // and log-uniform values in between. Returns what is asked; *used is the value
    // the core must end up with.
    auto pick = [&](range r, double def, double *used) {
        const double x = u01(rng);
        if (x < 0.25)
            return *used = r.lo;
        if (x < 0.5)
            return *used = r.hi;
        if (x < 0.55) {
            *used = r.lo;
            return r.lo - (std::fabs(r.lo) + 1.0) * std::pow(10.0, 3.0 * u01(rng));
        }
        if (x < 0.6) {
            *used = r.hi;
            return r.hi + (std::fabs(r.hi) + 1.0) * std::pow(10.0, 3.0 * u01(rng));
        }
        if (x < 0.62) {
            *used = def;
            return std::numeric_limits<double>::quiet_NaN();
        }
        const double lo = r.lo > 0.0 ? r.lo : 1e-3, v = lo * std::pow(r.hi / lo, u01(rng));
        return *used = v;
    };
    const double rates[] = {22050.0, 44100.0, 48000.0, 96000.0, 192000.0};
    const int trials = 240;
    double worst = 0.0;
    for (int t = 0; t < trials; t++) {
        stroke ask{}, s{};
        s.h.sr = ask.h.sr = rates[rng() % 5];
        ask.h.radius = pick(kRadius, MEMBRANE_DEFAULT_RADIUS, &s.h.radius);
        ask.h.tension = pick(kTension, MEMBRANE_DEFAULT_TENSION, &s.h.tension);
        ask.h.density = pick(kDensity, MEMBRANE_DEFAULT_DENSITY, &s.h.density);
        ask.t60 = pick(kT60, MEMBRANE_DEFAULT_T60, &s.t60);
        ask.hf = pick(kHf, MEMBRANE_DEFAULT_HF_DAMPING, &s.hf);
        // The gain only scales the output (and the bound): mostly the default.
        ask.gain = s.gain = MEMBRANE_DEFAULT_GAIN;
        if (u01(rng) < 0.2) {
            ask.gain = pick(kGain, MEMBRANE_DEFAULT_GAIN, &s.gain);
            if (u01(rng) < 0.5)
                ask.gain = -ask.gain, s.gain = -s.gain;
        }
        // Up to 4096 modes, a quarter of the trials at one end or the other.
        double modes = u01(rng) < 0.125  ? 1.0
                       : u01(rng) < 0.14 ? 4096.0
                                         : std::pow(4096.0, u01(rng));
        ask.h.modes = s.h.modes = (int)std::lround(modes);
        ask.stick_mass = pick(kStickMass, CONTACT_DEFAULT_MASS, &s.stick_mass);
        ask.stiffness = pick(kStiffness, CONTACT_DEFAULT_STIFFNESS, &s.stiffness);
        ask.alpha = pick(kAlpha, CONTACT_DEFAULT_ALPHA, &s.alpha);
        ask.damping = pick(kDamping, CONTACT_DEFAULT_DAMPING, &s.damping);
        // A hit velocity in the documented (0, 50] m/s, 50 itself a quarter of the time,
        // and now and then a faster one, which the core clamps to 50.
        s.velocity =
            u01(rng) < 0.25 ? kVelocityMax : 1e-3 * std::pow(kVelocityMax / 1e-3, u01(rng));
        ask.velocity = s.velocity;
        if (u01(rng) < 0.05) {
            ask.velocity = kVelocityMax * std::pow(10.0, 3.0 * u01(rng));
            s.velocity = kVelocityMax;
        }
        const double r_choices[] = {0.0, 1.0, u01(rng), u01(rng)};
        s.hit_r = r_choices[rng() % 4];
        s.hit_theta = 360.0 * u01(rng);
        for (int j = 0; j < 2; j++) {
            s.pick_r[j] = u01(rng);
            s.pick_theta[j] = 360.0 * u01(rng);
        }
        s.hit_offset = (int)(rng() % 64);
        if (u01(rng) < 0.25) {
            // A strike (membrane~ takes 0 .. 10 N s) as well, somewhere in the stroke.
            s.impulse = u01(rng) < 0.3 ? 10.0 : 10.0 * u01(rng);
            s.strike_r = u01(rng);
            s.strike_theta = 360.0 * u01(rng);
            s.strike_offset = (int)(rng() % 2000);
        }
        ask.h.sr = s.h.sr;
        const double bound = output_bound(s);
        result r = play(s, ask, 0.03);
        INFO("trial " << t << ": sr " << s.h.sr << ", head a " << s.h.radius << " T " << s.h.tension
                      << " sigma " << s.h.density << " modes " << s.h.modes << ", stick m "
                      << s.stick_mass << " k " << s.stiffness << " alpha " << s.alpha << " lambda "
                      << s.damping << ", v " << s.velocity << " at r/a " << s.hit_r << ", strike "
                      << s.impulse << " N s, gain " << s.gain << ": peak " << r.peak << ", bound "
                      << bound);
        REQUIRE(r.finite);
        REQUIRE(r.peak <= bound * (1.0 + kRoundingMargin));
        if (bound > 0.0)
            worst = std::max(worst, r.peak / bound);
    }
    WARN("largest peak / bound over " << trials << " strokes: " << worst);
}
