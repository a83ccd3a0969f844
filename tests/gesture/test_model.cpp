// The parametric stroke model and the database: shapes checked against
// properties stated independently of the code (docs/gestures.md): strike at the
// lowest point with a downward approach, C1 elsewhere, the loudness order of
// preparation heights and impact speeds, monotonic dynamics, the nuances'
// path features, the grips' lateral arc, the mirror image of the hands.
#include "ictus/gesture/gesture.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

using namespace ictus;

namespace
{

const Grip kGrips[] = {Grip::french, Grip::german};
const Side kHands[] = {Side::left, Side::right};

std::vector<Nuance> all_nuances()
{
    std::vector<Nuance> v;
    for (int i = 0; i < kNuances; ++i)
        v.push_back(static_cast<Nuance>(i));
    return v;
}

// Finite-difference velocity between samples k and k+1, m/s.
Eigen::Vector3d fd_velocity(const GestureUnit &u, int k)
{
    return (u.tip_m[k + 1] - u.tip_m[k]) * u.rate_hz;
}

double height_at(const GestureUnit &u, double t_from_strike_s)
{
    return u.sample(u.strike_time_s() + t_from_strike_s).y();
}

double max_abs(const GestureUnit &u, int axis)
{
    double m = 0.0;
    for (const auto &p : u.tip_m)
        m = std::max(m, std::abs(p[axis]));
    return m;
}

} // namespace

TEST_CASE("nuance names round-trip and bad names list the valid ones", "[gesture][names]")
{
    for (Nuance n : all_nuances())
        CHECK(nuance_from_string(to_string(n)) == n);
    CHECK(nuance_from_string("vertical-accent") == Nuance::vertical_accent);
    CHECK(std::string(to_string(Nuance::vertical_accent)) == "vertical_accent");
    try {
        nuance_from_string("fortissimo");
        FAIL("no error for an unknown nuance");
    } catch (const GestureError &e) {
        const std::string m = e.what();
        CHECK(m.find("fortissimo") != std::string::npos);
        for (const char *name :
             {"legato", "tenuto", "accent", "vertical_accent", "staccato", "buzz"})
            CHECK(m.find(name) != std::string::npos);
    }
    CHECK_THROWS_AS(side_from_string("middle"), GestureError);
    CHECK(side_from_string("L") == Side::left);
}

TEST_CASE("the builtin database holds 2 grips x 6 nuances x 2 hands at 250 Hz", "[gesture][db]")
{
    const GestureDatabase db = GestureDatabase::builtin();
    CHECK(db.units().size() == 2 * kNuances * 2);
    CHECK(kNuances == 6);
    for (Grip g : kGrips)
        for (Nuance n : all_nuances())
            for (Side h : kHands) {
                const GestureUnit *u = db.find(g, n, h);
                REQUIRE(u != nullptr);
                CHECK(u->rate_hz == 250.0);
                CHECK(u->source == "model");
                CHECK(u->stick_dir.size() == u->tip_m.size());
                // One unit spans one period: apex to strike to apex.
                CHECK(u->duration_s() == Approx(0.5).margin(1.0 / 250));
            }
}

TEST_CASE("every unit strikes at its lowest point, at the origin, from above", "[gesture][model]")
{
    for (double period : {0.25, 0.5, 1.2})
        for (double d : {0.0, 0.6, 1.0})
            for (Grip g : kGrips)
                for (Nuance n : all_nuances())
                    for (Side h : kHands) {
                        INFO(to_string(g) << " " << to_string(n) << " " << to_string(h)
                                          << " d=" << d << " period=" << period);
                        const GestureUnit u = stroke_model(g, n, h, d, period);
                        const int s = u.strike_index;
                        REQUIRE(s > 2);
                        REQUIRE(s < u.samples() - 3);
                        CHECK(u.tip_m[s].norm() == 0.0);
                        // The buzz presses on into the head after the strike (at most
                        // its 2 cm press), then lifts like the others.
                        const bool press = n == Nuance::buzz;
                        int lift = s + 1;
                        if (press) {
                            while (lift < u.samples() && u.tip_m[lift].y() <= 0.0)
                                ++lift;
                            REQUIRE(lift < u.samples());
                            for (int k = s + 1; k < lift; ++k)
                                REQUIRE(u.tip_m[k].y() >= -0.02 - 1e-12);
                            REQUIRE(u.tip_m[s + 1].y() < 0.0);
                        }
                        for (int k = 0; k < u.samples(); ++k) {
                            REQUIRE(u.tip_m[k].allFinite());
                            if (k != s && (k < s || k >= lift))
                                REQUIRE(u.tip_m[k].y() > 0.0);
                        }
                        // Apex at both ends: the highest points of each phase.
                        for (int k = 1; k <= s; ++k)
                            REQUIRE(u.tip_m[k].y() <= u.tip_m[0].y());
                        for (int k = s; k < u.samples() - 1; ++k)
                            REQUIRE(u.tip_m[k].y() <= u.tip_m.back().y());
                        // Height falls monotonically to the strike, rises after
                        // to the apex within 0.4 s of leaving the head (the longest
                        // lift, docs/gestures.md) and waits there.
                        for (int k = 1; k <= s; ++k)
                            REQUIRE(u.tip_m[k].y() < u.tip_m[k - 1].y());
                        const double apex = u.tip_m.back().y();
                        for (int k = lift + 1; k < u.samples(); ++k) {
                            if (u.tip_m[k - 1].y() < apex)
                                REQUIRE(u.tip_m[k].y() > u.tip_m[k - 1].y());
                            else
                                REQUIRE(u.tip_m[k].y() == apex);
                        }
                        const int at_apex = static_cast<int>(
                            std::find_if(u.tip_m.begin() + lift, u.tip_m.end(),
                                         [&](const Eigen::Vector3d &p) { return p.y() == apex; }) -
                            u.tip_m.begin());
                        CHECK((at_apex - lift) / u.rate_hz <= 0.4 + 1.0 / u.rate_hz);
                        // A clear downward approach: the last sample interval
                        // before the strike falls at over half the impact speed.
                        CHECK(-fd_velocity(u, s - 1).y() > 0.5 * u.impact_speed_mps());
                        for (const auto &dvec : u.stick_dir)
                            REQUIRE(dvec.norm() == Approx(1.0).epsilon(1e-9));
                    }
}

TEST_CASE("units are C1 except at the strike, where the velocity reverses", "[gesture][model]")
{
    for (Grip g : kGrips)
        for (Nuance n : all_nuances())
            for (double d : {0.0, 0.5, 1.0}) {
                INFO(to_string(g) << " " << to_string(n) << " d=" << d);
                const GestureUnit u = stroke_model(g, n, Side::right, d);
                const int s = u.strike_index;
                const double v_impact = u.impact_speed_mps();
                // Sampling a C1 curve whose acceleration is bounded, the
                // velocity changes between consecutive intervals by
                // a_max / 250 Hz: far below the impact speed. A corner (or a
                // jump in position) changes it by the size of the corner.
                // The buzz's press starts at the strike with a 12 ms time constant:
                // its first 40 ms curve as fast as that (checked in its own test).
                const int press_end = n == Nuance::buzz ? s + 10 : s;
                double max_jump = 0.0;
                for (int k = 0; k + 2 < u.samples(); ++k) {
                    if (k + 1 >= s && k + 1 <= press_end)
                        continue; // the impact: the intervals on both sides of it
                    max_jump =
                        std::max(max_jump, (fd_velocity(u, k + 1) - fd_velocity(u, k)).norm());
                }
                // The press has its own speed scale, 2 cm / 12 ms (docs/gestures.md),
                // whatever the impact speed: a soft buzz presses as a loud one does.
                const double v_scale =
                    n == Nuance::buzz ? std::max(v_impact, 0.02 / 0.012) : v_impact;
                CHECK(max_jump < 0.1 * v_scale);
                // The corner at the strike is there, and as big as a reversal (the
                // buzz does not reverse: the hand presses on).
                if (n != Nuance::buzz)
                    CHECK((fd_velocity(u, s) - fd_velocity(u, s - 1)).norm() > v_impact);
                else
                    CHECK(fd_velocity(u, s).y() < 0.0);
                // The interpolant is C1 across the sample boundaries too.
                const double dt = 1.0 / u.rate_hz, eps = 1e-7;
                for (int k = 1; k + 1 < u.samples(); ++k) {
                    if (k == s)
                        continue;
                    const Eigen::Vector3d vl = u.velocity(k * dt - eps),
                                          vr = u.velocity(k * dt + eps);
                    REQUIRE((vl - vr).norm() < 1e-3 * (1.0 + v_impact));
                    const Eigen::Vector3d pl = u.sample(k * dt - eps), pr = u.sample(k * dt + eps);
                    REQUIRE((pl - pr).norm() < 3.0 * eps * (1.0 + v_impact));
                }
                // The interpolant's derivative matches a central difference of
                // sample() (a second method) mid-segment.
                for (double t : {0.1 * u.duration_s(), 0.77 * u.duration_s()}) {
                    const double h = 1e-6;
                    const Eigen::Vector3d fd = (u.sample(t + h) - u.sample(t - h)) / (2 * h);
                    CHECK((fd - u.velocity(t)).norm() < 1e-4 * (1.0 + fd.norm()));
                }
            }
}

TEST_CASE("impact speed from the interpolant agrees with the sampled approach", "[gesture][model]")
{
    // The impact speed is the interpolant's left derivative at the strike;
    // the last interval's mean speed is its value half a sample earlier, a
    // little lower for an accelerating downswing.
    for (Nuance n : all_nuances()) {
        const GestureUnit u = stroke_model(Grip::french, n, Side::right, 0.6);
        const double mean_last = -fd_velocity(u, u.strike_index - 1).y();
        CHECK(u.impact_speed_mps() >= mean_last);
        CHECK(u.impact_speed_mps() < 1.15 * mean_last);
        // Plausible drum stroke speeds: 0.5 .. 15 m/s (Dahl 2004 reports
        // striking velocities of a few m/s; the TrajOptDrums stroke ~9 m/s).
        CHECK(u.impact_speed_mps() > 0.5);
        CHECK(u.impact_speed_mps() < 15.0);
    }
}

TEST_CASE("impact speed is monotonic in loudness order and dynamics", "[gesture][model]")
{
    // Dynamics set the height (d^1.3, floor 1.5 cm), the nuance brings it to
    // k_n x legato's impact speed (docs/gestures.md, "Dynamics rule"). Above
    // the floor (legato reaches it near d = 0.087, the others by d = 0.094) both orders are strict;
    // under it the strokes are all 1.5 cm high and may tie.
    const GestureDatabase db = GestureDatabase::builtin();
    for (Grip g : kGrips)
        for (Side h : kHands) {
            double previous_row[kNuances] = {0, 0, 0, 0, 0, 0};
            for (int step = 0; step <= 100; ++step) {
                const double d = step / 100.0;
                const bool above_floor = d >= 0.1;
                double previous = 0.0;
                for (int rank = 0; rank < kNuances; ++rank) {
                    const Nuance n = kLoudnessOrder[rank];
                    INFO(to_string(g) << " " << to_string(h) << " " << to_string(n) << " d=" << d);
                    const double v = db.instantiate(g, n, h, d).impact_speed_mps();
                    if (above_floor) {
                        REQUIRE(v > previous);           // louder nuance, same dynamics
                        REQUIRE(v > previous_row[rank]); // same nuance, louder dynamics
                    } else {
                        REQUIRE(v >= previous_row[rank]);
                    }
                    previous = v;
                    previous_row[rank] = v;
                }
            }
        }
    // The nuance's band: impact speed k_n x legato's at the same dynamics
    // (the table in docs/gestures.md), within the 250 Hz sampling of the
    // downswing (a few per cent).
    const std::pair<Nuance, double> bands[] = {{Nuance::tenuto, 0.85},
                                               {Nuance::buzz, 0.9},
                                               {Nuance::staccato, 1.1},
                                               {Nuance::accent, 1.2},
                                               {Nuance::vertical_accent, 1.3}};
    for (double d : {0.3, 0.6, 1.0}) {
        const double v_leg =
            db.instantiate(Grip::german, Nuance::legato, Side::right, d).impact_speed_mps();
        for (const auto &[n, k] : bands) {
            INFO(to_string(n) << " d=" << d);
            CHECK(db.instantiate(Grip::german, n, Side::right, d).impact_speed_mps() / v_leg ==
                  Approx(k).epsilon(0.05));
        }
    }
    // Clamped outside [0, 1].
    const double v1 =
        db.instantiate(Grip::french, Nuance::accent, Side::right, 1.0).impact_speed_mps();
    CHECK(db.instantiate(Grip::french, Nuance::accent, Side::right, 7.0).impact_speed_mps() == v1);
    const double v0 =
        db.instantiate(Grip::french, Nuance::accent, Side::right, 0.0).impact_speed_mps();
    CHECK(db.instantiate(Grip::french, Nuance::accent, Side::right, -3.0).impact_speed_mps() == v0);
    const GestureUnit nan_unit =
        db.instantiate(Grip::french, Nuance::accent, Side::right, std::nan(""));
    for (const auto &p : nan_unit.tip_m)
        REQUIRE(p.allFinite());
}

TEST_CASE("preparation heights follow the dynamics and the accents", "[gesture][model]")
{
    // Accents are prepared from higher than the legato at the same dynamics
    // (Dahl 2000, 2004), the vertical accent highest.
    for (Grip g : kGrips)
        for (double d : {0.1, 0.6, 1.0}) {
            const double leg =
                stroke_model(g, Nuance::legato, Side::right, d).preparation_height_m();
            const double acc =
                stroke_model(g, Nuance::accent, Side::right, d).preparation_height_m();
            const double ver =
                stroke_model(g, Nuance::vertical_accent, Side::right, d).preparation_height_m();
            INFO(to_string(g) << " d=" << d);
            CHECK(acc > leg);
            CHECK(ver > acc);
        }
    // Dynamics: the height grows as d^1.3 (the stroke-height principle), from
    // 0.36 m at d = 1 down to the 1.5 cm floor.
    const auto legato_height = [](double d) {
        return stroke_model(Grip::german, Nuance::legato, Side::right, d).preparation_height_m();
    };
    CHECK(legato_height(1.0) == Approx(0.36).epsilon(1e-9));
    CHECK(legato_height(1.0) / legato_height(0.5) == Approx(std::pow(2.0, 1.3)).epsilon(1e-9));
    CHECK(legato_height(0.2) / legato_height(0.1) == Approx(std::pow(2.0, 1.3)).epsilon(1e-9));
    CHECK(legato_height(0.0) == Approx(0.015).epsilon(1e-9));
}

TEST_CASE("a tenuto is not softer than a legato written one level softer", "[gesture][model]")
{
    // The score's dynamics words pp .. ff (docs/score.md): the nuance shapes the motion, the
    // dynamics set the loudness, so each word's tenuto (the softest nuance) lands at least as
    // fast as the legato of the word below it.
    const double words[] = {0.2, 0.3, 0.45, 0.6, 0.8, 1.0};
    const GestureDatabase db = GestureDatabase::builtin();
    for (Grip g : kGrips)
        for (Side h : kHands)
            for (int k = 1; k < 6; ++k) {
                const double ten =
                    db.instantiate(g, Nuance::tenuto, h, words[k]).impact_speed_mps();
                const double leg =
                    db.instantiate(g, Nuance::legato, h, words[k - 1]).impact_speed_mps();
                INFO(to_string(g) << " " << to_string(h) << " tenuto " << words[k] << ": " << ten
                                  << " m/s, legato " << words[k - 1] << ": " << leg << " m/s");
                CHECK(ten >= leg);
            }
}

TEST_CASE("nuance path features: vertical accent, staccato, tenuto", "[gesture][model]")
{
    for (Grip g : kGrips)
        for (Side h : kHands) {
            INFO(to_string(g) << " " << to_string(h));
            const GestureUnit legato = stroke_model(g, Nuance::legato, h, 0.6);
            const GestureUnit accent = stroke_model(g, Nuance::accent, h, 0.6);
            const GestureUnit vertical = stroke_model(g, Nuance::vertical_accent, h, 0.6);
            const GestureUnit staccato = stroke_model(g, Nuance::staccato, h, 0.6);
            const GestureUnit tenuto = stroke_model(g, Nuance::tenuto, h, 0.6);
            // The vertical accent is higher than the accent yet moves less
            // forward/back: under half the accent's excursion.
            CHECK(vertical.preparation_height_m() > accent.preparation_height_m());
            CHECK(max_abs(vertical, 2) < 0.5 * max_abs(accent, 2));
            // Relative to its own height, too (a path closer to vertical).
            CHECK(max_abs(vertical, 2) / vertical.preparation_height_m() <
                  0.5 * max_abs(legato, 2) / legato.preparation_height_m());
            // Staccato lifts away quickly: 40 ms after the hit it has risen
            // more than the legato, absolutely and as a fraction of its lift.
            const double t = 0.040;
            CHECK(height_at(staccato, t) > height_at(legato, t));
            CHECK(height_at(staccato, t) / staccato.tip_m.back().y() >
                  1.3 * height_at(legato, t) / legato.tip_m.back().y());
            // Tenuto stays close to the head after the hit.
            CHECK(height_at(tenuto, t) / tenuto.tip_m.back().y() <
                  0.7 * height_at(legato, t) / legato.tip_m.back().y());
            // (Not lower in absolute terms: at the same dynamics its slower,
            // less whipped downswing needs a higher start for its impact speed.)
        }
}

TEST_CASE("grips differ in the stick's rotation and the tip's lateral arc", "[gesture][model]")
{
    for (Nuance n : all_nuances()) {
        const GestureUnit french = stroke_model(Grip::french, n, Side::right, 0.6);
        const GestureUnit german = stroke_model(Grip::german, n, Side::right, 0.6);
        INFO(to_string(n));
        // French: forearm rotation swings the tip outward (to the right for
        // the right hand) as it rises; German: a wrist stroke in the stick's
        // vertical plane, little lateral motion.
        CHECK(french.tip_m.front().x() > 0.0);
        CHECK(max_abs(french, 0) > 2.0 * max_abs(german, 0));
        // Both sticks point forward and inward (-x for the right hand) at the
        // strike and pitch up as the tip rises.
        for (const GestureUnit *u : {&french, &german}) {
            const Eigen::Vector3d d0 = u->stick_dir[u->strike_index];
            CHECK(d0.z() > 0.8);
            CHECK(d0.x() < 0.0);
            CHECK(d0.y() < 0.0);
            CHECK(u->stick_dir.front().y() > d0.y() + 0.2);
        }
        // The stick turns outward (its x grows from strike to apex) much
        // more in the French grip's stroke than in the German wrist stroke.
        const double turn_french =
            french.stick_dir.front().x() - french.stick_dir[french.strike_index].x();
        const double turn_german =
            german.stick_dir.front().x() - german.stick_dir[german.strike_index].x();
        CHECK(turn_french > 0.1);
        CHECK(turn_french > 2.0 * std::abs(turn_german));
    }
}

TEST_CASE("the left hand is the mirror image of the right", "[gesture][model]")
{
    for (Nuance n : all_nuances()) {
        const GestureUnit r = stroke_model(Grip::french, n, Side::right, 0.7);
        const GestureUnit l = stroke_model(Grip::french, n, Side::left, 0.7);
        REQUIRE(r.samples() == l.samples());
        for (int k = 0; k < r.samples(); ++k) {
            REQUIRE(l.tip_m[k].x() == -r.tip_m[k].x());
            REQUIRE(l.tip_m[k].y() == r.tip_m[k].y());
            REQUIRE(l.tip_m[k].z() == r.tip_m[k].z());
            REQUIRE(l.stick_dir[k].x() == -r.stick_dir[k].x());
        }
    }
}

TEST_CASE("tempo: the strike lands one downswing after the apex, speed independent of tempo",
          "[gesture][model]")
{
    for (Nuance n : all_nuances()) {
        const double v_nominal =
            stroke_model(Grip::german, n, Side::right, 0.6, 0.5).impact_speed_mps();
        for (double period : {0.3, 0.4, 0.75, 1.5}) {
            const GestureUnit u = stroke_model(Grip::german, n, Side::right, 0.6, period);
            INFO(to_string(n) << " period " << period);
            CHECK(u.duration_s() == Approx(period).margin(1.0 / 250));
            // The dynamics set the strike speed; the tempo only the geometry
            // (rounding of the downswing to whole samples aside).
            CHECK(u.impact_speed_mps() == Approx(v_nominal).epsilon(0.05));
            if (period < 0.5)
                CHECK(u.preparation_height_m() <
                      stroke_model(Grip::german, n, Side::right, 0.6, 0.5).preparation_height_m());
        }
    }
}

TEST_CASE("instantiate: model units regenerated, imported units scaled, fallback to builtin",
          "[gesture][db]")
{
    GestureDatabase empty;
    const GestureUnit fb = empty.instantiate(Grip::german, Nuance::staccato, Side::left, 0.8);
    const GestureUnit direct = stroke_model(Grip::german, Nuance::staccato, Side::left, 0.8);
    REQUIRE(fb.samples() == direct.samples());
    for (int k = 0; k < fb.samples(); ++k)
        REQUIRE(fb.tip_m[k] == direct.tip_m[k]);

    // An imported unit: heights scale by (d / d0)^1.3 above the model's floor (d = 0.087).
    GestureUnit imported = stroke_model(Grip::french, Nuance::legato, Side::right, 0.6);
    imported.source = "mine.csv";
    for (auto &p : imported.tip_m)
        p.x() += 0.01 * p.y(); // anything not the model
    GestureDatabase db;
    db.add(imported);
    CHECK(db.units().size() == 1);
    db.add(imported); // replaces
    CHECK(db.units().size() == 1);
    const GestureUnit loud = db.instantiate(Grip::french, Nuance::legato, Side::right, 1.0);
    CHECK(loud.source == "mine.csv");
    CHECK(loud.preparation_height_m() ==
          Approx(imported.preparation_height_m() * std::pow(1.0 / 0.6, 1.3)));
    CHECK(loud.tip_m[3].x() == imported.tip_m[3].x());
    double previous = 0.0;
    for (int step = 2; step <= 50; ++step) { // from d = 0.04, where the clamp ends
        const double v = db.instantiate(Grip::french, Nuance::legato, Side::right, step / 50.0)
                             .impact_speed_mps();
        if (step / 50.0 > 0.09) // above the floor, where every softer level is the floor's
            REQUIRE(v > previous);
        else
            REQUIRE(v == Approx(previous == 0.0 ? v : previous));
        previous = v;
    }
    // Others fall back to the builtin.
    REQUIRE(db.find(Grip::french, Nuance::accent, Side::right) == nullptr);
    CHECK(db.instantiate(Grip::french, Nuance::accent, Side::right, 0.6).source == "model");
}

TEST_CASE("instantiate: an imported unit of level d0 played at d has the model's height at d, "
          "down to level 0 (the model's softest stroke)",
          "[gesture][db]")
{
    // A capture that is the model's legato at d0, imported as representing d0: played
    // at d, its preparation height is the model's at d, max(1.5 cm, 0.36 m x d^1.3)
    // (docs/gestures.md), whatever d0 and d, the floor's levels (d < 0.087) included.
    std::mt19937 rng(20261203);
    std::uniform_real_distribution<double> level(0.0, 1.0);
    std::vector<std::pair<double, double>> cases = {
        {0.0, 0.6}, {0.0, 1.0}, {0.0, 0.0}, {0.02, 0.6}, {0.04, 0.3}, {0.6, 0.0}, {1.0, 0.05}};
    for (int k = 0; k < 40; ++k)
        cases.emplace_back(level(rng) * (k % 2 ? 1.0 : 0.12), level(rng));
    for (const auto &[d0, d] : cases) {
        GestureUnit imported = stroke_model(Grip::french, Nuance::legato, Side::right, d0);
        imported.source = "capture.csv";
        GestureDatabase db;
        db.add(imported);
        const double expected = std::max(0.015, 0.36 * std::pow(d, 1.3));
        INFO("d0 " << d0 << ", d " << d);
        CHECK(db.instantiate(Grip::french, Nuance::legato, Side::right, d).preparation_height_m() ==
              Approx(expected).epsilon(1e-9));
    }
    // Level 0 at mf: 12.3x the softest stroke's height (0.36 x 0.6^1.3 / 0.015), not the
    // 34x (0.6 / 0.04)^1.3 of a level the model never plays.
    GestureUnit ppp = stroke_model(Grip::french, Nuance::legato, Side::right, 0.0);
    ppp.source = "capture.csv";
    GestureDatabase db;
    db.add(ppp);
    CHECK(db.instantiate(Grip::french, Nuance::legato, Side::right, 0.6).preparation_height_m() /
              ppp.preparation_height_m() ==
          Approx(0.36 * std::pow(0.6, 1.3) / 0.015).epsilon(1e-9));
}

TEST_CASE("a unit with two periods: the downswing of the one before, the lift of the one after, "
          "the same impact speed",
          "[gesture][model]")
{
    // docs/gestures.md: D = prep_fraction x min(period, 0.5 s), heights in
    // proportion to min(1, period / 0.5 s), lift apex = lift_ratio x height,
    // impact speed p H / D. With two periods the downswing (D, H) is the
    // first period's unit's and the lift (its duration and apex) the second's.
    std::mt19937 rng(2611);
    std::uniform_real_distribution<double> period(0.1, 1.5), dyn(0.0, 1.0);
    for (int trial = 0; trial < 60; ++trial) {
        const Grip g = kGrips[trial % 2];
        const Nuance n = static_cast<Nuance>(trial % kNuances);
        const Side h = kHands[(trial / 2) % 2];
        const double d = dyn(rng), before = period(rng), after = period(rng);
        INFO(to_string(g) << " " << to_string(n) << " d=" << d << " before=" << before
                          << " after=" << after);
        const GestureUnit u = stroke_model(g, n, h, d, before, after);
        const GestureUnit a = stroke_model(g, n, h, d, before);
        const GestureUnit b = stroke_model(g, n, h, d, after);
        // The downswing sample by sample, and the lift's duration and apex.
        REQUIRE(u.strike_index == a.strike_index);
        for (int k = 0; k <= u.strike_index; ++k)
            REQUIRE((u.tip_m[k] - a.tip_m[k]).norm() < 1e-12);
        CHECK(u.samples() - u.strike_index == b.samples() - b.strike_index);
        CHECK(u.tip_m.back().y() == Approx(b.tip_m.back().y()).epsilon(1e-9));
        CHECK(u.impact_speed_mps() == Approx(a.impact_speed_mps()).epsilon(1e-9));
        CHECK(u.period_s == Approx(std::clamp(after, 0.1, 4.0)));
    }
}
