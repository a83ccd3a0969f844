// BVH export (bvh_writer.cpp, bvh_export.cpp): write_bvh is the inverse of
// read_bvh (joint world positions through forward_kinematics within 1e-6 m,
// large rotations and gimbal lock included), a tiny file checked number by
// number against a hand computation, bad input refused with a message, and the
// character's poses exported onto its source skeleton land every body where
// CharacterModel::forward puts it.
#include "mocap_test_util.hpp"

#include "ictus/mocap/bvh.hpp"
#include "ictus/character/bvh_export.hpp"
#include "ictus/character/character.hpp"

#include <random>
#include <sstream>

using namespace ictus;
using mocap_test::deg;
using mocap_test::rot_axis;

namespace
{

// R_o0(a0) R_o1(a1) R_o2(a2) from the hand-written matrices (not the code under test).
Eigen::Matrix3d compose(const std::array<int, 3> &order, const Eigen::Vector3d &angles)
{
    const char names[3] = {'X', 'Y', 'Z'};
    return rot_axis(names[order[0]], angles[0]) * rot_axis(names[order[1]], angles[1]) *
           rot_axis(names[order[2]], angles[2]);
}

const std::array<std::array<int, 3>, 6> kOrders{
    {{{0, 1, 2}}, {{0, 2, 1}}, {{1, 0, 2}}, {{1, 2, 0}}, {{2, 0, 1}}, {{2, 1, 0}}}};

// A branching skeleton: root, a 5-joint chain with an end site, a 2-joint
// branch off the second joint, a joint with no children, a nonzero root OFFSET.
Skeleton test_skeleton()
{
    Skeleton s;
    auto add = [&s](const std::string &name, int parent, Eigen::Vector3d offset, bool end) {
        SkeletonJoint j;
        j.name = name;
        j.parent = parent;
        j.offset_m = offset;
        j.end_site = end;
        s.joints.push_back(j);
        return static_cast<int>(s.joints.size()) - 1;
    };
    const int root = add("Root", -1, {0.1, 0.9, -0.2}, false);
    int parent = root;
    int second = -1;
    for (int k = 0; k < 5; ++k) {
        parent = add("Chain" + std::to_string(k), parent, {0.05 * k, 0.3, -0.1 + 0.04 * k}, false);
        if (k == 1)
            second = parent;
    }
    add("Chain4_End", parent, {0.0, 0.2, 0.05}, true);
    const int b0 = add("Branch0", second, {-0.25, 0.0, 0.1}, false);
    const int b1 = add("Branch1", b0, {-0.3, -0.05, 0.0}, false);
    add("Branch1_End", b1, {-0.1, 0.0, 0.0}, true);
    add("Leaf", root, {0.0, -0.4, 0.0}, false);
    return s;
}

// Random rotations, plus ones whose middle angle sits at or within 1e-9 rad of
// +-90 degrees in the given order (gimbal lock), plus 180-degree turns.
Eigen::Quaterniond hard_rotation(std::mt19937 &rng, const std::array<int, 3> &order, int kind)
{
    std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
    Eigen::Vector3d a(angle(rng), angle(rng), angle(rng));
    if (kind % 4 == 1)
        a[1] = deg(90.0);
    else if (kind % 4 == 2)
        a[1] = -deg(90.0) + 1e-9;
    else if (kind % 4 == 3)
        a = Eigen::Vector3d(deg(180.0), 0.0, deg(180.0) * (kind % 8 == 3 ? 1 : 0));
    return Eigen::Quaterniond(compose(order, a));
}

Motion hard_motion(const Skeleton &s, const std::array<int, 3> &order, int frames)
{
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> position(-2.0, 2.0);
    Motion m;
    m.frame_rate_hz = 120.0;
    for (int f = 0; f < frames; ++f) {
        m.root_position_m.emplace_back(position(rng), position(rng), position(rng));
        std::vector<Eigen::Quaterniond> rotations;
        for (std::size_t j = 0; j < s.joints.size(); ++j)
            rotations.push_back(s.joints[j].end_site
                                    ? Eigen::Quaterniond::Identity()
                                    : hard_rotation(rng, order, f + static_cast<int>(j)));
        m.local_rotation.push_back(rotations);
    }
    return m;
}

double max_position_error(const Skeleton &a, const Motion &ma, const Skeleton &b, const Motion &mb)
{
    double worst = 0.0;
    for (int f = 0; f < ma.frames(); ++f) {
        const auto pa = forward_kinematics(a, ma, f);
        const auto pb = forward_kinematics(b, mb, f);
        for (std::size_t j = 0; j < a.joints.size(); ++j) {
            const int k = b.find(a.joints[j].name);
            REQUIRE(k >= 0);
            worst = std::max(worst, (pa[j] - pb[static_cast<std::size_t>(k)]).norm());
        }
    }
    return worst;
}

} // namespace

TEST_CASE("euler_angles: every Tait-Bryan order composes back, gimbal lock included",
          "[bvh][writer]")
{
    std::mt19937 rng(3);
    for (const auto &order : kOrders) {
        for (int kind = 0; kind < 40; ++kind) {
            const Eigen::Quaterniond q = hard_rotation(rng, order, kind);
            const Eigen::Vector3d a = euler_angles(q, order);
            INFO("order " << order[0] << order[1] << order[2] << " kind " << kind);
            CHECK(std::fabs(a[1]) <= deg(90.0) + 1e-12);
            const double error = (compose(order, a) - q.toRotationMatrix()).cwiseAbs().maxCoeff();
            CHECK(error < 1e-12);
        }
    }
    // Known angles away from the lock come back as they are.
    const Eigen::Vector3d want(deg(30.0), deg(-40.0), deg(120.0));
    const std::array<int, 3> zyx{{2, 1, 0}};
    const Eigen::Vector3d got = euler_angles(Eigen::Quaterniond(compose(zyx, want)), zyx);
    CHECK((got - want).norm() < 1e-12);
}

TEST_CASE("write_bvh: a tiny file, number by number", "[bvh][writer]")
{
    // Root at the origin, an arm 1 m up, its end 1 m along x. Frame 0: rest,
    // root moved to (1, 2, 3) m. Frame 1: root turned 90 deg about z, the arm
    // 90 deg about x. Centimetres, channels Z X Y.
    Skeleton s;
    s.joints.push_back({"Hips", -1, Eigen::Vector3d::Zero(), false});
    s.joints.push_back({"Arm", 0, Eigen::Vector3d(0, 1, 0), false});
    s.joints.push_back({"Arm_End", 1, Eigen::Vector3d(1, 0, 0), true});
    Motion m;
    m.frame_rate_hz = 50.0;
    const Eigen::Quaterniond id = Eigen::Quaterniond::Identity();
    m.root_position_m = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)};
    m.local_rotation = {{id, id, id},
                        {Eigen::Quaterniond(Eigen::AngleAxisd(deg(90), Eigen::Vector3d::UnitZ())),
                         Eigen::Quaterniond(Eigen::AngleAxisd(deg(90), Eigen::Vector3d::UnitX())),
                         id}};
    BvhWriteOptions options;
    options.units_per_m = 100.0;
    options.rotation_order = {{2, 0, 1}};
    options.decimals = 3;
    std::ostringstream out;
    write_bvh(out, s, m, options);
    const std::string expected = "HIERARCHY\n"
                                 "ROOT Hips\n"
                                 "{\n"
                                 "\tOFFSET 0.000 0.000 0.000\n"
                                 "\tCHANNELS 6 Xposition Yposition Zposition Zrotation "
                                 "Xrotation Yrotation\n"
                                 "\tJOINT Arm\n"
                                 "\t{\n"
                                 "\t\tOFFSET 0.000 100.000 0.000\n"
                                 "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
                                 "\t\tEnd Site\n"
                                 "\t\t{\n"
                                 "\t\t\tOFFSET 100.000 0.000 0.000\n"
                                 "\t\t}\n"
                                 "\t}\n"
                                 "}\n"
                                 "MOTION\n"
                                 "Frames: 2\n"
                                 "Frame Time: 0.0200000000\n"
                                 "100.000 200.000 300.000 0.000 0.000 0.000 0.000 0.000 0.000\n"
                                 "100.000 200.000 300.000 90.000 0.000 0.000 0.000 90.000 0.000\n";
    CHECK(out.str() == expected);

    // Read back in metres: the end site at frame 1 is the root + Rz(90) (
    // (0,1,0) + Rx(90) (1,0,0)) = (1,2,3) + Rz(90) (1,1,0) = (0, 3, 3).
    std::istringstream in(out.str());
    BvhOptions read_options;
    read_options.scale = 0.01;
    const BvhFile back = parse_bvh(in, "tiny", read_options);
    CHECK(back.motion.frame_rate_hz == 50.0);
    const auto p0 = forward_kinematics(back.skeleton, back.motion, 0);
    const auto p1 = forward_kinematics(back.skeleton, back.motion, 1);
    CHECK((p0[2] - Eigen::Vector3d(2, 3, 3)).norm() < 1e-12);
    CHECK((p1[1] - Eigen::Vector3d(0, 2, 3)).norm() < 1e-12);
    CHECK((p1[2] - Eigen::Vector3d(0, 3, 3)).norm() < 1e-12);
}

TEST_CASE("write_bvh then read_bvh: same joint world positions within 1e-6 m", "[bvh][writer]")
{
    const Skeleton s = test_skeleton();
    for (const auto &order : kOrders) {
        const Motion m = hard_motion(s, order, 60);
        for (double units_per_m : {1.0, 100.0, 1.0 / 0.0254}) {
            BvhWriteOptions options;
            options.units_per_m = units_per_m;
            options.rotation_order = order;
            std::ostringstream out;
            write_bvh(out, s, m, options);
            std::istringstream in(out.str());
            BvhOptions read_options;
            read_options.scale = 1.0 / units_per_m;
            const BvhFile back = parse_bvh(in, "round trip", read_options);
            INFO("order " << order[0] << order[1] << order[2] << ", " << units_per_m
                          << " units per m");
            REQUIRE(back.skeleton.joints.size() == s.joints.size());
            REQUIRE(back.motion.frames() == m.frames());
            CHECK(back.motion.frame_rate_hz == 120.0);
            // Depth-first order differs from index order here (the branch
            // and leaf are written after the chain): compare by name.
            CHECK(max_position_error(s, m, back.skeleton, back.motion) < 1e-6);
            // and the orientations of the joints
            double worst_angle = 0.0;
            for (int f = 0; f < m.frames(); ++f) {
                const auto ra = world_rotations(s, m, f);
                const auto rb = world_rotations(back.skeleton, back.motion, f);
                for (std::size_t j = 0; j < s.joints.size(); ++j)
                    if (!s.joints[j].end_site)
                        worst_angle =
                            std::max(worst_angle, ra[j].angularDistance(rb[static_cast<std::size_t>(
                                                      back.skeleton.find(s.joints[j].name))]));
            }
            CHECK(worst_angle < 1e-7);
        }
    }
}

TEST_CASE("write_bvh: the CMU clip read, written and read again", "[bvh][writer][data]")
{
    const std::string path = mocap_test::data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions options;
    options.scale = 0.056444;
    const BvhFile clip = read_bvh(path, options);
    const mocap_test::TempFile file("clip.bvh", "");
    write_bvh(file.path(), clip.skeleton, clip.motion); // metres, Z Y X
    const BvhFile back = read_bvh(file.path());
    REQUIRE(back.skeleton.joints.size() == clip.skeleton.joints.size());
    for (std::size_t j = 0; j < clip.skeleton.joints.size(); ++j)
        CHECK(back.skeleton.joints[j].name == clip.skeleton.joints[j].name);
    CHECK(back.motion.frame_rate_hz == clip.motion.frame_rate_hz);
    CHECK(max_position_error(clip.skeleton, clip.motion, back.skeleton, back.motion) < 1e-6);
}

TEST_CASE("write_bvh: bad input is refused with a message naming it", "[bvh][writer]")
{
    const Skeleton s = test_skeleton();
    Motion m = hard_motion(s, {{2, 1, 0}}, 3);
    std::ostringstream out;
    auto message = [&](const Skeleton &sk, const Motion &mo, const BvhWriteOptions &o) {
        try {
            std::ostringstream sink;
            write_bvh(sink, sk, mo, o, "perf.bvh");
        } catch (const MocapError &e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    Motion short_frame = m;
    short_frame.local_rotation[1].pop_back();
    CHECK_THAT(message(s, short_frame, {}),
               Catch::Contains("perf.bvh") && Catch::Contains("frame 1 has"));
    Motion nan_position = m;
    nan_position.root_position_m[2].x() = std::nan("");
    CHECK_THAT(message(s, nan_position, {}), Catch::Contains("frame 2: root position"));
    Motion zero_rotation = m;
    zero_rotation.local_rotation[0][3] = Eigen::Quaterniond(0, 0, 0, 0);
    CHECK_THAT(message(s, zero_rotation, {}), Catch::Contains("joint Chain2"));
    Motion no_rate = m;
    no_rate.frame_rate_hz = 0.0;
    CHECK_THAT(message(s, no_rate, {}), Catch::Contains("frame rate"));
    BvhWriteOptions bad_order;
    bad_order.rotation_order = {{2, 2, 0}};
    CHECK_THAT(message(s, m, bad_order), Catch::Contains("rotation_order"));
    BvhWriteOptions bad_units;
    bad_units.units_per_m = -1.0;
    CHECK_THAT(message(s, m, bad_units), Catch::Contains("units_per_m"));
    Skeleton cycle = s;
    cycle.joints[1].parent = 3; // Chain0 under Chain2, which is under Chain0
    CHECK_THAT(message(cycle, m, {}), Catch::Contains("cycle"));
    Skeleton child_of_end = s;
    child_of_end.joints[9].parent = 6; // Branch1_End under the end site Chain4_End
    CHECK_THAT(message(child_of_end, m, {}), Catch::Contains("end site"));
    // A path that cannot be written: the exception names it.
    try {
        write_bvh("/nonexistent-dir/perf.bvh", s, m);
        FAIL("no exception");
    } catch (const MocapError &e) {
        CHECK_THAT(std::string(e.what()), Catch::Contains("/nonexistent-dir/perf.bvh"));
    }
    // A motion with no frames is a valid, empty BVH.
    Motion empty;
    empty.frame_rate_hz = 30.0;
    std::ostringstream empty_out;
    write_bvh(empty_out, s, empty);
    CHECK_THAT(empty_out.str(), Catch::Contains("Frames: 0"));
}

TEST_CASE("motion_from_poses: exported poses put every body where the character does",
          "[bvh][writer][character][data]")
{
    const std::string path = mocap_test::data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions options;
    options.scale = 0.056444;
    options.skip_frames = 1;
    const BvhFile clip = read_bvh(path, options);
    const CharacterModel model = CharacterModel::from_skeleton(clip.skeleton);
    // Poses: captured frames, then the same with every joint turned further by
    // a large random rotation (what a simulation may do that the clip does not).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angle(-3.0, 3.0);
    std::vector<CharacterPose> poses;
    for (int f = 0; f < clip.motion.frames(); f += 97)
        poses.push_back(model.pose_from_motion(clip.motion, f));
    for (int k = 0; k < 10; ++k) {
        CharacterPose pose = poses[static_cast<std::size_t>(k) % poses.size()];
        for (auto &q : pose.local)
            q = q * Eigen::Quaterniond(compose({{2, 1, 0}}, {angle(rng), angle(rng), angle(rng)}));
        pose.pelvis_rotation =
            Eigen::Quaterniond(compose({{0, 1, 2}}, {angle(rng), angle(rng), angle(rng)}));
        pose.pelvis_position_m += Eigen::Vector3d(0.3, -0.1, 0.2);
        poses.push_back(pose);
    }
    const Skeleton with_sticks = skeleton_with_sticks(model, clip.skeleton);
    const Motion motion = motion_from_poses(model, with_sticks, poses, 250.0);
    REQUIRE(motion.frames() == static_cast<int>(poses.size()));
    CHECK(motion.frame_rate_hz == 250.0);

    // Through a BVH file in centimetres and back.
    std::ostringstream out;
    BvhWriteOptions write_options;
    write_options.units_per_m = 100.0;
    write_bvh(out, with_sticks, motion, write_options);
    std::istringstream in(out.str());
    BvhOptions read_options;
    read_options.scale = 0.01;
    const BvhFile back = parse_bvh(in, "performance.bvh", read_options);

    const int left_tip = back.skeleton.find("LeftHandStick_End");
    const int right_tip = back.skeleton.find("RightHandStick_End");
    REQUIRE(left_tip >= 0);
    REQUIRE(right_tip >= 0);
    double worst_origin = 0.0, worst_angle = 0.0, worst_tip = 0.0, worst_pose = 0.0;
    for (std::size_t f = 0; f < poses.size(); ++f) {
        BodyFrames frames;
        model.forward(poses[f], frames);
        const auto positions = forward_kinematics(back.skeleton, back.motion, static_cast<int>(f));
        const auto rotations = world_rotations(back.skeleton, back.motion, static_cast<int>(f));
        for (int b = 0; b < CharacterModel::kBodies; ++b) {
            const int j = back.skeleton.find(model.bodies()[static_cast<std::size_t>(b)].source);
            REQUIRE(j >= 0);
            worst_origin = std::max(worst_origin, (positions[static_cast<std::size_t>(j)] -
                                                   frames.origin_m[static_cast<std::size_t>(b)])
                                                      .norm());
            worst_angle =
                std::max(worst_angle, rotations[static_cast<std::size_t>(j)].angularDistance(
                                          frames.rotation[static_cast<std::size_t>(b)]));
        }
        for (Side side : {Side::left, Side::right}) {
            const int hb = model.hand_body(side);
            const Eigen::Vector3d tip =
                model.tip_position(side, frames.origin_m[static_cast<std::size_t>(hb)],
                                   frames.rotation[static_cast<std::size_t>(hb)]);
            const int j = side == Side::left ? left_tip : right_tip;
            worst_tip = std::max(worst_tip, (positions[static_cast<std::size_t>(j)] - tip).norm());
        }
        // and pose_from_motion of the exported motion is the pose again
        // (on the exported Motion: its joints have the source skeleton's indices)
        const CharacterPose again = model.pose_from_motion(motion, static_cast<int>(f));
        for (int j = 0; j < CharacterModel::kJoints; ++j)
            worst_pose =
                std::max(worst_pose, again.local[static_cast<std::size_t>(j)].angularDistance(
                                         poses[f].local[static_cast<std::size_t>(j)]));
    }
    INFO("body origin " << worst_origin << " m, angle " << worst_angle << " rad, tip " << worst_tip
                        << " m, pose " << worst_pose << " rad");
    CHECK(worst_origin < 1e-6);
    CHECK(worst_angle < 1e-7);
    CHECK(worst_tip < 1e-6);
    CHECK(worst_pose < 1e-7);

    // pose_from_frames inverts forward: the body frames of a pose give the pose back.
    double worst_inverse = 0.0;
    for (const CharacterPose &pose : poses) {
        BodyFrames frames;
        model.forward(pose, frames);
        const CharacterPose again = pose_from_frames(model, frames);
        worst_inverse =
            std::max(worst_inverse, (again.pelvis_position_m - pose.pelvis_position_m).norm());
        worst_inverse =
            std::max(worst_inverse, again.pelvis_rotation.angularDistance(pose.pelvis_rotation));
        for (int j = 0; j < CharacterModel::kJoints; ++j)
            worst_inverse =
                std::max(worst_inverse, again.local[static_cast<std::size_t>(j)].angularDistance(
                                            pose.local[static_cast<std::size_t>(j)]));
    }
    CHECK(worst_inverse < 1e-9);
    BodyFrames too_few;
    too_few.origin_m.resize(3);
    too_few.rotation.resize(3);
    CHECK_THROWS_WITH(pose_from_frames(model, too_few), Catch::Contains("3 bodies"));

    // BvhRecorder: body frames in, a BVH file out that reads back to the same
    // stick tips (through pose_from_frames, motion_from_poses, write_bvh).
    {
        BvhRecorder recorder(model, clip.skeleton, 120.0);
        for (const CharacterPose &pose : poses) {
            BodyFrames frames;
            model.forward(pose, frames);
            recorder.record(frames);
        }
        CHECK(recorder.frames() == static_cast<int>(poses.size()));
        const mocap_test::TempFile file("recorded.bvh", "");
        recorder.write(file.path());
        const BvhFile recorded = read_bvh(file.path());
        CHECK(recorded.motion.frame_rate_hz == 120.0);
        REQUIRE(recorded.motion.frames() == static_cast<int>(poses.size()));
        const int tip = recorded.skeleton.find("RightHandStick_End");
        REQUIRE(tip >= 0);
        double worst_recorded = 0.0;
        for (std::size_t f = 0; f < poses.size(); ++f) {
            BodyFrames frames;
            model.forward(poses[f], frames);
            const int hb = model.hand_body(Side::right);
            const Eigen::Vector3d want =
                model.tip_position(Side::right, frames.origin_m[static_cast<std::size_t>(hb)],
                                   frames.rotation[static_cast<std::size_t>(hb)]);
            worst_recorded =
                std::max(worst_recorded,
                         (forward_kinematics(recorded.skeleton, recorded.motion,
                                             static_cast<int>(f))[static_cast<std::size_t>(tip)] -
                          want)
                             .norm());
        }
        CHECK(worst_recorded < 1e-6);
        CHECK_THROWS_WITH(BvhRecorder(model, clip.skeleton, -1.0), Catch::Contains("frame rate"));
    }

    // Bad input: a pose with the wrong number of joints, a bad rate.
    std::vector<CharacterPose> bad = {poses[0]};
    bad[0].local.pop_back();
    CHECK_THROWS_WITH(motion_from_poses(model, with_sticks, bad, 250.0),
                      Catch::Contains("pose 0 has 18"));
    CHECK_THROWS_WITH(motion_from_poses(model, with_sticks, poses, 0.0),
                      Catch::Contains("frame rate"));
}
