// Cartesian (hybrid) tracking, Algorithm 2: IK (eq. 2) on the arms toward the
// stick tips, PD (eq. 1) everywhere. On the CMU clip it must track the tips to
// 5 mm RMS and better than joint-space tracking with the same gains (the
// paper's Figure 4 claim); on a synthetic motion its IK targets must agree
// with the motion that made the tips.
#include "ictus/bvh.hpp"
#include "ictus/character_limits.hpp"
#include "ictus/track.hpp"
#include "sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <sstream>

using namespace ictus;

TEST_CASE("CMU 80_13: Cartesian tracking holds the tips to 5 mm RMS, better than joint space",
          "[sim][track][cartesian][data]")
{
    const std::string path = simtest::data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions bo;
    bo.scale = simtest::kCmuScale;
    bo.skip_frames = 1;
    const BvhFile bvh = read_bvh(path, bo);
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
    const ReferenceMotion reference(model, bvh.motion, ReferenceFilter{});
    const ReferenceMotion raw(model, bvh.motion);
    // Limits at 4 standard deviations: at 3 (the joint-mode default) the
    // learned region leaves out ~1 % of this very clip's frames, which then no
    // mode can reach (measured: 14 mm RMS Cartesian with k = 3, all of it in
    // those frames). Both modes get the same limits and the same gains.
    CharacterLimitOptions lo;
    lo.k = 4.0;
    const CharacterLimits limits(model, reference, lo);
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
    // The requirement (and the paper's Figure 4 observation).
    for (int s = 0; s < 2; ++s) {
        CHECK(cart.tip_rms_mm[s] <= 5.0);
        CHECK(cart.tip_rms_mm[s] < joint.tip_rms_mm[s]);
    }
    // The IK targets keep the arm where the capture has it: the elbow flexion
    // of Theta^T within a few degrees of the captured one (the arm's null space
    // is held by the kinematic start, docs/ik.md).
    CHECK(cart.elbow_ik_rms_deg[0] < 3.0);
    CHECK(cart.elbow_ik_rms_deg[1] < 3.0);
    // Warm-started at 1 kHz the IK needs 1-2 iterations (docs/ik.md).
    CHECK(cart.ik_mean_iterations < 3.0);
    CHECK(cart.ik_max_iterations <= 16);
    CHECK(cart.max_linear_speed_mps < 20.0);
}

TEST_CASE("Cartesian tracking of a synthetic swing: tips within millimetres, IK = the motion",
          "[sim][track][cartesian]")
{
    const Skeleton skel = simtest::cmu_like_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    // Right elbow and shoulder swing 20 degrees at 1 Hz for 2 s.
    const Motion motion = simtest::make_motion(skel, 241, 120.0, [](int f, const std::string &j) {
        const double a = 20.0 * M_PI / 180 * std::sin(2 * M_PI * f / 120.0);
        if (j == "RightForeArm")
            return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()));
        if (j == "RightArm")
            return Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * a, Eigen::Vector3d::UnitZ()));
        return Eigen::Quaterniond::Identity();
    });
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
    // The IK starts from the captured arm, so Theta^T's elbow is the motion's
    // +/- 20 degree swing about the rest, up to the correction of eq. 2.
    CHECK(cart.elbow_ik_rms_deg[1] < 2.0);
    const nlohmann::json j = cart.to_json();
    CHECK(j["mode"] == "cartesian");
    CHECK(j["ik"]["mean_iterations"].get<double>() >= 0.0);
    CHECK(j["ik"]["us_per_step"].get<double>() > 0.0);
    std::istringstream in(csv.str());
    std::string header;
    std::getline(in, header);
    CHECK(header.find("r_elbow_flexion_target_deg") != std::string::npos);
}

TEST_CASE("Cartesian options are validated, naming the option", "[sim][track][cartesian]")
{
    TrackOptions o;
    o.cartesian.gain = 0.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("ik gain"));
    o = TrackOptions{};
    o.cartesian.correction_limit_m = -1.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("correction limit"));
    o = TrackOptions{};
    o.cartesian.ik.damping_m = 0.0;
    CHECK_THROWS_WITH(validate(o), Catch::Contains("ik parameters"));
    CHECK_THROWS_WITH(track_mode_from_string("foo"), Catch::Contains("joint or cartesian"));
    CHECK(track_mode_from_string("cartesian") == TrackMode::cartesian);
}
