// Marker CSV reader: units and axes conversion against hand-converted numbers,
// gap filling (value, warning, refusal), and malformed files.
#include "mocap_test_util.hpp"

#include "ictus/mocap/capture_bounds.hpp"
#include "ictus/mocap/marker_csv.hpp"

#include <algorithm>
#include <iomanip>
#include <map>
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

// `text` (ASCII) as UTF-16: little- or big-endian, with or without its byte order mark.
std::string utf16(const std::string &text, bool big, bool mark)
{
    std::string out = mark ? (big ? std::string("\xFE\xFF") : std::string("\xFF\xFE")) : "";
    for (char c : text)
        out += big ? std::string(1, '\0') + c : std::string(1, c) + '\0';
    return out;
}

const char *const kGapCsv = "time,m.x,m.y,m.z\n"
                            "0,0,0,0\n"
                            "0.01,NaN,NaN,NaN\n"
                            "0.02,,,\n"
                            "0.04,4,8,-4\n";

} // namespace

// A spreadsheet's "Unicode text" export is UTF-16: it read as "expected a column named
// time ..., got neither". Said to be UTF-16 at line 1, either byte order, with or without
// its byte order mark.
TEST_CASE("CSV: a UTF-16 file is said to be one", "[mocap][csv]")
{
    for (const bool big : {false, true})
        for (const bool mark : {false, true}) {
            INFO((big ? "big" : "little")
                 << "-endian, " << (mark ? "with" : "without") << " its mark");
            require_error(utf16(kGapCsv, big, mark), 1, "UTF-16");
        }
}

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
        // The fault is the rate, not a time column's unit (there is none): seeded rates
        // below 2 Hz (k / 100) and above 2 kHz (whole), said as the suspect.
        std::mt19937 rng(20261202);
        for (int trial = 0; trial < 12; ++trial) {
            const bool slow = trial % 2 == 0;
            const int k = slow ? std::uniform_int_distribution<int>(1, 199)(rng)
                               : std::uniform_int_distribution<int>(2001, 999999)(rng);
            rate.rate_hz = slow ? k / 100.0 : k;
            const std::string written = slow ? "" : std::to_string(k); // as typed
            std::string text = "frame,m.x,m.y,m.z\n";
            for (int f = 0; f < 5; ++f)
                text += std::to_string(f) + ",0,1,0\n";
            INFO("rate_hz " << rate.rate_hz);
            std::string what;
            try {
                parse(text, rate);
            } catch (const MocapBoundError &e) {
                what = e.what();
            }
            CHECK(what.find("; is rate_hz ") != std::string::npos);
            CHECK(what.find(" the capture's frame rate?)") != std::string::npos);
            if (!written.empty())
                CHECK(what.find("; is rate_hz " + written + " the capture's frame rate?)") !=
                      std::string::npos);
            CHECK(what.find("a time column") == std::string::npos);
        }
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

namespace
{

// Both captures hold the same numbers, bit for bit, and the same names.
void require_same_capture(const MarkerCapture &a, const MarkerCapture &b)
{
    REQUIRE(a.time_s == b.time_s);
    REQUIRE(a.tracks.size() == b.tracks.size());
    for (std::size_t k = 0; k < a.tracks.size(); ++k) {
        const MarkerTrack &p = a.tracks[k];
        const MarkerTrack &q = b.tracks[k];
        CHECK(p.name == q.name);
        REQUIRE(p.position_m.size() == q.position_m.size());
        for (std::size_t f = 0; f < p.position_m.size(); ++f)
            CHECK(p.position_m[f] == q.position_m[f]);
        REQUIRE(p.orientation.size() == q.orientation.size());
        for (std::size_t f = 0; f < p.orientation.size(); ++f)
            CHECK(p.orientation[f].coeffs() == q.orientation[f].coeffs());
    }
}

// A file as lines: a comment (kept as is) or the cells of the header or a row.
struct CsvLine {
    std::string comment;
    std::vector<std::string> cells;
};

// The text of `lines`, each data line ended by "," when `trailing` (a
// spreadsheet's empty last field), every line by `eol`.
std::string csv_text(const std::vector<CsvLine> &lines, bool trailing, const char *eol)
{
    std::string text;
    for (const CsvLine &line : lines) {
        if (line.cells.empty()) {
            text += line.comment + eol;
            continue;
        }
        for (std::size_t c = 0; c < line.cells.size(); ++c)
            text += (c ? "," : "") + line.cells[c];
        text += std::string(trailing ? "," : "") + eol;
    }
    return text;
}

} // namespace

// Spreadsheet exporters end every line with a comma: the header and each row
// then have an empty last field, which is not data.
TEST_CASE("CSV: a trailing comma on every line reads as the same capture", "[mocap][csv]")
{
    const std::vector<CsvLine> lines = {
        {"# exported by a spreadsheet", {}},
        {"", {"time", "m.x", "m.y", "m.z", "m.qw", "m.qx", "m.qy", "m.qz", "m.residual"}},
        {"", {"0", "1", "2", "3", "1", "0", "0", "0", "0.1"}},
        {"", {"0.01", "", "", "", "", "", "", "", ""}},
        {"", {}},
        {"", {"0.02", "3", "6", "", "0", "0", "0", "1", "0.2"}}, // a gap: the last value empty
        {"", {"0.03", "4", "8", "12", "0", "0", "0", "1", "0.3"}},
    };
    for (const char *eol : {"\n", "\r\n"}) {
        INFO((eol[0] == '\r' ? "CRLF" : "LF"));
        MocapWarnings plain_warnings, trailing_warnings;
        const MarkerCapture plain = parse(csv_text(lines, false, eol), {}, &plain_warnings);
        const MarkerCapture trailing = parse(csv_text(lines, true, eol), {}, &trailing_warnings);
        require_same_capture(plain, trailing);
        CHECK(trailing_warnings == plain_warnings);
        // The numbers by hand: frames 1-2 filled linearly between (1, 2, 3) at
        // 0 s and (4, 8, 12) at 0.03 s; orientation by slerp (half a turn at 0.03 s).
        REQUIRE(trailing.time_s == std::vector<double>{0, 0.01, 0.02, 0.03});
        REQUIRE(trailing.tracks.size() == 1);
        const MarkerTrack &m = trailing.tracks[0];
        CHECK((m.position_m[1] - Eigen::Vector3d(2, 4, 6)).norm() < 1e-12);
        CHECK((m.position_m[2] - Eigen::Vector3d(3, 6, 9)).norm() < 1e-12);
        CHECK((m.orientation[3].toRotationMatrix() - rot_z(deg(180))).norm() < 1e-12);
        REQUIRE(trailing_warnings.size() == 2);
        CHECK(trailing_warnings[0] == "take.csv:2: column 9 'm.residual' ignored (not time, "
                                      "frame or NAME.x|y|z|qw|qx|qy|qz)");
        CHECK(trailing_warnings[1] == "take.csv:4: interpolated 2 missing frame(s) of object 'm' "
                                      "frames 1-2 (lines 4-6)");
    }
    // Blanks after the last comma are an empty field too.
    require_same_capture(parse("time,m.x,m.y,m.z, \n0,1,2,3,\t\n0.01,4,5,6, \n"),
                         parse("time,m.x,m.y,m.z\n0,1,2,3\n0.01,4,5,6\n"));
}

TEST_CASE("CSV: trailing commas that the header and a row do not agree on are refused",
          "[mocap][csv][errors]")
{
    for (const char *eol : {"\n", "\r\n"}) {
        INFO((eol[0] == '\r' ? "CRLF" : "LF"));
        const std::string e(eol);
        const std::string head = "# take" + e + "time,m.x,m.y,m.z," + e + "0,1,2,3," + e;
        // A row without the trailing comma, with a missing value, with a stray
        // empty field in the middle, with a value under the header's empty column.
        require_error(head + "0.01,1,2,3" + e, 4, "expected 5 cells (as the header), got 4");
        require_error(head + "0.01,1,2," + e, 4, "expected 5 cells (as the header), got 4");
        require_error(head + "0.01,1,,2,3," + e, 4, "expected 5 cells (as the header), got 6");
        require_error(head + "0.01,1,2,3,4" + e, 4,
                      "expected an empty cell in column 5 (the header ends with a comma), "
                      "got '4'");
        // Rows that end with a comma under a header that does not.
        require_error("time,m.x,m.y,m.z" + e + "0,1,2,3," + e, 2,
                      "expected 4 cells (as the header), got 5");
        // Only one empty last column; an empty name elsewhere is still refused.
        require_error("time,m.x,m.y,m.z,," + e + "0,1,2,3,," + e, 1,
                      "expected a column name in column 5, got an empty cell");
        require_error("time,,m.x,m.y,m.z," + e + "0,0,1,2,3," + e, 1,
                      "expected a column name in column 2, got an empty cell");
        require_error("time," + e + "0," + e, 1, "expected at least one object");
        require_error("time;m.x;m.y;m.z;," + e + "0;1;2;3;," + e, 1,
                      "expected comma-separated columns, got one column holding ';'");
    }
}

// Property: random takes (objects with and without orientations, columns in
// any order, an ignored column, gaps, comments, LF or CRLF) read the same with
// and without a trailing comma on every line, and hold the numbers written;
// one row broken in a random way is refused at its line. Seeded.
TEST_CASE("CSV: random takes with trailing commas read as without, broken rows are named",
          "[mocap][csv]")
{
    std::mt19937 rng(40561);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto pick = [&](int n) { return static_cast<int>(unit(rng) * n) % n; };
    for (int trial = 0; trial < 150; ++trial) {
        const int objects = 1 + pick(3);
        std::vector<bool> rotated(static_cast<std::size_t>(objects));
        std::vector<std::string> names = {"time", "extra"};
        for (int k = 0; k < objects; ++k) {
            const std::string o = "o" + std::to_string(k);
            rotated[static_cast<std::size_t>(k)] = unit(rng) < 0.5;
            for (const char *c : {"x", "y", "z", "qw", "qx", "qy", "qz"})
                if (c[1] == 0 || rotated[static_cast<std::size_t>(k)])
                    names.push_back(o + "." + c);
        }
        std::shuffle(names.begin(), names.end(), rng);
        const int rows = 3 + pick(25);
        const double rate = 50.0 + 950.0 * unit(rng);
        std::vector<CsvLine> lines = {{"# take " + std::to_string(trial), {}}, {"", names}};
        std::vector<int> row_line; // [row] -> line in the file
        // [row][column name] -> value written; a gap is left empty.
        std::vector<std::map<std::string, double>> written(static_cast<std::size_t>(rows));
        std::vector<std::vector<bool>> gap(static_cast<std::size_t>(rows),
                                           std::vector<bool>(static_cast<std::size_t>(objects)));
        for (int r = 0; r < rows; ++r) {
            if (unit(rng) < 0.1)
                lines.push_back({unit(rng) < 0.5 ? "" : "# note", {}});
            auto &values = written[static_cast<std::size_t>(r)];
            values["time"] = (r + 0.2 * (unit(rng) - 0.5)) / rate;
            values["extra"] = unit(rng);
            for (int k = 0; k < objects; ++k) {
                const std::string o = "o" + std::to_string(k);
                for (const char *c : {"x", "y", "z"})
                    values[o + "." + c] = (2.0 * unit(rng) - 1.0) * 50.0;
                Eigen::Quaterniond q(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5,
                                     unit(rng) - 0.5);
                q.normalize();
                values[o + ".qw"] = q.w(), values[o + ".qx"] = q.x();
                values[o + ".qy"] = q.y(), values[o + ".qz"] = q.z();
                gap[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)] =
                    r > 0 && r + 1 < rows && unit(rng) < 0.15;
            }
            std::vector<std::string> cells;
            for (const std::string &name : names) {
                const std::size_t dot = name.find('.');
                const bool in_gap = dot != std::string::npos &&
                                    gap[static_cast<std::size_t>(r)][std::stoul(name.substr(1))] &&
                                    unit(rng) < 0.6; // some cells of a missing sample are empty
                std::ostringstream cell;
                cell << std::setprecision(17) << values[name];
                cells.push_back(in_gap ? "" : cell.str());
            }
            // At least one empty cell makes the sample missing.
            for (int k = 0; k < objects; ++k)
                if (gap[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)]) {
                    const std::string z = "o" + std::to_string(k) + ".z";
                    cells[static_cast<std::size_t>(std::find(names.begin(), names.end(), z) -
                                                   names.begin())] = "";
                }
            row_line.push_back(static_cast<int>(lines.size()) + 1);
            lines.push_back({"", cells});
        }
        const char *eol = trial % 2 ? "\r\n" : "\n";
        INFO("trial " << trial << "\n" << csv_text(lines, true, "\n"));
        MocapWarnings plain_warnings, trailing_warnings;
        const MarkerCapture plain = parse(csv_text(lines, false, eol), {}, &plain_warnings);
        const MarkerCapture trailing = parse(csv_text(lines, true, eol), {}, &trailing_warnings);
        require_same_capture(plain, trailing);
        CHECK(trailing_warnings == plain_warnings);
        // The numbers written: exact where sampled, on the line between the
        // neighbouring samples in a gap.
        REQUIRE(trailing.time_s.size() == static_cast<std::size_t>(rows));
        REQUIRE(trailing.tracks.size() == static_cast<std::size_t>(objects));
        for (int k = 0; k < objects; ++k) {
            const std::string o = "o" + std::to_string(k);
            const MarkerTrack &track = trailing.tracks[static_cast<std::size_t>(trailing.find(o))];
            CHECK(track.orientation.size() ==
                  (rotated[static_cast<std::size_t>(k)] ? static_cast<std::size_t>(rows) : 0));
            auto position = [&](int r) {
                auto &v = written[static_cast<std::size_t>(r)];
                return Eigen::Vector3d(v[o + ".x"], v[o + ".y"], v[o + ".z"]);
            };
            for (int r = 0; r < rows; ++r) {
                const double t = written[static_cast<std::size_t>(r)]["time"];
                CHECK(trailing.time_s[static_cast<std::size_t>(r)] == t);
                const Eigen::Vector3d &p = track.position_m[static_cast<std::size_t>(r)];
                if (!gap[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)]) {
                    CHECK(p == position(r));
                    auto &v = written[static_cast<std::size_t>(r)];
                    if (rotated[static_cast<std::size_t>(k)])
                        CHECK((track.orientation[static_cast<std::size_t>(r)].coeffs() -
                               Eigen::Quaterniond(v[o + ".qw"], v[o + ".qx"], v[o + ".qy"],
                                                  v[o + ".qz"])
                                   .coeffs())
                                  .norm() < 1e-14);
                    continue;
                }
                int before = r, after = r;
                while (gap[static_cast<std::size_t>(before)][static_cast<std::size_t>(k)])
                    --before;
                while (gap[static_cast<std::size_t>(after)][static_cast<std::size_t>(k)])
                    ++after;
                const double t0 = written[static_cast<std::size_t>(before)]["time"];
                const double t1 = written[static_cast<std::size_t>(after)]["time"];
                const double u = (t - t0) / (t1 - t0);
                CHECK((p - (position(before) + u * (position(after) - position(before)))).norm() <
                      1e-9);
            }
        }
        // One row broken: its line is named, CRLF or not. A trailing comma is
        // an empty last cell: `ended` gives one to every data line but row r.
        const int r = pick(rows);
        const std::size_t columns = names.size();
        const std::size_t broken_line =
            static_cast<std::size_t>(row_line[static_cast<std::size_t>(r)] - 1);
        std::vector<CsvLine> ended = lines;
        for (std::size_t l = 0; l < ended.size(); ++l)
            if (!ended[l].cells.empty() && l != broken_line)
                ended[l].cells.push_back("");
        std::vector<CsvLine> broken = lines;
        std::vector<std::string> &cells = broken[broken_line].cells;
        const auto at = cells.begin() + 1 + pick(static_cast<int>(columns) - 1);
        std::string text;
        std::size_t header_cells = columns + 1, got = 0;
        switch (trial % 4) {
        case 0: // a stray empty field in the middle
            cells.insert(at, "");
            text = csv_text(broken, true, eol);
            got = columns + 2;
            break;
        case 1: // a value missing
            cells.erase(at);
            text = csv_text(broken, true, eol);
            got = columns;
            break;
        case 2: // this row alone without its trailing comma
            text = csv_text(ended, false, eol);
            got = columns;
            break;
        default: // this row alone with a trailing comma, under a header without
            cells.push_back("");
            text = csv_text(broken, false, eol);
            header_cells = columns;
            got = columns + 1;
            break;
        }
        const std::string expected = "expected " + std::to_string(header_cells) +
                                     " cells (as the header), got " + std::to_string(got);
        require_error(text, row_line[static_cast<std::size_t>(r)], expected);
    }
}
