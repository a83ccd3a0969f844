// Marker CSV reader: units and axes conversion against hand-converted numbers,
// gap filling (value, warning, refusal), and malformed files.
#include "mocap_test_util.hpp"

#include "ictus/mocap/marker_csv.hpp"

#include <sstream>

using namespace ictus;
using namespace mocap_test;

namespace
{

MarkerCapture parse(const std::string &text, const MarkerCsvOptions &options = {},
                    MocapWarnings *warnings = nullptr)
{
    std::istringstream in(text);
    return parse_marker_csv(in, "take.csv", options, warnings);
}

void require_error(const std::string &text, int line, const std::string &expected,
                   const MarkerCsvOptions &options = {})
{
    try {
        parse(text, options);
    } catch (const MocapError &error) {
        const std::string what = error.what();
        INFO("what(): " << what);
        CHECK(what.rfind("take.csv:" + std::to_string(line) + ": ", 0) == 0);
        CHECK(error.line() == line);
        CHECK(what.find(expected) != std::string::npos);
        return;
    }
    FAIL("no MocapError for a malformed file (expected '" << expected << "')");
}

const char *const kGapCsv = "time,m.x,m.y,m.z\n"
                            "0,0,0,0\n"
                            "0.01,NaN,NaN,NaN\n"
                            "0.02,,,\n"
                            "0.04,4,8,-4\n";

} // namespace

TEST_CASE("CSV: millimetres and z up become metres and y up", "[mocap][csv]")
{
    // A right-handed z-up frame to a right-handed y-up frame: (x, y, z) -> (x, z, -y).
    // The hand turned 90 deg about the z-up vertical: its body x axis points
    // along world +y (z-up), i.e. along -z in the y-up frame.
    const std::string text = "# exported by hand\r\n"
                             "time,hand.x,hand.y,hand.z,hand.qw,hand.qx,hand.qy,hand.qz,stick.x,"
                             "stick.y,stick.z\r\n"
                             "0.000,100,200,300,0.7071067811865476,0,0,0.7071067811865476,1,2,3\r\n"
                             "0.004,-50,0,1000,1,0,0,0,4,5,6\r\n";
    MarkerCsvOptions options;
    options.units = MarkerCsvOptions::Units::mm;
    options.up = MarkerCsvOptions::Up::z;
    MocapWarnings warnings;
    const MarkerCapture capture = parse(text, options, &warnings);
    CHECK(warnings.empty());
    REQUIRE(capture.time_s.size() == 2);
    CHECK(capture.time_s[1] == 0.004);
    REQUIRE(capture.tracks.size() == 2);
    const int hand = capture.find("hand");
    const int stick = capture.find("stick");
    REQUIRE(hand == 0);
    REQUIRE(stick == 1);
    CHECK(capture.find("drum") == -1);
    const MarkerTrack &h = capture.tracks[0];
    CHECK((h.position_m[0] - Eigen::Vector3d(0.1, 0.3, -0.2)).norm() < 1e-15);
    CHECK((h.position_m[1] - Eigen::Vector3d(-0.05, 1.0, 0.0)).norm() < 1e-15);
    CHECK((capture.tracks[1].position_m[1] - Eigen::Vector3d(0.004, 0.006, -0.005)).norm() < 1e-15);
    CHECK(capture.tracks[1].orientation.empty());
    REQUIRE(h.orientation.size() == 2);
    CHECK((h.orientation[0] * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-12);
    // Body z (the z-up vertical, unchanged by the turn) is now world y.
    CHECK((h.orientation[0] * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(0, 1, 0)).norm() < 1e-12);
    // Identity in z-up: the body's own axes are the old world axes, re-expressed.
    CHECK((h.orientation[1] * Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-12);

    // Metres and y up: numbers pass through.
    const MarkerCapture raw = parse(text);
    CHECK((raw.tracks[0].position_m[0] - Eigen::Vector3d(100, 200, 300)).norm() < 1e-12);
}

TEST_CASE("CSV: frame column with a rate", "[mocap][csv]")
{
    MarkerCsvOptions options;
    options.rate_hz = 250;
    const MarkerCapture capture = parse("frame,m.x,m.y,m.z\n1,0,0,0\n2,1,1,1\n4,2,2,2\n", options);
    REQUIRE(capture.time_s.size() == 3);
    CHECK(capture.time_s[0] == Approx(0.004));
    CHECK(capture.time_s[2] == Approx(0.016));
    require_error("frame,m.x,m.y,m.z\n1,0,0,0\n", 1,
                  "expected MarkerCsvOptions::rate_hz > 0 for a file with a frame column");
}

TEST_CASE("CSV: short interior gaps are interpolated with a warning", "[mocap][csv]")
{
    MocapWarnings warnings;
    const MarkerCapture capture = parse(kGapCsv, {}, &warnings);
    const MarkerTrack &m = capture.tracks[0];
    // Linear in time between t = 0 (0, 0, 0) and t = 0.04 (4, 8, -4).
    CHECK((m.position_m[1] - Eigen::Vector3d(1, 2, -1)).norm() < 1e-12);
    CHECK((m.position_m[2] - Eigen::Vector3d(2, 4, -2)).norm() < 1e-12);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0] ==
          "take.csv:3: interpolated 2 missing frame(s) of object 'm' frames 1-2 (lines 3-4)");

    // Orientation: slerp. Halfway between identity and 90 deg about z is 45 deg.
    const MarkerCapture turned = parse("time,m.x,m.y,m.z,m.qw,m.qx,m.qy,m.qz\n"
                                       "0,0,0,0,1,0,0,0\n"
                                       "1,,,,,,,\n"
                                       "2,0,0,0,0.7071067811865476,0,0,0.7071067811865476\n");
    const Eigen::Quaterniond half = turned.tracks[0].orientation[1];
    CHECK((half.toRotationMatrix() - rot_z(deg(45))).norm() < 1e-12);
}

TEST_CASE("CSV: gaps that cannot be filled are errors", "[mocap][csv][errors]")
{
    MarkerCsvOptions short_gaps;
    short_gaps.max_gap_frames = 1;
    require_error(kGapCsv, 3,
                  "expected gaps of at most 1 frames, got 2: object 'm' frames 1-2 (lines 3-4)",
                  short_gaps);
    MarkerCsvOptions no_fill;
    no_fill.interpolate_gaps = false;
    require_error(kGapCsv, 3, "expected no gaps (interpolate_gaps is off)", no_fill);
    require_error("time,m.x,m.y,m.z\n0,,,\n1,1,1,1\n", 2, "got a gap at the start");
    require_error("time,m.x,m.y,m.z\n0,1,1,1\n1,2,2,2\n2,nan,2,2\n", 4, "got a gap at the end");
}

TEST_CASE("CSV: extra columns of real exports are skipped with a warning", "[mocap][csv]")
{
    MocapWarnings warnings;
    MarkerCapture c = parse("time,m.x,m.y,m.z,m.residual\n0,1,2,3,0.5\n0.01,4,5,6,0.7\n",
                            MarkerCsvOptions{}, &warnings);
    REQUIRE(c.tracks.size() == 1);
    CHECK(c.tracks[0].position_m[1].isApprox(Eigen::Vector3d(4, 5, 6)));
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0] == "take.csv:1: column 5 'm.residual' ignored (not time, frame or "
                         "NAME.x|y|z|qw|qx|qy|qz)");
}

TEST_CASE("CSV: malformed files give FILE:LINE errors", "[mocap][csv][errors]")
{
    require_error("time,m.x,m.y,m.z,m.x\n0,0,0,0,0\n", 1,
                  "expected each column name once, got a duplicate column 'm.x'");
    require_error("time,m.x,m.z\n0,0,0\n", 1, "expected column m.y for object 'm', got none");
    require_error("time,m.x,m.y,m.z,m.qw\n0,0,0,0,1\n", 1,
                  "expected all of m.qw .qx .qy .qz, or none, got no m.qx");
    require_error("m.x,m.y,m.z\n0,0,0\n", 1, "expected a time (s) or frame column, got neither");
    require_error("time\n0\n", 1, "expected at least one object");
    require_error("time,m.x,m.y,m.z\n0,0,0,0\n0.02,0,0,0\n0.01,0,0,0\n", 4,
                  "expected time to increase");
    require_error("time,m.x,m.y,m.z\n0,0,0,0\n0,0,0,0\n", 3, "expected time to increase");
    require_error("time,m.x,m.y,m.z\n0,0,0,0\n0.01,0,0\n", 3,
                  "expected 4 cells (as the header), got 3");
    require_error("time,m.x,m.y,m.z\n0,0,abc,0\n", 2,
                  "expected a number or an empty cell in column 3, got 'abc'");
    require_error("time,m.x,m.y,m.z\n0,0,inf,0\n", 2,
                  "expected a finite number (|x| <= 1e9) in column 3");
    require_error("time,m.x,m.y,m.z\n0,0,2e9,0\n", 2, "got '2e9'");
    require_error("time,m.x,m.y,m.z\n,0,0,0\n", 2, "expected a time (s), got an empty cell");
    require_error("time,m.x,m.y,m.z,m.qw,m.qx,m.qy,m.qz\n0,0,0,0,0,0,0,0\n", 2,
                  "expected a non-zero quaternion for m");
    require_error("time,m.x,m.y,m.z\n", 1, "expected at least one data row, got none");
    try {
        parse("");
        FAIL("no error for an empty file");
    } catch (const MocapError &error) {
        CHECK(std::string(error.what()).find("expected a header row") != std::string::npos);
    }
    CHECK_THROWS_AS(read_marker_csv("/nonexistent/take.csv"), MocapError);
}
