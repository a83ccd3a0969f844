// BVH reader and forward kinematics against hand-computed joint positions, the
// CMU drumming file's documented facts (data README), and malformed files.
#include "mocap_test_util.hpp"

#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/capture_bounds.hpp"

#include <array>
#include <fstream>
#include <iomanip>
#include <map>
#include <random>
#include <sstream>

using namespace ictus;
using namespace mocap_test;

namespace
{

// Three chained joints with three different rotation orders, mixed CRLF / LF
// line endings, root OFFSET (0.5, 0, 0).
const char *const kChainBvh = "HIERARCHY\r\n"
                              "ROOT root\n"
                              "{\r\n"
                              "  OFFSET 0.5 0 0\r\n"
                              "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
                              "Yrotation\r\n"
                              "  JOINT a\r\n"
                              "  {\n"
                              "    OFFSET 1 2 3\r\n"
                              "    CHANNELS 3 Yrotation Xrotation Zrotation\r\n"
                              "    JOINT b\r\n"
                              "    {\r\n"
                              "      OFFSET 0 4 0\r\n"
                              "      CHANNELS 3 Xrotation Zrotation Yrotation\r\n"
                              "      End Site\r\n"
                              "      {\r\n"
                              "        OFFSET 2 0 0\r\n"
                              "      }\r\n"
                              "    }\r\n"
                              "  }\r\n"
                              "}\r\n"
                              "MOTION\n"
                              "Frames: 3\n"
                              "Frame Time: 0.04\r\n"
                              "0 0 0 0 0 0 0 0 0 0 0 0\r\n"
                              "10 20 30 90 0 0 0 0 0 0 0 0\n"
                              "1 2 3 30 -40 50 15 25 -35 60 -20 10\r\n";

void require_near(const Eigen::Vector3d &got, const Eigen::Vector3d &want, double tol)
{
    INFO("got " << got.transpose() << ", want " << want.transpose());
    REQUIRE((got - want).norm() < tol);
}

// The same minimal file for the error tests; line numbers in comments.
std::string minimal_bvh_lines[] = {
    "HIERARCHY",                                                                // 1
    "ROOT Hips",                                                                // 2
    "{",                                                                        // 3
    "  OFFSET 0 0 0",                                                           // 4
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation", // 5
    "  JOINT Chest",                                                            // 6
    "  {",                                                                      // 7
    "    OFFSET 0 1 0",                                                         // 8
    "    CHANNELS 3 Zrotation Yrotation Xrotation",                             // 9
    "    End Site",                                                             // 10
    "    {",                                                                    // 11
    "      OFFSET 0 1 0",                                                       // 12
    "    }",                                                                    // 13
    "  }",                                                                      // 14
    "}",                                                                        // 15
    "MOTION",                                                                   // 16
    "Frames: 2",                                                                // 17
    "Frame Time: 0.01",                                                         // 18
    "0 1 0 0 0 0 0 0 0",                                                        // 19
    "0 1 0 10 0 0 0 0 5",                                                       // 20
};

// The minimal file with line `line` (1-based) replaced by `text` (or removed
// when text is null), cut after `keep_lines` lines when > 0.
std::string minimal_bvh(int line = 0, const char *text = "", int keep_lines = 0)
{
    std::string out;
    int n = 0;
    for (const std::string &original : minimal_bvh_lines) {
        ++n;
        if (keep_lines > 0 && n > keep_lines)
            break;
        if (n == line) {
            if (text)
                out += std::string(text) + "\n";
        } else {
            out += original + "\n";
        }
    }
    return out;
}

// Parses and requires a MocapError whose what() starts with "src.bvh:LINE:"
// (or "src.bvh: " for line 0) and contains `expected`.
void require_error(const std::string &text, int line, const std::string &expected,
                   const BvhOptions &options = {})
{
    std::istringstream in(text);
    try {
        parse_bvh(in, "src.bvh", options);
    } catch (const MocapError &error) {
        const std::string what = error.what();
        INFO("what(): " << what);
        const std::string prefix =
            line > 0 ? "src.bvh:" + std::to_string(line) + ": " : std::string("src.bvh: ");
        CHECK(what.rfind(prefix, 0) == 0);
        CHECK(error.line() == line);
        CHECK(error.file() == "src.bvh");
        CHECK(what.find(expected) != std::string::npos);
        return;
    }
    FAIL("no MocapError for a malformed file (expected '" << expected << "')");
}

// `text` (ASCII) as UTF-16: little- or big-endian, with or without its byte order mark.
std::string utf16(const std::string &text, bool big, bool mark)
{
    std::string out = mark ? (big ? std::string("\xFE\xFF") : std::string("\xFF\xFE")) : "";
    for (char c : text)
        out += big ? std::string(1, '\0') + c : std::string(1, c) + '\0';
    return out;
}

} // namespace

TEST_CASE("BVH: hierarchy, channels, rate and mixed line endings", "[mocap][bvh]")
{
    const TempFile file("chain.bvh", kChainBvh);
    MocapWarnings warnings;
    const BvhFile bvh = read_bvh(file.path(), {}, &warnings);
    CHECK(warnings.empty());
    REQUIRE(bvh.skeleton.joints.size() == 4);
    CHECK(bvh.skeleton.find("root") == 0);
    CHECK(bvh.skeleton.find("b") == 2);
    CHECK(bvh.skeleton.find("nope") == -1);
    CHECK(bvh.skeleton.joints[3].end_site);
    CHECK(bvh.skeleton.joints[3].parent == 2);
    CHECK(bvh.channelled_joints() == 3);
    CHECK(bvh.channel_count == 12);
    CHECK(bvh.channels[1][0] == BvhChannel::Yrotation);
    CHECK(bvh.motion.frames() == 3);
    CHECK(bvh.motion.frame_rate_hz == 25.0);
    CHECK(bvh.frame_time_s == 0.04);
    // The same file with a UTF-8 byte order mark first (as Windows' Notepad saves it).
    const TempFile marked("chain-bom.bvh", std::string("\xEF\xBB\xBF") + kChainBvh);
    const BvhFile same = read_bvh(marked.path(), {}, &warnings);
    CHECK(same.channel_count == bvh.channel_count);
    CHECK(same.motion.frames() == bvh.motion.frames());
}

// A BVH saved as UTF-16 (Windows' "Unicode") read as "expected 'HIERARCHY', got
// '??H?I?E?R?...'": said to be UTF-16, at line 1, in either byte order, with or without
// its byte order mark.
TEST_CASE("BVH: a UTF-16 file is said to be one", "[mocap][bvh]")
{
    for (const bool big : {false, true})
        for (const bool mark : {false, true}) {
            INFO((big ? "big" : "little")
                 << "-endian, " << (mark ? "with" : "without") << " its mark");
            require_error(utf16(kChainBvh, big, mark), 1, "UTF-16");
        }
}

TEST_CASE("BVH: forward kinematics reproduces hand-computed joint positions", "[mocap][bvh]")
{
    std::istringstream in(kChainBvh);
    const BvhFile bvh = parse_bvh(in, "chain.bvh");

    // Frame 0, rest pose: cumulative offsets.
    auto p = forward_kinematics(bvh.skeleton, bvh.motion, 0);
    require_near(p[0], {0.5, 0, 0}, 1e-12);
    require_near(p[1], {1.5, 2, 3}, 1e-12);
    require_near(p[2], {1.5, 6, 3}, 1e-12);
    require_near(p[3], {3.5, 6, 3}, 1e-12);

    // Frame 1: root at offset + (10, 20, 30), turned 90 deg about z, which maps
    // (x, y, z) to (-y, x, z): a = root + (-2, 1, 3), b = a + (-4, 0, 0),
    // end = b + (0, 2, 0).
    p = forward_kinematics(bvh.skeleton, bvh.motion, 1);
    require_near(p[0], {10.5, 20, 30}, 1e-12);
    require_near(p[1], {8.5, 21, 33}, 1e-12);
    require_near(p[2], {4.5, 21, 33}, 1e-12);
    require_near(p[3], {4.5, 23, 33}, 1e-12);

    // Frame 2: every joint rotated, each in its own channel order, composed in
    // listed order (intrinsic) with rotation matrices written out by hand.
    const Eigen::Matrix3d r_root = rot_z(deg(30)) * rot_x(deg(-40)) * rot_y(deg(50));
    const Eigen::Matrix3d r_a = r_root * rot_y(deg(15)) * rot_x(deg(25)) * rot_z(deg(-35));
    const Eigen::Matrix3d r_b = r_a * rot_x(deg(60)) * rot_z(deg(-20)) * rot_y(deg(10));
    const Eigen::Vector3d root(1.5, 2, 3);
    const Eigen::Vector3d a = root + r_root * Eigen::Vector3d(1, 2, 3);
    const Eigen::Vector3d b = a + r_a * Eigen::Vector3d(0, 4, 0);
    const Eigen::Vector3d end = b + r_b * Eigen::Vector3d(2, 0, 0);
    p = forward_kinematics(bvh.skeleton, bvh.motion, 2);
    require_near(p[0], root, 1e-12);
    require_near(p[1], a, 1e-12);
    require_near(p[2], b, 1e-12);
    require_near(p[3], end, 1e-12);
    const auto world = world_rotations(bvh.skeleton, bvh.motion, 2);
    CHECK((world[2].toRotationMatrix() - r_b).norm() < 1e-12);
    CHECK((world[3].toRotationMatrix() - r_b).norm() < 1e-12); // end site: identity local

    // Scale converts every length (offsets and root translation) to metres.
    std::istringstream again(kChainBvh);
    BvhOptions cm;
    cm.scale = 0.01;
    const BvhFile scaled = parse_bvh(again, "chain.bvh", cm);
    const auto p_scaled = forward_kinematics(scaled.skeleton, scaled.motion, 2);
    require_near(p_scaled[3], 0.01 * end, 1e-14);

    CHECK_THROWS_AS(forward_kinematics(bvh.skeleton, bvh.motion, 3), MocapError);
    CHECK_THROWS_AS(forward_kinematics(bvh.skeleton, bvh.motion, -1), MocapError);
}

TEST_CASE("BVH: the channel order decides the composition", "[mocap][bvh]")
{
    // Rz(90) Rx(90) (0, 1, 0) = Rz(90) (0, 0, 1) = (0, 0, 1), while
    // Rx(90) Rz(90) (0, 1, 0) = Rx(90) (-1, 0, 0) = (-1, 0, 0).
    auto tip = [](const std::string &channels) {
        const std::string text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 2 " + channels +
                                 "\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\n"
                                 "Frame Time: 0.01\n90 90\n";
        std::istringstream in(text);
        const BvhFile bvh = parse_bvh(in, "order.bvh");
        return forward_kinematics(bvh.skeleton, bvh.motion, 0)[1];
    };
    require_near(tip("Zrotation Xrotation"), {0, 0, 1}, 1e-12);
    require_near(tip("Xrotation Zrotation"), {-1, 0, 0}, 1e-12);
}

TEST_CASE("BVH: a body lying in the first frame (a z-up capture) is said, not refused",
          "[mocap][bvh]")
{
    // Hips -> Spine -> Head, the spine along `axis`; the root turned by `turn` degrees
    // about x in the motion. Upright (y): nothing said. Along z, or y turned -90 about x
    // (a z-up exporter's frame): a warning with the angle from +y, computed here from the
    // axis: 90 degrees. Seeded tilts: said exactly when the tilt is beyond 60 degrees.
    auto warned = [](const std::string &axis, double turn) {
        const std::string text = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xrotation "
                                 "Yrotation Zrotation\nJOINT Spine\n{\nOFFSET " +
                                 axis + "\nCHANNELS 0\nJOINT Head\n{\nOFFSET " + axis +
                                 "\nCHANNELS 0\nEnd Site\n{\nOFFSET 0 0 0\n}\n}\n}\n}\n"
                                 "MOTION\nFrames: 1\nFrame Time: 0.01\n" +
                                 std::to_string(turn) + " 0 0\n";
        std::istringstream in(text);
        MocapWarnings warnings;
        parse_bvh(in, "up.bvh", {}, &warnings);
        return warnings;
    };
    CHECK(warned("0 0.3 0", 0.0).empty());
    const MocapWarnings z = warned("0 0 0.3", 0.0);
    REQUIRE(z.size() == 1);
    CHECK(z[0].find("up.bvh: the body's hips-to-head line is 90 degrees from up (+y)") == 0);
    CHECK(warned("0 0.3 0", -90.0).size() == 1);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> tilt(0.0, 120.0);
    for (int k = 0; k < 20; ++k) {
        const double t = tilt(rng);
        if (std::abs(t - 60.0) < 0.5)
            continue;
        INFO("tilt " << t);
        CHECK(warned("0 0.3 0", t).size() == (t > 60.0 ? 1u : 0u));
    }
}

TEST_CASE("BVH: position channels on a non-root joint", "[mocap][bvh]")
{
    // Root turned 90 deg about y, which maps (x, y, z) to (z, y, -x). Joint a
    // sits at OFFSET (1, 0, 0) + its channels (0.5, 0, 0) and turns 90 deg about
    // z. a = Ry90 (1.5, 0, 0) = (0, 0, -1.5); its end site, (0, 1, 0) in a's
    // frame, is Ry90 Rz90 (0, 1, 0) = Ry90 (-1, 0, 0) = (0, 0, 1) further.
    const std::string text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation "
                             "Yrotation Xrotation\nJOINT a\n{\nOFFSET 1 0 0\nCHANNELS 6 "
                             "Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
                             "End Site\n{\nOFFSET 0 1 0\n}\n}\n}\nMOTION\nFrames: 1\n"
                             "Frame Time: 0.01\n0 90 0 0.5 0 0 90 0 0\n";
    std::istringstream in(text);
    MocapWarnings warnings;
    const BvhFile bvh = parse_bvh(in, "nonroot.bvh", {}, &warnings);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("bvh_forward_kinematics") != std::string::npos);
    // It names the joint and the line of its position channel (line 9: `CHANNELS 6
    // Xposition ...`), and says what the character does with them: `ictusd --mocap`
    // plays the joints' rotations, and a forearm moved 17 cm by its channels played the
    // same strikes as without them. The warning used to give a C++ function to a
    // command-line user.
    CHECK(warnings[0].find("nonroot.bvh:9: joint 'a' has position channels") == 0);
    CHECK(warnings[0].find("the character (ictusd --mocap) plays the joints' rotations on "
                           "the OFFSETs and ignores them") != std::string::npos);
    const auto p = bvh_forward_kinematics(bvh, 0);
    require_near(p[1], {0, 0, -1.5}, 1e-12);
    require_near(p[2], {0, 0, -0.5}, 1e-12);
}

TEST_CASE("BVH: frame time printed to few digits snaps to the integer rate", "[mocap][bvh]")
{
    auto rate = [](const std::string &frame_time) {
        std::istringstream in(minimal_bvh(18, ("Frame Time: " + frame_time).c_str()));
        return parse_bvh(in, "rate.bvh").motion.frame_rate_hz;
    };
    CHECK(rate(".0083333") == 120.0); // |1/120 - .0083333| < 0.5e-7
    CHECK(rate("0.033333") == 30.0);
    CHECK(rate("0.004") == 250.0);
    CHECK(rate("0.0123") == Approx(1.0 / 0.0123).epsilon(1e-12));   // 81.3 Hz: not snapped
    CHECK(rate("0.00833") == Approx(1.0 / 0.00833).epsilon(1e-12)); // 120.05 Hz: 4e-4 off
    CHECK(rate("0.3") == Approx(1.0 / 0.3).epsilon(1e-12));         // not 3 Hz
}

TEST_CASE("BVH: malformed files give FILE:LINE errors", "[mocap][bvh][errors]")
{
    {
        std::istringstream fine(minimal_bvh());
        REQUIRE(parse_bvh(fine, "src.bvh").motion.frames() == 2);
    }
    SECTION("truncated in the hierarchy")
    {
        require_error(minimal_bvh(0, "", 12), 12, "expected '}', got end of file");
    }
    SECTION("truncated motion: fewer lines than Frames")
    {
        require_error(minimal_bvh(0, "", 19), 19, "expected 2 motion lines (Frames: 2), got 1");
        require_error(minimal_bvh(17, "Frames: 3"), 20, "expected 3 motion lines");
    }
    SECTION("truncated in the middle of a motion line")
    {
        require_error(minimal_bvh(20, "0 1 0 10 0"), 20,
                      "expected 9 values (one per channel) on motion line 2, got 5");
    }
    SECTION("too many values on a line")
    {
        require_error(minimal_bvh(19, "0 1 0 0 0 0 0 0 0 7"), 19, "expected 9 values");
    }
    SECTION("NaN and infinity in the motion")
    {
        require_error(
            minimal_bvh(20, "0 1 0 10 nan 0 0 0 5"), 20,
            "expected a finite number (|x| <= 1e9) in column 5 (Hips Yrotation), got 'nan'");
        require_error(minimal_bvh(19, "0 1 0 0 0 0 0 inf 0"), 19,
                      "column 8 (Chest Yrotation), got 'inf'");
        require_error(minimal_bvh(19, "0 1 0 0 0 0 0 1e999 0"), 19, "got '1e999'");
        require_error(minimal_bvh(19, "0 1 0 0 0 0 0 x 0"), 19, "got 'x'");
        require_error(minimal_bvh(19, "0 1 0 0 0 0 0 -2e9 0"), 19, "got '-2e9'");
    }
    SECTION("absurd frame counts and frame times")
    {
        require_error(minimal_bvh(17, "Frames: 1e12"), 17,
                      "expected a whole frame count in [1, 10000000], got '1e12'");
        require_error(minimal_bvh(17, "Frames: 0"), 17, "got '0'");
        require_error(minimal_bvh(17, "Frames: -3"), 17, "got '-3'");
        require_error(minimal_bvh(17, "Frames: 2.5"), 17, "got '2.5'");
        require_error(minimal_bvh(18, "Frame Time: 0"), 18,
                      "expected a frame time in [1e-05, 60] s, got '0'");
        require_error(minimal_bvh(18, "Frame Time: -0.01"), 18, "got '-0.01'");
        require_error(minimal_bvh(18, "Frame Time: nan"), 18, "got 'nan'");
        require_error(minimal_bvh(17, "Frame: 2"), 17, "expected Frames:, got 'Frame:'");
        BvhOptions cap;
        cap.max_frames = 1;
        require_error(minimal_bvh(), 17, "expected a whole frame count in [1, 1]", cap);
    }
    SECTION("bad channels")
    {
        require_error(minimal_bvh(9, "CHANNELS 3 Zrotation Wrotation Xrotation"), 9,
                      "Yrotation Zrotation), got 'Wrotation'");
        require_error(minimal_bvh(9, "CHANNELS 7 Zrotation Yrotation Xrotation"), 9,
                      "expected a channel count 0..6, got '7'");
        require_error(minimal_bvh(9, "CHANNELS 3 Zrotation Zrotation Xrotation"), 9,
                      "expected each channel once per joint, got 'Zrotation'");
    }
    SECTION("unbalanced braces and bad keywords")
    {
        require_error(minimal_bvh(14, nullptr), 15,
                      "expected JOINT, End Site or '}' (in joint Hips), got 'MOTION'");
        require_error(minimal_bvh(16, "}\nMOTION"), 16,
                      "expected MOTION (one ROOT hierarchy, braces balanced), got '}'");
        require_error(minimal_bvh(1, "HIERARCHIE"), 1, "expected 'HIERARCHY', got 'HIERARCHIE'");
        require_error(minimal_bvh(6, "  BONE Chest"), 6, "got 'BONE'");
        require_error(minimal_bvh(8, "OFFSET 0 nan 0"), 8,
                      "expected an OFFSET coordinate (a finite number, |x| <= 1e9), got 'nan'");
        require_error(minimal_bvh(2, "ROOT"), 2, "expected a joint name, got end of line");
        require_error("", 0, "expected 'HIERARCHY', got end of file");
    }
    SECTION("skip_frames outside the file")
    {
        BvhOptions skip;
        skip.skip_frames = 2;
        require_error(minimal_bvh(), 17,
                      "expected the frames skipped at the start (--skip-frames, "
                      "BvhOptions::skip_frames) in [0, 1], got 2 (the file has 2 frames)",
                      skip);
    }
    SECTION("extra motion lines are ignored with a warning")
    {
        std::istringstream in(minimal_bvh(20, "0 1 0 10 0 0 0 0 5\n1 1 1 1 1 1 1 1 1"));
        MocapWarnings warnings;
        CHECK(parse_bvh(in, "src.bvh", {}, &warnings).motion.frames() == 2);
        REQUIRE(warnings.size() == 1);
        CHECK(warnings[0] == "src.bvh:21: ignored 1 motion line(s) beyond the declared Frames: 2");
    }
    SECTION("a missing file")
    {
        try {
            read_bvh("/nonexistent/x.bvh");
            FAIL("no error");
        } catch (const MocapError &error) {
            CHECK(std::string(error.what()) ==
                  "/nonexistent/x.bvh: expected a readable BVH file, got one that cannot be "
                  "opened (No such file or directory)");
        }
    }
}

namespace
{

// The CMU file's motion columns, read with nothing but the README's facts
// (motion lines start at line 188, 96 numbers each).
std::vector<std::vector<double>> cmu_columns(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    std::string line;
    std::vector<std::vector<double>> rows;
    for (int n = 1; std::getline(in, line); ++n) {
        if (n < 188)
            continue;
        std::istringstream fields(line);
        std::vector<double> row;
        double value;
        while (fields >> value)
            row.push_back(value);
        rows.push_back(row);
    }
    return rows;
}

} // namespace

TEST_CASE("BVH: the CMU drumming file (80_13)", "[mocap][bvh][data]")
{
    const std::string path = data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    MocapWarnings warnings;
    const BvhFile bvh = read_bvh(path, {}, &warnings);
    CHECK(warnings.empty());
    CHECK(bvh.motion.frames() == 1015);
    CHECK(bvh.motion.frame_rate_hz == 120.0);
    CHECK(bvh.channelled_joints() == 31);
    CHECK(bvh.channel_count == 96);
    CHECK(bvh.skeleton.joints.size() == 31 + 7); // + 7 end sites
    const Skeleton &skeleton = bvh.skeleton;

    // Frame 1 is the converter's reference pose (README).
    require_near(bvh.motion.root_position_m[0], {-0.4238, 17.5047, 7.9002}, 1e-12);
    const int left_up_leg = skeleton.find("LeftUpLeg");
    REQUIRE(left_up_leg > 0);
    CHECK((bvh.motion.local_rotation[0][static_cast<std::size_t>(left_up_leg)].toRotationMatrix() -
           rot_z(deg(-21)))
              .norm() < 1e-12);

    // Rest pose: forward kinematics equals the cumulative OFFSETs.
    Motion rest;
    rest.frame_rate_hz = 120;
    rest.root_position_m.push_back(skeleton.joints[0].offset_m);
    rest.local_rotation.emplace_back(skeleton.joints.size(), Eigen::Quaterniond::Identity());
    const auto rest_positions = forward_kinematics(skeleton, rest, 0);
    for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = static_cast<int>(j); k >= 0;
             k = skeleton.joints[static_cast<std::size_t>(k)].parent)
            sum += skeleton.joints[static_cast<std::size_t>(k)].offset_m;
        INFO(skeleton.joints[j].name);
        require_near(rest_positions[j], sum, 1e-12);
    }
    const int left_arm = skeleton.find("LeftArm");
    const int left_fore_arm = skeleton.find("LeftForeArm");
    require_near(rest_positions[static_cast<std::size_t>(left_fore_arm)] -
                     rest_positions[static_cast<std::size_t>(left_arm)],
                 {5.11878, 0, 0}, 1e-12);

    // Bone lengths stay the OFFSET norms (README table) in every frame.
    const struct {
        const char *joint;
        double length;
    } table[] = {{"LeftArm", 3.42227},        {"LeftForeArm", 5.11878}, {"LeftHand", 3.59971},
                 {"LeftHandIndex1", 0.62877}, {"RightArm", 3.52737},    {"RightForeArm", 5.49020},
                 {"RightHand", 3.20659},      {"LeftUpLeg", 2.60678},   {"LeftLeg", 6.63812},
                 {"LeftFoot", 7.51179}};
    for (const auto &row : table) {
        const int j = skeleton.find(row.joint);
        REQUIRE(j > 0);
        CHECK(skeleton.joints[static_cast<std::size_t>(j)].offset_m.norm() ==
              Approx(row.length).margin(0.5e-5)); // the README prints 5 decimals
    }
    double worst = 0.0;
    for (int f = 0; f < bvh.motion.frames(); ++f) {
        const auto p = forward_kinematics(skeleton, bvh.motion, f);
        for (std::size_t j = 1; j < skeleton.joints.size(); ++j) {
            const auto parent = static_cast<std::size_t>(skeleton.joints[j].parent);
            worst = std::max(
                worst, std::fabs((p[j] - p[parent]).norm() - skeleton.joints[j].offset_m.norm()));
        }
    }
    CHECK(worst < 1e-9);

    // Every joint at three frames against forward kinematics done here with
    // hand-written matrices from the raw columns (root: position + Z Y X,
    // every other joint: Z Y X, in degrees; README).
    const auto columns = cmu_columns(path);
    REQUIRE(columns.size() == 1015);
    for (int f : {1, 500, 1014}) {
        const auto &row = columns[static_cast<std::size_t>(f)];
        REQUIRE(row.size() == 96);
        std::vector<Eigen::Matrix3d> world(skeleton.joints.size());
        std::vector<Eigen::Vector3d> position(skeleton.joints.size());
        std::size_t column = 0;
        for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
            const SkeletonJoint &joint = skeleton.joints[j];
            Eigen::Matrix3d local = Eigen::Matrix3d::Identity();
            if (j == 0) {
                position[0] = joint.offset_m + Eigen::Vector3d(row[0], row[1], row[2]);
                column = 3;
            } else {
                const auto parent = static_cast<std::size_t>(joint.parent);
                position[j] = position[parent] + world[parent] * joint.offset_m;
            }
            if (!joint.end_site) {
                local = rot_z(deg(row[column])) * rot_y(deg(row[column + 1])) *
                        rot_x(deg(row[column + 2]));
                column += 3;
            }
            world[j] = j == 0 ? local : world[static_cast<std::size_t>(joint.parent)] * local;
        }
        CHECK(column == 96);
        const auto p = forward_kinematics(skeleton, bvh.motion, f);
        for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
            INFO("frame " << f << " joint " << skeleton.joints[j].name);
            require_near(p[j], position[j], 1e-9);
        }
    }

    // skip_frames = 1 drops the reference pose.
    BvhOptions skip;
    skip.skip_frames = 1;
    const BvhFile captured = read_bvh(path, skip);
    CHECK(captured.motion.frames() == 1014);
    require_near(captured.motion.root_position_m[0], {columns[1][0], columns[1][1], columns[1][2]},
                 1e-12);
}

namespace
{

// The minimal file with several lines replaced (1-based line -> text).
std::string minimal_bvh_with(const std::map<int, std::string> &lines)
{
    std::string out;
    int n = 0;
    for (const std::string &original : minimal_bvh_lines) {
        ++n;
        const auto found = lines.find(n);
        out += (found == lines.end() ? original : found->second) + "\n";
    }
    return out;
}

// Parses and requires a MocapBoundError at `line` whose what() contains `expected`.
void require_bound_error(const std::string &text, int line, const std::string &expected,
                         const BvhOptions &options = {})
{
    std::istringstream in(text);
    try {
        parse_bvh(in, "src.bvh", options);
    } catch (const MocapBoundError &error) {
        const std::string what = error.what();
        INFO("what(): " << what);
        CHECK(what.rfind("src.bvh:" + std::to_string(line) + ": ", 0) == 0);
        CHECK(error.line() == line);
        CHECK(what.find(expected) != std::string::npos);
        return;
    } catch (const MocapError &error) {
        FAIL("a MocapError that is not a MocapBoundError: " << error.what());
    }
    FAIL("no MocapBoundError (expected '" << expected << "')");
}

// The same file read with accept_out_of_bounds: no error, one warning at `line`.
void require_bound_warning(const std::string &text, int line, const std::string &expected,
                           BvhOptions options = {})
{
    options.accept_out_of_bounds = true;
    std::istringstream in(text);
    MocapWarnings warnings;
    parse_bvh(in, "src.bvh", options, &warnings);
    REQUIRE(warnings.size() == 1);
    INFO(warnings[0]);
    CHECK(warnings[0].rfind("src.bvh:" + std::to_string(line) + ": ", 0) == 0);
    CHECK(warnings[0].find(expected) != std::string::npos);
    CHECK(warnings[0].find("read anyway") != std::string::npos);
}

} // namespace

// A Frame Time of 60 s, a 1e9 coordinate: the format allows them, a capture
// of a human performer does not (capture_bounds.hpp). They became hours-long
// runs and a drum kilometres away with no word; now refused at their line.
TEST_CASE("BVH: values out of the physical bounds of a capture are refused at their line",
          "[mocap][bvh][bounds]")
{
    SECTION("frame time")
    {
        require_bound_error(minimal_bvh(18, "Frame Time: 60"), 18,
                            "expected a frame time in [0.0005, 0.5] s (a capture at 2 Hz to "
                            "2 kHz), got '60'");
        require_bound_error(minimal_bvh(18, "Frame Time: 1"), 18, "got '1'");
        // a rate typed for the interval: said as such, with the interval it means
        require_bound_error(minimal_bvh(18, "Frame Time: 30"), 18,
                            "got '30' (a rate? Frame Time is seconds per frame: 30 Hz is "
                            "0.0333333 s)");
        require_error(minimal_bvh(18, "Frame Time: 120"), 18,
                      "got '120' (a rate? Frame Time is seconds per frame: 120 Hz is "
                      "0.00833333 s)");
        require_bound_error(minimal_bvh(18, "Frame Time: 0.0001"), 18, "got '0.0001'");
        require_bound_warning(minimal_bvh(18, "Frame Time: 60"), 18, "got '60'");
        // The bounds themselves are accepted.
        for (const char *edge : {"Frame Time: 0.5", "Frame Time: 0.0005"}) {
            std::istringstream in(minimal_bvh(18, edge));
            MocapWarnings warnings;
            CHECK_NOTHROW(parse_bvh(in, "src.bvh", {}, &warnings));
            CHECK(warnings.empty());
        }
        // Beyond what the format holds at all: refused even when accepting.
        BvhOptions accept;
        accept.accept_out_of_bounds = true;
        require_error(minimal_bvh(18, "Frame Time: 61"), 18,
                      "expected a frame time in [1e-05, 60] s, got '61'", accept);
    }
    SECTION("duration: (Frames - 1) * Frame Time at most 3 h")
    {
        require_bound_error(minimal_bvh_with({{17, "Frames: 21602"}, {18, "Frame Time: 0.5"}}), 17,
                            "expected a capture of at most 10800 s (3 h), got Frames: 21602 at "
                            "Frame Time 0.5 s = 10800.5 s");
        // 21601 frames are exactly 3 h: no bound error (the file is then short of lines).
        std::istringstream in(minimal_bvh_with({{17, "Frames: 21601"}, {18, "Frame Time: 0.5"}}));
        try {
            parse_bvh(in, "src.bvh");
            FAIL("no error for a truncated file");
        } catch (const MocapBoundError &error) {
            FAIL("a bound error at exactly 3 h: " << error.what());
        } catch (const MocapError &error) {
            CHECK(std::string(error.what()).find("expected 21601 motion lines") !=
                  std::string::npos);
        }
    }
    SECTION("coordinates: OFFSETs and position channels, in metres after the scale")
    {
        require_bound_error(minimal_bvh(8, "    OFFSET 0 1e9 0"), 8,
                            "expected |OFFSET coordinate| * scale <= 100 m (joint Chest, scale "
                            "1), got 1e+09 = 1e+09 m");
        require_bound_error(minimal_bvh(12, "      OFFSET 0 0 -101"), 12, "joint Chest_End");
        require_bound_error(minimal_bvh(4, "  OFFSET 100.5 0 0"), 4, "joint Hips");
        require_bound_error(minimal_bvh(20, "0 1 1e9 10 0 0 0 0 5"), 20,
                            "expected |position| * scale <= 100 m in column 3 (Hips Zposition, "
                            "scale 1), got '1e9' = 1e+09 m");
        require_bound_warning(minimal_bvh(20, "0 1 1e9 10 0 0 0 0 5"), 20, "Hips Zposition");
        // The scale decides: 1000 units are 56 m at the CMU scale, 1000 m at 1.
        BvhOptions cmu;
        cmu.scale = kCmuBvhScale_m;
        {
            std::istringstream in(minimal_bvh(19, "1000 1 0 0 0 0 0 0 0"));
            CHECK(parse_bvh(in, "src.bvh", cmu).motion.root_position_m[0].x() ==
                  Approx(1000 * kCmuBvhScale_m));
        }
        require_bound_error(minimal_bvh(19, "1000 1 0 0 0 0 0 0 0"), 19, "Hips Xposition");
        // Angles are not coordinates: any finite angle up to the format's 1e9.
        std::istringstream angles(minimal_bvh(19, "0 1 0 1e8 0 0 0 0 -1e8"));
        CHECK_NOTHROW(parse_bvh(angles, "src.bvh"));
    }
    SECTION("accepted: one warning per kind, the values kept")
    {
        BvhOptions accept;
        accept.accept_out_of_bounds = true;
        std::istringstream in(minimal_bvh_with({{8, "    OFFSET 0 500 0"},
                                                {18, "Frame Time: 60"},
                                                {19, "200 1 0 0 0 0 0 0 0"},
                                                {20, "300 1 0 0 0 0 0 0 0"}}));
        MocapWarnings warnings;
        const BvhFile bvh = parse_bvh(in, "src.bvh", accept, &warnings);
        REQUIRE(warnings.size() == 3);
        CHECK(warnings[0].rfind("src.bvh:8: ", 0) == 0);
        CHECK(warnings[1].rfind("src.bvh:18: ", 0) == 0);
        CHECK(warnings[2].rfind("src.bvh:19: ", 0) == 0); // line 20 is the same kind
        CHECK(bvh.frame_time_s == 60.0);
        CHECK(bvh.skeleton.joints[1].offset_m.y() == 500.0);
        CHECK(bvh.motion.root_position_m[1].x() == 300.0);
    }
}

TEST_CASE("BVH: the skeleton keeps its file and the line of every OFFSET", "[mocap][bvh]")
{
    std::istringstream in(minimal_bvh());
    const BvhFile bvh = parse_bvh(in, "src.bvh");
    CHECK(bvh.skeleton.source == "src.bvh");
    REQUIRE(bvh.skeleton.joints.size() == 3);
    CHECK(bvh.skeleton.joints[0].offset_line == 4);
    CHECK(bvh.skeleton.joints[1].offset_line == 8);
    CHECK(bvh.skeleton.joints[2].offset_line == 12); // the end site
}

namespace
{

// A BVH of the minimal layout (line numbers as minimal_bvh_lines, motion from
// line 19) with the given numbers, printed to full precision.
struct BoundsBvh {
    double frame_time_s = 0.01;
    std::array<std::array<double, 3>, 3> offsets{}; // Hips, Chest, Chest_End
    std::vector<std::array<double, 9>> frames;
    std::string text() const
    {
        std::ostringstream out;
        out << std::setprecision(17);
        auto offset = [&](int j) {
            return "OFFSET " + [&] {
                std::ostringstream o;
                o << std::setprecision(17) << offsets[j][0] << " " << offsets[j][1] << " "
                  << offsets[j][2];
                return o.str();
            }();
        };
        out << "HIERARCHY\nROOT Hips\n{\n  " << offset(0)
            << "\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
            << "  JOINT Chest\n  {\n    " << offset(1)
            << "\n    CHANNELS 3 Zrotation Yrotation Xrotation\n    End Site\n    {\n      "
            << offset(2) << "\n    }\n  }\n}\nMOTION\nFrames: " << frames.size()
            << "\nFrame Time: " << frame_time_s << "\n";
        for (const auto &row : frames) {
            for (std::size_t c = 0; c < row.size(); ++c)
                out << (c ? " " : "") << row[c];
            out << "\n";
        }
        return out.str();
    }
};

} // namespace

// Property: random files inside the bounds read without a warning at any
// scale; one value pushed out of them is refused at its own line (and read
// with one warning when accepted). Seeded: the same files every run.
TEST_CASE("BVH: random files inside the bounds pass, one value outside fails at its line",
          "[mocap][bvh][bounds]")
{
    std::mt19937 rng(20240917);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
    for (int trial = 0; trial < 200; ++trial) {
        BoundsBvh file;
        BvhOptions options;
        options.scale = log_uniform(0.001, 1.0);
        const double limit = kMaxCoordinate_m / options.scale; // in file units
        auto coordinate = [&] { return (2.0 * unit(rng) - 1.0) * 0.999 * limit; };
        file.frame_time_s = log_uniform(kMinSampleInterval_s, kMaxSampleInterval_s);
        for (auto &offset : file.offsets)
            for (double &x : offset)
                x = coordinate();
        const int frames = 2 + static_cast<int>(unit(rng) * 20);
        for (int f = 0; f < frames; ++f) {
            std::array<double, 9> row{};
            for (int c = 0; c < 9; ++c)
                row[static_cast<std::size_t>(c)] =
                    c < 3 ? coordinate() : (2.0 * unit(rng) - 1.0) * 1e4;
            file.frames.push_back(row);
        }
        INFO("trial " << trial << ", scale " << options.scale << "\n" << file.text());
        {
            std::istringstream in(file.text());
            MocapWarnings warnings;
            CHECK_NOTHROW(parse_bvh(in, "src.bvh", options, &warnings));
            CHECK(warnings.empty());
        }
        // One value out of bounds, at a known line.
        const double sign = unit(rng) < 0.5 ? -1.0 : 1.0;
        const double outside = sign * std::min(1e9, limit * log_uniform(1.001, 1000.0));
        int line = 0;
        std::string expected;
        switch (trial % 4) {
        case 0:
            file.frame_time_s = log_uniform(kMaxSampleInterval_s * 1.001, 60.0);
            line = 18;
            expected = "expected a frame time in [0.0005, 0.5] s";
            break;
        case 1:
            file.frame_time_s = log_uniform(1e-5, kMinSampleInterval_s * 0.999);
            line = 18;
            expected = "expected a frame time in [0.0005, 0.5] s";
            break;
        case 2: {
            const int joint = static_cast<int>(unit(rng) * 3);
            file.offsets[static_cast<std::size_t>(joint)][static_cast<std::size_t>(trial % 3)] =
                outside;
            line = 4 + 4 * joint;
            expected = "expected |OFFSET coordinate| * scale <= 100 m";
            break;
        }
        default: {
            const int f = static_cast<int>(unit(rng) * frames);
            file.frames[static_cast<std::size_t>(f)][static_cast<std::size_t>(trial % 3)] = outside;
            line = 19 + f;
            expected =
                "expected |position| * scale <= 100 m in column " + std::to_string(trial % 3 + 1);
            break;
        }
        }
        INFO("out of bounds at line " << line << ":\n" << file.text());
        require_bound_error(file.text(), line, expected, options);
        require_bound_warning(file.text(), line, expected, options);
    }
}

TEST_CASE("BVH: a hierarchy with more than 4 joints per channel is refused before its frames",
          "[mocap][bvh]")
{
    // The fuzzer's input: End Sites under a one-channel root cost a rotation
    // each per frame (1300 of them, 14000 frames: 740 MB and 35 s from 61 kB).
    // n End Sites and 1 channel: n + 1 joints, allowed up to 4.
    for (int sites : {1, 2, 3, 4, 10, 1300}) {
        std::string text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
        for (int k = 0; k < sites; ++k)
            text += "End Site { OFFSET 0 0 0 }\n";
        text += "}\nMOTION\nFrames: 2\nFrame Time: 0.01\n0\n0\n";
        INFO(sites << " End Sites");
        if (sites + 1 <= 4) {
            std::istringstream in(text);
            CHECK(parse_bvh(in, "src.bvh").skeleton.joints.size() ==
                  static_cast<size_t>(sites + 1));
        } else {
            // Reported at the MOTION keyword, the hierarchy's end.
            require_error(text, 7 + sites, "joints (End Sites included) per channel");
        }
    }
}
