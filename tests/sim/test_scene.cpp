// The ODE scene: still-pose PD equilibrium against statics, divergence handling.
#include "ictus/joint_controller.hpp"
#include "ictus/scene.hpp"
#include "sim_test_util.hpp"

#include <catch2/catch.hpp>

using namespace ictus;

namespace
{

// T-pose (every rotation identity) with the elbows bent 60 degrees forward and
// the hips flexed a little: gravity loads shoulders, elbows, wrists and hips.
CharacterPose still_pose(const CharacterModel &m)
{
    CharacterPose p = m.rest_pose();
    p.pelvis_position_m = Eigen::Vector3d(0, 1.0, 0);
    p.local[m.joint_index("l_elbow")] = Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitY());
    p.local[m.joint_index("r_elbow")] = Eigen::AngleAxisd(-1.0, Eigen::Vector3d::UnitY());
    p.local[m.joint_index("l_hip")] = Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX());
    p.local[m.joint_index("r_hip")] = Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX());
    return p;
}

// Gravity torque about joint j of everything below it, computed here from the
// bodies' masses and a forward kinematics written for this test.
double gravity_torque(const CharacterModel &m, const CharacterPose &pose, int joint, double g)
{
    const int n = CharacterModel::kBodies;
    std::vector<Eigen::Vector3d> origin(n);
    std::vector<Eigen::Matrix3d> rot(n);
    origin[0] = pose.pelvis_position_m;
    rot[0] = pose.pelvis_rotation.toRotationMatrix();
    for (int b = 1; b < n; ++b) {
        const int p = m.bodies()[b].parent;
        origin[b] = origin[p] + rot[p] * m.bodies()[b].offset_m;
        rot[b] = rot[p] * pose.local[b - 1].toRotationMatrix();
    }
    const int top = joint + 1;
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    for (int b = top; b < n; ++b) {
        int a = b;
        while (a > top)
            a = m.bodies()[a].parent;
        if (a != top)
            continue;
        const BodySpec &body = m.bodies()[b];
        std::vector<std::pair<double, Eigen::Vector3d>> masses = {{body.mass_kg, body.com_m}};
        for (Side s : {Side::left, Side::right})
            if (m.hand_body(s) == b)
                masses.push_back({m.options().stick.mass_kg, m.stick(s).com_m});
        for (const auto &mc : masses) {
            const Eigen::Vector3d c = origin[b] + rot[b] * mc.second;
            torque += (c - origin[top]).cross(Eigen::Vector3d(0, -g * mc.first, 0));
        }
    }
    return torque.norm();
}

} // namespace

TEST_CASE("still pose: each joint sags by its gravity torque over k_s, and no more", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(simtest::cmu_like_skeleton());
    const CharacterPose pose = still_pose(m);
    const std::vector<JointGains> gains = default_gains(m, pose);
    SceneOptions so;
    so.drum.center_m = Eigen::Vector3d(0, -5, 0); // out of reach
    // The direct solver gives the equilibrium exactly; QuickStep (the default,
    // 20 iterations) leaves a residual at the light neck between thorax and head.
    const bool direct = GENERATE(true, false);
    so.stepper = direct ? Stepper::direct : Stepper::quick;
    Scene scene(m, so, pose, gains);
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    for (int i = 0; i < 3000; ++i) {
        scene.set_joint_targets(pose.local, zero);
        REQUIRE(scene.step() == StepResult::ok);
    }
    std::vector<Eigen::Quaterniond> local;
    scene.local_rotations(local);
    int loaded = 0;
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        // At rest the motor row's force is k_d * v = k_s * e: it must equal the
        // gravity torque (no torque limit reached: all well below).
        const double tg = gravity_torque(m, pose, j, so.gravity_mps2);
        REQUIRE(tg < gains[j].torque_limit_nm);
        const double predicted_deg = tg / gains[j].kp_nm_per_rad * 180 / M_PI;
        const double err_deg =
            rotation_vector(pose.local[j] * local[j].conjugate()).norm() * 180 / M_PI;
        INFO("joint " << m.joint_name(j) << ": sag " << err_deg << " deg, statics " << predicted_deg
                      << " deg, direct solver " << direct);
        if (direct) {
            // Subtrees sag a little too (a few percent of the lever arm): 10 %.
            CHECK(err_deg == Approx(predicted_deg).epsilon(0.10).margin(0.002));
        } else {
            // Iterative solver: same order, never a tenth of a degree off.
            CHECK(err_deg < 3.0 * predicted_deg + 0.05);
        }
        if (predicted_deg > 0.05)
            ++loaded;
    }
    CHECK(loaded >= 6); // the test is not vacuous: shoulders, elbows, hips... carry load
    CHECK(scene.max_angular_speed_rad_s() < (direct ? 1e-3 : 0.1));
    CHECK(scene.divergences() == 0);
}

TEST_CASE("divergence is detected, counted and the character reset to its targets", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(simtest::cmu_like_skeleton());
    const CharacterPose pose = still_pose(m);
    Scene scene(m, SceneOptions{}, pose, default_gains(m, pose));
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    scene.set_joint_targets(pose.local, zero);
    REQUIRE(scene.step() == StepResult::ok);

    SECTION("an absurd kick")
    {
        scene.kick(m.hand_body(Side::right), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 5e4, 0));
    }
    SECTION("an absurd push")
    {
        scene.kick(m.body_index("l_forearm"), Eigen::Vector3d(1e3, 0, 0), Eigen::Vector3d::Zero());
    }
    CHECK(scene.step() == StepResult::diverged);
    CHECK(scene.divergences() == 1);
    // Back at the targets, at rest.
    std::vector<Eigen::Quaterniond> local;
    scene.local_rotations(local);
    for (int j = 0; j < CharacterModel::kJoints; ++j)
        CHECK(rotation_vector(pose.local[j] * local[j].conjugate()).norm() < 1e-9);
    CHECK(scene.max_linear_speed_mps() == 0.0);
    // And it carries on.
    for (int i = 0; i < 100; ++i)
        REQUIRE(scene.step() == StepResult::ok);
    CHECK(scene.divergences() == 1);
}

TEST_CASE("a NaN never enters ODE (which would abort)", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(simtest::cmu_like_skeleton());
    const CharacterPose pose = still_pose(m);
    Scene scene(m, SceneOptions{}, pose, default_gains(m, pose));
    CHECK_THROWS_WITH(
        scene.kick(3, Eigen::Vector3d::Constant(std::nan("")), Eigen::Vector3d::Zero()),
        Catch::Contains("finite"));
    CHECK_THROWS_WITH(scene.kick(99, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
                      Catch::Contains("no body"));
    CHECK(scene.step() == StepResult::ok);
}

TEST_CASE("scene options are checked", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(simtest::cmu_like_skeleton());
    const CharacterPose pose = still_pose(m);
    const auto gains = default_gains(m, pose);
    SceneOptions so;
    so.step_s = -0.001;
    CHECK_THROWS_WITH(Scene(m, so, pose, gains), Catch::Contains("physics step"));
    so = {};
    so.quickstep_iterations = 0;
    CHECK_THROWS_WITH(Scene(m, so, pose, gains), Catch::Contains("iterations"));
    so = {};
    so.drum.radius_m = 0;
    CHECK_THROWS_WITH(Scene(m, so, pose, gains), Catch::Contains("drum radius"));
    so = {};
    auto bad = gains;
    bad[3].kd_nm_s_per_rad = 0;
    CHECK_THROWS_WITH(Scene(m, so, pose, bad), Catch::Contains(m.joint_name(3)));
    Scene scene(m, so, pose, gains);
    auto targets = pose.local;
    targets[2] = Eigen::Quaterniond(std::nan(""), 0, 0, 0);
    CHECK_THROWS_WITH(
        scene.set_joint_targets(targets, std::vector<Eigen::Vector3d>(19, Eigen::Vector3d::Zero())),
        Catch::Contains(m.joint_name(2)));
    GainOptions go;
    go.natural_frequency_hz = -1;
    CHECK_THROWS_WITH(default_gains(m, pose, go), Catch::Contains("natural frequency"));
}

TEST_CASE("the drum: a stick pressed onto the membrane is held by contact", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(simtest::cmu_like_skeleton());
    const CharacterPose pose = still_pose(m);
    SceneOptions so;
    // Membrane 2 cm above the right stick's tip in the target pose: the motor
    // pushes the tip into the drum, which must stop it near the membrane.
    BodyFrames frames;
    m.forward(pose, frames);
    const int hb = m.hand_body(Side::right);
    const Eigen::Vector3d tip =
        m.tip_position(Side::right, frames.origin_m[hb], frames.rotation[hb]);
    so.drum.center_m = tip + Eigen::Vector3d(0, 0.02, 0);
    Scene scene(m, so, pose, default_gains(m, pose));
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    // The scene starts with the stick 2 cm into the drum; the contact pushes
    // it back against the arm's PD springs.
    for (int i = 0; i < 1000; ++i) {
        scene.set_joint_targets(pose.local, zero);
        REQUIRE(scene.step() == StepResult::ok);
    }
    CHECK(scene.contact_steps() > 0);
    // Without the drum the tip would sit 20 mm under the membrane; the
    // membrane spring (k = 2 pi T / ln(R/r), ~5.8 kN/m) in series with the
    // arm's PD holds it measurably higher.
    CHECK(scene.tip_position(Side::right).y() > so.drum.center_m.y() - 0.018);
    CHECK(scene.divergences() == 0);
}
