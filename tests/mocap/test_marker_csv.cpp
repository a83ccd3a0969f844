// Marker CSV reader: units and axes conversion against hand-converted numbers,
// gap filling (value, warning, refusal), and malformed files.
#include "mocap_test_util.hpp"

#include "ictus/mocap/capture_bounds.hpp"
#include "ictus/mocap/marker_csv.hpp"

#include <iomanip>
#include <random>
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

    // Metres and y up: numbers pass through (300 m and 1000 m are beyond the
    // bounds of a capture, kMaxCoordinate_m: read by accepting them, with a warning).
    MarkerCsvOptions accept;
    accept.accept_out_of_bounds = true;
    MocapWarnings raw_warnings;
    const MarkerCapture raw = parse(text, accept, &raw_warnings);
    CHECK((raw.tracks[0].position_m[0] - Eigen::Vector3d(100, 200, 300)).norm() < 1e-12);
    REQUIRE(raw_warnings.size() == 1);
    CHECK(raw_warnings[0].rfind("take.csv:3: expected |coordinate| <= 100 m", 0) == 0);
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
                  "expected a frame rate (--rate HZ) for a file with a frame column and no time "
                  "column, got none");
}

// TrajOptDrums' exports name their clock "Time (s)": seconds, as a `time` column.
TEST_CASE("CSV: a Time (s) column is the time in seconds", "[mocap][csv]")
{
    for (const char *name : {"Time (s)", "time (s)", "TIME(S)"}) {
        INFO(name);
        const MarkerCapture capture =
            parse(std::string(name) + ",m.x,m.y,m.z\n0,0,0,0\n0.004,1,1,1\n0.008,2,2,2\n");
        REQUIRE(capture.time_s.size() == 3);
        CHECK(capture.time_s[1] == 0.004);
        CHECK(capture.time_s[2] == 0.008);
    }
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
    // (Steps of 1 s are slower than a capture, kMaxSampleInterval_s: accepted.)
    MarkerCsvOptions accept;
    accept.accept_out_of_bounds = true;
    const MarkerCapture turned = parse("time,m.x,m.y,m.z,m.qw,m.qx,m.qy,m.qz\n"
                                       "0,0,0,0,1,0,0,0\n"
                                       "1,,,,,,,\n"
                                       "2,0,0,0,0.7071067811865476,0,0,0.7071067811865476\n",
                                       accept);
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
    require_error("m.x,m.y,m.z\n0,0,0\n", 1,
                  "expected a column named time or Time (s) (seconds), or frame (with --rate HZ), "
                  "got neither");
    // Another separator: one column; said so.
    require_error("time;m.x;m.y;m.z\n0;0;0;0\n", 1,
                  "expected comma-separated columns, got one column holding ';'");
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

namespace
{

// Parses and requires a MocapBoundError at `line` containing `expected`; then
// the same text accepted: no error, one warning at that line.
void require_bound_error(const std::string &text, int line, const std::string &expected,
                         MarkerCsvOptions options = {})
{
    try {
        parse(text, options);
        FAIL("no MocapBoundError (expected '" << expected << "')");
    } catch (const MocapBoundError &error) {
        const std::string what = error.what();
        INFO("what(): " << what);
        CHECK(what.rfind("take.csv:" + std::to_string(line) + ": ", 0) == 0);
        CHECK(error.line() == line);
        CHECK(what.find(expected) != std::string::npos);
    } catch (const MocapError &error) {
        FAIL("a MocapError that is not a MocapBoundError: " << error.what());
    }
    options.accept_out_of_bounds = true;
    MocapWarnings warnings;
    parse(text, options, &warnings);
    REQUIRE(warnings.size() == 1);
    INFO(warnings[0]);
    CHECK(warnings[0].rfind("take.csv:" + std::to_string(line) + ": ", 0) == 0);
    CHECK(warnings[0].find(expected) != std::string::npos);
    CHECK(warnings[0].find("read anyway") != std::string::npos);
}

// `rows` rows of one object at `rate_hz`, the time column scaled by
// `time_unit` (1: s, 1000: ms), printed to full precision.
std::string clocked_csv(int rows, double rate_hz, double time_unit, double coordinate = 0.5)
{
    std::ostringstream out;
    out << std::setprecision(17) << "time,m.x,m.y,m.z\n";
    for (int k = 0; k < rows; ++k)
        out << k / rate_hz * time_unit << "," << coordinate << ",1,0\n";
    return out.str();
}

} // namespace

// A time column in ms or us, or a 1e9 mm coordinate, read as they were: a
// 200 Hz take of 2 s in ms "lasted" 33 minutes, in us 23 days; a 1e9 mm cell
// put a stick 1000 km away. Refused now, at the row of the offending value.
TEST_CASE("CSV: a clock or a coordinate out of the physical bounds is refused at its row",
          "[mocap][csv][bounds]")
{
    SECTION("a time column in ms, us, or minutes")
    {
        require_bound_error(clocked_csv(400, 200, 1000), 3,
                            "expected a median time step in [0.0005, 0.5] s (a capture at 2 Hz "
                            "to 2 kHz) from the time column (s), got 5 s");
        require_bound_error(clocked_csv(400, 200, 1000), 3, "a time column in ms or us?");
        require_bound_error(clocked_csv(3, 200, 1e6), 3, "got 5000 s");  // 10000 s: < 3 h
        require_bound_error(clocked_csv(400, 1000, 1000), 3, "got 1 s"); // ms at 1 kHz
        require_bound_error(clocked_csv(400, 200, 1.0 / 60), 3, "a time column in minutes");
        // The same takes in seconds pass, and so do the bounds themselves.
        for (double rate : {200.0, 1000.0, 2.0, 2000.0}) {
            INFO(rate << " Hz");
            MocapWarnings warnings;
            CHECK(parse(clocked_csv(40, rate, 1), {}, &warnings).time_s.size() == 40);
            CHECK(warnings.empty());
        }
    }
    SECTION("the median step: dropped frames do not matter, the first slow row is named")
    {
        // 200 Hz with one 3 s hole (tracking lost): the median is 5 ms, fine.
        std::string text = "time,m.x,m.y,m.z\n";
        for (int k = 0; k < 20; ++k)
            text += std::to_string(k * 0.005 + (k >= 10 ? 3.0 : 0.0)) + ",0,1,0\n";
        CHECK_NOTHROW(parse(text));
        // Ten rows at 200 Hz, then ms: the first row of 1-"s" steps is line 13.
        text = "time,m.x,m.y,m.z\n";
        for (int k = 0; k < 11; ++k)
            text += std::to_string(k * 0.005) + ",0,1,0\n";
        for (int k = 1; k <= 20; ++k)
            text += std::to_string(0.05 + k) + ",0,1,0\n";
        require_bound_error(text, 13, "median time step");
    }
    SECTION("a frame column with a rate that makes it a slow clock")
    {
        MarkerCsvOptions rate;
        rate.rate_hz = 0.01; // --rate in the wrong unit: one frame per 100 s
        require_bound_error("frame,m.x,m.y,m.z\n0,0,1,0\n1,0,1,0\n2,0,1,0\n", 3,
                            "from the frame column / rate_hz 0.01, got 100 s", rate);
    }
    SECTION("duration: at most 3 h from the first row")
    {
        std::string text = "time,m.x,m.y,m.z\n";
        for (int k = 0; k < 10; ++k)
            text += std::to_string(k * 0.01) + ",0,1,0\n";
        text += "10800,0,1,0\n10800.5,0,1,0\n10801,0,1,0\n"; // lines 12, 13, 14
        require_bound_error(text, 13,
                            "expected a capture of at most 10800 s (3 h) from the time column (s), "
                            "got 10801 s (this row is 10800.5 s after the first)");
    }
    SECTION("coordinates, in the file's units")
    {
        MarkerCsvOptions mm;
        mm.units = MarkerCsvOptions::Units::mm;
        require_bound_error("time,m.x,m.y,m.z\n0,0,1,0\n0.01,0,1,0\n0.02,0,0,1e9\n", 4,
                            "expected |coordinate| <= 100 m (100000 mm) in column 4 (m.z), got "
                            "'1e9' mm",
                            mm);
        require_bound_error("time,m.x,m.y,m.z\n0,-100001,1,0\n", 2, "column 2 (m.x)", mm);
        CHECK(parse("time,m.x,m.y,m.z\n0,-100000,99999,0\n", mm).tracks[0].position_m[0].x() ==
              Approx(-100.0));
        require_bound_error(
            "time,a.x,a.y,a.z,m.x,m.y,m.z\n0,0,0,0,0,0,0\n0.01,0,0,0,0,150,0\n", 3,
            "expected |coordinate| <= 100 m (100 m) in column 6 (m.y), got '150' m");
    }
}

// Property: random takes inside the bounds (rates from 2.5 Hz to 1.7 kHz, any
// unit, jittered clocks, coordinates up to the bound) read without a warning;
// the same take with its clock in ms, or one coordinate pushed out, is refused
// at the right row. Seeded: the same takes every run.
TEST_CASE("CSV: random takes inside the bounds pass, out of them fail at the right row",
          "[mocap][csv][bounds]")
{
    std::mt19937 rng(77031);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        MarkerCsvOptions options;
        options.units = trial % 2 ? MarkerCsvOptions::Units::mm : MarkerCsvOptions::Units::m;
        const double limit = options.units == MarkerCsvOptions::Units::mm ? 1e5 : 100.0;
        // 2.5 Hz .. 1.7 kHz, so that with +-10 % jitter every step lies in the
        // bounds, and the same clock in ms has every step > 0.5 "s" (and, with
        // at most 20 rows, lasts under 3 h: one bound broken at a time).
        const double rate = 2.5 * std::pow(1700.0 / 2.5, unit(rng));
        const int rows = 3 + static_cast<int>(unit(rng) * 18);
        std::vector<double> time(static_cast<std::size_t>(rows));
        std::vector<std::array<double, 3>> xyz(static_cast<std::size_t>(rows));
        double t = unit(rng) * 100.0; // clocks need not start at 0
        for (int k = 0; k < rows; ++k) {
            time[static_cast<std::size_t>(k)] = t;
            t += (1.0 + 0.2 * (unit(rng) - 0.5)) / rate; // +-10 % jitter
            for (double &x : xyz[static_cast<std::size_t>(k)])
                x = (2.0 * unit(rng) - 1.0) * 0.999 * limit;
        }
        auto text = [&](double time_unit) {
            std::ostringstream out;
            out << std::setprecision(17) << "# take " << trial << "\ntime,m.x,m.y,m.z\n";
            for (int k = 0; k < rows; ++k) {
                const auto &p = xyz[static_cast<std::size_t>(k)];
                out << time[static_cast<std::size_t>(k)] * time_unit << "," << p[0] << "," << p[1]
                    << "," << p[2] << "\n";
            }
            return out.str();
        };
        INFO("trial " << trial << ", " << rate << " Hz\n" << text(1.0));
        MocapWarnings warnings;
        CHECK_NOTHROW(parse(text(1.0), options, &warnings));
        CHECK(warnings.empty());
        // The clock in ms: every step is > 0.5 "s"; the first is named (line 4:
        // a comment, the header, then the rows).
        require_bound_error(text(1000.0), 4, "median time step", options);
        // One coordinate out of bounds (and within the format's 1e9).
        const int row = static_cast<int>(unit(rng) * rows);
        const int axis = trial % 3;
        const double sign = unit(rng) < 0.5 ? -1.0 : 1.0;
        xyz[static_cast<std::size_t>(row)][static_cast<std::size_t>(axis)] =
            sign * std::min(1e9, limit * 1.001 * std::pow(1000.0, unit(rng)));
        require_bound_error(text(1.0), 3 + row,
                            "in column " + std::to_string(2 + axis) + " (m." +
                                std::string(1, static_cast<char>('x' + axis)) + ")",
                            options);
    }
}
