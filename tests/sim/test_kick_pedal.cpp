// The bass-drum pedal (docs/pedal.md): the spring's free oscillation against the exact
// solution of velocity Verlet, the contact against a separate RK4 integration of the
// published felt law in series with a linear head, passivity of the contact, the planner
// over seeded note sequences, and the refusals. The constants are written out here (the
// felt: Chaigne & Askenfelt 1994; the `kick` head), not read from the code.
#include "ictus/sim/kick_pedal.hpp"
#include "ictus/sim/sim_error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace ictus;

namespace
{

const double kPi = 3.14159265358979323846;
// The felt: k x^alpha, Hunt-Crossley mu (s/m).
const double kFeltK = 4.5e9, kFeltAlpha = 2.5, kFeltMu = 0.6;

double inertia_of(const KickPedalParams &p)
{
    const double l = p.beater_length_m;
    return p.felt_mass_kg * l * l + p.shaft_mass_kg * l * l / 3.0 + p.axle_inertia_kg_m2;
}

// The head's point stiffness 2 pi T / ln(R / r_felt).
double head_k1(const KickPedalParams &p)
{
    return 2.0 * kPi * p.head_tension_n_per_m / std::log(p.head_radius_m / p.felt_radius_m);
}

// The felt in series with a linear head at depth d: k x^alpha = k1 (d - x) for the felt's
// compression x, by Newton's method from the last root, kept in its bracket by bisection.
double series_linear(double k1, double d)
{
    static double x_last = 0.0;
    if (!(d > 0.0))
        return 0.0;
    double lo = 0.0, hi = d, x = std::min(std::max(x_last, 0.0), d);
    for (int i = 0; i < 200; ++i) {
        const double xa = x > 0.0 ? std::pow(x, kFeltAlpha) : 0.0;
        const double g = kFeltK * xa - k1 * (d - x);
        (g > 0.0 ? hi : lo) = x;
        const double dg = (x > 0.0 ? kFeltK * kFeltAlpha * xa / x : 0.0) + k1;
        double next = x - g / dg;
        if (!(next > lo && next < hi))
            next = 0.5 * (lo + hi);
        if (std::fabs(next - x) <= 1e-15 * d || hi - lo <= 1e-15 * d) {
            x = next;
            break;
        }
        x = next;
    }
    x_last = x;
    return k1 * (d - x);
}

struct Contact {
    double duration_ms = 0.0, peak_n = 0.0;
};

// The felt's depth x (m) from onset at speed v: m x'' = -F(x, x') - (spring + axle) / L,
// F = max(0, F_s(x) (1 + mu x')), by RK4 at 1e-7 s, until x returns to 0 (interpolated).
Contact reference_contact(const KickPedalParams &p, double v)
{
    const double L = p.beater_length_m, m = inertia_of(p) / (L * L), k1 = head_k1(p);
    auto acc = [&](double x, double xd) {
        double f = x > 0.0 ? series_linear(k1, x) * (1.0 + kFeltMu * xd) : 0.0;
        f = std::max(f, 0.0);
        const double phi = p.phi_head_rad + x / L, om = xd / L;
        const double tau =
            p.spring_preload_n_m + p.spring_stiffness_n_m_per_rad * phi + p.axle_damping_n_m_s * om;
        return (-f - tau / L) / m;
    };
    const double dt = 1e-7;
    double x = 0.0, xd = v, t = 0.0;
    Contact c;
    for (;;) {
        const double k1x = xd, k1v = acc(x, xd);
        const double k2x = xd + 0.5 * dt * k1v, k2v = acc(x + 0.5 * dt * k1x, k2x);
        const double k3x = xd + 0.5 * dt * k2v, k3v = acc(x + 0.5 * dt * k2x, k3x);
        const double k4x = xd + dt * k3v, k4v = acc(x + dt * k3x, k4x);
        const double xn = x + dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        const double xdn = xd + dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if (xn <= 0.0 && t > 0.0) {
            c.duration_ms = 1000.0 * (t + dt * x / (x - xn));
            return c;
        }
        x = xn;
        xd = xdn;
        t += dt;
        c.peak_n = std::max(c.peak_n, std::max(0.0, series_linear(k1, x) * (1.0 + kFeltMu * xd)));
    }
}

// Throws the beater (chain slack, no push) from just before the head at speed v and returns
// its first strike.
PedalStrike throw_at_head(KickPedal &pedal, double v, double *e_before = nullptr,
                          double *e_after = nullptr)
{
    const KickPedalParams &p = pedal.params();
    pedal.set_beater(p.phi_head_rad - 1e-3, v / p.beater_length_m);
    if (e_before)
        *e_before = pedal.energy_j();
    PedalStrike s;
    for (int i = 0; i < 200; ++i) {
        pedal.advance_to(pedal.time_s() + 1e-3);
        if (pedal.take_strike(s))
            break;
    }
    if (e_after)
        *e_after = pedal.energy_j();
    return s;
}

std::vector<double> seeded(unsigned seed, int n, double lo, double hi)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<double> v;
    for (int i = 0; i < n; ++i)
        v.push_back(u(rng));
    return v;
}

} // namespace

TEST_CASE("kick pedal: the spring's free oscillation is velocity Verlet's exact solution",
          "[kick_pedal]")
{
    KickPedalParams p;
    p.axle_damping_n_m_s = 0.0;
    p.phi_head_rad = 1.5; // the head out of reach
    KickPedal pedal(p);
    const double I = inertia_of(p), k = p.spring_stiffness_n_m_per_rad;
    const double w = std::sqrt(k / I), h = p.substep_s;
    REQUIRE(pedal.inertia_kg_m2() == Approx(I).epsilon(1e-14));
    // Released from rest at phi0: phi = phi_eq + A cos(w t), phi_eq = -preload / k, until the
    // stop. Verlet's positions are exactly phi_eq + A cos(w~ t_n), cos(w~ h) = 1 - (w h)^2 / 2
    // (the three-term recurrence with x_1 = x_0 (1 - (w h)^2 / 2)).
    const double phi0 = 1.2, phi_eq = -p.spring_preload_n_m / k, A = phi0 - phi_eq;
    const double wd = std::acos(1.0 - 0.5 * (w * h) * (w * h)) / h;
    // The discrete frequency is the spring's to (w h)^2 / 24: the period 2 pi sqrt(I / k).
    CHECK(std::fabs(wd / w - 1.0) <= (w * h) * (w * h) / 24.0 * 1.01);
    pedal.set_beater(phi0, 0.0);
    const double e0 = pedal.energy_j() + 0.5 * k * phi_eq * phi_eq;
    // Velocity Verlet keeps v^2 + w^2 (1 - (w h)^2 / 4) x^2: the energy moves by at most
    // (w h)^2 / 4 / (1 - (w h)^2 / 4) of itself.
    const double q = 0.25 * (w * h) * (w * h), e_bound = q / (1.0 - q);
    REQUIRE(e_bound < 1e-6);
    const double t_stop = std::acos(-phi_eq / A) / w;
    double worst_phi = 0.0, worst_e = 0.0;
    for (int i = 1;; ++i) {
        const double t = i * 1e-3;
        if (t > t_stop - 2e-3)
            break;
        pedal.advance_to(t);
        const double tn = std::floor(t / h + 1e-9) * h;
        worst_phi = std::max(
            worst_phi, std::fabs(pedal.beater_angle_rad() - (phi_eq + A * std::cos(wd * tn))));
        const double e = pedal.energy_j() + 0.5 * k * phi_eq * phi_eq;
        worst_e = std::max(worst_e, std::fabs(e / e0 - 1.0));
        // Against the spring's own period: the phase drifts by (w~ - w) t.
        CHECK(std::fabs(pedal.beater_angle_rad() - (phi_eq + A * std::cos(w * tn))) <=
              A * std::fabs(wd - w) * tn + 1e-9);
    }
    CHECK(worst_phi <= 1e-9);
    CHECK(worst_e <= e_bound + 1e-12);
    WARN("free oscillation: period " << 2.0 * kPi / w << " s, worst |phi - exact| " << worst_phi
                                     << " rad, worst energy drift " << worst_e << " (bound "
                                     << e_bound << ")");
    // The stop: reached at t_stop, within a substep, at speed A w sin(w t_stop).
    pedal.advance_to(t_stop + 2e-3);
    CHECK(pedal.beater_angle_rad() == 0.0);
    CHECK(pedal.beater_velocity_rad_s() == 0.0);
}

TEST_CASE("kick pedal: the contact against RK4 of the felt law in series with a linear head",
          "[kick_pedal]")
{
    KickPedalParams p;
    p.head_modulus_pa = 0.0; // k3 = 0: a linear head
    KickPedal pedal(p);
    const std::vector<double> speeds =
        seeded(20261129u, 6, pedal.min_speed_mps(), pedal.max_speed_mps());
    double worst_d = 0.0, worst_f = 0.0;
    for (double v : speeds) {
        const PedalStrike s = throw_at_head(pedal, v);
        REQUIRE(s.speed_mps > 0.0);
        // The speed at onset: v less the spring's work over the last 1 mrad of flight,
        // (1/2) I (w0^2 - w^2) = preload dphi + k (phi_h^2 - (phi_h - dphi)^2) / 2; the axle's
        // damping changes it by c dphi / (2 I w0) < 1e-4.
        const double ph = p.phi_head_rad, dphi = 1e-3, w0 = v / p.beater_length_m;
        const double work = p.spring_preload_n_m * dphi + 0.5 * p.spring_stiffness_n_m_per_rad *
                                                              (ph * ph - (ph - dphi) * (ph - dphi));
        const double w_on = std::sqrt(w0 * w0 - 2.0 * work / inertia_of(p));
        CHECK(s.speed_mps == Approx(w_on * p.beater_length_m).epsilon(1e-4));
        CHECK(s.bounce); // no push: a contact without a push is no note
        const Contact ref = reference_contact(p, s.speed_mps);
        INFO("v " << v << " m/s: duration " << s.duration_ms << " ms (RK4 " << ref.duration_ms
                  << "), peak " << s.peak_force_n << " N (RK4 " << ref.peak_n << ")");
        CHECK(s.duration_ms == Approx(ref.duration_ms).epsilon(0.01));
        CHECK(s.peak_force_n == Approx(ref.peak_n).epsilon(0.01));
        worst_d = std::max(worst_d, std::fabs(s.duration_ms / ref.duration_ms - 1.0));
        worst_f = std::max(worst_f, std::fabs(s.peak_force_n / ref.peak_n - 1.0));
        CHECK(s.effective_mass_kg ==
              Approx(inertia_of(p) / (p.beater_length_m * p.beater_length_m)));
        // At least 100 substeps per contact.
        CHECK(s.duration_ms * 1e-3 / p.substep_s >= 100.0);
    }
    WARN("contact against RK4: worst duration error " << worst_d * 100.0 << " %, worst peak error "
                                                      << worst_f * 100.0 << " %");
}

TEST_CASE("kick pedal: a contact never adds energy", "[kick_pedal]")
{
    KickPedalParams p;
    p.axle_damping_n_m_s = 0.0;
    KickPedal pedal(p);
    double kept_lo = 1.0, kept_hi = 0.0;
    for (double v : seeded(7u, 12, 0.2, 2.0 * pedal.max_speed_mps())) {
        double e0 = 0.0, e1 = 0.0;
        const PedalStrike s = throw_at_head(pedal, v, &e0, &e1);
        REQUIRE(s.duration_ms > 0.0);
        INFO("v " << v << " m/s: energy " << e0 << " J before, " << e1 << " J after");
        CHECK(e1 <= e0);
        kept_lo = std::min(kept_lo, e1 / e0);
        kept_hi = std::max(kept_hi, e1 / e0);
        // The impulse at least the momentum the head took back: m (v_in + v_out) >= m v_in
        // (the spring's share over the contact is at most its torque / L times the duration).
        const double m = s.effective_mass_kg;
        const double spring_n =
            (p.spring_preload_n_m + p.spring_stiffness_n_m_per_rad * 1.6) / p.beater_length_m;
        CHECK(s.impulse_n_s >= m * s.speed_mps - spring_n * s.duration_ms * 1e-3);
    }
    WARN("passivity: the beater keeps " << kept_lo * 100.0 << " .. " << kept_hi * 100.0
                                        << " % of its energy");
}

namespace
{

struct Note {
    double t, v, got;
};

// Schedules n notes (gaps log-uniform in [0.06, 1] s, speeds uniform over the range and 10 %
// beyond it on either side), all ahead or each 0.4 s before its time, and checks every
// note's first contact: one non-bounce strike each, within 0.5 ms of its time and 2 % of its
// clamped speed.
void check_sequence(unsigned seed, int n, bool interleaved, double *worst_dt, double *worst_dv,
                    const KickPedalParams &p = KickPedalParams(), double min_gap_s = 0.06)
{
    KickPedal pedal(p);
    const double lo = pedal.min_speed_mps(), hi = pedal.max_speed_mps();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> lgap(std::log(min_gap_s), std::log(1.0));
    std::uniform_real_distribution<double> uv(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo));
    std::vector<Note> notes;
    std::vector<PedalStrike> firsts;
    int bounces = 0;
    auto drain = [&]() {
        PedalStrike s;
        while (pedal.take_strike(s)) {
            if (s.bounce)
                ++bounces;
            else
                firsts.push_back(s);
        }
    };
    double t = 0.4;
    for (int i = 0; i < n; ++i) {
        const double v = uv(rng);
        if (interleaved) {
            pedal.advance_to(std::max(pedal.time_s(), t - 0.4));
            drain();
        }
        const double got = pedal.schedule(t, v);
        const double want = std::clamp(v, lo, hi);
        INFO("seed " << seed << " note " << i << " at " << t << " s, " << v << " m/s");
        CHECK(std::fabs(got / want - 1.0) <= 0.02);
        notes.push_back({t, want, got});
        t += std::exp(lgap(rng));
    }
    for (double s = pedal.time_s(); s < t + 0.5; s += 0.01) {
        pedal.advance_to(s);
        drain();
    }
    REQUIRE(firsts.size() == notes.size());
    for (std::size_t i = 0; i < notes.size(); ++i) {
        INFO("seed " << seed << " note " << i << " at " << notes[i].t << " s, " << notes[i].v
                     << " m/s: struck at " << firsts[i].time_s << " s, " << firsts[i].speed_mps
                     << " m/s");
        const double dt = std::fabs(firsts[i].time_s - notes[i].t);
        const double dv = std::fabs(firsts[i].speed_mps / notes[i].v - 1.0);
        CHECK(dt <= 0.5e-3);
        CHECK(dv <= 0.02);
        *worst_dt = std::max(*worst_dt, dt);
        *worst_dv = std::max(*worst_dv, dv);
    }
    (void)bounces;
}

} // namespace

TEST_CASE("kick pedal: scheduled notes land on time at their speed", "[kick_pedal]")
{
    double worst_dt = 0.0, worst_dv = 0.0;
    check_sequence(11u, 60, false, &worst_dt, &worst_dv);
    check_sequence(12u, 60, false, &worst_dt, &worst_dv);
    check_sequence(13u, 40, true, &worst_dt, &worst_dv);
    WARN("scheduling: worst onset error " << worst_dt * 1e3 << " ms, worst speed error "
                                          << worst_dv * 100.0 << " %");
}

// The hi-hat's pedal (hihat_pedal_params: the `hihat` preset's plate, D 12.45 N m, R 0.1778 m):
// the same planner and the same law, a plate closing on a plate.
TEST_CASE("hi-hat pedal: chicks land on time at their speed", "[kick_pedal][hihat_pedal]")
{
    const KickPedalParams p = hihat_pedal_params(12.45, 0.1778);
    double worst_dt = 0.0, worst_dv = 0.0;
    check_sequence(21u, 40, false, &worst_dt, &worst_dv, p, 0.1);
    check_sequence(22u, 30, true, &worst_dt, &worst_dv, p, 0.1);
    WARN("hi-hat scheduling: worst onset error " << worst_dt * 1e3 << " ms, worst speed error "
                                                 << worst_dv * 100.0 << " %");
}

TEST_CASE("hi-hat pedal: the gap, the plates' stiffness, passivity, no NaN",
          "[kick_pedal][hihat_pedal]")
{
    const KickPedalParams p = hihat_pedal_params(12.45, 0.1778);
    CHECK(p.beater_length_m * p.phi_head_rad == Approx(0.015)); // the gap open, 1.5 cm
    CHECK(p.surface_stiffness_n_per_m == Approx(0.5 * 16.0 * kPi * 12.45 / (0.1778 * 0.1778)));
    KickPedal pedal(p);
    CHECK(pedal.effective_mass_kg() == Approx(1.19));
    for (double v : seeded(8u, 10, 0.1, 2.0 * pedal.max_speed_mps())) {
        double e0 = 0.0, e1 = 0.0;
        const PedalStrike s = throw_at_head(pedal, v, &e0, &e1);
        INFO("v " << v << " m/s: energy " << e0 << " J before, " << e1 << " J after");
        REQUIRE(s.duration_ms > 0.0);
        CHECK(std::isfinite(s.peak_force_n));
        CHECK(std::isfinite(pedal.beater_angle_rad()));
        CHECK(e1 <= e0 + 1e-12);
        // A linear contact lasts at most about half the period of the mass on the plates,
        // pi sqrt(m / k) (the return spring pushes the plates apart sooner, the more so the
        // slower they meet).
        const double half =
            1e3 * kPi * std::sqrt(s.effective_mass_kg / p.surface_stiffness_n_per_m);
        CHECK(s.duration_ms <= 1.1 * half);
    }
    CHECK_THROWS_AS(hihat_pedal_params(0.0, 0.1778), SimError);
}

TEST_CASE("hi-hat pedal: the closing speed grows with the dynamics asked",
          "[kick_pedal][hihat_pedal]")
{
    const KickPedalParams p = hihat_pedal_params(12.45, 0.1778);
    double last = 0.0;
    for (double v : {0.2, 0.4, 0.6, 0.8, 1.0, 1.2}) {
        KickPedal pedal(p);
        const double got = pedal.schedule(0.3, v);
        pedal.advance_to(0.6);
        PedalStrike s;
        REQUIRE(pedal.take_strike(s));
        INFO("asked " << v << " m/s, planned " << got << ", struck " << s.speed_mps << " at "
                      << s.time_s);
        CHECK(std::fabs(s.time_s - 0.3) <= 0.5e-3);
        CHECK(s.speed_mps == Approx(v).epsilon(0.02));
        CHECK(s.speed_mps > last);
        last = s.speed_mps;
    }
}

TEST_CASE("kick pedal: sixteenths at 120 bpm and heel-toe doubles", "[kick_pedal]")
{
    // 125 ms apart, and pairs 60 ms apart, each at the range's ends and middle.
    for (double v : {1.0, 3.0, 5.0}) {
        KickPedal pedal;
        std::vector<double> times;
        for (int i = 0; i < 8; ++i)
            times.push_back(0.3 + 0.125 * i);
        for (int i = 0; i < 4; ++i) {
            times.push_back(1.5 + 0.3 * i);
            times.push_back(1.5 + 0.3 * i + 0.06);
        }
        for (double t : times)
            CHECK(pedal.schedule(t, v) == Approx(v).epsilon(0.02));
        pedal.advance_to(times.back() + 0.3);
        PedalStrike s;
        std::size_t i = 0;
        while (pedal.take_strike(s)) {
            if (s.bounce)
                continue;
            REQUIRE(i < times.size());
            CHECK(std::fabs(s.time_s - times[i]) <= 0.5e-3);
            CHECK(s.speed_mps == Approx(v).epsilon(0.02));
            ++i;
        }
        CHECK(i == times.size());
    }
}

TEST_CASE("kick pedal: bad input is refused by name", "[kick_pedal]")
{
    using Catch::Matchers::Contains;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    KickPedal pedal;
    REQUIRE_THROWS_WITH(pedal.schedule(nan, 2.0), Contains("impact_time_s"));
    REQUIRE_THROWS_WITH(pedal.schedule(inf, 2.0), Contains("impact_time_s"));
    REQUIRE_THROWS_WITH(pedal.schedule(0.5, nan), Contains("impact_speed_mps"));
    REQUIRE_THROWS_WITH(pedal.advance_to(nan), Contains("t_s"));
    pedal.advance_to(1.0);
    REQUIRE_THROWS_WITH(pedal.schedule(0.5, 2.0), Contains("impact_time_s"));
    REQUIRE_THROWS_WITH(pedal.schedule(1.0, 2.0), Contains("impact_time_s"));
    REQUIRE_THROWS_WITH(pedal.advance_to(0.5), Contains("t_s"));
    pedal.schedule(1.5, 2.0);
    REQUIRE_THROWS_WITH(pedal.schedule(1.4, 2.0), Contains("pending"));
    REQUIRE_THROWS_AS(pedal.schedule(1.5, 2.0), SimError);
    REQUIRE_THROWS_WITH(pedal.set_beater(-0.1, 0.0), Contains("phi_rad"));
    REQUIRE_THROWS_WITH(pedal.set_beater(0.1, nan), Contains("omega_rad_s"));

    struct Bad {
        const char *field;
        double KickPedalParams::*member;
        double value;
    };
    const Bad bad[] = {
        {"beater_length_m", &KickPedalParams::beater_length_m, 0.0},
        {"felt_mass_kg", &KickPedalParams::felt_mass_kg, -0.01},
        {"shaft_mass_kg", &KickPedalParams::shaft_mass_kg, nan},
        {"felt_radius_m", &KickPedalParams::felt_radius_m, 0.0},
        {"felt_radius_m", &KickPedalParams::felt_radius_m, 0.2},
        {"axle_inertia_kg_m2", &KickPedalParams::axle_inertia_kg_m2, -1.0},
        {"spring_stiffness_n_m_per_rad", &KickPedalParams::spring_stiffness_n_m_per_rad, inf},
        {"spring_preload_n_m", &KickPedalParams::spring_preload_n_m, -0.1},
        {"axle_damping_n_m_s", &KickPedalParams::axle_damping_n_m_s, -1e-3},
        {"phi_head_rad", &KickPedalParams::phi_head_rad, 2.0},
        {"chain_ratio", &KickPedalParams::chain_ratio, 0.0},
        {"head_radius_m", &KickPedalParams::head_radius_m, 0.01},
        {"head_tension_n_per_m", &KickPedalParams::head_tension_n_per_m, 0.0},
        {"head_thickness_m", &KickPedalParams::head_thickness_m, 0.0},
        {"head_modulus_pa", &KickPedalParams::head_modulus_pa, -1.0},
        {"head_poisson", &KickPedalParams::head_poisson, 0.5},
        {"substep_s", &KickPedalParams::substep_s, 0.0},
        {"min_speed_mps", &KickPedalParams::min_speed_mps, 10.0},
        {"max_speed_mps", &KickPedalParams::max_speed_mps, nan},
        {"stroke_min_s", &KickPedalParams::stroke_min_s, 0.5},
        {"stroke_max_s", &KickPedalParams::stroke_max_s, 0.0},
        {"throw_fraction", &KickPedalParams::throw_fraction, 1.0},
    };
    for (const Bad &b : bad) {
        KickPedalParams p;
        p.*b.member = b.value;
        INFO(b.field << " = " << b.value);
        REQUIRE_THROWS_AS(KickPedal(p), SimError);
        REQUIRE_THROWS_WITH(KickPedal(p), Contains(b.field) && Contains("must be in"));
    }
    REQUIRE_NOTHROW(KickPedal(KickPedalParams()));
}

// The numbers docs/pedal.md quotes: contact durations and peaks on the `kick` head, and the
// tightest gap at which a second note lands (0.5 ms, 2 %) after a first of the same speed.
TEST_CASE("kick pedal: onsets once each, before their strikes, and pushes dropped by "
          "cancel_pending",
          "[kick_pedal]")
{
    // Notes of one speed 0.5 s apart (the beater back on its stop between them: the push found
    // for the first is reused, shifted), seeded speeds per run.
    std::mt19937 rng(7);
    for (int run = 0; run < 3; ++run) {
        KickPedal pedal;
        const double v = std::uniform_real_distribution<double>(1.0, 6.0)(rng);
        std::vector<double> times;
        for (int k = 0; k < 6; ++k)
            times.push_back(0.3 + 0.5 * k);
        std::vector<PedalStrike> onsets, strikes;
        size_t next = 0;
        for (double t = 0.0; t < 3.6; t += 0.001) {
            while (next < times.size() && times[next] <= t + 0.5)
                pedal.schedule(times[next++], v);
            pedal.advance_to(t);
            PedalStrike s;
            while (pedal.take_onset(s)) {
                // Its onset is taken before its strike ends.
                CHECK(s.duration_ms == 0.0);
                onsets.push_back(s);
            }
            while (pedal.take_strike(s))
                strikes.push_back(s);
        }
        std::vector<PedalStrike> primary;
        for (const PedalStrike &s : strikes)
            if (!s.bounce)
                primary.push_back(s);
        REQUIRE(primary.size() == times.size());
        REQUIRE(onsets.size() == strikes.size());
        for (size_t k = 0; k < times.size(); ++k) {
            INFO("run " << run << " note " << k << " speed " << v);
            CHECK(std::fabs(primary[k].time_s - times[k]) <= 0.5e-3);
            CHECK(std::fabs(primary[k].speed_mps - v) <= 0.02 * v);
        }
        for (size_t k = 0; k < strikes.size(); ++k) {
            CHECK(onsets[k].time_s == strikes[k].time_s);
            CHECK(onsets[k].speed_mps == strikes[k].speed_mps);
            CHECK(onsets[k].bounce == strikes[k].bounce);
        }
    }
    // A note scheduled, then dropped before its push begins: no strike, the foot stays up.
    KickPedal pedal;
    pedal.schedule(1.0, 3.0);
    pedal.advance_to(0.5);
    pedal.cancel_pending(0.5);
    pedal.advance_to(2.0);
    PedalStrike s;
    CHECK_FALSE(pedal.take_onset(s));
    CHECK_FALSE(pedal.take_strike(s));
    CHECK(pedal.footboard_angle_rad() == 0.0);
    CHECK(pedal.beater_angle_rad() == 0.0);
}

TEST_CASE("kick pedal: numbers for the doc", "[.kick_pedal_numbers]")
{
    KickPedal pedal;
    for (double v : {1.0, 3.0, 5.0, 6.0}) {
        const PedalStrike s = throw_at_head(pedal, v);
        std::printf("v %.1f m/s: duration %.2f ms, peak %.1f N, impulse %.4f N s\n", v,
                    s.duration_ms, s.peak_force_n, s.impulse_n_s);
    }
    std::printf("speed range %.2f .. %.2f m/s, effective mass %.4f kg\n", pedal.min_speed_mps(),
                pedal.max_speed_mps(), pedal.inertia_kg_m2() / 0.04);
    for (double v1 : {1.0, 3.0, 6.0})
        for (double v2 : {1.0, 3.0, 6.0}) {
            double tightest = -1.0;
            for (double gap = 0.080; gap >= 0.020; gap -= 0.002) {
                KickPedal k;
                k.schedule(0.3, v1);
                k.schedule(0.3 + gap, v2);
                k.advance_to(0.3 + gap + 0.3);
                PedalStrike s;
                std::vector<PedalStrike> f;
                while (k.take_strike(s))
                    if (!s.bounce)
                        f.push_back(s);
                if (f.size() == 2 && std::fabs(f[1].time_s - 0.3 - gap) <= 5e-4 &&
                    std::fabs(f[1].speed_mps / v2 - 1.0) <= 0.02)
                    tightest = gap;
                else
                    break;
            }
            std::printf("%.0f -> %.0f m/s: tightest gap %.0f ms\n", v1, v2, tightest * 1e3);
        }
}
