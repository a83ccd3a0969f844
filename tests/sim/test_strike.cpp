// Strike detection against analytic contacts: a ball meeting a linear spring
// (duration pi sqrt(m/k), impulse 2 m v, peak v sqrt(k m)), bounce tagging on
// a ball bouncing to known apex heights, membrane coordinates, file formats.
#include "ictus/perform/strike_log.hpp"
#include "ictus/sim/strike_detector.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <vector>

using ictus::MembraneGeometry;
using ictus::StrikeDetector;
using ictus::StrikeEvent;
using ictus::TipSample;

namespace
{

MembraneGeometry flat_membrane(double k, double c)
{
    MembraneGeometry m;
    m.center_m = Eigen::Vector3d(0.0, 0.0, 0.0);
    m.radius_m = 0.178;
    m.stiffness_n_per_m = k;
    m.damping_n_s_per_m = c;
    m.friction = 0.0;
    m.tip_radius_m = 0.007;
    return m;
}

// The exact motion of a bead of mass m meeting an undamped spring k at t_c
// with normal speed v (no gravity), sliding along +x at u; sampled at `dt`.
struct AnalyticContact {
    double m = 0.03, k = 5825.0, v = 1.5, u = 0.2, t_c = 0.1037, r = 0.007;
    double x_c = 0.05, y_c = 0.03; // membrane coordinates at onset
    double omega() const { return std::sqrt(k / m); }
    double t_end() const { return t_c + M_PI / omega(); }
    TipSample at(double t) const
    {
        TipSample s;
        s.time_s = t;
        double height, vel;
        if (t < t_c) {
            height = r + v * (t_c - t);
            vel = -v;
        } else if (t <= t_end()) {
            const double w = omega();
            height = r - (v / w) * std::sin(w * (t - t_c));
            vel = -v * std::cos(w * (t - t_c));
        } else {
            height = r + v * (t - t_end());
            vel = v;
        }
        // membrane y_m is world -z
        s.center_m = Eigen::Vector3d(x_c + u * (t - t_c), height, -y_c);
        s.velocity_mps = Eigen::Vector3d(u, vel, 0.0);
        return s;
    }
};

// Samples of a continuous motion (not of semi-implicit steps).
ictus::StrikeDetectorOptions continuous_samples()
{
    ictus::StrikeDetectorOptions o;
    o.semi_implicit_samples = false;
    return o;
}

std::vector<StrikeEvent> run_detector(StrikeDetector &det, int hand,
                                      const std::vector<TipSample> &samples)
{
    std::vector<StrikeEvent> events;
    StrikeEvent e;
    for (const TipSample &s : samples)
        if (det.update(hand, s, e))
            events.push_back(e);
    while (det.flush(e))
        events.push_back(e);
    return events;
}

} // namespace

TEST_CASE("strike: a bead on a linear spring gives the analytic duration, impulse and peak",
          "[sim][strike]")
{
    const AnalyticContact a;
    const double duration_ms = M_PI / a.omega() * 1e3; // half a period of sqrt(k/m)
    const double impulse = 2.0 * a.m * a.v;            // m (v_in + v_out), elastic
    const double peak = a.v * std::sqrt(a.k * a.m);    // k x_max, x_max = v / omega

    struct Case {
        double dt, time_tol_ms, impulse_rel, peak_rel;
    };
    // Sampling errors, from the sampling analysis (h = dt, w = omega):
    // crossings by secant on a sine, error ~ h (w h)^2 / 6 per edge; trapezoid
    // on a half sine, relative error ~ (w h)^2 / 12; a parabola through three
    // samples of a sine near its crest, ~ (w h)^4 / 24 relative.
    // At 1e-5 s all of them are far below 1e-4; at 1 ms (w h = 0.44):
    // 0.032 ms, 1.6 %, 0.16 %.
    const Case cases[] = {{1e-5, 1e-4, 1e-4, 1e-4}, {1e-3, 0.05, 0.025, 0.005}};
    for (const Case &c : cases) {
        StrikeDetector det(flat_membrane(a.k, 0.0), continuous_samples());
        std::vector<TipSample> samples;
        for (long n = 0; n * c.dt <= 0.2; ++n)
            samples.push_back(a.at(n * c.dt));
        const std::vector<StrikeEvent> ev = run_detector(det, 1, samples);
        REQUIRE(ev.size() == 1);
        const StrikeEvent &e = ev[0];
        std::printf("strike dt %g s: onset %.6f s (exact %.6f), duration %.4f ms (exact %.4f), "
                    "impulse %.6f N s (exact %.6f), peak %.3f N (exact %.3f)\n",
                    c.dt, e.time_s, a.t_c, e.duration_ms, duration_ms, e.impulse_n_s, impulse,
                    e.peak_force_n, peak);
        CHECK(e.hand == 1);
        CHECK(e.drum == 0);
        CHECK(e.seq == 0);
        CHECK_FALSE(e.bounce);
        CHECK(std::fabs(e.time_s - a.t_c) * 1e3 <= c.time_tol_ms);
        CHECK(std::fabs(e.duration_ms - duration_ms) <= 2.0 * c.time_tol_ms);
        CHECK(std::fabs(e.impulse_n_s - impulse) <= c.impulse_rel * impulse);
        CHECK(std::fabs(e.peak_force_n - peak) <= c.peak_rel * peak);
        // Pre-contact velocity is the free flight's, exactly.
        CHECK(e.normal_velocity_mps == Approx(a.v).epsilon(1e-12));
        CHECK(e.tangential_velocity_mps == Approx(a.u).epsilon(1e-12));
        // Position at onset: x, y given; r/a and theta by hand.
        const double pos_tol = a.u * c.time_tol_ms * 1e-3 + 1e-9;
        CHECK(std::fabs(e.x_m - a.x_c) <= pos_tol);
        CHECK(std::fabs(e.y_m - a.y_c) <= 1e-12);
        CHECK(e.r_over_a == Approx(std::hypot(0.05, 0.03) / 0.178).epsilon(1e-3));
        CHECK(e.theta_deg == Approx(30.963756532).epsilon(1e-3)); // atan(0.6) in degrees
        // Frictionless: the force on the membrane is straight down.
        CHECK(e.force_dir.isApprox(Eigen::Vector3d(0, -1, 0)));
    }
}

TEST_CASE("strike: the zone is the rim when the rim takes at least half of the contact's force",
          "[sim][strike]")
{
    // The samples' forces on the rim and the head, as Scene's contact feedback
    // gives them (stick_drum_forces): the head's the spring's k x, the rim's a
    // fixed share of it in the contact's samples; a rim force before the onset
    // (the shaft on the hoop while the bead is still above the head) is no part
    // of the contact. Equal steps: the sums' ratio is the impulses' ratio.
    const AnalyticContact a;
    struct Case {
        double rim_share, rim_before;
        int zone;
    };
    const Case cases[] = {{0.0, 0.0, ictus::kZoneHead}, {0.9, 0.0, ictus::kZoneHead},
                          {1.0, 0.0, ictus::kZoneRim},  {1.1, 0.0, ictus::kZoneRim},
                          {0.0, 1e4, ictus::kZoneHead}, {0.5, 1e4, ictus::kZoneHead}};
    for (const Case &c : cases) {
        StrikeDetector det(flat_membrane(a.k, 0.0), continuous_samples());
        std::vector<TipSample> samples;
        for (long n = 0; n * 1e-3 <= 0.2; ++n) {
            TipSample s = a.at(n * 1e-3);
            const double depth = a.r - s.center_m.y(); // the bead below the plane
            if (depth > 0.0) {
                s.head_force_n = a.k * depth;
                s.rim_force_n = c.rim_share * s.head_force_n;
            } else if (s.time_s < a.t_c) {
                s.rim_force_n = c.rim_before;
            }
            samples.push_back(s);
        }
        const std::vector<StrikeEvent> ev = run_detector(det, 1, samples);
        REQUIRE(ev.size() == 1);
        INFO("rim share " << c.rim_share << ", rim force before the onset " << c.rim_before);
        CHECK(ev[0].zone == c.zone);
    }
}

TEST_CASE("strike: the onset is reported in the sample that crosses the head, with the fields "
          "a sound needs, and equals the strike reported at the release",
          "[sim][strike]")
{
    // ictusd run sends a strike at its onset (docs/osc.md): the detector
    // hands the onset out once, in the update() whose sample first touches,
    // before the release; its fields are those of the finished strike,
    // without the contact measures.
    const AnalyticContact a;
    const double dt = 1e-3;
    StrikeDetector det(flat_membrane(a.k, 0.0), continuous_samples());
    StrikeEvent onset, end, e;
    double onset_sample_t = -1.0, end_sample_t = -1.0;
    int onsets = 0;
    for (long n = 0; n * dt <= 0.2; ++n) {
        const TipSample s = a.at(n * dt);
        if (det.update(1, s, e)) {
            end = e;
            end_sample_t = s.time_s;
        }
        while (det.take_onset(1, e)) {
            onset = e;
            onset_sample_t = s.time_s;
            ++onsets;
        }
        CHECK_FALSE(det.take_onset(0, e)); // the other hand never touched
    }
    REQUIRE(onsets == 1);
    REQUIRE(end_sample_t > 0.0);
    // The first sample at or past the exact contact time a.t_c.
    CHECK(onset_sample_t == Approx(std::ceil(a.t_c / dt) * dt));
    CHECK(onset_sample_t < end_sample_t);
    CHECK(end_sample_t - onset_sample_t >= 0.5 * M_PI / a.omega()); // half a period later
    CHECK(onset.seq == end.seq);
    CHECK(onset.hand == end.hand);
    CHECK(onset.bounce == end.bounce);
    CHECK(onset.stroke == end.stroke);
    CHECK(onset.time_s == end.time_s);
    CHECK(onset.x_m == end.x_m);
    CHECK(onset.y_m == end.y_m);
    CHECK(onset.normal_velocity_mps == end.normal_velocity_mps);
    CHECK(onset.normal_velocity_mps == Approx(a.v).epsilon(1e-12));
    CHECK(onset.peak_force_n == 0.0);
    CHECK(onset.impulse_n_s == 0.0);
    CHECK(onset.duration_ms == 0.0);
    CHECK(end.duration_ms > 0.0);
}

TEST_CASE("strike: membrane coordinates in all four quadrants", "[sim][strike]")
{
    // x_m along world +X, y_m along world -Z (docs/osc.md).
    struct P {
        double wx, wz, theta;
    };
    const P points[] = {{0.1, 0.0, 0.0},   {0.0, -0.1, 90.0},   {-0.1, 0.0, 180.0},
                        {0.0, 0.1, -90.0}, {0.05, -0.05, 45.0}, {-0.05, 0.05, -135.0}};
    for (const P &p : points) {
        StrikeDetector det(flat_membrane(5000.0, 0.0));
        std::vector<TipSample> s;
        for (int n = 0; n < 40; ++n) {
            TipSample t;
            t.time_s = n * 1e-3;
            // Down at 1 m/s through the membrane plane at n = 20, then back up.
            const double h =
                0.007 + 0.001 * (20 - n) * (n < 25 ? 1.0 : -1.0) + (n < 25 ? 0.0 : -0.010);
            t.center_m = Eigen::Vector3d(p.wx, h, p.wz);
            t.velocity_mps = Eigen::Vector3d(0, n < 25 ? -1.0 : 1.0, 0);
            s.push_back(t);
        }
        const auto ev = run_detector(det, 0, s);
        REQUIRE(ev.size() == 1);
        CHECK(ev[0].theta_deg == Approx(p.theta).margin(1e-9));
        CHECK(ev[0].r_over_a == Approx(std::hypot(p.wx, p.wz) / 0.178).epsilon(1e-12));
        CHECK(ev[0].time_s == Approx(0.020).margin(1e-12));
    }
}

TEST_CASE("strike: no strike outside the disk, nor above the membrane", "[sim][strike]")
{
    StrikeDetector det(flat_membrane(5000.0, 0.0));
    StrikeEvent e;
    int n = 0;
    for (; n < 100; ++n) {
        TipSample t;
        t.time_s = n * 1e-3;
        // Beside the drum (r = 0.2 m > 0.178 m), well below the membrane plane.
        t.center_m = Eigen::Vector3d(0.2, -0.05, 0.0);
        CHECK_FALSE(det.update(0, t, e));
        // Over the drum, 1 mm above it.
        t.center_m = Eigen::Vector3d(0.0, 0.008, 0.0);
        CHECK_FALSE(det.update(1, t, e));
    }
    CHECK_FALSE(det.flush(e));
    CHECK(det.strikes() == 0);
}

TEST_CASE("strike: a bead that meets only the edge, from outside the disk, strikes it on the edge",
          "[sim][strike]")
{
    // The bead falls beside the head, its centre delta beyond the rim circle
    // in plan: the sphere meets the circle when its centre is
    // sqrt(r^2 - delta^2) above the plane (delta < r), never when delta > r.
    const double r = 0.007, a = 0.178, v = 1.5, h0 = 0.03, dt = 1e-4;
    std::mt19937 rng(20261130);
    std::uniform_real_distribution<double> angle(-M_PI, M_PI), frac(0.02, 0.98);
    for (int trial = 0; trial < 40; ++trial) {
        const bool meets = trial % 2 == 0;
        const double delta = meets ? frac(rng) * r : r * (1.0 + frac(rng));
        const double phi = angle(rng);
        StrikeDetector det(flat_membrane(5000.0, 0.0), continuous_samples());
        std::vector<TipSample> s;
        const double h_min = 0.0005, t_low = (h0 - h_min) / v; // still above the plane
        for (int n = 0; n * dt < 2.0 * t_low; ++n) {
            TipSample t;
            t.time_s = n * dt;
            // Down to h_min, then up again at the same speed.
            const bool down = t.time_s < t_low;
            const double h = down ? h0 - v * t.time_s : h_min + v * (t.time_s - t_low);
            t.center_m =
                Eigen::Vector3d((a + delta) * std::cos(phi), h, -(a + delta) * std::sin(phi));
            t.velocity_mps = Eigen::Vector3d(0, down ? -v : v, 0);
            s.push_back(t);
        }
        const auto ev = run_detector(det, 0, s);
        CAPTURE(trial, delta, phi);
        if (!meets) {
            CHECK(ev.empty());
            continue;
        }
        REQUIRE(ev.size() == 1);
        const double t_on = (h0 - std::sqrt(r * r - delta * delta)) / v;
        CHECK(ev[0].time_s == Approx(t_on).margin(dt));
        CHECK(ev[0].r_over_a == Approx(1.0).epsilon(1e-12));
        CHECK(ev[0].theta_deg == Approx(phi * 180.0 / M_PI).margin(1e-9));
        // Along the edge's normal: the fall's part toward the circle, v h / r,
        // with h the onset's height (known within one step's fall, v dt).
        CHECK(ev[0].normal_velocity_mps ==
              Approx(v * std::sqrt(r * r - delta * delta) / r).margin(v * v * dt / r));
        // Released where it met the edge on the way up.
        CHECK(ev[0].duration_ms == Approx(2e3 * (t_low - t_on)).margin(1e3 * dt));
    }
}

TEST_CASE("strike: bounces of a dropped bead are tagged by the apex heights between contacts",
          "[sim][strike]")
{
    // A bead of 30 g under gravity dropped from 10 cm on a damped spring:
    // integrated finely here (semi-implicit Euler, 10 us) with the same law;
    // the apex of each flight is measured from the trajectory, so the rule
    // (apex < 1 cm and re-contact within 150 ms of the release) can be
    // checked strike by strike, and the impulse against m (v_in + v_out) + m g T.
    const double m = 0.03, k = 5825.0, c = 6.0, g = 9.81, r = 0.007, dt = 1e-5;
    StrikeDetector det(flat_membrane(k, c));
    double y = r + 0.10, v = 0.0; // bead centre height, velocity (up +)
    struct Flight {
        double apex = 0.0, release = 0.0;
        double v_out = 0.0;
    };
    std::vector<StrikeEvent> events;
    std::vector<double> apex_before; // the apex of the flight before each contact
    std::vector<double> since_release, v_in, v_out;
    double apex = y - r, release_t = -1.0;
    bool touching = false;
    StrikeEvent e;
    for (long n = 0; n * dt < 1.2; ++n) {
        const double t = n * dt;
        TipSample s;
        s.time_s = t;
        s.center_m = Eigen::Vector3d(0.0, y, 0.0);
        s.velocity_mps = Eigen::Vector3d(0.0, v, 0.0);
        const bool now = y - r < 0.0;
        if (now && !touching) {
            apex_before.push_back(apex);
            since_release.push_back(release_t < 0 ? 1e9 : t - release_t);
            // This integrator moved the bead across the plane with the
            // velocity it now has (y += v dt after v changed; no contact
            // force in that step: it started above the plane).
            v_in.push_back(-v);
        }
        if (!now && touching) {
            release_t = t;
            apex = 0.0;
            v_out.push_back(v);
        }
        touching = now;
        if (!now)
            apex = std::max(apex, y - r);
        if (det.update(0, s, e))
            events.push_back(e);
        const double depth = r - y;
        const double f = depth > 0.0 ? std::max(0.0, k * depth - c * v) : 0.0;
        v += (f / m - g) * dt;
        y += v * dt;
    }
    REQUIRE(events.size() >= 4);
    REQUIRE(apex_before.size() >= events.size());
    long strokes = 0;
    for (size_t i = 0; i < events.size(); ++i) {
        const bool expect_bounce = i > 0 && apex_before[i] < 0.01 && since_release[i] <= 0.15;
        std::printf("contact %zu: apex before %.2f mm, %.1f ms after release, bounce %d "
                    "(expected %d), v_in %.3f m/s, impulse %.5f N s\n",
                    i, apex_before[i] * 1e3, since_release[i] * 1e3, events[i].bounce,
                    expect_bounce, events[i].normal_velocity_mps, events[i].impulse_n_s);
        CHECK(events[i].bounce == expect_bounce);
        if (!expect_bounce)
            ++strokes;
        CHECK(events[i].stroke == strokes - 1);
        // Momentum: contact impulse = m (v_in + v_out) + m g T.
        if (i < v_out.size()) {
            const double expected = m * (v_in[i] + v_out[i]) + m * g * events[i].duration_ms * 1e-3;
            CHECK(events[i].impulse_n_s == Approx(expected).epsilon(0.01));
            CHECK(events[i].normal_velocity_mps == Approx(v_in[i]).epsilon(1e-3));
        }
    }
    // The first contacts are real strokes (10 cm and then a ~2.5 cm flight: restitution ~0.5 at
    // zeta ~0.23) , the late ones bounces: both tags occur.
    CHECK_FALSE(events[0].bounce);
    CHECK(events.back().bounce);
}

TEST_CASE("strike: a re-contact after a long low hover is a new stroke", "[sim][strike]")
{
    StrikeDetector det(flat_membrane(5000.0, 0.0));
    // Two dips 400 ms apart, hovering 5 mm above between them: below the
    // bounce height but outside the 150 ms window.
    std::vector<TipSample> s;
    for (int n = 0; n < 1000; ++n) {
        TipSample t;
        t.time_s = n * 1e-3;
        const bool dip = (n >= 100 && n < 104) || (n >= 500 && n < 504);
        t.center_m = Eigen::Vector3d(0.0, 0.007 + (dip ? -0.001 : 0.005), 0.0);
        s.push_back(t);
    }
    const auto ev = run_detector(det, 1, s);
    REQUIRE(ev.size() == 2);
    CHECK_FALSE(ev[1].bounce);
    CHECK(ev[1].stroke == 1);
    CHECK(ev[1].seq == 1);
}

TEST_CASE("strike: CSV and events lines have fixed, documented formats", "[sim][strike]")
{
    StrikeEvent e;
    e.seq = 3;
    e.hand = 1;
    e.bounce = true;
    e.stroke = 2;
    e.time_s = 1.25;
    e.x_m = 0.05;
    e.y_m = -0.0;
    e.r_over_a = 0.280899;
    e.theta_deg = 0.0;
    e.normal_velocity_mps = 1.5;
    e.tangential_velocity_mps = 0.2;
    e.peak_force_n = 19.123456;
    e.impulse_n_s = 0.09;
    e.duration_ms = 7.1302;
    e.force_dir = Eigen::Vector3d(0.0, -1.0, 0.0);
    e.stick_mass_kg = 0.0123456;
    e.stick_tip = ictus::stick_tip_code("felt");
    e.zone = ictus::kZoneRim;
    std::ostringstream csv;
    ictus::write_strikes_csv_header(csv);
    ictus::write_strike_csv_row(csv, e);
    CHECK(csv.str() ==
          "seq,hand,drum,bounce,stroke,time_s,x_m,y_m,r_over_a,theta_deg,normal_velocity_mps,"
          "tangential_velocity_mps,peak_force_n,impulse_n_s,duration_ms,force_dir_x,force_dir_y,"
          "force_dir_z,stick_mass_kg,stick_tip,zone\n"
          "3,1,0,1,2,1.250000,0.05000,0.00000,0.28090,0.00,1.5000,0.2000,19.123,0.090000,7.130,"
          "0.0000,-1.0000,0.0000,0.01235,3,1\n");
    // The tip codes: stick_tip.h's table order + 1, 0 for none (docs/osc.md).
    CHECK(ictus::stick_tip_code("") == 0);
    CHECK(ictus::stick_tip_code("wood") == 1);
    CHECK(ictus::stick_tip_code("nylon") == 2);
    CHECK(ictus::stick_tip_code("bamboo") == 0);
    CHECK(ictus::stick_tip_name(3) == "felt");
    CHECK(ictus::stick_tip_name(0).empty());
    CHECK(ictus::stick_tip_name(4).empty());
    std::ostringstream ev;
    ictus::write_events_line(ev, e, 1.0);
    CHECK(ev.str() == "250.000 hit 1 0 1 1.5000 0.28090 0.00 19.123 0.090000 7.130 0.2000 1.250000 "
                      "0.01235 1;\n");
}

namespace
{
// A bead sampled as the Scene's integrator moves it (semi-implicit Euler:
// p[n+1] = p[n] + h v[n+1]), from its velocities alone: the samples are
// consistent by construction, and the velocity that crossed the membrane
// plane in a step is the velocity of the sample that ends it.
std::vector<TipSample> semi_implicit(double h, double gap0, const std::vector<double> &vy,
                                     const std::vector<double> &vx)
{
    std::vector<TipSample> s;
    Eigen::Vector3d p(0.0, 0.007 + gap0, 0.0);
    for (size_t n = 0; n < vy.size(); ++n) {
        const Eigen::Vector3d v(vx[n], vy[n], 0.0);
        if (n > 0)
            p += h * v;
        TipSample t;
        t.time_s = n * h;
        t.center_m = p;
        t.velocity_mps = v;
        s.push_back(t);
    }
    return s;
}
} // namespace

TEST_CASE("strike: a re-contact after a lift of less than one step has the velocity that crossed",
          "[sim][strike]")
{
    // A press, a release rising at 1 m/s to a gap of 0.2 mm, and at once a
    // re-contact moving down at 0.7 m/s (a stick the arm holds against the
    // head). Gaps (mm) at 1 ms: 9.5, 8.5 ... 0.5, -0.5, -1.0, -0.8, +0.2, -0.5,
    // -0.6, -0.2, +0.6, rising. The free sample before the re-contact is still
    // rising (+1 m/s): reporting its velocity gave normal_velocity_mps = -1.
    const double h = 1e-3;
    std::vector<double> vy, vx;
    for (int n = 0; n <= 10; ++n)
        vy.push_back(-1.0);
    for (double v : {-0.5, 0.2, 1.0, -0.7, -0.1, 0.4, 0.8, 0.8, 0.8, 0.8, 0.8})
        vy.push_back(v);
    for (size_t n = 0; n < vy.size(); ++n)
        vx.push_back(n == 14 ? 0.3 : 0.2);
    const std::vector<TipSample> s = semi_implicit(h, 0.0095, vy, vx);
    REQUIRE(s[13].center_m.y() - 0.007 == Approx(0.0002).margin(1e-12));
    REQUIRE(s[14].center_m.y() - 0.007 == Approx(-0.0005).margin(1e-12));
    // Both readings of the samples agree here: the stroke's free sample
    // approaches at 1 m/s (and could cross), the re-contact's is rising.
    const bool semi_implicit = GENERATE(true, false);
    ictus::StrikeDetectorOptions o;
    o.semi_implicit_samples = semi_implicit;
    StrikeDetector det(flat_membrane(5000.0, 0.0), o);
    const auto ev = run_detector(det, 0, s);
    REQUIRE(ev.size() == 2);
    // The stroke: the free flight's 1 m/s, onset halfway through step 9-10.
    CHECK_FALSE(ev[0].bounce);
    CHECK(ev[0].normal_velocity_mps == Approx(1.0).epsilon(1e-12));
    CHECK(ev[0].time_s == Approx(0.0095).margin(1e-12));
    // The re-contact: a bounce (0.2 mm apex, 0 ms after the release) whose
    // approach is the step's 0.7 mm in 1 ms down and 0.3 mm along x, its onset
    // 0.2 / 0.7 of the way through step 13-14.
    CHECK(ev[1].bounce);
    CHECK(ev[1].stroke == 0);
    CHECK(ev[1].normal_velocity_mps == Approx(0.7).epsilon(1e-9));
    CHECK(ev[1].tangential_velocity_mps == Approx(0.3).epsilon(1e-9));
    CHECK(ev[1].time_s == Approx(0.013 + 0.001 * 0.2 / 0.7).margin(1e-12));
}

TEST_CASE("strike: every onset's normal velocity is > 0, from physics steps it is the velocity "
          "that crossed, from a continuous motion within one step's change of it",
          "[sim][strike]")
{
    // 10^4 random steps that cross the plane, sampled as the Scene's
    // integrator moves the bead: the free sample (gap 0 to 2 mm, vertical
    // velocity -2 to +2 m/s, i.e. falling, hovering or still rising) and the
    // first touching one, which the velocity v1 (< -g0 / h) carried across.
    // Read as physics steps, the crossing velocity is v1 exactly. Read as
    // samples of a continuous motion, an estimate can be off by at most the
    // step's velocity change |v1 - v0|, and is never negative.
    const double h = 1e-3;
    unsigned state = 12345u;
    auto uniform = [&](double lo, double hi) {
        state = state * 1664525u + 1013904223u;
        return lo + (hi - lo) * ((state >> 8) / 16777216.0);
    };
    int mean_cases = 0;
    for (int i = 0; i < 10000; ++i) {
        const double g0 = uniform(1e-7, 0.002);
        const double v0 = uniform(-2.0, 2.0);
        const double v1 = -g0 / h - uniform(1e-4, 3.0);
        const std::vector<TipSample> s = semi_implicit(h, g0, {v0, v1}, {0.0, 0.0});
        for (const bool steps : {true, false}) {
            ictus::StrikeDetectorOptions o;
            o.semi_implicit_samples = steps;
            StrikeDetector det(flat_membrane(5000.0, 0.0), o);
            StrikeEvent e;
            REQUIRE_FALSE(det.update(0, s[0], e));
            REQUIRE_FALSE(det.update(0, s[1], e));
            REQUIRE(det.flush(e));
            INFO("g0 " << g0 << " m, v0 " << v0 << " m/s, v1 " << v1 << " m/s, steps " << steps);
            REQUIRE(e.normal_velocity_mps > 0.0);
            if (steps) {
                REQUIRE(e.normal_velocity_mps == Approx(-v1).epsilon(1e-9));
                continue;
            }
            REQUIRE(std::fabs(e.normal_velocity_mps - (-v1)) <= std::fabs(v1 - v0) * (1 + 1e-9));
            // A free sample that could not reach the plane in the step: the
            // step's mean, here exactly v1.
            if (!(-v0 * h >= g0)) {
                ++mean_cases;
                REQUIRE(e.normal_velocity_mps == Approx(-v1).epsilon(1e-9));
            }
        }
    }
    CHECK(mean_cases > 5000); // the rising and hovering half, at least
}

TEST_CASE("strike: a tip first seen below the membrane plane is no strike until it lifts",
          "[sim][strike]")
{
    // Resting pressed into the head when watching starts (e.g. after a
    // rebuild): no approach was seen, so no onset velocity exists to report.
    const double h = 1e-3;
    std::vector<double> vy(10, 0.0), vx(30, 0.0);
    for (int n = 0; n < 5; ++n)
        vy.push_back(1.0); // from 1.5 mm deep to 3.5 mm above
    for (int n = 0; n < 15; ++n)
        vy.push_back(-1.0); // and strikes again
    const std::vector<TipSample> s = semi_implicit(h, -0.0015, vy, vx);
    StrikeDetector det(flat_membrane(5000.0, 0.0));
    const auto ev = run_detector(det, 1, s);
    REQUIRE(ev.size() == 1);
    CHECK(ev[0].normal_velocity_mps == Approx(1.0).epsilon(1e-12));
    CHECK(ev[0].time_s == Approx(0.0175).margin(1e-12)); // gap 0.5 mm at 17 ms, 1 m/s
    CHECK(det.side_entries() == 0);
}

TEST_CASE("strike log: strikes reported at release come out in onset order, none lost, none held "
          "longer than an open contact",
          "[sim][strike]")
{
    // Two hands with random, overlapping contacts (seeded): a contact of one
    // hand ends after later ones of the other, so the detector reports out of
    // onset order; every other seed one stick rests on the head for seconds
    // while the other plays. StrikeOrder (run) must give seq 0, 1, 2 ... and
    // let a strike go as soon as no lower-numbered contact is open; StrikeLog
    // (track, render) must give the same list.
    long out_of_order_reports = 0, long_rests = 0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> gap_s(0.005, 0.3), contact_s(0.002, 0.2);
        const double h = 0.001, end_s = 8.0;
        std::vector<std::pair<double, double>> contacts[2]; // [hand] (onset, release)
        for (int hand = 0; hand < 2; ++hand)
            for (double t = gap_s(rng); t < end_s - 0.5; t += gap_s(rng)) {
                // A rest of 3 to 5 s on the head, once, for hand 0 on even seeds.
                const bool rest = hand == 0 && seed % 2 == 0 && contacts[0].size() == 3;
                const double d = rest ? 3.0 + 2.0 * contact_s(rng) / 0.2 : contact_s(rng);
                long_rests += rest;
                contacts[hand].push_back({t, t + d});
                t += d;
            }
        const MembraneGeometry m;
        StrikeDetector detector(m, continuous_samples());
        ictus::StrikeOrder order;
        ictus::StrikeLog log;
        std::vector<StrikeEvent> written;
        auto write = [&](const StrikeEvent &e) { written.push_back(e); };
        long last_reported_seq = -1;
        for (long n = 0; n * h <= end_s; ++n) {
            const double t = n * h;
            StrikeEvent out[2];
            int k = 0;
            for (int hand = 0; hand < 2; ++hand) {
                bool in = false;
                for (const auto &c : contacts[hand])
                    in = in || (t >= c.first && t < c.second);
                TipSample s;
                s.time_s = t;
                s.center_m = m.center_m + Eigen::Vector3d(hand ? 0.05 : -0.05,
                                                          m.tip_radius_m + (in ? -0.001 : 0.01), 0);
                s.velocity_mps = Eigen::Vector3d(0, in ? -0.5 : 0.5, 0);
                if (detector.update(hand, s, out[k]))
                    ++k;
            }
            for (int i = 0; i < k; ++i) {
                out_of_order_reports += out[i].seq < last_reported_seq;
                last_reported_seq = std::max(last_reported_seq, out[i].seq);
                order.push(out[i], write);
            }
            order.release(detector.first_open_seq(), write);
            log.add(out, k);
            // Everything below the first open contact has been let go, in order.
            REQUIRE(static_cast<long>(written.size()) == detector.first_open_seq());
        }
        StrikeEvent e;
        while (detector.flush(e)) {
            order.push(e, write);
            log.add(&e, 1);
        }
        order.flush(write);
        log.finish();
        const long expected = static_cast<long>(contacts[0].size() + contacts[1].size());
        REQUIRE(detector.strikes() == expected);
        REQUIRE(static_cast<long>(written.size()) == expected);
        REQUIRE(static_cast<long>(log.strikes().size()) == expected);
        CHECK(order.early() == 0);
        for (long i = 0; i < expected; ++i) {
            const size_t u = static_cast<size_t>(i);
            REQUIRE(written[u].seq == i);
            REQUIRE(log.strikes()[u].seq == i);
            REQUIRE(log.strikes()[u].time_s == written[u].time_s);
            if (i > 0)
                REQUIRE(written[u].time_s >= written[u - 1].time_s);
        }
    }
    // The cases the log exists for did happen.
    CHECK(out_of_order_reports > 0);
    CHECK(long_rests == 10);
}

TEST_CASE("strike: a stick bouncing on its fulcrum while the hand stays down is one stroke",
          "[sim][strike]")
{
    // Two contacts 40 ms apart; between them the bead flies 2 cm high (over
    // the 1 cm bounce height). When the hand (the held bead) stayed below the
    // head the second contact is a bounce of the same stroke; when the hand
    // lifted the stick 2 cm and drives it down again through the onset it is
    // a new stroke; when the hand lifted it and stays up (the stick falls back
    // onto the head on its fulcrum by itself) it is a bounce again. A hand that
    // pressed the stick into the head (a buzz: the held bead going down, below
    // the head) and then lifts it 3.6 cm at 3 m/s, the stick springing back
    // onto the head on its fulcrum, did not drive a stroke either: a bounce
    // (random scores 153, 208: the buzz's hand lifting for its next note).
    enum Hand { stays_down, lifts_and_drives, lifts_and_stays, presses_then_lifts };
    for (const Hand hand : {stays_down, lifts_and_drives, lifts_and_stays, presses_then_lifts}) {
        StrikeDetector det(flat_membrane(5825.0, 3.0));
        const double r = 0.007;
        std::vector<StrikeEvent> events;
        StrikeEvent e;
        for (int n = 0; n <= 120; ++n) {
            const double t = n * 1e-3;
            // Bead: down into the head at 1-4 ms and 40-44 ms, a 2 cm arc between.
            double gap;
            if (t < 0.001)
                gap = 0.002;
            else if (t <= 0.004 || (t >= 0.040 && t <= 0.044))
                gap = -0.001;
            else if (t < 0.040)
                gap = 0.02 * std::sin(M_PI * (t - 0.004) / 0.036);
            else
                gap = 0.01;
            TipSample s;
            s.time_s = t;
            s.center_m = Eigen::Vector3d(0.0, r + gap, 0.0);
            s.velocity_mps = Eigen::Vector3d(0.0, gap < 0 ? -1.0 : 1.0, 0.0);
            // The held bead: below the head, or lifted 2.5 cm by 25 ms and then
            // either brought down at 1.25 m/s through the onset (40 ms) or held up.
            double held = -0.005;
            if (hand == presses_then_lifts && t > 0.005)
                held =
                    t <= 0.028 ? -0.005 - 0.015 * (t - 0.005) / 0.023 : -0.02 + 3.0 * (t - 0.028);
            else if (hand != stays_down && t > 0.005) {
                const double up = 0.025 * std::min(1.0, (t - 0.005) / 0.02);
                held = -0.005 + up;
                if (hand == lifts_and_drives && t > 0.025)
                    held = std::max(-0.005, 0.02 - 1.25 * (t - 0.025));
            }
            s.held_center_m = Eigen::Vector3d(0.0, r + held, 0.0);
            s.effective_mass_kg = 0.015;
            if (det.update(1, s, e))
                events.push_back(e);
        }
        REQUIRE(events.size() == 2);
        INFO("hand: " << hand);
        CHECK_FALSE(events[0].bounce);
        CHECK(events[1].bounce == (hand != lifts_and_drives));
        CHECK(events[1].stroke == (hand == lifts_and_drives ? 1 : 0));
        // The effective mass at the onset rides with the strike.
        CHECK(events[0].stick_mass_kg == 0.015);
    }
}

TEST_CASE("strike: a seq claimed for the foot's strike keeps onset order with the hands'",
          "[sim][strike]")
{
    // The left hand down at 1 m/s through the head at t = 20.5 ms (its
    // onset found in the step that ends at 21 ms), the foot's onset claimed
    // in that step before and after it.
    for (double foot_t : {0.0202, 0.0208}) {
        INFO(foot_t);
        StrikeDetector det(flat_membrane(5000.0, 0.0));
        StrikeEvent e;
        long foot_seq = -1;
        for (int n = 0; n <= 23; ++n) {
            TipSample t;
            t.time_s = n * 1e-3;
            t.center_m = Eigen::Vector3d(0.0, 0.0075 + 0.001 * (20 - n), 0.0);
            t.velocity_mps = Eigen::Vector3d(0.0, -1.0, 0.0);
            const long first = det.strikes();
            det.update(0, t, e);
            if (n == 21)
                foot_seq = det.claim_seq(foot_t, first);
        }
        REQUIRE(det.take_onset(0, e));
        CHECK(e.time_s == Approx(0.0205).margin(1e-9));
        // Two strikes numbered 0 and 1 in onset order, whichever came first.
        CHECK(foot_seq == (foot_t < 0.0205 ? 0 : 1));
        CHECK(e.seq == (foot_t < 0.0205 ? 1 : 0));
        // The foot's strike is open until it ends: nothing after it is released.
        CHECK(det.first_open_seq() == 0);
        det.end_claimed();
        CHECK(det.first_open_seq() == e.seq); // the hand still presses
        // A later claim, in a later step, takes the next seq.
        CHECK(det.claim_seq(0.030, det.strikes()) == 2);
    }
}
