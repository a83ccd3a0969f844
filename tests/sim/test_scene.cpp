// The ODE scene: still-pose PD equilibrium against statics, divergence handling.
#include "ictus/base/rotation.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/sim/scene.hpp"
#include "ictus/sim/strike_detector.hpp"
#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <memory>

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
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
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
        const double err_deg = log_map(pose.local[j] * local[j].conjugate()).norm() * 180 / M_PI;
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
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
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
        CHECK(log_map(pose.local[j] * local[j].conjugate()).norm() < 1e-9);
    CHECK(scene.max_linear_speed_mps() == 0.0);
    // And it carries on.
    for (int i = 0; i < 100; ++i)
        REQUIRE(scene.step() == StepResult::ok);
    CHECK(scene.divergences() == 1);
}

TEST_CASE("a NaN never enters ODE (which would abort)", "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
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
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
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
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
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

namespace
{
// The still pose with the right bead pressed `press_m` into a drum placed
// under it: the membrane `press_m` above the bead's lowest point.
struct PressedStick {
    CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    CharacterPose pose = still_pose(model);
    SceneOptions options;
    Eigen::Vector3d bead_lowest_m; // in the target pose
    explicit PressedStick(double press_m)
    {
        BodyFrames frames;
        model.forward(pose, frames);
        const int hb = model.hand_body(Side::right);
        const StickInHand &st = model.stick(Side::right);
        const double r = model.options().stick.tip_radius_m;
        const Eigen::Vector3d bead =
            frames.origin_m[hb] + frames.rotation[hb] * (st.tip_m - r * st.axis);
        bead_lowest_m = bead - Eigen::Vector3d(0, r, 0);
        options.drum.center_m = bead_lowest_m + Eigen::Vector3d(0.03, press_m, 0.02);
        options.stepper = Stepper::direct; // the exact constraint solution
    }
};

// k = 2 pi T / ln(R / r): the static point-load stiffness of a membrane,
// written out here again.
double membrane_stiffness(double tension, double radius, double tip_radius)
{
    return 2.0 * M_PI * tension / std::log(radius / tip_radius);
}

void settle(Scene &scene, const CharacterPose &pose, int steps)
{
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    for (int i = 0; i < steps; ++i) {
        scene.set_joint_targets(pose.local, zero);
        REQUIRE(scene.step() == StepResult::ok);
    }
}
} // namespace

TEST_CASE("drum contact forces: a stick resting on the membrane feels k d, and the weld and the "
          "drum together carry the weight",
          "[sim][scene]")
{
    PressedStick p(0.005);
    p.options.drum.head_thickness_m = 0.0; // the linear head: no stretching (k3 = 0)
    Scene scene(p.model, p.options, p.pose, default_gains(p.model, p.pose));
    settle(scene, p.pose, 2000);
    const double r = p.model.options().stick.tip_radius_m;
    const StickDrumContact &right = scene.drum_contact(Side::right);
    const StickDrumContact &left = scene.drum_contact(Side::left);
    REQUIRE(right.bead_points >= 1);
    CHECK(left.bead_points + left.shaft_points == 0);
    CHECK(left.force_n().norm() == 0.0);
    // At rest the soft contact is the membrane's spring: F_n = k d, d the
    // bead's depth below the membrane plane, measured from the geometry.
    const double k = membrane_stiffness(p.options.drum.tension_n_per_m, p.options.drum.radius_m, r);
    const double depth = p.options.drum.center_m.y() - (scene.bead_position(Side::right).y() - r);
    const Eigen::Vector3d f = right.bead_force_n;
    std::printf("resting stick: depth %.3f mm, contact force (%.3f, %.3f, %.3f) N, k d = %.3f N, "
                "shaft points %d\n",
                depth * 1e3, f.x(), f.y(), f.z(), k * depth, right.shaft_points);
    REQUIRE(depth > 0.0);
    CHECK(f.y() == Approx(k * depth).epsilon(0.005));
    CHECK(scene.drum_contact_stiffness_n_per_m() == Approx(k).epsilon(1e-12));
    // Friction inside ODE's pyramid (dContactApprox1: each of the two friction
    // directions, world x and z for a +y normal, bounded by mu F_n; mu = 0.3).
    CHECK(std::fabs(f.x()) <= p.options.drum.friction * f.y() * (1 + 1e-6));
    CHECK(std::fabs(f.z()) <= p.options.drum.friction * f.y() * (1 + 1e-6));
    // Statics of the whole character: gravity, the pelvis weld and the drum are
    // the only external forces (motors and ball joints act between bodies).
    const double weight = p.model.total_mass_kg() * p.options.gravity_mps2;
    const Eigen::Vector3d external = scene.support_force_n() + right.force_n() + left.force_n();
    std::printf("weight %.3f N: weld %.3f N + drum %.3f N\n", weight, scene.support_force_n().y(),
                right.force_n().y());
    CHECK(external.y() == Approx(weight).epsilon(1e-3));
    CHECK(std::hypot(external.x(), external.z()) <= 1e-3 * weight);
}

TEST_CASE("set_drum moves, resizes and re-tensions the drum of a live scene at once",
          "[sim][scene]")
{
    PressedStick p(0.005);
    Scene scene(p.model, p.options, p.pose, default_gains(p.model, p.pose));
    settle(scene, p.pose, 1000);
    const double r = p.model.options().stick.tip_radius_m;
    const double y_before = scene.bead_position(Side::right).y();

    // 4 mm higher and twice the tension: the bead settles against the new
    // membrane with the new k.
    DrumParams d = p.options.drum;
    d.center_m.y() += 0.004;
    d.tension_n_per_m = 6000.0;
    d.radius_m = 0.2;
    scene.set_drum(d);
    CHECK(scene.drum().center_m == d.center_m);
    settle(scene, p.pose, 1500);
    const double k = membrane_stiffness(6000.0, 0.2, r);
    const double depth = d.center_m.y() - (scene.bead_position(Side::right).y() - r);
    const double f = scene.drum_contact(Side::right).bead_force_n.y();
    std::printf("after set_drum: bead %.3f mm higher, depth %.3f mm, force %.3f N, k d = %.3f N\n",
                (scene.bead_position(Side::right).y() - y_before) * 1e3, depth * 1e3, f, k * depth);
    REQUIRE(depth > 0.0);
    CHECK(scene.bead_position(Side::right).y() > y_before + 0.001);
    CHECK(f == Approx(k * depth).epsilon(0.005));

    // Moved away (a drum whose disk no longer reaches the stick): no contact
    // from the very next step.
    d.center_m.x() += 1.0;
    scene.set_drum(d);
    settle(scene, p.pose, 1);
    CHECK(scene.drum_contact(Side::right).bead_points == 0);
    CHECK(scene.drum_contact(Side::right).force_n().norm() == 0.0);

    // Bad values are refused by name, and the drum stays as it was.
    DrumParams bad = d;
    bad.radius_m = 0.005; // inside the bead
    CHECK_THROWS_WITH(scene.set_drum(bad), Catch::Contains("drum radius"));
    bad = d;
    bad.tension_n_per_m = std::nan("");
    CHECK_THROWS_WITH(scene.set_drum(bad), Catch::Contains("drum tension"));
    bad = d;
    bad.center_m.y() = INFINITY;
    CHECK_THROWS_WITH(scene.set_drum(bad), Catch::Contains("drum position"));
    CHECK(scene.drum().center_m == d.center_m);
    CHECK(scene.drum().radius_m == 0.2);
}

TEST_CASE("bead centre: one tip radius back along the stick, moving as a point of the hand",
          "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
    const CharacterPose pose = still_pose(m);
    SceneOptions so;
    so.drum.center_m = Eigen::Vector3d(0, -5, 0); // out of reach
    so.step_s = 1e-4;                             // finite differences of the motion to O(h)
    Scene scene(m, so, pose, default_gains(m, pose));
    const double r = m.options().stick.tip_radius_m;
    // A whip of the right hand: large angular and linear velocities.
    scene.kick(m.hand_body(Side::right), Eigen::Vector3d(0.5, -1.0, 0.3),
               Eigen::Vector3d(0.0, 15.0, 20.0));
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    BodyFrames frames;
    Eigen::Vector3d previous = scene.bead_position(Side::right);
    double worst = 0.0, speed_max = 0.0;
    for (int i = 0; i < 200; ++i) {
        scene.set_joint_targets(pose.local, zero);
        REQUIRE(scene.step() == StepResult::ok);
        for (Side side : {Side::left, Side::right}) {
            // Geometry: tip minus r along the stick axis (the hand's rotation
            // applied to the model's axis).
            scene.body_frames(frames);
            const int hb = m.hand_body(side);
            const Eigen::Vector3d axis = frames.rotation[hb] * m.stick(side).axis;
            CHECK((scene.bead_position(side) - (scene.tip_position(side) - r * axis)).norm() <
                  1e-12);
            // Rigid body: two points of one body have relative velocity
            // normal to the segment joining them.
            const Eigen::Vector3d dv = scene.tip_velocity(side) - scene.bead_velocity(side);
            CHECK(std::fabs(dv.dot(axis)) < 1e-9 * (1.0 + dv.norm()));
        }
        const Eigen::Vector3d now = scene.bead_position(Side::right);
        const Eigen::Vector3d fd = (now - previous) / so.step_s;
        const Eigen::Vector3d v = scene.bead_velocity(Side::right);
        worst = std::max(worst, (fd - v).norm() / std::max(v.norm(), 0.1));
        speed_max = std::max(speed_max, v.norm());
        previous = now;
    }
    std::printf("bead velocity vs finite difference: worst relative error %.2e (speeds up to "
                "%.2f m/s)\n",
                worst, speed_max);
    CHECK(speed_max > 1.0);
    CHECK(worst < 0.01);
    // The bead is not the end point: their velocities differ by omega x (r axis).
    CHECK((scene.tip_velocity(Side::right) - scene.bead_velocity(Side::right)).norm() > 0.0);
}

TEST_CASE("a simulated strike: each step's contact-joint force is the membrane law (spring "
          "at the step's start, damper at its end), the detector's onset speed is the bead's",
          "[sim][scene]")
{
    // The membrane 1 cm under the right bead, and the hand thrown down at
    // 1.5 m/s: one stroke on the drum, seen by the detector on the scene's
    // beads and felt by ODE's contact joints.
    PressedStick p(-0.01);
    p.options.drum.head_thickness_m = 0.0; // the linear head: no stretching (k3 = 0)
    Scene scene(p.model, p.options, p.pose, default_gains(p.model, p.pose));
    StrikeDetector detector(membrane_of(scene));
    const double k = scene.drum_contact_stiffness_n_per_m(),
                 c = p.options.drum.contact_damping_n_s_per_m;
    const double r = p.model.options().stick.tip_radius_m, h = p.options.step_s;
    CHECK(detector.membrane().stiffness_n_per_m == k);
    settle(scene, p.pose, 200);
    scene.kick(p.model.hand_body(Side::right), Eigen::Vector3d(0, -1.5, 0),
               Eigen::Vector3d::Zero());
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    std::vector<StrikeEvent> events;
    StrikeEvent out[2];
    double joints_impulse = 0.0, joints_peak = 0.0, worst_law_error_n = 0.0, speed_crossing = 0.0;
    int contact_steps = 0;
    for (int i = 0; i < 400; ++i) {
        scene.set_joint_targets(p.pose.local, zero);
        REQUIRE(scene.step() == StepResult::ok);
        // ODE's soft contact (ERP = hk/(hk+c'), CFM = 1/(hk+c')) is the
        // spring-damper integrated implicitly: the force of a step is
        // k d + c' d' at the step's END state (d = d0 + h d' for the bead).
        // With c' = c - hk (the numerical damping taken out, scene.hpp's
        // soft_contact) that is k d0 + c d': the spring at the step's start,
        // the damper at its end (symplectic Euler: it keeps the energy the
        // damper does not take).
        const StickDrumContact &contact = scene.drum_contact(Side::right);
        if (contact.bead_points > 0) {
            ++contact_steps;
            const double depth =
                p.options.drum.center_m.y() - (scene.bead_position(Side::right).y() - r);
            const double vy = scene.bead_velocity(Side::right).y();
            const double depth_start = depth + h * vy; // d0 = d - h d', d' = -vy
            const double law = std::max(0.0, k * depth_start - c * vy);
            worst_law_error_n =
                std::max(worst_law_error_n, std::fabs(contact.bead_force_n.y() - law));
            joints_impulse += contact.bead_force_n.y() * h;
            joints_peak = std::max(joints_peak, contact.bead_force_n.y());
        }
        const bool was_in_contact = detector.in_contact(1);
        const int n = detect_strikes(detector, scene, out);
        for (int m = 0; m < n; ++m)
            events.push_back(out[m]);
        if (!was_in_contact && detector.in_contact(1))
            speed_crossing = -scene.bead_velocity(Side::right).y(); // the step that crossed
        if (events.size() == 1 && !detector.in_contact(1))
            break; // one stroke
    }
    REQUIRE(events.size() == 1);
    const StrikeEvent &e = events[0];
    std::printf(
        "simulated strike: onset %.4f s, v_n %.3f m/s (bead velocity after the crossing "
        "step %.3f), %.2f ms, %d contact steps; law vs joints per step within %.2e N; "
        "impulse: detector %.5f N s, joints %.5f N s; peak: detector %.2f N, joints %.2f N\n",
        e.time_s, e.normal_velocity_mps, speed_crossing, e.duration_ms, contact_steps,
        worst_law_error_n, e.impulse_n_s, joints_impulse, e.peak_force_n, joints_peak);
    CHECK(e.hand == 1);
    CHECK_FALSE(e.bounce);
    REQUIRE(contact_steps >= 3);
    CHECK(worst_law_error_n <= 1e-3 * joints_peak);
    // The crossing step's mean velocity vs the bead's velocity at its end: a
    // point of a rotating hand moves along a chord, O(h |w|^2 r) apart
    // (the bead test above: 1e-3 relative at h = 0.1 ms, so ~1 % at 1 ms).
    CHECK(e.normal_velocity_mps > 0.5);
    CHECK(e.normal_velocity_mps == Approx(speed_crossing).epsilon(0.01));
    // ODE collides at the start of a step: the step that ends below the
    // plane has no force yet, nor has the last one's release within it. So
    // the joints' impulse lacks up to one step of force at each end of the
    // contact, compared with the detector's law over the whole episode.
    CHECK(e.impulse_n_s >= joints_impulse);
    CHECK(e.impulse_n_s - joints_impulse <= 2.0 * e.peak_force_n * h);
}

namespace
{
// The still pose with the right shoulder turned by `angle` about the body's
// forward axis: the right arm (along +x in the T-pose) swings up or down.
CharacterPose shoulder_turned(const CharacterModel &m, double angle)
{
    CharacterPose p = still_pose(m);
    const int j = m.joint_index("r_shoulder");
    p.local[j] = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()) * p.local[j];
    return p;
}

// Sweeps the right shoulder from `from` to `to` rad over `seconds`, then
// holds; returns the right tip's height each step and the largest drum
// force on the right stick.
struct Sweep {
    std::vector<Eigen::Vector3d> tip;
    double max_force_n = 0.0;
    long shell_passes = 0;
    int divergences = 0;
};
Sweep sweep_arm(const CharacterModel &m, const SceneOptions &so, double from, double to,
                double seconds)
{
    Scene scene(m, so, shoulder_turned(m, from), default_gains(m, shoulder_turned(m, from)));
    const std::vector<Eigen::Vector3d> zero(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    Sweep out;
    const int steps = static_cast<int>(std::lround((seconds + 0.3) / so.step_s));
    for (int i = 0; i < steps; ++i) {
        const double u = std::min(1.0, i * so.step_s / seconds);
        const double s = u * u * (3.0 - 2.0 * u); // smoothstep
        scene.set_joint_targets(shoulder_turned(m, from + (to - from) * s).local, zero);
        scene.step();
        out.tip.push_back(scene.tip_position(Side::right));
        const StickDrumContact &c = scene.drum_contact(Side::right);
        out.max_force_n = std::max(out.max_force_n, (c.bead_force_n + c.shaft_force_n).norm());
    }
    out.shell_passes = scene.shell_passes();
    out.divergences = scene.divergences();
    return out;
}
} // namespace

// docs/character.md, "Drum": only the head stops a stick, met from above. A
// stick that rises into the drum from below (a clip's arm lifting under a drum
// placed for its strokes) passes through the shell as if the drum were not
// there, instead of being pinned and wrenched round its fulcrum.
TEST_CASE("the drum stops a stick on its head from above, a stick rising into its shell "
          "passes through",
          "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
    SceneOptions far;
    far.drum.center_m = Eigen::Vector3d(5.0, 0.5, 5.0); // out of reach
    // Which way is up for this shoulder turn: the tip must rise > 10 cm.
    double from = -0.35, to = 0.35;
    Sweep free = sweep_arm(m, far, from, to, 0.4);
    if (free.tip.back().y() < free.tip.front().y())
        std::swap(from, to), free = sweep_arm(m, far, from, to, 0.4);
    double top_y = -1e9;
    size_t top_i = 0;
    for (size_t i = 0; i < free.tip.size(); ++i)
        if (free.tip[i].y() > top_y)
            top_y = free.tip[i].y(), top_i = i;
    REQUIRE(top_y - free.tip.front().y() > 0.10);
    CHECK(free.max_force_n == 0.0);

    // The drum over the tip's highest point, its head 3 cm above it: the
    // rising stick enters through the bottom (or the side) and never reaches
    // the head. Bit for bit the free motion.
    SceneOptions under = far;
    under.drum.center_m = free.tip[top_i] + Eigen::Vector3d(0.0, 0.03, 0.0);
    const Sweep through = sweep_arm(m, under, from, to, 0.4);
    CHECK(through.shell_passes >= 1);
    CHECK(through.max_force_n == 0.0);
    CHECK(through.divergences == 0);
    REQUIRE(through.tip.size() == free.tip.size());
    double worst = 0.0;
    for (size_t i = 0; i < free.tip.size(); ++i)
        worst = std::max(worst, (through.tip[i] - free.tip[i]).norm());
    CHECK(worst == 0.0);

    // The same arm coming down from the top onto a head 4 cm under the
    // tip's highest point is stopped by it: the membrane force rises and the
    // tip stays within the head's travel under k, never near the free path.
    SceneOptions onto = far;
    const double head_y = top_y - 0.04;
    onto.drum.center_m = Eigen::Vector3d(free.tip[top_i].x(), head_y, free.tip[top_i].z());
    const Sweep down = sweep_arm(m, onto, to, from, 0.4);
    double lowest = 1e9;
    for (const Eigen::Vector3d &p : down.tip)
        if (std::hypot(p.x() - onto.drum.center_m.x(), p.z() - onto.drum.center_m.z()) <
            0.5 * onto.drum.radius_m)
            lowest = std::min(lowest, p.y());
    CHECK(down.shell_passes == 0);
    CHECK(down.max_force_n > 1.0);
    CHECK(down.divergences == 0);
    CHECK(lowest > head_y - 0.03);
    CHECK(lowest < head_y + 0.01);
}

TEST_CASE("kinematic legs and pelvis (score mode): the legs leave the solve and follow their "
          "targets, the arms and sticks move as beside simulated legs and a welded pelvis",
          "[sim][scene]")
{
    const CharacterModel m = CharacterModel::from_skeleton(default_skeleton());
    const CharacterPose pose = still_pose(m);
    const std::vector<JointGains> gains = default_gains(m, pose);
    // Direct solver, then QuickStep: legs simulated, legs kinematic, legs and
    // pelvis kinematic (SceneOptions::pelvis_kinematic: no weld).
    std::vector<std::unique_ptr<Scene>> scenes;
    for (bool direct : {true, false})
        for (int kinematic = 0; kinematic < 3; ++kinematic) {
            SceneOptions so;
            so.drum.center_m = Eigen::Vector3d(0, -5, 0); // out of reach
            so.sticks = StickMount::fulcrum;
            so.stepper = direct ? Stepper::direct : Stepper::quick;
            so.legs_kinematic = kinematic >= 1;
            so.pelvis_kinematic = kinematic == 2;
            scenes.push_back(std::make_unique<Scene>(m, so, pose, gains));
        }
    Scene &exact = *scenes[0], &exact_kin = *scenes[1], &exact_fixed = *scenes[2],
          &quick = *scenes[3], &quick_kin = *scenes[4], &quick_fixed = *scenes[5];

    // The legs, found here by name: the bodies below the thighs.
    std::vector<bool> leg(CharacterModel::kBodies, false);
    for (int b = 1; b < CharacterModel::kBodies; ++b)
        for (int a = b; a > 0; a = m.bodies()[a].parent)
            if (m.bodies()[a].name == "l_thigh" || m.bodies()[a].name == "r_thigh")
                leg[b] = true;
    int legs = 0;
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        INFO("body " << m.bodies()[b].name);
        CHECK(exact_kin.body_kinematic(b) == leg[b]);
        CHECK(quick_kin.body_kinematic(b) == leg[b]);
        CHECK(exact_fixed.body_kinematic(b) == (leg[b] || b == 0));
        CHECK_FALSE(exact.body_kinematic(b));
        legs += leg[b];
    }
    REQUIRE(legs == 6);
    // A placed body takes no kick (it would keep the velocity forever).
    CHECK_THROWS_AS(
        exact_kin.kick(m.body_index("l_shank"), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::Zero()),
        SimError);
    CHECK_THROWS_AS(exact_fixed.kick(0, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::Zero()),
                    SimError);

    // Arms and legs swing together for 2 s: elbows and shoulders at 2 Hz,
    // hips and knees at 1.5 Hz (rates given in the parent frame).
    const int l_elbow = m.joint_index("l_elbow"), r_elbow = m.joint_index("r_elbow");
    const int l_shoulder = m.joint_index("l_shoulder"), r_shoulder = m.joint_index("r_shoulder");
    const int hips[2] = {m.joint_index("l_hip"), m.joint_index("r_hip")};
    const int knees[2] = {m.joint_index("l_knee"), m.joint_index("r_knee")};
    std::vector<Eigen::Quaterniond> target = pose.local, local;
    std::vector<Eigen::Vector3d> rate(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    const auto swing = [&](int j, const Eigen::Vector3d &axis, double amp, double hz, double t) {
        const double w = 2.0 * M_PI * hz;
        target[j] = Eigen::AngleAxisd(amp * std::sin(w * t), axis) * pose.local[j];
        rate[j] = axis * (amp * w * std::cos(w * t));
    };
    // The largest distance of a stick tip, and of a fulcrum angle, of `a` from `b`'s.
    struct Gap {
        double tip_m = 0.0, fulcrum_rad = 0.0;
        void add(const Scene &a, const Scene &b)
        {
            for (Side s : {Side::left, Side::right}) {
                tip_m = std::max(tip_m, (a.tip_position(s) - b.tip_position(s)).norm());
                fulcrum_rad = std::max(fulcrum_rad,
                                       std::fabs(a.fulcrum_angle_rad(s) - b.fulcrum_angle_rad(s)));
            }
        }
    } exact_gap, quick_gap, quick_from_exact, quick_kin_from_exact, fixed_gap,
        quick_fixed_from_exact;
    double leg_off = 0.0, leg_lag = 0.0;
    for (int i = 0; i < 2000; ++i) {
        const double t = i * 0.001;
        swing(l_elbow, Eigen::Vector3d::UnitY(), 0.6, 2.0, t);
        swing(r_elbow, Eigen::Vector3d::UnitY(), -0.6, 2.0, t);
        swing(l_shoulder, Eigen::Vector3d::UnitZ(), 0.4, 2.0, t);
        swing(r_shoulder, Eigen::Vector3d::UnitZ(), -0.4, 2.0, t);
        for (int s = 0; s < 2; ++s) {
            swing(hips[s], Eigen::Vector3d::UnitX(), 0.5, 1.5, t);
            swing(knees[s], Eigen::Vector3d::UnitX(), 0.7, 1.5, t);
        }
        for (auto &scene : scenes) {
            scene->set_joint_targets(target, rate);
            REQUIRE(scene->step() == StepResult::ok);
        }
        for (Scene *kin : {&exact_kin, &quick_kin, &exact_fixed, &quick_fixed}) {
            kin->local_rotations(local);
            for (int j = 0; j < CharacterModel::kJoints; ++j)
                if (leg[j + 1])
                    leg_off = std::max(leg_off, log_map(target[j] * local[j].conjugate()).norm());
        }
        exact.local_rotations(local);
        for (int j = 0; j < CharacterModel::kJoints; ++j)
            if (leg[j + 1])
                leg_lag = std::max(leg_lag, log_map(target[j] * local[j].conjugate()).norm());
        exact_gap.add(exact_kin, exact);
        quick_gap.add(quick_kin, quick);
        quick_from_exact.add(quick, exact);
        quick_kin_from_exact.add(quick_kin, exact);
        fixed_gap.add(exact_fixed, exact_kin);
        quick_fixed_from_exact.add(quick_fixed, exact);
    }
    std::printf("kinematic legs: off their targets by %.2e rad (simulated legs: %.4f rad)\n"
                "  direct solver, kinematic vs simulated legs: tips %.2e mm, fulcrums %.2e rad\n"
                "  QuickStep, kinematic vs simulated legs: tips %.3f mm, fulcrums %.2e rad\n"
                "  QuickStep vs direct: simulated legs: tips %.3f mm, fulcrums %.2e rad; "
                "kinematic legs: tips %.3f mm, fulcrums %.2e rad\n",
                leg_off, leg_lag, exact_gap.tip_m * 1e3, exact_gap.fulcrum_rad,
                quick_gap.tip_m * 1e3, quick_gap.fulcrum_rad, quick_from_exact.tip_m * 1e3,
                quick_from_exact.fulcrum_rad, quick_kin_from_exact.tip_m * 1e3,
                quick_kin_from_exact.fulcrum_rad);
    std::printf("  kinematic pelvis vs welded, direct solver: tips %.2e mm, fulcrums %.2e rad; "
                "QuickStep vs direct: tips %.3f mm, fulcrums %.2e rad\n",
                fixed_gap.tip_m * 1e3, fixed_gap.fulcrum_rad, quick_fixed_from_exact.tip_m * 1e3,
                quick_fixed_from_exact.fulcrum_rad);
    CHECK(leg_off < 1e-9); // placed at the targets
    CHECK(leg_lag > 1e-3); // which simulated legs are not: the check above can fail
    // With the weld and the joints solved exactly the legs move nothing else.
    CHECK(exact_gap.tip_m < 1e-6);
    CHECK(exact_gap.fulcrum_rad < 1e-6);
    // QuickStep's own residual (15 iterations, against the exact solve) is
    // what separates them there: no larger without the legs' rows or the
    // weld's. (It moves by ~15 % with the rows' order alone, which ODE draws
    // from one generator for all scenes: 0.0102 and 0.0118 rad measured for
    // the same scene stepped beside three or five others.)
    for (const Gap *g : {&quick_kin_from_exact, &quick_fixed_from_exact}) {
        CHECK(g->tip_m < 1.25 * quick_from_exact.tip_m);
        CHECK(g->fulcrum_rad < 1.25 * quick_from_exact.fulcrum_rad);
    }
    CHECK(quick_gap.tip_m < quick_from_exact.tip_m);
    // A kinematic pelvis is the weld made exact: the same motion.
    CHECK(fixed_gap.tip_m < 1e-6);
    CHECK(fixed_gap.fulcrum_rad < 1e-6);

    // At rest the weld carries what is simulated: without the legs' weight.
    for (Scene *scene : {&exact, &exact_kin, &exact_fixed})
        settle(*scene, pose, 1500);
    double legs_kg = 0.0;
    for (int b = 0; b < CharacterModel::kBodies; ++b)
        legs_kg += leg[b] ? m.bodies()[b].mass_kg : 0.0;
    const double weight = m.total_mass_kg() * exact.options().gravity_mps2;
    const double without_legs = weight - legs_kg * exact.options().gravity_mps2;
    std::printf("  weld: %.3f N of %.3f N (simulated legs), %.3f N of %.3f N (kinematic legs), "
                "%.3f N (and pelvis)\n",
                exact.support_force_n().y(), weight, exact_kin.support_force_n().y(), without_legs,
                exact_fixed.support_force_n().y());
    CHECK(exact.support_force_n().y() == Approx(weight).epsilon(1e-6));
    CHECK(exact_kin.support_force_n().y() == Approx(without_legs).epsilon(1e-6));
    const Eigen::Vector3d fixed_support = exact_fixed.support_force_n();
    CHECK(fixed_support.y() == Approx(without_legs).epsilon(1e-6));
    CHECK(std::hypot(fixed_support.x(), fixed_support.z()) < 1e-6 * without_legs);
    for (auto &scene : scenes)
        CHECK(scene->divergences() == 0);
}
