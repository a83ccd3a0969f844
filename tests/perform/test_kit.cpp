// A kit (docs/perform.md, "A kit"): the built-in kits' layouts (no two shells
// closer than 2 cm in plan, every drum within the arms' and sticks' reach of
// a shoulder), the checks that refuse a bad kit, the scene built with every
// drum, and the strike detector giving each strike its drum.
#include "ictus/character/range_of_motion.hpp"
#include "ictus/perform/kit.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/perform/perform_error.hpp"
#include "ictus/perform/strike_log.hpp"
#include "ictus/perform/strike_match.hpp"
#include "ictus/score/score.hpp"
#include "ictus/sim/strike_detector.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace ictus;
using Catch::Matchers::Contains;

namespace
{

void require_refused(const Kit &kit, const std::string &words)
{
    try {
        validate_kit(kit);
        FAIL("kit accepted");
    } catch (const PerformError &e) {
        CHECK_THAT(e.what(), Contains(words));
    }
}

} // namespace

TEST_CASE("kit: the built-in kits placed in the scene: no shells within 2 cm, all within reach",
          "[perform][kit]")
{
    for (const char *name :
         {"standard", "standard-cymbals", "full", "standard-timpani", "timpani"}) {
        INFO(name);
        PerformanceOptions o;
        o.kit = kit_named(name);
        o.score.score_text = "R";
        Performance perf(o);
        const Scene &scene = perf.scene();
        // The sticks' scene has the hands' pieces (the kick is the foot's).
        REQUIRE(scene.drum_count() == kit_hand_pieces(o.kit));
        // Shells in plan view: centre distance less the two radii, from the
        // placed scene (world frame, y up).
        for (int i = 0; i < scene.drum_count(); ++i)
            for (int j = i + 1; j < scene.drum_count(); ++j) {
                const Eigen::Vector3d d = scene.drum(i).center_m - scene.drum(j).center_m;
                CHECK(std::hypot(d.x(), d.z()) - scene.drum(i).radius_m - scene.drum(j).radius_m >=
                      0.02);
            }
        // Reach: the clavicle's root to the shoulder, elbow, wrist and the
        // stick's tip, straightened, from the body at rest (its frames and
        // tips), against the distance from the nearer root to the head's
        // nearest point at r/a 0.3 (a cymbal's: at kCymbalRadiusFraction, where
        // it is played): at most 95 % of it (the arm a little bent).
        const CharacterModel &m = scene.model();
        BodyFrames f;
        scene.body_frames(f);
        double reach[2];
        Eigen::Vector3d shoulder[2];
        for (int s = 0; s < 2; ++s) {
            const std::string p = s == 0 ? "l_" : "r_";
            shoulder[s] = f.origin_m[m.body_index(p + "clavicle")]; // the arm's chain from here
            const Eigen::Vector3d arm = f.origin_m[m.body_index(p + "upper_arm")];
            const Eigen::Vector3d elbow = f.origin_m[m.body_index(p + "forearm")];
            const Eigen::Vector3d wrist = f.origin_m[m.body_index(p + "hand")];
            reach[s] = (arm - shoulder[s]).norm() + (elbow - arm).norm() + (wrist - elbow).norm() +
                       (scene.tip_position(static_cast<Side>(s)) - wrist).norm();
        }
        for (int i = 0; i < scene.drum_count(); ++i) {
            const DrumParams &d = scene.drum(i);
            double best = 1e9;
            for (int s = 0; s < 2; ++s) {
                Eigen::Vector3d toward = shoulder[s] - d.center_m;
                toward.y() = 0.0;
                const double r_over_a =
                    o.kit.drums[static_cast<size_t>(i)].cymbal() ? kCymbalRadiusFraction : 0.3;
                const Eigen::Vector3d spot =
                    d.center_m + r_over_a * d.radius_m * toward.normalized();
                best = std::min(best, (spot - shoulder[s]).norm() / reach[s]);
            }
            INFO("drum " << i);
            CHECK(best < 0.95);
        }
    }
}

TEST_CASE("kit: full is standard-cymbals and a 22-inch kick for the right foot, last, off the "
          "sticks' scene",
          "[perform][kit]")
{
    const Kit full = kit_named("full"), cymbals = kit_named("standard-cymbals");
    REQUIRE(full.drums.size() == cymbals.drums.size() + 1);
    for (size_t i = 0; i < cymbals.drums.size(); ++i) {
        CHECK(full.drums[i].name == cymbals.drums[i].name);
        CHECK(!full.drums[i].foot);
    }
    const KitDrum &kick = full.drums.back();
    CHECK((kick.name == "kick" && kick.preset == "kick" && kick.foot && !kick.cymbal()));
    CHECK(kick.radius_m == Approx(11.0 * 0.0254)); // 22 inches across
    CHECK(kick.midi_note == 36);                   // General MIDI's Bass Drum 1
    CHECK(kit_hand_pieces(full) == static_cast<int>(cymbals.drums.size()));
    CHECK(kit_foot_piece(full) == static_cast<int>(full.drums.size()) - 1);
    CHECK(kit_foot_piece(cymbals) == -1);
    // Its centre half its diameter above the floor, before the right foot.
    CHECK(kick.place_m.y() == Approx(kick.radius_m));
    CHECK(kick.place_m.x() == 0.0);
    CHECK((kick.place_m.z() > 0.2 && kick.place_m.z() < 0.35)); // a pedal's footboard ahead
    // Placed: the scene has the hands' pieces only, at standard-cymbals'
    // places but for the rack toms (higher, over the kick) and the floor tom
    // (right of the seated right knee; docs/kit.md, "The throne").
    const std::vector<DrumParams> placed =
        place_kit(full, DrumParams(), Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitX(),
                  Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ());
    const std::vector<DrumParams> placed_c =
        place_kit(cymbals, DrumParams(), Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitX(),
                  Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ());
    REQUIRE(placed.size() == placed_c.size());
    for (size_t i = 0; i < placed.size(); ++i) {
        const Eigen::Vector3d moved = placed[i].center_m - placed_c[i].center_m;
        INFO(full.drums[i].name);
        if (full.drums[i].name == "tom1" || full.drums[i].name == "tom2")
            CHECK((moved.x() == 0.0 && moved.z() == 0.0 && moved.y() > 0.1 && moved.y() < 0.2));
        else if (full.drums[i].name == "floor" || full.drums[i].name == "ride")
            CHECK((moved.y() == 0.0 && moved.norm() > 0.1 && moved.norm() < 0.3));
        else
            CHECK(moved.norm() == 0.0);
    }
    // A foot's piece first, or a hand's after it, is refused.
    Kit k = full;
    std::swap(k.drums.front(), k.drums.back());
    require_refused(k, "a foot's piece is a drum and not the kit's first");
    k = full;
    std::swap(k.drums[6], k.drums[7]);
    require_refused(k, "drum 'hihat': the hands' pieces come before the foot's");
}

namespace
{

// The distance from a point to a solid cylinder (m, < 0 inside): its top
// face's centre, its axis (unit, from the top face into the shell), depth
// and radius.
double to_cylinder(const Eigen::Vector3d &p, const Eigen::Vector3d &top,
                   const Eigen::Vector3d &axis, double depth, double radius)
{
    const Eigen::Vector3d v = p - top;
    const double t = v.dot(axis);
    const double out_r = (v - t * axis).norm() - radius;
    const double out_t = t < 0.0 ? -t : (t > depth ? t - depth : 0.0);
    if (out_r <= 0.0 && out_t == 0.0)
        return std::max(out_r, -std::min(t, depth - t));
    return std::hypot(std::max(out_r, 0.0), out_t);
}

} // namespace

TEST_CASE("kit: seated at the full kit, no leg through a drum, a stand or the kick, no drum "
          "through the kick",
          "[perform][kit]")
{
    PerformanceOptions o;
    o.kit = kit_named("full");
    o.score.score_text = "R";
    Performance perf(o);
    const Scene &scene = perf.scene();
    const CharacterModel &m = scene.model();
    BodyFrames f;
    scene.body_frames(f);
    auto at = [&](const char *body) { return f.origin_m[m.body_index(body)]; };
    // On a throne: the hips 0.15 m lower than standing (0.9 m), the knees
    // bent in front of the hips, the ankles level, a foot's height up.
    CHECK(at("pelvis").y() == Approx(0.75).margin(1e-9));
    for (const char *side : {"l_", "r_"}) {
        const std::string s(side);
        const Eigen::Vector3d hip = at((s + "thigh").c_str()), knee = at((s + "shank").c_str()),
                              ankle = at((s + "foot").c_str());
        CHECK(knee.z() - hip.z() > 0.15);
        CHECK(std::abs(knee.y() - hip.y()) < 0.25);
        // Within 0.1 mm: the knee is a hinge, and the CMU shank's small offset
        // from its flexion plane keeps the ankle off its place by tens of um.
        CHECK(ankle.y() == Approx(0.08).margin(1e-4));
    }
    // Each leg a chain of capsules (radii: a thigh's 38 cm circumference at
    // the knee, a calf's 31 cm, an ankle's 22 cm, over 2 pi), sampled every
    // 1 % of its length; drums and cymbals as solid cylinders (a cymbal a
    // 1 cm disc on a stand: a 2.5 cm rod from the floor to its centre), the
    // kick lying on the floor, its batter facing the performer.
    const struct {
        const char *from, *to;
        double radius_m;
    } legs[] = {{"l_thigh", "l_shank", 0.06}, {"l_shank", "l_foot", 0.05},
                {"r_thigh", "r_shank", 0.06}, {"r_shank", "r_foot", 0.05},
                {"l_foot", "l_foot", 0.035},  {"r_foot", "r_foot", 0.035}};
    const PerformerFrame &frame = perf.performer_frame();
    REQUIRE(frame.drums.size() == o.kit.drums.size());
    const PerformerFrame::Drum &kick = frame.drums.back();
    const KitDrum &kick_k = o.kit.drums.back();
    const Eigen::Vector3d down = -Eigen::Vector3d::UnitY(), forward = Eigen::Vector3d::UnitZ();
    for (size_t i = 0; i < o.kit.drums.size(); ++i) {
        const KitDrum &k = o.kit.drums[i];
        const bool foot = k.foot;
        const Eigen::Vector3d top =
            foot ? kick.membrane_center_m : scene.drum(static_cast<int>(i)).center_m;
        const double radius = foot ? kick_k.radius_m : scene.drum(static_cast<int>(i)).radius_m;
        const Eigen::Vector3d axis = foot ? forward : down;
        INFO(k.name);
        double leg = 1e9, stand = 1e9;
        for (const auto &l : legs)
            for (int n = 0; n <= 100; ++n) {
                const Eigen::Vector3d p = at(l.from) + (at(l.to) - at(l.from)) * (n / 100.0);
                leg =
                    std::min(leg, to_cylinder(p, top, axis, k.shell_depth_m, radius) - l.radius_m);
                if (k.cymbal() && p.y() < top.y())
                    stand = std::min(stand, std::hypot(p.x() - top.x(), p.z() - top.z()) -
                                                l.radius_m - 0.0125);
            }
        CHECK(leg >= kKitMinGap_m);
        if (k.cymbal())
            CHECK(stand >= kKitMinGap_m);
        if (foot)
            continue;
        // Every hand piece clear of the kick: its top, middle and bottom
        // rings and their centres.
        double clear = 1e9;
        for (int a = 0; a < 64; ++a)
            for (double r : {0.0, 0.5, 1.0})
                for (double d : {0.0, 0.5, 1.0}) {
                    const double th = 2.0 * M_PI * a / 64.0;
                    const Eigen::Vector3d p =
                        top + Eigen::Vector3d(r * radius * std::cos(th), -d * k.shell_depth_m,
                                              r * radius * std::sin(th));
                    clear = std::min(clear, to_cylinder(p, kick.membrane_center_m, forward,
                                                        kick_k.shell_depth_m, kick_k.radius_m));
                }
        CHECK(clear >= kKitMinGap_m);
    }
    // The seated legs are within their joints' ranges, so that the scene's
    // limits hold them where they are placed (a knee turned about anything but
    // its hinge is clamped back toward standing, and the feet leave their
    // pedals).
    const RangeOfMotion rom(m);
    for (const char *joint : {"l_hip", "l_knee", "l_ankle", "r_hip", "r_knee", "r_ankle"}) {
        const int j = m.joint_index(joint);
        const int child = j + 1, parent = m.bodies()[static_cast<size_t>(child)].parent;
        const Eigen::Quaterniond local = f.rotation[static_cast<size_t>(parent)].conjugate() *
                                         f.rotation[static_cast<size_t>(child)];
        INFO(joint);
        CHECK(rom.limit(j).excursion_rad(local) < 1e-6);
    }
    // The feet on their pedals: the kick's batter 0.27 m before the right
    // ankle, in line with it; the hi-hat's rod 0.2-0.3 m before the left.
    const Eigen::Vector3d r_ankle = at("r_foot"), l_ankle = at("l_foot");
    CHECK(kick.membrane_center_m.z() - r_ankle.z() == Approx(0.27).margin(1e-9));
    CHECK(kick.membrane_center_m.x() == Approx(r_ankle.x()).margin(1e-9));
    const Eigen::Vector3d hat = scene.drum(6).center_m;
    REQUIRE(o.kit.drums[6].name == "hihat");
    CHECK((hat.z() - l_ankle.z() > 0.2 && hat.z() - l_ankle.z() < 0.3));
    CHECK(std::abs(hat.x() - l_ankle.x()) < 0.1);
    // A kit without a foot piece: standing, as before.
    PerformanceOptions so;
    so.kit = kit_named("standard-cymbals");
    so.score.score_text = "R";
    Performance standing(so);
    standing.scene().body_frames(f);
    CHECK(f.origin_m[0].y() == Approx(0.9).margin(1e-9));
}

TEST_CASE("kit: a bad kit is refused naming the drum and the fault", "[perform][kit]")
{
    Kit k = kit_named("standard");
    k.drums[3].place_m.x() = 0.3; // the floor tom into the snare
    require_refused(k, "two shells are");
    k = kit_named("standard");
    k.drums[2].name = "tom1";
    require_refused(k, "drum 'tom1': the name is given twice");
    k = kit_named("standard");
    k.drums[1].preset = "cowbell";
    require_refused(k, "unknown preset 'cowbell'");
    k = kit_named("standard");
    k.drums[1].preset = "crash"; // a plate's preset on a drum's head (no bending stiffness)
    require_refused(k, "preset 'crash' is a cymbal, and the drum has no bending stiffness");
    k = kit_named("standard-cymbals");
    k.drums[4].preset = "tom"; // a drum's preset on a cymbal
    require_refused(k, "preset 'tom' is a drum, and the drum has a bending stiffness");
    k = kit_named("standard-cymbals");
    std::swap(k.drums[0], k.drums[4]); // the crash first: the one drum's head
    require_refused(k, "drum 'crash': the first drum must be a drum, not a cymbal");
    k = kit_named("standard-cymbals");
    k.drums[5].tension_n_per_m = 3000.0;
    require_refused(k, "drum 'ride': a cymbal's bending stiffness must be 0..1e4 N m");
    k = kit_named("standard");
    k.drums[1].preset = "hihat"; // the hi-hat too: a plate
    require_refused(k, "preset 'hihat' is a cymbal, and the drum has no bending stiffness");
    k = kit_named("standard");
    k.drums[1].name = "Tom 1";
    require_refused(k, "drum name 'Tom 1'");
    k = kit_named("standard");
    k.drums[0].midi_note = 128;
    require_refused(k, "MIDI note must be 0..127");
    k.drums.assign(9, k.drums[0]);
    require_refused(k, "expected 1..8 drums, got 9");
    CHECK_THROWS_WITH(kit_named("jazz"), Contains("unknown kit 'jazz' (valid: standard"));
    // The standard kit's sizes (inches to m) and General MIDI notes.
    const Kit s = kit_named("standard");
    REQUIRE(s.drums.size() == 4);
    const double inch = 0.0254;
    CHECK(s.drums[0].radius_m == Approx(7.0 * inch));
    CHECK(s.drums[1].radius_m == Approx(5.0 * inch));
    CHECK(s.drums[2].radius_m == Approx(6.0 * inch));
    CHECK(s.drums[3].radius_m == Approx(8.0 * inch));
    CHECK(s.drums[0].midi_note == 38);
    CHECK(s.drums[3].midi_note == 43);
}

TEST_CASE("kit: the detector gives a strike the drum its bead came down on", "[perform][kit]")
{
    MembraneGeometry a, b;
    a.center_m = Eigen::Vector3d(0.0, 0.7, 0.45);
    a.radius_m = 0.178;
    b.center_m = Eigen::Vector3d(-0.4, 0.8, 0.45);
    b.radius_m = 0.2;
    b.drum_id = 1;
    StrikeDetectorOptions so;
    so.semi_implicit_samples = false;
    StrikeDetector det(a, so);
    det.set_membrane(b);
    REQUIRE(det.drum_count() == 2);
    // The right hand comes down at 2 m/s onto drum 1, 5 cm from its centre
    // toward world +X (x_m = 0.05), then the left onto drum 0.
    auto drop = [&](int hand, const Eigen::Vector3d &over, double plane_y, double t0) {
        StrikeEvent out, got;
        bool ended = false;
        for (int k = 0; k < 200 && !ended; ++k) {
            TipSample s;
            s.time_s = t0 + k * 0.001;
            const double y = plane_y + 0.007 + 0.05 - 2.0 * k * 0.001; // bead centre
            s.center_m = Eigen::Vector3d(over.x(), k < 40 ? y : plane_y + 0.1, over.z());
            s.velocity_mps = Eigen::Vector3d(0.0, k < 40 ? -2.0 : 2.0, 0.0);
            ended = det.update(hand, s, out);
            if (ended)
                got = out;
        }
        REQUIRE(ended);
        return got;
    };
    const StrikeEvent e1 = drop(1, Eigen::Vector3d(-0.35, 0.0, 0.45), 0.8, 0.0);
    CHECK(e1.drum == 1);
    CHECK(e1.x_m == Approx(0.05).margin(1e-9));
    CHECK(e1.r_over_a == Approx(0.05 / 0.2));
    CHECK(e1.time_s == Approx(0.025)); // 5 cm at 2 m/s
    const StrikeEvent e0 = drop(0, Eigen::Vector3d(0.0, 0.0, 0.40), 0.7, 1.0);
    CHECK(e0.drum == 0);
    CHECK(e0.y_m == Approx(0.05).margin(1e-9));
    CHECK(e0.seq == e1.seq + 1);
}

TEST_CASE("kit: a stick that passed under a cymbal's edge plays the drum it then comes down on",
          "[perform][kit]")
{
    // A cymbal (drum 1) whose plate lies 0.2 m above a drum's head (drum 0),
    // beside it in plan. The bead slides along +X at 0.16 m below the plate,
    // enters the plate's disk from the side (no strike: side_entries 1), leaves
    // it over the drum and comes down on the drum at 2 m/s: one strike of
    // drum 0 with that speed, at the time the bead's bottom reaches the head.
    MembraneGeometry drum, plate;
    drum.center_m = Eigen::Vector3d(0.15, 0.7, 0.45);
    drum.radius_m = 0.178;
    plate.center_m = Eigen::Vector3d(-0.3, 0.9, 0.45);
    plate.radius_m = 0.2;
    plate.drum_id = 1;
    StrikeDetectorOptions so;
    so.semi_implicit_samples = false;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> speed(0.5, 4.0), depth(0.01, 0.15);
    for (int trial = 0; trial < 20; ++trial) {
        StrikeDetector det(drum, so);
        det.set_membrane(plate);
        const double u = speed(rng), v = speed(rng), h = 0.9 - depth(rng);
        const double dt = 0.001, x_turn = 0.1, r = drum.tip_radius_m;
        const double t_turn = (x_turn - -0.6) / u, t_hit = t_turn + (h - r - 0.7) / v;
        std::vector<StrikeEvent> got;
        StrikeEvent out;
        for (int k = 0; k * dt < t_hit + 0.05; ++k) {
            const double t = k * dt;
            TipSample s;
            s.time_s = t;
            // Across under the plate at height h, then down onto the drum,
            // then back up after 10 ms in the head.
            const bool across = t < t_turn, down = !across && t < t_hit + 0.01;
            const double x = across ? -0.6 + u * t : x_turn;
            const double y = across ? h : down ? h - v * (t - t_turn) : 0.7 + r;
            s.center_m = Eigen::Vector3d(x, y, 0.45);
            s.velocity_mps = Eigen::Vector3d(across ? u : 0.0, down ? -v : 0.0, 0.0);
            if (det.update(1, s, out))
                got.push_back(out);
        }
        while (det.flush(out))
            got.push_back(out);
        INFO("trial " << trial << ": across at " << u << " m/s, " << 0.9 - h
                      << " m under the plate, down at " << v << " m/s");
        CHECK(det.side_entries() == 1);
        REQUIRE(got.size() == 1);
        CHECK(got[0].drum == 0);
        CHECK(got[0].normal_velocity_mps == Approx(v).epsilon(1e-9));
        CHECK(got[0].time_s == Approx(t_hit).margin(1e-9));
        CHECK(got[0].x_m == Approx(x_turn - drum.center_m.x()).margin(1e-12));
    }
}

TEST_CASE("kit: the cymbals are plates of cymbal bronze, their contact a disc's point stiffness",
          "[perform][kit]")
{
    const Kit kit = kit_named("standard-cymbals");
    REQUIRE(kit.drums.size() == 7);
    PerformanceOptions o;
    o.kit = kit;
    o.score.score_text = "R";
    Performance perf(o);
    const Scene &scene = perf.scene();
    // The bending stiffness from the bronze alone (E 100 GPa, nu 0.33; docs/plates.md):
    // D = E h^3 / (12 (1 - nu^2)), an 18-inch crash 1.0 mm and a 20-inch ride 1.4 mm thick.
    const double inch = 0.0254;
    struct Want {
        const char *name;
        double diameter_in, h_m;
        int note;
    };
    for (const Want &w : {Want{"crash", 18.0, 1.0e-3, 49}, Want{"ride", 20.0, 1.4e-3, 51}}) {
        INFO(w.name);
        const int i = kit_drum_index(kit, w.name);
        REQUIRE(i > 0);
        const KitDrum &k = kit.drums[static_cast<size_t>(i)];
        const double D = 100e9 * w.h_m * w.h_m * w.h_m / (12.0 * (1.0 - 0.33 * 0.33));
        CHECK(k.cymbal());
        CHECK(k.bending_n_m == Approx(D).epsilon(0.005));
        CHECK(k.tension_n_per_m == 0.0);
        CHECK(k.radius_m == Approx(0.5 * w.diameter_in * inch).epsilon(1e-3));
        CHECK(k.midi_note == w.note);
        // A clamped disc loaded at its centre deflects F R^2 / (16 pi D) (Timoshenko).
        const double R = 0.5 * w.diameter_in * inch;
        CHECK(scene.drum_contact_stiffness_n_per_m(i) ==
              Approx(16.0 * 3.141592653589793 * D / (R * R)).epsilon(0.01));
        // Higher than every drum's head, and no stretching of a film.
        for (int j = 0; j < 4; ++j)
            CHECK(scene.drum(i).center_m.y() > scene.drum(j).center_m.y() + 0.1);
        CHECK(scene.drum(i).stretch_n_per_m3() == 0.0);
    }
    // The drums are as in "standard".
    const Kit s = kit_named("standard");
    for (size_t j = 0; j < s.drums.size(); ++j) {
        CHECK(kit.drums[j].name == s.drums[j].name);
        CHECK(kit.drums[j].place_m == s.drums[j].place_m);
        CHECK_FALSE(kit.drums[j].cymbal());
    }
}

TEST_CASE("kit: a cymbal's strike is on its plate, never its rim", "[perform][kit]")
{
    // A plate's edge is the plate's own (no hoop): a contact at its edge is a
    // strike on it. The same edge contact on a membrane is its rim.
    PerformanceOptions o;
    o.kit = kit_named("standard-cymbals");
    o.score.score_text = "R";
    Performance perf(o);
    const MembraneGeometry crash = membrane_of(perf.scene(), kit_drum_index(o.kit, "crash"));
    const MembraneGeometry snare = membrane_of(perf.scene(), 0);
    CHECK(crash.plate);
    CHECK_FALSE(snare.plate);
}

TEST_CASE("kit: standard-cymbals' hi-hat: a 14-inch plate with a pedal, left of the snare, a "
          "little higher",
          "[perform][kit][hihat]")
{
    const Kit kit = kit_named("standard-cymbals");
    REQUIRE(kit.drums.size() == 7);
    const int h = kit_drum_index(kit, "hihat");
    REQUIRE(h > 0);
    const KitDrum &hh = kit.drums[static_cast<size_t>(h)];
    const KitDrum &snare = kit.drums[0];
    CHECK(hh.preset == "hihat");
    CHECK(hh.cymbal());
    CHECK(hh.radius_m == Approx(7.0 * 0.0254));
    CHECK(hh.midi_note == 42); // General MIDI's Closed Hi-Hat
    CHECK(hh.shell_depth_m == Approx(0.01).epsilon(0.02));
    // Where a right-handed drummer's stands: to the performer's left of the
    // snare (x < 0), clear of it, and above it by less than the crash.
    CHECK(hh.place_m.x() < snare.place_m.x() - snare.radius_m - hh.radius_m);
    CHECK(hh.place_m.y() > snare.place_m.y() + 0.05);
    CHECK(hh.place_m.y() <
          kit.drums[static_cast<size_t>(kit_drum_index(kit, "crash"))].place_m.y());
    // Only the hi-hat has a pedal.
    for (const KitDrum &d : kit.drums)
        CHECK(kit_drum_has_pedal(d) == (d.name == "hihat"));
    for (const char *name : {"standard", "standard-timpani", "timpani"})
        for (const KitDrum &d : kit_named(name).drums)
            CHECK_FALSE(kit_drum_has_pedal(d));
}

namespace
{
PlannedNote note_at(double time_s, Side hand, int drum, double openness)
{
    PlannedNote n;
    n.time_s = time_s;
    n.hand = hand;
    n.drum = drum;
    n.openness = openness;
    return n;
}
StrikeEvent strike_at(double time_s, int hand, int drum, double openness = -1.0)
{
    StrikeEvent e;
    e.time_s = time_s;
    e.hand = hand;
    e.drum = drum;
    e.pedal_openness = openness;
    return e;
}
} // namespace

TEST_CASE("kit: a strike on the hi-hat takes the pedal of the note it plays",
          "[perform][kit][hihat]")
{
    // The plan's notes in time order: the hi-hat is drum 6, the snare 0.
    const std::vector<PlannedNote> notes = {
        note_at(1.00, Side::left, 6, 1.0), note_at(1.10, Side::right, 0, -1.0),
        note_at(1.25, Side::right, 6, 0.0), note_at(1.50, Side::left, 6, 0.5),
        note_at(2.00, Side::left, 6, 0.0)};
    const double origin = 10.0; // simulation time of the plan's time 0
    // Each strike the nearest note of its hand on its drum, a few ms off.
    CHECK(strike_pedal_openness(notes, strike_at(11.003, 0, 6), origin) == 1.0);
    CHECK(strike_pedal_openness(notes, strike_at(10.996, 0, 6), origin) == 1.0);
    CHECK(strike_pedal_openness(notes, strike_at(11.249, 1, 6), origin) == 0.0);
    // Nearer the right hand's note at 1.25, but the left hand's: its own at 1.50.
    CHECK(strike_pedal_openness(notes, strike_at(11.26, 0, 6), origin) == 0.5);
    // The right hand's only note on the hi-hat is at 1.25, however far.
    CHECK(strike_pedal_openness(notes, strike_at(11.98, 1, 6), origin) == 0.0);
    // A hand with no note there: the other hand's nearest.
    const std::vector<PlannedNote> left_only = {note_at(1.0, Side::left, 6, 1.0),
                                                note_at(2.0, Side::left, 6, 0.0)};
    CHECK(strike_pedal_openness(left_only, strike_at(11.9, 1, 6), origin) == 0.0);
    // Another drum, or no notes: none.
    CHECK(strike_pedal_openness(notes, strike_at(11.1, 1, 0), origin) == -1.0);
    CHECK(strike_pedal_openness(notes, strike_at(11.1, 1, 5), origin) == -1.0);
    CHECK(strike_pedal_openness({}, strike_at(11.1, 1, 6), origin) == -1.0);
}

TEST_CASE("kit: events.txt has a hi-hat's pedal line before the strike that plays it, when it "
          "changes",
          "[perform][kit][hihat]")
{
    // Strikes (seq order): snare, hi-hat closed, closed, open, snare, open, closed; a
    // second pedalled drum (5) keeps its own.
    const std::vector<StrikeEvent> strikes = {
        strike_at(0.5, 1, 0),      strike_at(1.0, 0, 6, 0.0), strike_at(1.25, 0, 6, 0.0),
        strike_at(1.5, 1, 6, 1.0), strike_at(1.6, 1, 0),      strike_at(1.75, 0, 6, 1.0),
        strike_at(2.0, 0, 5, 0.0), strike_at(2.25, 0, 6, 0.0)};
    StrikeLog log;
    log.add(strikes.data(), static_cast<int>(strikes.size()));
    std::ostringstream got;
    log.write_events(got);
    // By hand: each line's delay from the previous line, a pedal line at its
    // strike's time (the strike then 0 ms after it).
    std::ostringstream want;
    double prev = 0.0;
    auto hit = [&](const StrikeEvent &e) {
        write_events_line(want, e, prev);
        prev = e.time_s;
    };
    hit(strikes[0]);
    want << "500.000 pedal 6 0.000;\n";
    prev = 1.0;
    hit(strikes[1]);
    hit(strikes[2]);
    want << "250.000 pedal 6 1.000;\n";
    prev = 1.5;
    hit(strikes[3]);
    hit(strikes[4]);
    hit(strikes[5]);
    want << "250.000 pedal 5 0.000;\n";
    prev = 2.0;
    hit(strikes[6]);
    want << "250.000 pedal 6 0.000;\n";
    prev = 2.25;
    hit(strikes[7]);
    CHECK(got.str() == want.str());
    CHECK(want.str().find("0.000 hit 0 6") != std::string::npos); // a strike 0 ms after its pedal
    // Without a pedal the file is as it was: hit lines only.
    StrikeLog plain;
    std::vector<StrikeEvent> none = strikes;
    for (StrikeEvent &e : none)
        e.pedal_openness = -1.0;
    plain.add(none.data(), static_cast<int>(none.size()));
    std::ostringstream plain_got, plain_want;
    plain.write_events(plain_got);
    prev = 0.0;
    for (const StrikeEvent &e : none) {
        write_events_line(plain_want, e, prev);
        prev = e.time_s;
    }
    CHECK(plain_got.str() == plain_want.str());
    CHECK(plain_got.str().find("pedal") == std::string::npos);
}

TEST_CASE("kit: events.txt's pedal lines on seeded random strikes: one before each change, at "
          "its strike's time",
          "[perform][kit][hihat]")
{
    // Strikes on drum 0 (no pedal) and on two pedalled drums, each pedal one of
    // closed, half, open, at seeded random times; the file read back line by line.
    for (unsigned seed = 1; seed <= 20; ++seed) {
        INFO("seed " << seed);
        std::mt19937 rng(seed);
        std::uniform_int_distribution<int> pick(0, 2);
        std::uniform_real_distribution<double> gap(0.0, 0.4);
        const double pedals[3] = {kHihatClosed, kHihatHalf, kHihatOpen};
        const int drums[3] = {0, 5, 6};
        std::vector<StrikeEvent> strikes;
        double t = 0.0;
        for (int k = 0; k < 60; ++k) {
            t += gap(rng);
            const int drum = drums[pick(rng)];
            strikes.push_back(strike_at(t, pick(rng) % 2, drum, drum ? pedals[pick(rng)] : -1.0));
            strikes.back().seq = k;
        }
        StrikeLog log;
        log.add(strikes.data(), static_cast<int>(strikes.size()));
        std::ostringstream text;
        log.write_events(text);
        // Expected by the rule: a pedal line when a drum's pedal differs from its last one.
        double last[kMaxDrums];
        std::fill(last, last + kMaxDrums, -1.0);
        std::istringstream in(text.str());
        std::string line;
        long long sum_us = 0;
        size_t k = 0;
        int pedal_lines = 0, changes = 0;
        while (std::getline(in, line)) {
            std::istringstream words(line);
            double delay_ms = 0.0;
            std::string kind;
            words >> delay_ms >> kind;
            sum_us += std::llround(delay_ms * 1000.0);
            REQUIRE(k < strikes.size());
            const StrikeEvent &e = strikes[k];
            const bool change = e.drum != 0 && e.pedal_openness != last[e.drum];
            if (kind == "pedal") {
                int drum = -1;
                double openness = -1.0;
                words >> drum >> openness;
                CHECK(change);
                CHECK(drum == e.drum);
                CHECK(openness == e.pedal_openness);
                CHECK(sum_us == std::llround(e.time_s * 1e6)); // at its strike's time
                last[e.drum] = openness;
                ++pedal_lines;
            } else {
                REQUIRE(kind == "hit");
                CHECK_FALSE(change); // its pedal, if any, was written before it
                CHECK(sum_us == std::llround(e.time_s * 1e6));
                ++k;
            }
        }
        CHECK(k == strikes.size());
        // Every change counted independently of the file.
        double seen[kMaxDrums];
        std::fill(seen, seen + kMaxDrums, -1.0);
        for (const StrikeEvent &e : strikes)
            if (e.drum != 0 && e.pedal_openness != seen[e.drum]) {
                seen[e.drum] = e.pedal_openness;
                ++changes;
            }
        CHECK(pedal_lines == changes);
    }
}

TEST_CASE("kit: a stick thrown across the kit holds back its own hand's strikes only, and "
          "briefly",
          "[perform][kit]")
{
    // A seeded cross-kit groove at 139 bpm: after a fill the right hand goes
    // floor tom -> crash -> ride in 8ths, 1.3 m a move, and its stick, thrown
    // from the crash toward the ride, flies past the runaway guard's 40 m/s
    // with the built-in controller, for a few milliseconds. Such a flight is
    // the move's, not a controller's running away: it counts as a whip, not a
    // runaway, the gains stay, no refusal is reported, the left hand plays
    // on, and the right's strikes come back kWhipSettle_s after its stick
    // slows down, not after kRunawayQuiet_s (which held back 6 notes here).
    // The crash and the ride are written at the bow toward the performer:
    // their spots turned toward where the hand comes from
    // (kCymbalFaceAbove_mps) the stick is not thrown.
    PerformanceOptions o;
    o.kit = kit_named("full");
    o.score.score_text = "tempo 139\ngrip french\n"
                         "R on hihat 1/2 p + RF 1/2 mp\nR on hihat 1/2 pp\n"
                         "R on hihat 1/2 mf + L on snare 1/2 mf\nR on hihat 1/2 ff\n"
                         "R on hihat 1/2 p + RF 1/2 pp\nR on hihat 1/2 mf\n"
                         "R on hihat 1/2 pp + L on snare 1/2 f\nR on hihat 1/2 p\n"
                         "R on hihat 1/2 p + RF 1/2 f\nR on hihat 1/2 f\n"
                         "R on hihat 1/2 mf + L on snare 1/2 ff\nR on hihat 1/2 mp\n"
                         "R on snare 1/4 mf\nL on snare 1/4 p\nR on tom2 1/4 mf\n"
                         "L on snare 1/4 ff\nR on tom2 1/4 ff\nL on snare 1/4 f\n"
                         "R on floor 1/4 mp\nL on tom1 1/4 mp\n"
                         "R on crash 1/2 p at 0.7 110 + RF 1/2 p\nR on ride 1/2 ff at 0.7 110\n"
                         "R on ride 1/2 mp + L on snare 1/2 pp\nR on ride 1/2 pp\n"
                         "R on floor 1/4 ff\nL on tom2 1/4 p\nR on tom1 1/4 mf\n"
                         "L on tom2 1/4 f\nR on floor 1/4 ff\nL on tom2 1/4 f\n"
                         "R on tom2 1/4 pp\nL on snare 1/4 ff\nR on crash 1/1 pp + RF\n";
    Performance perf(o);
    perf.start_score();
    std::vector<StrikeEvent> sent;
    StrikeEvent ev[kStepStrikes];
    double thrown_s = -1.0, last_fast_s = -1.0;
    while (perf.plan_active()) {
        const int k = perf.step(ev);
        sent.insert(sent.end(), ev, ev + k);
        if (thrown_s < 0.0 && perf.whips() > 0)
            thrown_s = perf.time_s();
        if (perf.scene().tip_velocity(Side::right).norm() > Performance::kRunawayTipSpeed_mps)
            last_fast_s = perf.time_s();
    }
    REQUIRE(perf.whips() == 1); // the groove throws the stick once (else it needs another)
    INFO("thrown at " << thrown_s << " s, fast until " << last_fast_s << " s");
    CHECK(last_fast_s - thrown_s <= Performance::kWhipLongest_s);
    CHECK(perf.runaways() == 0);
    Refusal f;
    CHECK_FALSE(perf.pop_refusal(f)); // the gains were not at fault
    // Every note in the second after the throw, the left hand's from the
    // throw on, the right's once its stick has slowed down for kWhipSettle_s
    // (+ 10 ms of onset tolerance), has one primary strike of its hand within
    // 5 ms.
    const GesturePlan *plan = perf.plan();
    REQUIRE(plan != nullptr);
    const double origin = perf.plan_origin_s();
    int checked[2] = {0, 0};
    for (const PlannedNote &n : plan->notes) {
        const double t = origin + n.time_s;
        const int hand = n.hand == Side::left ? 0 : 1;
        const double from = hand == 0 ? thrown_s : last_fast_s + Performance::kWhipSettle_s + 0.01;
        if (t < from || t > thrown_s + Performance::kRunawayQuiet_s)
            continue;
        INFO("note of hand " << hand << " at " << t << " s");
        int near = 0;
        for (const StrikeEvent &e : sent)
            near += e.hand == hand && !e.bounce && std::abs(e.time_s - t) <= 0.005;
        CHECK(near == 1);
        ++checked[hand];
    }
    // Both hands had notes there (4 of the right, 3 of the left on this score).
    CHECK(checked[0] >= 2);
    CHECK(checked[1] >= 2);
}
