// Cartesian (hybrid) tracking, Algorithm 2: IK (eq. 2) on the arms toward the
// stick tips, PD (eq. 1) everywhere. On the CMU clip it must track the tips to
// 5 mm RMS and better than joint-space tracking with the same gains (the
// paper's Figure 4 claim); on a synthetic motion its IK targets must agree
// with the motion that made the tips.
#include "ictus/mocap/bvh.hpp"
#include "ictus/character/character_limits.hpp"
#include "ictus/character/range_of_motion.hpp"
#include "ictus/perform/track.hpp"
#include "ictus/sim/strike_detector.hpp"
#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <cctype>
#include <fstream>
#include <random>
#include <sstream>

using namespace ictus;

TEST_CASE("CMU 80_13: Cartesian tracking holds the tips to 5 mm RMS, better than joint space",
          "[perform][track][cartesian][data]")
{
    const std::string path = simtest::data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions bo;
    bo.scale = kCmuBvhScale_m;
    bo.skip_frames = 1;
    const BvhFile bvh = read_bvh(path, bo);
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
    // `ictusd track`'s clean-up: de-spiked, Butterworth low-pass at 10 Hz.
    const ReferenceMotion reference(model, bvh.motion, track_reference_filter());
    const ReferenceMotion raw(model, bvh.motion);
    // The default options throughout (limits at k = 3, Algorithm 2 from the
    // simulated state with the posture task, docs/ik.md). Both modes get the
    // same limits and the same gains.
    const CharacterLimits limits(model, reference, CharacterLimitOptions{});
    TrackOptions joint_options;
    const std::vector<JointGains> gains =
        default_gains(model, reference.frame(0), joint_options.gains);
    TrackOptions cart_options = joint_options;
    cart_options.mode = TrackMode::cartesian;

    const TrackSummary joint = track_joint_space(model, reference, joint_options, limits.refs(),
                                                 nullptr, {}, &gains, &raw);
    const TrackSummary cart =
        track_joint_space(model, reference, cart_options, limits.refs(), nullptr, {}, &gains, &raw);
    INFO("joint tip rms mm " << joint.tip_rms_mm[0] << " " << joint.tip_rms_mm[1] << "; cartesian "
                             << cart.tip_rms_mm[0] << " " << cart.tip_rms_mm[1] << " (raw "
                             << cart.tip_rms_raw_mm[0] << " " << cart.tip_rms_raw_mm[1]
                             << "), ik iterations " << cart.ik_mean_iterations << ", elbow rms deg "
                             << cart.elbow_ik_rms_deg[0] << " " << cart.elbow_ik_rms_deg[1]);
    CHECK(cart.mode == "cartesian");
    CHECK_FALSE(cart.diverged);
    CHECK(cart.samples > 900);
    // docs/ik.md's bound (and the paper's Figure 4 observation).
    for (int s = 0; s < 2; ++s) {
        CHECK(cart.tip_rms_mm[s] <= 5.0);
        CHECK(cart.tip_rms_mm[s] < joint.tip_rms_mm[s]);
        // ... and against the raw capture as well: with the
        // Gaussian clean-up the right tip was 25.7 mm from the raw capture,
        // joint space 24.0 (docs/ik.md).
        CHECK(cart.tip_rms_raw_mm[s] < joint.tip_rms_raw_mm[s]);
    }
    // Where the raw-capture error comes from: the clean-up itself. The
    // cleaned tips' distance from the raw ones, computed here from the two
    // references' frames (FK of the hand x the grip), bounds what tracking the
    // cleaned tips can score against the raw capture; the Butterworth keeps
    // the strokes (4-8 Hz) the Gaussian at the same cutoff rounds off.
    ReferenceFilter gaussian = track_reference_filter();
    gaussian.kernel = ReferenceFilter::Kernel::gaussian;
    const ReferenceMotion gauss_reference(model, bvh.motion, gaussian);
    std::array<double, 2> bw_sq{}, gauss_sq{};
    for (int f = 0; f < raw.frames(); ++f) {
        const auto r = reference_tips(model, raw.frame(f));
        const auto b = reference_tips(model, reference.frame(f));
        const auto g = reference_tips(model, gauss_reference.frame(f));
        for (int s = 0; s < 2; ++s) {
            bw_sq[s] += (b[s] - r[s]).squaredNorm();
            gauss_sq[s] += (g[s] - r[s]).squaredNorm();
        }
    }
    for (int s = 0; s < 2; ++s) {
        const double bw_mm = 1000.0 * std::sqrt(bw_sq[s] / raw.frames());
        const double gauss_mm = 1000.0 * std::sqrt(gauss_sq[s] / raw.frames());
        INFO("side " << s << ": cleaned tips from raw, Butterworth " << bw_mm << " mm, Gaussian "
                     << gauss_mm << " mm; Cartesian vs raw " << cart.tip_rms_raw_mm[s] << " mm");
        CHECK(bw_mm < gauss_mm);
    }
    // Driven by the stick tips alone (the capture's arm pose seeds nothing;
    // the posture task holds the null space near the clip's mean arm pose),
    // the IK's elbow flexion stays within ~10 degrees RMS of the captured one
    // (measured 10.3 / 11.9, docs/ik.md); the capture-seeded start, below, to
    // within a few degrees.
    CHECK(cart.elbow_ik_rms_deg[0] < 15.0);
    CHECK(cart.elbow_ik_rms_deg[1] < 15.0);
    // The arms do not run away in their null space: all joints within 15
    // degrees RMS of the capture in the simulation (measured 13.4; the posture
    // is the clip's mean arm pose, not each frame's, docs/ik.md).
    CHECK(cart.to_json()["joint_rms_deg_all"].get<double>() < 15.0);
    // Warm-started at 1 kHz the IK needs 1-2 iterations (docs/ik.md).
    CHECK(cart.ik_mean_iterations < 3.0);
    CHECK(cart.ik_max_iterations <= 16);
    CHECK(cart.max_linear_speed_mps < 20.0);

    // The capture-seeded variant (--ik-start kinematic) keeps Theta^T's elbow
    // where the capture has it, by construction.
    TrackOptions seeded = cart_options;
    seeded.cartesian.start_from_simulated = false;
    seeded.cartesian.posture_weight = 0.0;
    seeded.cartesian.feedback_iterations = 0;
    seeded.cartesian.kinematic_iterations = 0;
    seeded.cartesian.correction_limit_m = 0.1;
    seeded.duration_s = 3.0;
    const TrackSummary kin =
        track_joint_space(model, reference, seeded, limits.refs(), nullptr, {}, &gains, &raw);
    INFO("capture-seeded: elbow rms deg " << kin.elbow_ik_rms_deg[0] << " "
                                          << kin.elbow_ik_rms_deg[1]);
    CHECK(kin.elbow_ik_rms_deg[0] < 3.0);
    CHECK(kin.elbow_ik_rms_deg[1] < 3.0);
}

TEST_CASE("Cartesian tracking of a synthetic swing: tips within millimetres",
          "[perform][track][cartesian]")
{
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    // Right elbow and shoulder swing 20 degrees at 1 Hz for 2 s.
    const Motion motion = simtest::right_arm_swing(skel);
    const ReferenceMotion ref(m, motion);
    TrackOptions o;
    o.sample_rate_hz = 50.0;
    const TrackSummary joint = track_joint_space(m, ref, o);
    o.mode = TrackMode::cartesian;
    std::ostringstream csv;
    const TrackSummary cart = track_joint_space(m, ref, o, {}, &csv);
    INFO("joint " << joint.tip_rms_mm[1] << " mm, cartesian " << cart.tip_rms_mm[1] << " mm; elbow "
                  << cart.elbow_ik_rms_deg[1] << " deg");
    CHECK_FALSE(cart.diverged);
    CHECK(cart.tip_rms_mm[0] < 2.0);
    CHECK(cart.tip_rms_mm[1] < 2.0);
    CHECK(cart.tip_rms_mm[1] < joint.tip_rms_mm[1]);
    // Driven by the tips alone from the simulated arm (the default), Theta^T's
    // elbow is not the motion's: the tips do not determine how the swing is
    // shared between shoulder and elbow (measured 11 deg RMS off a 14 deg RMS
    // flexion signal). The capture-seeded start's tighter bound is checked in
    // the CMU test above.
    INFO("elbow flexion rms " << cart.elbow_ik_rms_deg[1] << " deg");
    const nlohmann::json j = cart.to_json();
    CHECK(j["mode"] == "cartesian");
    CHECK(j["ik"]["mean_iterations"].get<double>() >= 0.0);
    CHECK(j["ik"]["us_per_step"].get<double>() > 0.0);
    // Reseeds are counted among the solves that did not converge (a reseed follows ten).
    CHECK(j["ik"]["reseeded"].get<long>() >= 0);
    CHECK(j["ik"]["reseeded"].get<long>() <= j["ik"]["not_converged"].get<long>());
    std::istringstream in(csv.str());
    std::string header;
    std::getline(in, header);
    CHECK(header.find("r_elbow_flexion_target_deg") != std::string::npos);
}

TEST_CASE("Cartesian options are validated, naming the option", "[perform][track][cartesian]")
{
    TrackOptions o;
    o.cartesian.gain = 0.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("ik gain"));
    o = TrackOptions{};
    o.cartesian.correction_limit_m = -1.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("correction limit"));
    o = TrackOptions{};
    o.cartesian.posture_weight = 1.5;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("ik posture weight"));
    o = TrackOptions{};
    o.cartesian.ik.damping_m = 0.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("ik parameters"));
    CHECK_THROWS_WITH(track_mode_from_string("foo"), Catch::Contains("joint or cartesian"));
    CHECK(track_mode_from_string("cartesian") == TrackMode::cartesian);
}

namespace
{

// Two sticks striking alternately at 2 Hz, 12 cm strokes, 0.3 m apart, in a
// capture frame turned 120 degrees about the vertical and moved by (3, 0.8, 2)
// m. Tip-space strokes centred where place_behind_sticks puts them are within
// the default arm's reach (0.56 m from the shoulder, reach ~0.85 m).
MarkerCapture synthetic_strokes(double seconds = 3.0, double rate_hz = 200.0)
{
    MarkerCapture c;
    c.tracks.resize(2);
    c.tracks[0].name = "Left Stick";
    c.tracks[1].name = "RightStick";
    const Eigen::AngleAxisd turn(120.0 * M_PI / 180.0, Eigen::Vector3d::UnitY());
    const Eigen::Vector3d offset(3.0, 0.8, 2.0);
    for (int f = 0; f < std::lround(seconds * rate_hz); ++f) {
        const double t = f / rate_hz;
        c.time_s.push_back(t);
        for (int s = 0; s < 2; ++s) {
            const double phase = 2 * M_PI * 2.0 * t + (s == 0 ? 0.0 : M_PI);
            const Eigen::Vector3d p(s == 0 ? 0.15 : -0.15, 0.06 * (1 - std::cos(phase)), 0.0);
            c.tracks[s].position_m.push_back(turn * p + offset);
        }
    }
    return c;
}

CharacterPose held_pose(const CharacterModel &m)
{
    CharacterPose p = m.rest_pose();
    p.pelvis_position_m = Eigen::Vector3d(0, 0.9, 0);
    return p;
}

} // namespace

TEST_CASE("stick-only: the sticks are found by name, or by the default names", "[perform][cartesian]")
{
    MarkerCapture c = synthetic_strokes(0.1);
    CHECK(find_stick_tracks(c, "", "") == std::array<int, 2>{0, 1});
    CHECK(find_stick_tracks(c, "RightStick", "Left Stick") == std::array<int, 2>{1, 0});
    c.tracks[1].name = "STICK_R";
    c.tracks.push_back(c.tracks[0]);
    c.tracks.back().name = "stick_l"; // an exact default name wins over "left"
    CHECK(find_stick_tracks(c, "", "") == std::array<int, 2>{2, 1});
    CHECK_THROWS_WITH(find_stick_tracks(c, "nope", ""), Catch::Contains("'nope'"));
    CHECK_THROWS_WITH(find_stick_tracks(c, "Left Stick", "Left Stick"),
                      Catch::Contains("same object"));
    c.tracks[1].name = "head";
    CHECK_THROWS_WITH(find_stick_tracks(c, "", ""), Catch::Contains("no right stick"));
}

TEST_CASE("stick-only: a stick named in another casing is its object, unless two are so named",
          "[perform][cartesian]")
{
    MarkerCapture c = synthetic_strokes(0.1);
    // Seeded random casings of the capture's own names, never the names as written.
    std::mt19937 rng(20261203);
    const auto recase = [&rng](const std::string &name) {
        std::string out;
        do {
            out = name;
            for (char &ch : out)
                ch = static_cast<char>(rng() % 2 ? std::toupper(static_cast<unsigned char>(ch))
                                                 : std::tolower(static_cast<unsigned char>(ch)));
        } while (out == name);
        return out;
    };
    for (int trial = 0; trial < 40; ++trial) {
        const std::string left = recase("Left Stick"), right = recase("RightStick");
        INFO(left << " / " << right);
        CHECK(find_stick_tracks(c, left, right) == std::array<int, 2>{0, 1});
        CHECK(find_stick_tracks(c, right, left) == std::array<int, 2>{1, 0});
    }
    // The name as written wins over another casing of it.
    c.tracks.push_back(c.tracks[0]);
    c.tracks.back().name = "LEFT STICK";
    CHECK(find_stick_tracks(c, "LEFT STICK", "") == std::array<int, 2>{2, 1});
    CHECK(find_stick_tracks(c, "Left Stick", "") == std::array<int, 2>{0, 1});
    // Two objects in other casings: which one is meant is not guessed.
    CHECK_THROWS_WITH(find_stick_tracks(c, "left stick", ""),
                      Catch::Contains("--left-stick") && Catch::Contains("Left Stick, LEFT STICK"));
    // No object in any casing: the error lists the capture's objects.
    CHECK_THROWS_WITH(find_stick_tracks(c, "", "Right Stick"),
                      Catch::Contains("--right-stick") &&
                          Catch::Contains("objects: Left Stick, RightStick, LEFT STICK"));
}

TEST_CASE("stick-only: placement behind the sticks and the drum under the strokes",
          "[perform][cartesian]")
{
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
    const MarkerCapture c = synthetic_strokes();
    const TipTrajectory tips = place_behind_sticks(m, held_pose(m), c, {0, 1});
    // The goal, from the shoulders' positions (rest pose: the pelvis at 0.9 m,
    // the default skeleton's offsets summed by hand in CMU units x 0.056444:
    // shoulder = pelvis + (+-3.1, 1.7 + 1.7 + 1.4, -0.2 + 0.2 + 0.3)).
    const double u = 0.056444;
    const Eigen::Vector3d shoulder_mid(0.0, 0.9 + 4.8 * u, 0.3 * u);
    // The body faces +z (its left, +x, crossed with up).
    const Eigen::Vector3d goal = shoulder_mid + Eigen::Vector3d(0, -kStickBelow_m, kStickForward_m);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    Eigen::Vector3d mean[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int s = 0; s < 2; ++s)
        for (const Eigen::Vector3d &p : tips.tip_m[s]) {
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
            mean[s] += p / tips.tip_m[s].size();
        }
    CHECK((0.5 * (lo + hi) - goal).norm() < 1e-9);
    // The capture's left stick ends up on the body's left (+x), 0.3 m apart,
    // strokes vertical and 0.12 m high: the transform is rigid.
    CHECK((mean[0] - mean[1] - Eigen::Vector3d(0.3, 0, 0)).norm() < 1e-9);
    CHECK(hi.y() - lo.y() == Approx(0.12).margin(1e-6));
    // Drum: the strokes' lowest points are the tips at the bottom of the box;
    // centred between the sticks (each stick's strike points average to its
    // lateral position, +-0.15 m about the goal), one tip radius below.
    const double r = m.options().stick.tip_radius_m;
    const Eigen::Vector3d drum = fit_drum_to_strokes(tips, r);
    // (Half a tip radius below since 2026-11-24: the tracked end of a stick 30
    // degrees below the horizontal is r / 2 above the membrane at contact,
    // stick_capture.hpp's kImpactPitchFactor; one radius before.)
    CHECK(drum.y() == Approx(lo.y() - kImpactPitchFactor * r).margin(1e-6));
    CHECK(drum.x() == Approx(goal.x()).margin(1e-3));
    CHECK(drum.z() == Approx(goal.z()).margin(1e-3));
    // A flat capture has no strokes.
    TipTrajectory flat = tips;
    for (auto &side : flat.tip_m)
        for (Eigen::Vector3d &p : side)
            p.y() = 1.0;
    CHECK_THROWS_WITH(fit_drum_to_strokes(flat, r), Catch::Contains("no strokes"));
}

TEST_CASE("stick-only: the default body tracks synthetic strokes to a few millimetres",
          "[perform][cartesian]")
{
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    const Motion held = simtest::make_motion(
        skel, 2, 100.0, [](int, const std::string &) { return Eigen::Quaterniond::Identity(); });
    Motion held09 = held;
    for (Eigen::Vector3d &p : held09.root_position_m)
        p = Eigen::Vector3d(0, 0.9, 0);
    const ReferenceMotion ref(m, held09);
    const TipTrajectory tips = place_behind_sticks(m, ref.frame(0), synthetic_strokes(), {0, 1});
    TrackOptions o;
    o.mode = TrackMode::cartesian;
    o.tip_reference = &tips;
    const TrackSummary s = track_joint_space(m, ref, o);
    INFO("tip rms mm " << s.tip_rms_mm[0] << " " << s.tip_rms_mm[1] << ", max " << s.tip_max_mm[0]
                       << " " << s.tip_max_mm[1]);
    CHECK_FALSE(s.diverged);
    CHECK(s.duration_s == Approx(tips.duration_s()).margin(1e-3));
    // Peak tip speed 0.75 m/s; the CMU clip's strokes (up to 10 m/s) are
    // tracked to 5 mm, these slow ones to well under that.
    CHECK(s.tip_rms_mm[0] < 3.0);
    CHECK(s.tip_rms_mm[1] < 3.0);
    CHECK(s.tip_max_mm[0] < 10.0);
    CHECK(s.tip_max_mm[1] < 10.0);
    // The drum was fitted under the strokes: one tip radius below the lowest tip.
    double lowest = 1e9;
    for (const auto &side : tips.tip_m)
        for (const Eigen::Vector3d &p : side)
            lowest = std::min(lowest, p.y());
    CHECK(s.drum_center_m.y() ==
          Approx(lowest - kImpactPitchFactor * m.options().stick.tip_radius_m).margin(1e-6));
    // Joint mode cannot take a stick-only capture.
    o.mode = TrackMode::joint;
    CHECK_THROWS_WITH(track_joint_space(m, ref, o), Catch::Contains("Cartesian mode"));
}

namespace
{
// Stick-tip height of a stroke train: an impact every period_s from t0_s at
// speed v_mps (downwards), rebounding at rebound * v_mps, with the cubic
// Hermite curve between impacts; the stick's end at impact_y_m at each
// impact (a V at the impact: the capture's sampling cuts it at random).
// The tracked point is the stick's end.
double stroke_height(double t, double t0_s, double period_s, double v_mps, double rebound,
                     double impact_y_m)
{
    const double u = (t - t0_s) / period_s;
    const double s = u - std::floor(u);
    const double m0 = rebound * v_mps * period_s, m1 = -v_mps * period_s;
    return impact_y_m + m0 * (s * s * s - 2 * s * s + s) + m1 * (s * s * s - s * s);
}
} // namespace

TEST_CASE("drum auto: the membrane at the strokes' turnarounds within 5 mm, one impact each",
          "[perform][cartesian][drum]")
{
    // The bead's radius: the sticks meet the membrane 30 degrees below the
    // horizontal, their tracked end r / 2 above it (kImpactPitchFactor).
    const double r = 0.007;
    // Seeded random captures over the whole range: membranes at 0.25-1.1 m, taps to
    // piston-like strokes (0.5-8 m/s at impact, a stroke every 0.18-0.4 s, rebound
    // 0.3-0.85 of the impact speed), the usual capture rates, each stick at its own
    // phase, lateral place and depth. The true membrane is the generator's.
    std::mt19937 rng(20261124);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const double rates[] = {120.0, 200.0, 240.0, 250.0};
    for (int member = 0; member < 300; ++member) {
        const double drum_y = 0.25 + 0.85 * U(rng);
        const double v = 0.5 + 7.5 * U(rng);
        const double period = 0.18 + 0.22 * U(rng);
        const double rebound = 0.3 + 0.55 * U(rng);
        const double rate_hz = rates[static_cast<int>(4 * U(rng)) % 4];
        const double t0[2] = {period * U(rng), period * U(rng)};
        const double x[2] = {0.05 + 0.1 * U(rng), -0.05 - 0.1 * U(rng)};
        const double z = 0.2 + 0.3 * U(rng);
        TipTrajectory tips;
        const double duration = 3.0;
        for (int f = 0; f < std::lround(duration * rate_hz); ++f) {
            const double t = f / rate_hz;
            tips.time_s.push_back(t);
            for (int s = 0; s < 2; ++s)
                tips.tip_m[s].push_back(Eigen::Vector3d(
                    x[s], stroke_height(t, t0[s], period, v, rebound, drum_y + 0.5 * r), z));
        }
        const DrumPlacement placed = place_drum(tips, r, 0.178);
        const DrumFit &fit = placed.fit;
        INFO("member " << member << ": drum " << drum_y << " m, " << v << " m/s every " << period
                       << " s, rebound " << rebound << ", " << rate_hz << " Hz: fitted "
                       << fit.center_m.y());
        CHECK(std::abs(fit.center_m.y() - drum_y) <= 0.005);
        // Centred between the sticks' strike points (each stick counts once).
        CHECK(std::abs(fit.center_m.x() - 0.5 * (x[0] + x[1])) <= 1e-9);
        CHECK(std::abs(fit.center_m.z() - z) <= 1e-9);
        // The tips never go below the impacts: the drum stays at the turnarounds.
        CHECK(placed.at_turnarounds);
        CHECK(placed.through_fraction == 0.0);
        CHECK(placed.center_m == fit.center_m);
        // One impact per captured impact: every detected impact is within a
        // sample of a true one, and every true impact with a whole stroke
        // captured before it (the first may start part-way down) and its turn
        // captured after it (two samples: with one, that sample may be the
        // capture's lowest, still on the way down for all the capture shows) is
        // detected exactly once.
        for (int s = 0; s < 2; ++s) {
            for (const StrokeTurnaround &d : fit.impacts[s]) {
                const double u = (d.time_s - t0[s]) / period;
                CHECK(std::abs(u - std::round(u)) * period <= 1.0 / rate_hz);
            }
            for (double ti = t0[s]; ti < duration; ti += period) {
                if (ti - period < tips.time_s.front() || ti + 2.0 / rate_hz > tips.time_s.back())
                    continue;
                int found = 0;
                for (const StrokeTurnaround &d : fit.impacts[s])
                    found += std::abs(d.time_s - ti) <= 1.0 / rate_hz;
                INFO("stick " << s << " impact at " << ti << " s of " << tips.time_s.back());
                CHECK(found == 1);
            }
        }
    }
}

TEST_CASE("drum auto: a capture whose tips pass through the drum at the turnarounds (a kit) "
          "gets it under the lowest tips",
          "[perform][cartesian][drum]")
{
    const double r = 0.007;
    // The right stick strikes a drum at 0.7 m, at (-0.1, 0.4); the left plays a
    // cymbal in the air (turning at 0.9 m, higher than the impact band) and, from
    // 2 s on, rests at 0.5 m right under the first drum, as a kit's sticks may.
    TipTrajectory tips;
    const double rate = 200.0;
    for (int f = 0; f < 600; ++f) {
        const double t = f / rate;
        tips.time_s.push_back(t);
        tips.tip_m[0].push_back(
            t < 2.0 ? Eigen::Vector3d(0.2, stroke_height(t, 0.05, 0.3, 3.0, 0.7, 0.9), 0.5)
                    : Eigen::Vector3d(0.0, 0.5, 0.4));
        tips.tip_m[1].push_back(
            Eigen::Vector3d(-0.1, stroke_height(t, 0.12, 0.25, 4.0, 0.6, 0.7 + 0.5 * r), 0.4));
    }
    const DrumPlacement placed = place_drum(tips, r, 0.178);
    INFO("at the turnarounds " << placed.fit.center_m.transpose() << ", through "
                               << placed.through_fraction);
    // The turnarounds alone put it at the right stick's impacts ...
    CHECK(placed.fit.center_m.y() == Approx(0.7).margin(0.005));
    CHECK(placed.fit.center_m.x() == Approx(-0.1).margin(1e-9));
    // ... where the left stick rests for a third of the capture (200 of 600 samples).
    CHECK(placed.through_fraction == Approx(200.0 / 600.0).margin(1e-9));
    CHECK_FALSE(placed.at_turnarounds);
    // Under the lowest tips instead: (x, z) the mean of the two lowest points, the
    // membrane r / 2 below the lower (the resting left stick at 0.5 m).
    CHECK(placed.center_m.y() == Approx(0.5 - 0.5 * r).margin(1e-9));
    CHECK(placed.center_m.x() == Approx(0.5 * (0.0 + -0.1)).margin(1e-9));
    CHECK(placed.center_m.z() == Approx(0.4).margin(1e-9));
    // The impacts (the contact windows) are the turnarounds' in either case.
    CHECK(placed.fit.impacts[1].size() >= 10);
    // A few samples under the drum (a rim shot, a marker glitch) do not move it:
    // 1 % is the rule's threshold (kDrumThroughFraction).
    TipTrajectory few = tips;
    for (int f = 400; f < 600; ++f)
        few.tip_m[0][f] = Eigen::Vector3d(0.2, 0.9, 0.5);
    for (int f = 400; f < 405; ++f)
        few.tip_m[0][f] = Eigen::Vector3d(0.0, 0.5, 0.4);
    const DrumPlacement kept = place_drum(few, r, 0.178);
    CHECK(kept.through_fraction == Approx(5.0 / 600.0).margin(1e-9));
    CHECK(kept.at_turnarounds);
    CHECK(kept.center_m.y() == Approx(0.7).margin(0.005));
}

TEST_CASE("drum auto on a full-body capture: the turnaround rule, as for stick-only captures",
          "[perform][cartesian][drum]")
{
    // A body that plays the strokes by bending at the lower back (the arms held
    // still, the pelvis anchored): bend phi(t) = 0.6 rad - 1.5 rad/m h(t), h(t) >= 0
    // a stroke train with its impacts (h = 0) every 0.3 s at 4 m/s, rebound 0.6,
    // captured at 120 Hz. The tips' height falls monotonically with the bend, so
    // the strokes turn where the bend is deepest, 0.6 rad.
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    const auto bend = [](double phi) {
        return Eigen::Quaterniond(Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()));
    };
    const Motion motion = simtest::make_motion(skel, 360, 120.0, [&](int f, const std::string &j) {
        if (j != "LowerBack")
            return Eigen::Quaterniond::Identity();
        return bend(0.6 - 1.5 * stroke_height(f / 120.0, 0.031, 0.3, 4.0, 0.6, 0.0));
    });
    const ReferenceMotion ref(m, motion);
    // The truth: the tips of the pose bent 0.6 rad (forward kinematics of one
    // pose), the membrane r / 2 below the lower tip.
    const ReferenceMotion deepest(
        m, simtest::make_motion(skel, 2, 120.0, [&](int, const std::string &j) {
            return j == "LowerBack" ? bend(0.6) : Eigen::Quaterniond::Identity();
        }));
    const auto tips = reference_tips(m, deepest.frame(0));
    const double r = m.options().stick.tip_radius_m;
    TrackOptions o;
    o.duration_s = 0.002;
    const TrackSummary s = track_joint_space(m, ref, o);
    INFO("drum " << s.drum_center_m.transpose() << " (" << s.drum_rule << "), tips at the impacts "
                 << tips[0].transpose() << " / " << tips[1].transpose());
    CHECK(s.drum_rule == "turnarounds");
    CHECK(s.drum_through_fraction == 0.0);
    CHECK(std::abs(s.drum_center_m.y() - (std::min(tips[0].y(), tips[1].y()) - 0.5 * r)) <= 0.005);
    const Eigen::Vector3d mid = 0.5 * (tips[0] + tips[1]);
    CHECK(std::abs(s.drum_center_m.x() - mid.x()) <= 0.005);
    CHECK(std::abs(s.drum_center_m.z() - mid.z()) <= 0.005);
    CHECK(s.captured_impacts[0] >= 8);
    CHECK(s.captured_impacts[1] >= 8);
    const nlohmann::json j = s.to_json();
    CHECK(j["drum_rule"] == "turnarounds");
    // --drum X,Y,Z: the given place.
    o.drum_auto = false;
    o.scene.drum.center_m = Eigen::Vector3d(0.1, 0.2, 0.3);
    const TrackSummary given = track_joint_space(m, ref, o);
    CHECK(given.drum_rule == "given");
    CHECK(given.drum_center_m == Eigen::Vector3d(0.1, 0.2, 0.3));
}

TEST_CASE("drum auto on the TrajOptDrums stroke: its turnaround at the paper's drum height",
          "[perform][cartesian][drum][data]")
{
    const std::string xs = simtest::data_file("trajoptdrums/JointCenters_XPose_cm.csv");
    const std::string ys = simtest::data_file("trajoptdrums/JointCenters_YPose_cm.csv");
    if (xs.empty() || ys.empty())
        return;
    // Columns: time, shoulder, elbow, wrist, finger, drum bead (cm, shoulder at 0).
    const auto read = [](const std::string &path) {
        std::ifstream in(path);
        std::string line;
        std::getline(in, line); // header
        std::vector<std::pair<double, double>> rows;
        while (std::getline(in, line)) {
            std::istringstream cells(line);
            std::string cell;
            std::vector<double> v;
            while (std::getline(cells, cell, ',') && v.size() < 6)
                v.push_back(std::stod(cell));
            if (v.size() == 6)
                rows.emplace_back(v[0], v[5] / 100.0);
        }
        return rows;
    };
    const auto x = read(xs), y = read(ys);
    REQUIRE(x.size() == 160);
    REQUIRE(y.size() == x.size());
    TipTrajectory tips;
    for (size_t i = 0; i < x.size(); ++i) {
        tips.time_s.push_back(x[i].first);
        for (int s = 0; s < 2; ++s)
            tips.tip_m[s].push_back(Eigen::Vector3d(x[i].second, y[i].second, 0.0));
    }
    // One down-stroke at 100 bpm: one turnaround, where the original analysis
    // puts the drum head (YD = -0.47108 m below the shoulder, README.md).
    const std::vector<StrokeTurnaround> t = find_turnarounds(tips, 0);
    REQUIRE(t.size() == 1);
    INFO("turnaround at " << t[0].time_s << " s, height " << t[0].position_m.y() << " m, "
                          << t[0].speed_in_mps << " m/s");
    CHECK(std::abs(t[0].position_m.y() - -0.47108) <= 0.005);
    CHECK(t[0].time_s == Approx(0.62).margin(0.01));
    CHECK(t[0].speed_in_mps > 1.0);
    // --drum auto's placement (place_drum): at the turnaround (nothing passes
    // through a drum there), the membrane r / 2 below the bead's vertex, within
    // 5 mm of the analysis's drum head.
    const double r = 0.007;
    const DrumPlacement placed = place_drum(tips, r, 0.178);
    INFO("membrane at " << placed.center_m.y() << " m");
    CHECK(placed.at_turnarounds);
    CHECK(placed.through_fraction == 0.0);
    CHECK(std::abs(placed.center_m.y() - -0.47108) <= 0.005);
    CHECK(placed.fit.impacts[0].size() == 1);
}

namespace
{
// One synthetic stick-only capture through `ictusd track`'s path: two sticks
// playing stroke trains (stroke_height) on a membrane at `membrane_y_m`, placed
// behind by place_behind_sticks, tracked in Cartesian mode with the strike
// detector of strikes.csv, with the human range of motion as the joint limits. Checks: the drum
// within 5 mm of the true membrane, free-flight tip RMS <= 5 mm, every impact from 1 s on struck
// exactly once and no other strike (the first strokes after the 0.25 s ramp may be missed while the
// arms settle from their cold start).
struct StrokeCase {
    double v_mps, period_s, rebound, membrane_y_m, rate_hz;
    double t0_s[2];      // each stick's first impact
    double lateral_m[2]; // each stick's x in the capture
};

void check_stick_only_tracking(const CharacterModel &m, const ReferenceMotion &ref,
                               const StrokeCase &c)
{
    const double r = m.options().stick.tip_radius_m;
    MarkerCapture cap;
    cap.tracks.resize(2);
    cap.tracks[0].name = "stick_l";
    cap.tracks[1].name = "stick_r";
    for (int f = 0; f < std::lround(3.0 * c.rate_hz); ++f) {
        const double t = f / c.rate_hz;
        cap.time_s.push_back(t);
        for (int s = 0; s < 2; ++s)
            cap.tracks[s].position_m.push_back(
                Eigen::Vector3d(c.lateral_m[s],
                                stroke_height(t, c.t0_s[s], c.period_s, c.v_mps, c.rebound,
                                              c.membrane_y_m + 0.5 * r),
                                0.0));
    }
    const TipTrajectory tips = place_behind_sticks(m, ref.frame(0), cap, {0, 1});
    // The placement is a turn about the vertical and a shift: heights move by the shift.
    const double membrane = c.membrane_y_m + tips.tip_m[0][0].y() - cap.tracks[0].position_m[0].y();
    TrackOptions o;
    o.mode = TrackMode::cartesian;
    o.tip_reference = &tips;
    // The strikes, as `ictusd track` detects them (strikes.csv).
    StrikeDetector detector;
    std::vector<StrikeEvent> strikes;
    o.on_step = [&](const Scene &scene) {
        detector.set_membrane(membrane_of(scene));
        StrikeEvent out[2];
        const int n = detect_strikes(detector, scene, out);
        strikes.insert(strikes.end(), out, out + n);
    };
    // The joint limits `ictusd track` gives a stick-only capture: the human range of motion.
    const RangeOfMotion rom(m);
    const TrackSummary s = track_joint_space(m, ref, o, rom.refs());
    INFO(c.v_mps << " m/s every " << c.period_s << " s, rebound " << c.rebound << ", " << c.rate_hz
                 << " Hz, first impacts " << c.t0_s[0] << " / " << c.t0_s[1] << " s: drum "
                 << s.drum_center_m.y() << " (true " << membrane << "), free flight rms mm "
                 << s.tip_rms_free_mm[0] << " " << s.tip_rms_free_mm[1] << ", contact windows "
                 << s.tip_rms_contact_mm[0] << " " << s.tip_rms_contact_mm[1] << ", impacts "
                 << s.captured_impacts[0] << " " << s.captured_impacts[1]);
    for (int hand = 0; hand < 2; ++hand) {
        int impacts = 0, struck = 0, extra = 0;
        for (double ti = c.t0_s[hand]; ti < 2.99; ti += c.period_s)
            if (ti >= 1.0) {
                ++impacts;
                int n = 0;
                for (const StrikeEvent &e : strikes)
                    n += e.hand == hand && !e.bounce && std::abs(e.time_s - ti) < 0.02;
                struck += n == 1;
            }
        for (const StrikeEvent &e : strikes) {
            bool near = false;
            for (double ti = c.t0_s[hand]; ti < 3.0; ti += c.period_s)
                near = near || std::abs(e.time_s - ti) < 0.02;
            extra += e.hand == hand && !e.bounce && !near;
        }
        INFO("hand " << hand << ": " << struck << " of " << impacts << " impacts struck once, "
                     << extra << " other strikes");
        CHECK(struck == impacts);
        CHECK(extra == 0);
    }
    CHECK_FALSE(s.diverged);
    CHECK(s.drum_rule == "turnarounds");
    CHECK(std::abs(s.drum_center_m.y() - membrane) <= 0.005);
    CHECK(s.tip_rms_free_mm[0] <= 5.0);
    CHECK(s.tip_rms_free_mm[1] <= 5.0);
    // Every impact with a whole stroke before it is found (3 s of strokes).
    CHECK(s.captured_impacts[0] >= static_cast<int>(3.0 / c.period_s) - 1);
    CHECK(s.captured_impacts[1] >= static_cast<int>(3.0 / c.period_s) - 1);
}
} // namespace

TEST_CASE("stick-only: synthetic strokes up to 8 m/s, drum found within 5 mm, free flight to 5 mm",
          "[perform][cartesian][drum]")
{
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    Motion held = simtest::make_motion(
        skel, 2, 100.0, [](int, const std::string &) { return Eigen::Quaterniond::Identity(); });
    for (Eigen::Vector3d &p : held.root_position_m)
        p = Eigen::Vector3d(0, 0.9, 0);
    const ReferenceMotion ref(m, held);
    // Taps, legato, accents at 250 Hz (the examples of docs/ik.md).
    for (const StrokeCase &c :
         {StrokeCase{1.0, 0.2, 0.8, 0.2, 250.0, {0.0015, 0.113}, {0.15, -0.15}},
          StrokeCase{3.0, 0.25, 0.7, 0.7, 250.0, {0.0015, 0.138}, {0.15, -0.15}},
          StrokeCase{5.0, 0.3, 0.6, 0.5, 250.0, {0.0015, 0.163}, {0.15, -0.15}}})
        check_stick_only_tracking(m, ref, c);
    // Seeded random captures over the whole range: 1-8 m/s at impact, a stroke
    // every 0.2-0.35 s, rebound 0.3-0.8, membranes at 0.2-0.9 m, the usual capture
    // rates, each stick at its own phase and place.
    std::mt19937 rng(15);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const double rates[] = {120.0, 200.0, 240.0, 250.0};
    for (int member = 0; member < 14; ++member) {
        StrokeCase c;
        c.v_mps = 1.0 + 7.0 * U(rng);
        c.period_s = 0.2 + 0.15 * U(rng);
        c.rebound = 0.3 + 0.5 * U(rng);
        c.membrane_y_m = 0.2 + 0.7 * U(rng);
        c.rate_hz = rates[static_cast<int>(4 * U(rng)) % 4];
        for (int s = 0; s < 2; ++s) {
            c.t0_s[s] = c.period_s * U(rng);
            c.lateral_m[s] = (s == 0 ? 1.0 : -1.0) * (0.1 + 0.06 * U(rng));
        }
        INFO("random member " << member);
        check_stick_only_tracking(m, ref, c);
    }
}
