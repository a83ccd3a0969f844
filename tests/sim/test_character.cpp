// The character model: mapping, anthropometry (de Leva 1996), sticks and grips.
#include "ictus/character/anthropometry.hpp"
#include "ictus/character/character.hpp"
#include "sim_test_util.hpp"

#include <catch2/catch.hpp>

using namespace ictus;

TEST_CASE("de Leva's male mass fractions of the whole body add up to 1", "[sim][character]")
{
    // Head + trunk (three parts) + 2 x (upper arm, forearm, hand, thigh, shank, foot).
    double sum = de_leva_male(DeLevaSegment::head).mass_fraction;
    for (DeLevaSegment s :
         {DeLevaSegment::upper_trunk, DeLevaSegment::middle_trunk, DeLevaSegment::lower_trunk})
        sum += de_leva_male(s).mass_fraction;
    for (DeLevaSegment s : {DeLevaSegment::upper_arm, DeLevaSegment::forearm, DeLevaSegment::hand,
                            DeLevaSegment::thigh, DeLevaSegment::shank, DeLevaSegment::foot})
        sum += 2.0 * de_leva_male(s).mass_fraction;
    CHECK(sum == Approx(1.0).margin(1e-3));
    // The trunk parts are de Leva's trunk, 43.46 %.
    CHECK(de_leva_male(DeLevaSegment::upper_trunk).mass_fraction +
              de_leva_male(DeLevaSegment::middle_trunk).mass_fraction +
              de_leva_male(DeLevaSegment::lower_trunk).mass_fraction ==
          Approx(0.4346).margin(1e-4));
}

TEST_CASE("the character has 19 three-DoF joints with CMU segment lengths", "[sim][character]")
{
    const Skeleton skel = simtest::cmu_like_skeleton();
    CharacterOptions opt;
    opt.body_mass_kg = 80.0;
    const CharacterModel m = CharacterModel::from_skeleton(skel, opt);
    REQUIRE(m.bodies().size() == 20u);
    // Every body but the pelvis hangs from a parent that comes before it.
    for (int b = 1; b < CharacterModel::kBodies; ++b) {
        CHECK(m.bodies()[b].parent >= 0);
        CHECK(m.bodies()[b].parent < b);
    }
    // Upper arm: 5.1 units of 0.056444 m (the CMU convention) = 0.288 m.
    const BodySpec &upper_arm = m.bodies()[m.body_index("l_upper_arm")];
    CHECK(upper_arm.length_m == Approx(5.1 * 0.056444).epsilon(1e-9));
    CHECK(upper_arm.length_m > 0.25);
    CHECK(upper_arm.length_m < 0.35);
    // Mass: de Leva's 2.71 % of 80 kg; CoM at 57.72 % from the shoulder.
    CHECK(upper_arm.mass_kg == Approx(0.0271 * 80.0));
    CHECK(upper_arm.com_m.norm() == Approx(0.5772 * upper_arm.length_m));
    // Inertia about the long axis (x at rest): m (0.158 L)^2.
    CHECK(upper_arm.inertia_kg_m2(0, 0) ==
          Approx(upper_arm.mass_kg * std::pow(0.158 * upper_arm.length_m, 2)).epsilon(1e-9));
    // The whole body: the table's 100 % plus two sticks.
    CHECK(m.total_mass_kg() == Approx(80.0 + 2 * opt.stick.mass_kg).epsilon(1e-3));
    // Spine1 has no segment of its own: its rotation is composed into the
    // neck and the clavicles (it sits where they do), so the neck's source path
    // is Spine1 then Neck.
    const BodySpec &neck = m.bodies()[m.body_index("neck")];
    REQUIRE(neck.source_path.size() == 2u);
    CHECK(skel.joints[neck.source_path[0]].name == "Spine1");
    CHECK(skel.joints[neck.source_path[1]].name == "Neck");
    CHECK(m.joint_index("l_wrist") >= 0);
    CHECK(m.joint_index("nonsense") == -1);
}

TEST_CASE("a missing CMU joint or a bad option is refused with its name", "[sim][character]")
{
    Skeleton skel = simtest::cmu_like_skeleton();
    skel.joints[skel.find("LeftForeArm")].name = "LeftLowerArm";
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel), Catch::Contains("LeftForeArm"));
    const Skeleton good = simtest::cmu_like_skeleton();
    CharacterOptions opt;
    opt.body_mass_kg = -3;
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("body mass"));
    opt = {};
    opt.stick.tip_radius_m = 0.5;
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("tip radius"));
    opt = {};
    opt.stick.length_m = std::nan("");
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("stick length"));
    CHECK_THROWS_WITH(grip_from_string("italian"), Catch::Contains("italian"));
    CHECK(grip_from_string("German") == Grip::german);
}

TEST_CASE("grips: German sticks lie in the palm plane, French ones in the finger-palm plane",
          "[sim][character]")
{
    const Skeleton skel = simtest::cmu_like_skeleton();
    for (Grip grip : {Grip::german, Grip::french}) {
        CharacterOptions opt;
        opt.grip = grip;
        const CharacterModel m = CharacterModel::from_skeleton(skel, opt);
        const StickInHand &st = m.stick(Side::left);
        // Left hand at rest: fingers +x, thumb +z, palm facing -y.
        if (grip == Grip::german) {
            CHECK(st.axis.y() == Approx(0.0).margin(1e-12));
            CHECK(st.axis.z() == Approx(std::sin(opt.stick.grip_angle_rad)));
        } else {
            CHECK(st.axis.z() == Approx(0.0).margin(1e-12));
            CHECK(st.axis.y() == Approx(-std::sin(opt.stick.grip_angle_rad)));
        }
        CHECK(st.axis.x() == Approx(std::cos(opt.stick.grip_angle_rad)));
        // The tip is the stick's far end: length minus the butt-to-grip part.
        CHECK((st.tip_m - st.grip_m).norm() ==
              Approx(opt.stick.length_m - opt.stick.grip_from_butt_m));
        CHECK((st.tip_m - st.butt_m).norm() == Approx(opt.stick.length_m));
        // Merging the stick moves the hand's centre of mass towards the stick's.
        double mass;
        Eigen::Vector3d com;
        Eigen::Matrix3d inertia;
        m.merged_mass(m.hand_body(Side::left), mass, com, inertia);
        const BodySpec &hand = m.bodies()[m.hand_body(Side::left)];
        CHECK(mass == Approx(hand.mass_kg + opt.stick.mass_kg));
        CHECK((com - (hand.mass_kg * hand.com_m + opt.stick.mass_kg * st.com_m) / mass).norm() <
              1e-12);
    }
}

TEST_CASE("reference motion: composed rotations, slerp in time, ping-pong past the end",
          "[sim][character]")
{
    const Skeleton skel = simtest::cmu_like_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    // Elbow (LeftForeArm) turns about z by 10 degrees per frame, Spine1 by 1 per frame.
    const Motion motion = simtest::make_motion(skel, 5, 10.0, [](int f, const std::string &j) {
        if (j == "LeftForeArm")
            return Eigen::Quaterniond(
                Eigen::AngleAxisd(f * 10.0 * M_PI / 180, Eigen::Vector3d::UnitZ()));
        if (j == "Spine1")
            return Eigen::Quaterniond(Eigen::AngleAxisd(f * M_PI / 180, Eigen::Vector3d::UnitX()));
        return Eigen::Quaterniond::Identity();
    });
    const ReferenceMotion ref(m, motion);
    CHECK(ref.duration_s() == Approx(0.4));
    const int elbow = m.joint_index("l_elbow"), clav = m.joint_index("l_clavicle");
    CharacterPose p;
    ref.sample(0.15, p); // between frames 1 and 2: 15 degrees
    CHECK(Eigen::AngleAxisd(p.local[elbow]).angle() * 180 / M_PI == Approx(15.0));
    CHECK(Eigen::AngleAxisd(p.local[clav]).angle() * 180 / M_PI == Approx(1.5));
    ref.sample(0.5, p); // 0.1 s past the end: back at frame 3, 30 degrees
    CHECK(Eigen::AngleAxisd(p.local[elbow]).angle() * 180 / M_PI == Approx(30.0));
}
