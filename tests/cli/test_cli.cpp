// The real ictusd binary: help, version, usage errors, bad values for every
// option, missing and malformed files (exit 1), and the files `track --out` writes.
#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <regex>
#include <set>
#include <thread>

#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <sstream>

namespace
{

struct Run {
    int status;
    std::string output; // stdout and stderr
};

Run ictusd(const std::string &args)
{
    const std::string cmd = std::string(ICTUSD_PATH) + " " + args + " 2>&1";
    FILE *pipe = popen(cmd.c_str(), "r");
    REQUIRE(pipe != nullptr);
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, pipe)) > 0)
        out.append(buf, n);
    const int st = pclose(pipe);
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

// A small valid BVH with the CMU joint names: the right elbow swings.
std::string tiny_bvh()
{
    static const std::string path = simtest::write_temp(
        "tiny.bvh", simtest::default_skeleton_bvh(121, 1.0 / 120, [](int f, const std::string &j) {
            if (j == "RightForeArm")
                return Eigen::Vector3d(0, 20.0 * std::sin(2 * M_PI * f / 120.0), 0);
            return Eigen::Vector3d(0, 0, 0);
        }));
    return path;
}

} // namespace

TEST_CASE("ictusd --help and per-verb help exit 0 with examples", "[sim][cli]")
{
    for (const char *args : {"--help", "track --help", "limits --help"}) {
        const Run r = ictusd(args);
        INFO(args << "\n" << r.output);
        CHECK(r.status == 0);
        CHECK(r.output.find("usage: ictusd") != std::string::npos);
        CHECK(r.output.find("example") != std::string::npos);
    }
}

TEST_CASE("ictusd: unknown verbs and options are usage errors (exit 2)", "[sim][cli]")
{
    Run r = ictusd("");
    CHECK(r.status == 2);
    r = ictusd("dance");
    CHECK(r.status == 2);
    CHECK(r.output.find("unknown verb 'dance'") != std::string::npos);
    r = ictusd("track --mode joint --mocap x.bvh --frobnicate");
    CHECK(r.status == 2);
    CHECK(r.output.find("unknown option '--frobnicate'") != std::string::npos);
    r = ictusd("limits a.bvh --frobnicate");
    CHECK(r.status == 2);
    r = ictusd("track --mocap " + tiny_bvh());
    CHECK(r.status == 2);
    CHECK(r.output.find("--mode is required") != std::string::npos);
    r = ictusd("track --mode joint");
    CHECK(r.status == 2);
    CHECK(r.output.find("--mocap") != std::string::npos);
    r = ictusd("limits");
    CHECK(r.status == 2);
}

TEST_CASE("ictusd track: every option refuses a bad value, naming it", "[sim][cli]")
{
    const std::string base = "track --mode joint --quiet --mocap " + tiny_bvh() + " ";
    // option, bad value, text the message must contain
    const std::vector<std::array<std::string, 3>> cases = {
        {"--mode", "foo", "--mode"},
        {"--scale", "0", "--scale"},
        {"--scale", "abc", "--scale"},
        {"--skip-frames", "-1", "--skip-frames"},
        {"--duration", "-5", "--duration"},
        {"--step", "-0.001", "--step"},
        {"--step", "1", "physics step"},
        {"--stepper", "slow", "--stepper"},
        {"--iterations", "0", "--iterations"},
        {"--body-mass", "0", "--body-mass"},
        {"--grip", "italian", "grip"},
        {"--stick-length", "-1", "--stick-length"},
        {"--stick-mass", "nan", "--stick-mass"},
        {"--stick-tip-radius", "0", "--stick-tip-radius"},
        {"--drum-pos", "1,2", "--drum-pos"},
        {"--drum-radius", "-0.1", "--drum-radius"},
        {"--drum-tension", "0", "--drum-tension"},
        {"--gain-hz", "0", "--gain-hz"},
        {"--damping-ratio", "-1", "--damping-ratio"},
        {"--torque-scale", "0", "--torque-scale"},
        {"--limits", "loose", "--limits"},
        {"--limit-k", "0", "--limit-k"},
        {"--limit-min-deg", "-1", "--limit-min-deg"},
        {"--ramp", "-1", "--ramp"},
        {"--smooth-hz", "-1", "--smooth-hz"},
        {"--despike-deg", "-1", "--despike-deg"},
        {"--smooth-kernel", "boxcar", "--smooth-kernel"},
        {"--ik-gain", "0", "--ik-gain"},
        {"--ik-gain", "500", "ik gain"},
        {"--ik-velocity-gain", "abc", "--ik-velocity-gain"},
        {"--ik-accel-ff", "-1", "acceleration feedforward"},
        {"--ik-correction-limit", "-1", "correction limit"},
        {"--ik-integral", "-1", "ik integral"},
        {"--ik-start", "nowhere", "--ik-start"},
        {"--tip-smooth-hz", "2000", "got 2000"},
    };
    for (const auto &c : cases) {
        const Run r = ictusd(base + c[0] + " " + c[1]);
        INFO(c[0] << " " << c[1] << " -> " << r.status << ": " << r.output);
        CHECK(r.status == 2);
        CHECK(r.output.find(c[2]) != std::string::npos);
    }
    // A missing value.
    const Run r = ictusd(base + "--step");
    CHECK(r.status == 2);
    CHECK(r.output.find("--step: missing value") != std::string::npos);
    // Values only the model can judge: exit 1 with the parameter named.
    const Run tip = ictusd(base + "--stick-tip-radius 0.3");
    CHECK(tip.status == 1);
    CHECK(tip.output.find("tip radius") != std::string::npos);
}

TEST_CASE("ictusd: missing and malformed files are errors naming the file (exit 1)", "[sim][cli]")
{
    Run r = ictusd("track --mode joint --quiet --mocap /nonexistent/clip.bvh");
    CHECK(r.status == 1);
    CHECK(r.output.find("/nonexistent/clip.bvh") != std::string::npos);
    const std::string bad =
        simtest::write_temp("bad.bvh", "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n}\n");
    r = ictusd("track --mode joint --quiet --mocap " + bad);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(bad + ":5") != std::string::npos); // file:line (the '}' of line 5)
    r = ictusd("limits " + bad);
    CHECK(r.status == 1);
    // A valid BVH without the CMU joints the character needs.
    const std::string other = simtest::write_temp(
        "other.bvh", "HIERARCHY\nROOT pelvis\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation "
                     "Xrotation\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame "
                     "Time: 0.01\n0 0 0\n0 0 0\n");
    r = ictusd("track --mode joint --quiet --mocap " + other);
    CHECK(r.status == 1);
    CHECK(r.output.find("Hips") != std::string::npos);
    // An output folder that cannot be created.
    r = ictusd("track --mode joint --quiet --mocap " + tiny_bvh() + " --out /proc/ictus_test");
    CHECK(r.status == 1);
    CHECK(r.output.find("--out") != std::string::npos);
}

TEST_CASE("ictusd track --out writes the CSV and a summary with the required fields", "[sim][cli]")
{
    const std::string dir = simtest::temp_path("out");
    const Run r =
        ictusd("track --mode joint --mocap " + tiny_bvh() + " --out " + dir + " --duration 1.5");
    INFO(r.output);
    REQUIRE(r.status == 0);
    // Not a terminal: plain progress lines.
    CHECK(r.output.find("track: 100%") != std::string::npos);
    std::ifstream js(dir + "/summary.json");
    REQUIRE(js.good());
    const nlohmann::json s = nlohmann::json::parse(js);
    CHECK(s.at("mode") == "joint");
    CHECK(s.at("frames").get<int>() == 120); // 121 minus the skipped first frame
    CHECK(s.at("tip_rms_mm").at("left").get<double>() >= 0.0);
    CHECK(s.at("tip_rms_mm").at("right").get<double>() < 10.0);
    CHECK(s.at("joint_rms_deg").size() == 19u);
    CHECK(s.at("joint_rms_deg").at("r_elbow").get<double>() < 1.0);
    CHECK(s.at("realtime_factor").get<double>() > 0.0);
    CHECK(s.at("diverged") == false);
    CHECK(s.at("duration_s").get<double>() == Approx(1.5));
    std::ifstream csv(dir + "/track.csv");
    std::string header, line;
    std::getline(csv, header);
    CHECK(header.find("r_elbow_err_deg") != std::string::npos);
    CHECK(header.find("tip_right_sim_y_m") != std::string::npos);
    int rows = 0;
    while (std::getline(csv, line))
        ++rows;
    CHECK(rows == 180); // 1.5 s at the clip's 120 Hz
}

TEST_CASE("ictusd track --mode cartesian writes the same outputs plus IK statistics",
          "[sim][cli][cartesian]")
{
    const std::string dir = simtest::temp_path("out_cartesian");
    const Run r = ictusd("track --mode cartesian --quiet --mocap " + tiny_bvh() + " --out " + dir +
                         " --duration 1");
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(r.output.find("mode cartesian") != std::string::npos);
    CHECK(r.output.find("ik: ") != std::string::npos);
    std::ifstream js(dir + "/summary.json");
    REQUIRE(js.good());
    const nlohmann::json s = nlohmann::json::parse(js);
    CHECK(s.at("mode") == "cartesian");
    CHECK(s.at("ik").at("gain").get<double>() == Approx(10.0));
    CHECK(s.at("ik").at("mean_iterations").get<double>() < 3.0);
    CHECK(s.at("ik").at("us_per_step").get<double>() > 0.0);
    CHECK(s.at("tip_rms_mm").at("right").get<double>() < 5.0);
    std::ifstream csv(dir + "/track.csv");
    std::string header;
    std::getline(csv, header);
    CHECK(header.find("r_elbow_flexion_target_deg") != std::string::npos);
    // A bad mode names the choices.
    const Run bad = ictusd("track --mode foo --mocap " + tiny_bvh());
    CHECK(bad.status == 2);
    CHECK(bad.output.find("joint or cartesian") != std::string::npos);
}

namespace
{
// Stick-only capture in a z-up millimetre frame: two sticks striking
// alternately, 12 cm strokes at 2 Hz, 0.3 m apart.
std::string stick_csv()
{
    std::ostringstream out;
    out << "time,stick_l.x,stick_l.y,stick_l.z,stick_r.x,stick_r.y,stick_r.z\n";
    for (int f = 0; f < 400; ++f) {
        const double t = f / 200.0;
        out << t;
        for (int s = 0; s < 2; ++s) {
            const double h = 60.0 * (1 - std::cos(2 * M_PI * 2 * t + (s == 0 ? 0 : M_PI)));
            // z up: x lateral, y (depth) constant, z the height.
            out << ',' << (s == 0 ? 150.0 : -150.0) + 1000.0 << ',' << 2000.0 << ',' << 700.0 + h;
        }
        out << '\n';
    }
    return simtest::write_temp("sticks.csv", out.str());
}
} // namespace

TEST_CASE("ictusd track: a stick-only capture runs in Cartesian mode, drum fitted",
          "[sim][cli][cartesian]")
{
    const std::string csv = stick_csv();
    const std::string dir = simtest::temp_path("out_sticks");
    const Run r = ictusd("track --mode cartesian --quiet --mocap " + csv +
                         " --units mm --up z --drum auto --out " + dir);
    INFO(r.output);
    REQUIRE(r.status == 0);
    std::ifstream js(dir + "/summary.json");
    REQUIRE(js.good());
    const nlohmann::json s = nlohmann::json::parse(js);
    CHECK(s.at("mode") == "cartesian");
    CHECK(s.at("duration_s").get<double>() == Approx(1.995).margin(0.002));
    CHECK(s.at("tip_rms_mm").at("left").get<double>() < 3.0);
    CHECK(s.at("tip_rms_mm").at("right").get<double>() < 3.0);
    CHECK(s.at("ik").at("elbow_flexion_rms_deg").is_null()); // no captured elbow
    // No capture to learn limits from: a person's range of motion; the drum at
    // the strokes' turnarounds (nothing passes through it there).
    CHECK(s.at("limits") == "range_of_motion");
    CHECK(s.at("drum_rule") == "turnarounds");
    CHECK(s.at("drum_through_fraction").get<double>() == 0.0);
    // The sticks were moved in front of the body (it faces +z, pelvis at the
    // origin's vertical): the drum under them, ahead of the pelvis and below
    // the shoulders (~1.17 m), above the floor.
    const auto drum = s.at("drum_center_m");
    CHECK(std::abs(drum[0].get<double>()) < 0.05);
    CHECK(drum[1].get<double>() > 0.4);
    CHECK(drum[1].get<double>() < 1.0);
    CHECK(drum[2].get<double>() > 0.2);

    // --limits none: none.
    const std::string dir_none = simtest::temp_path("out_sticks_none");
    const Run none = ictusd("track --mode cartesian --quiet --mocap " + csv +
                            " --units mm --up z --limits none --duration 0.3 --out " + dir_none);
    REQUIRE(none.status == 0);
    std::ifstream js_none(dir_none + "/summary.json");
    CHECK(nlohmann::json::parse(js_none).at("limits") == "none");

    // Bad stick options and drum values are usage errors naming the thing.
    Run bad = ictusd("track --mode cartesian --quiet --mocap " + csv +
                     " --units mm --up z --left-stick nope");
    CHECK(bad.status == 2);
    CHECK(bad.output.find("'nope'") != std::string::npos);
    CHECK(bad.output.find("stick_l") != std::string::npos); // lists the objects
    bad = ictusd("track --mode cartesian --quiet --mocap " + csv + " --left-stick");
    CHECK(bad.status == 2);
    CHECK(bad.output.find("--left-stick: missing value") != std::string::npos);
    bad = ictusd("track --mode cartesian --quiet --mocap " + csv + " --drum bogus");
    CHECK(bad.status == 2);
    CHECK(bad.output.find("--drum") != std::string::npos);
    bad = ictusd("track --mode joint --quiet --mocap " + csv);
    CHECK(bad.status == 2);
    CHECK(bad.output.find("--mode cartesian") != std::string::npos);
    bad = ictusd("track --mode cartesian --quiet --mocap " + tiny_bvh() + " --left-stick a");
    CHECK(bad.status == 2);
    bad = ictusd("track --mode cartesian --quiet --mocap " + csv + " --units inch");
    CHECK(bad.status == 2);
    CHECK(bad.output.find("--units") != std::string::npos);
    bad = ictusd("track --mode cartesian --quiet --mocap " + csv + " --up x");
    CHECK(bad.status == 2);
}

TEST_CASE("ictusd track --gains overrides one joint and refuses bad files", "[sim][cli]")
{
    const std::string base = "track --mode joint --quiet --duration 0.5 --mocap " + tiny_bvh();
    const std::string good = simtest::write_temp(
        "gains.json", R"({"r_wrist": {"kp_nm_per_rad": 33.0, "torque_limit_nm": 7.5}})");
    const std::string dir = simtest::temp_path("gains_out");
    Run r = ictusd(base + " --gains " + good + " --out " + dir);
    INFO(r.output);
    REQUIRE(r.status == 0);
    std::ifstream js(dir + "/summary.json");
    const nlohmann::json s = nlohmann::json::parse(js);
    CHECK(s.at("gains").at("r_wrist").at("kp_nm_per_rad").get<double>() == 33.0);
    CHECK(s.at("gains").at("r_wrist").at("torque_limit_nm").get<double>() == 7.5);
    // Untouched: the default wrist limit, 15 N m at 70 kg.
    CHECK(s.at("gains").at("l_wrist").at("torque_limit_nm").get<double>() == Approx(15.0));
    const std::vector<std::array<std::string, 2>> bad = {
        {R"({"r_pinky": {"kp_nm_per_rad": 1}})", "r_pinky"},
        {R"({"r_wrist": {"kp": 1}})", "unknown field 'kp'"},
        {R"({"r_wrist": {"torque_limit_nm": -1}})", "torque_limit_nm"},
        {R"({"r_wrist": {"torque_limit_nm": "strong"}})", "torque_limit_nm"},
        {R"([1, 2])", "expected a JSON object"},
        {R"({"r_wrist": )", "not valid JSON"},
    };
    for (const auto &b : bad) {
        const std::string f = simtest::write_temp("bad_gains.json", b[0]);
        r = ictusd(base + " --gains " + f);
        INFO(b[0] << " -> " << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(b[1]) != std::string::npos);
        CHECK(r.output.find("bad_gains.json") != std::string::npos);
    }
    r = ictusd(base + " --gains /nonexistent/gains.json");
    CHECK(r.status == 1);
    CHECK(r.output.find("/nonexistent/gains.json") != std::string::npos);
}

TEST_CASE("ictusd track stops cleanly on SIGINT and writes what it simulated", "[sim][cli]")
{
    const std::string dir = simtest::temp_path("sigint_out");
    const std::string mocap = tiny_bvh();
    std::vector<std::string> args = {ICTUSD_PATH, "track",   "--mode", "joint",
                                     "--quiet",   "--mocap", mocap,    "--duration",
                                     "3600",      "--out",   dir};
    std::vector<char *> argv;
    for (std::string &a : args)
        argv.push_back(&a[0]);
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    REQUIRE(posix_spawn(&pid, ICTUSD_PATH, &actions, nullptr, argv.data(), environ) == 0);
    posix_spawn_file_actions_destroy(&actions);
    // Wait until it is in the loop (CSV rows reach the file; an hour of
    // simulated time cannot finish meanwhile), at most 60 s.
    for (int i = 0; i < 600; ++i) {
        std::error_code ec;
        if (std::filesystem::file_size(dir + "/track.csv", ec) > 0 && !ec)
            break;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    REQUIRE(kill(pid, SIGINT) == 0);
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    std::ifstream js(dir + "/summary.json");
    REQUIRE(js.good());
    const nlohmann::json s = nlohmann::json::parse(js);
    CHECK(s.at("interrupted") == true);
    CHECK(s.at("duration_s").get<double>() > 0.0);
    CHECK(s.at("duration_s").get<double>() < 3600.0);
}

TEST_CASE("ictusd limits prints the 19 joints and writes JSON", "[sim][cli]")
{
    const std::string out = simtest::temp_path("limits.json");
    const Run r = ictusd("limits " + tiny_bvh() + " --out " + out);
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(r.output.find("r_elbow") != std::string::npos);
    std::ifstream js(out);
    const nlohmann::json j = nlohmann::json::parse(js);
    REQUIRE(j.at("joints").size() == 19u);
    CHECK(j.at("joints")[0].at("name") == "lumbar");
    CHECK(j.at("joints")[0].contains("quaternion"));
    CHECK(j.at("joints")[0].contains("euler"));
    const std::vector<std::array<std::string, 2>> cases = {
        {"--k", "-2"},          {"--min-deg", "-1"},   {"--min-deg", "200"},    {"--scale", "0"},
        {"--skip-frames", "x"}, {"--smooth-hz", "-1"}, {"--despike-deg", "-3"},
    };
    for (const auto &c : cases) {
        const Run bad = ictusd("limits " + tiny_bvh() + " " + c[0] + " " + c[1]);
        INFO(c[0] << " " << c[1] << " -> " << bad.output);
        CHECK(bad.status == 2);
        CHECK(bad.output.find(c[0]) != std::string::npos);
    }
    // Skipping every frame leaves nothing to learn from: a data error.
    const Run empty = ictusd("limits " + tiny_bvh() + " --skip-frames 500");
    INFO(empty.output);
    CHECK(empty.status == 1);
}

TEST_CASE("ictusd gestures is a verb of ictusd: help, export of the built-in database, usage "
          "errors",
          "[sim][cli]")
{
    Run r = ictusd("--help");
    CHECK(r.output.find("gestures") != std::string::npos);
    r = ictusd("gestures --help");
    INFO(r.output);
    CHECK(r.status == 0);
    CHECK(r.output.find("usage: ictusd gestures") != std::string::npos);
    // The built-in database holds one unit per grip x nuance x hand (docs/gestures.md):
    // 2 x 6 x 2 = 24.
    const std::string path = simtest::temp_path("gestures.json");
    std::remove(path.c_str());
    r = ictusd("gestures --export " + path);
    CHECK(r.status == 0);
    CHECK(r.output.find("wrote 24 units to " + path) != std::string::npos);
    CHECK(std::ifstream(path).good());
    std::remove(path.c_str());
    r = ictusd("gestures --frobnicate");
    CHECK(r.status == 2);
    r = ictusd("gestures");
    CHECK(r.status == 2); // exactly one action is required
}

namespace
{
struct CsvRows {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    int column(const std::string &name) const
    {
        for (size_t i = 0; i < header.size(); ++i)
            if (header[i] == name)
                return static_cast<int>(i);
        FAIL("no column " << name);
        return -1;
    }
};

CsvRows read_csv(const std::string &path)
{
    CsvRows out;
    std::ifstream in(path);
    REQUIRE(in.good());
    std::string line;
    bool first = true;
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ','))
            cells.push_back(cell);
        if (first)
            out.header = cells;
        else
            out.rows.push_back(cells);
        first = false;
    }
    return out;
}
} // namespace

// `track` and `render --mocap` simulate the same clip in joint mode through
// two different code paths (track_joint_space + the CLI's strike writer vs the
// Performance of run/render): on the same drum, with the same sticks (track's
// are rigid in the hand; render's on their fulcrum unless --sticks rigid),
// both must log the same strikes.
TEST_CASE("ictusd track --out writes strikes.csv, the same strikes render finds", "[sim][cli]")
{
    const std::string bvh = simtest::data_file("cmu/80_13.bvh");
    if (bvh.empty())
        return;
    const std::string rdir = simtest::temp_path("render-strikes");
    const Run r =
        ictusd("render --mocap " + bvh + " --sticks rigid --duration 6 --bvh-rate 0 --out " + rdir);
    INFO(r.output);
    REQUIRE(r.status == 0);
    std::ifstream rj(rdir + "/render.json");
    const nlohmann::json render = nlohmann::json::parse(rj);
    const auto c = render.at("drum").at("center_m");
    std::ostringstream drum;
    drum.precision(17);
    drum << c.at(0).get<double>() << "," << c.at(1).get<double>() << "," << c.at(2).get<double>();

    const std::string tdir = simtest::temp_path("track-strikes");
    // render's reference is the Gaussian-smoothed clip (the score performance's
    // ReferenceFilter); track's default is the Butterworth (docs/mocap.md).
    const Run t = ictusd("track --mode joint --quiet --mocap " + bvh +
                         " --smooth-kernel gaussian --duration 6 --drum-pos " + drum.str() +
                         " --out " + tdir);
    INFO(t.output);
    REQUIRE(t.status == 0);
    std::ifstream tj(tdir + "/summary.json");
    const nlohmann::json summary = nlohmann::json::parse(tj);

    const CsvRows a = read_csv(tdir + "/strikes.csv"), b = read_csv(rdir + "/strikes.csv");
    CHECK(a.header == b.header);
    REQUIRE(a.rows.size() >= 10); // the clip strikes this drum a few times a second
    CHECK(summary.at("strikes").get<size_t>() == a.rows.size());
    REQUIRE(a.rows.size() == b.rows.size());
    const int time = a.column("time_s"), hand = a.column("hand"),
              vn = a.column("normal_velocity_mps");
    for (size_t i = 0; i < a.rows.size(); ++i) {
        INFO("strike " << i);
        CHECK(a.rows[i][static_cast<size_t>(hand)] == b.rows[i][static_cast<size_t>(hand)]);
        // Same physics to the microsecond (the two loops round the clip's
        // sample times differently: a few ulp in the targets).
        CHECK(std::stod(a.rows[i][static_cast<size_t>(time)]) ==
              Approx(std::stod(b.rows[i][static_cast<size_t>(time)])).margin(1e-4));
        CHECK(std::stod(a.rows[i][static_cast<size_t>(vn)]) ==
              Approx(std::stod(b.rows[i][static_cast<size_t>(vn)])).epsilon(0.01));
        CHECK(std::stod(a.rows[i][static_cast<size_t>(vn)]) > 0.0);
    }
}

namespace
{

// The tiny clip's text with one line changed: the OFFSET of `joint` (a JOINT,
// or "X_end" for X's End Site) set to `offset`. Returns the text; `line` gets
// the 1-based line of that OFFSET.
std::string with_offset(const std::string &joint, const std::string &offset, int &line)
{
    std::istringstream in(simtest::default_skeleton_bvh(
        121, 1.0 / 120, [](int, const std::string &) { return Eigen::Vector3d::Zero(); }));
    const bool end_site = joint.size() > 4 && joint.substr(joint.size() - 4) == "_end";
    const std::string owner = end_site ? joint.substr(0, joint.size() - 4) : joint;
    std::string text, l;
    int n = 0, stage = 0; // 0: looking for the joint, 1: (End Site), 2: its OFFSET, 3: done
    line = 0;
    while (std::getline(in, l)) {
        ++n;
        const size_t first = l.find_first_not_of('\t');
        const std::string trimmed = first == std::string::npos ? "" : l.substr(first);
        if (stage == 0 && (trimmed == "JOINT " + owner || trimmed == "ROOT " + owner))
            stage = end_site ? 1 : 2;
        else if (stage == 1 && trimmed.rfind("JOINT", 0) == 0)
            stage = 3; // the joint has children before an End Site: none here
        else if (stage == 1 && trimmed == "End Site")
            stage = 2;
        else if (stage == 2 && trimmed.rfind("OFFSET", 0) == 0) {
            l = l.substr(0, first) + "OFFSET " + offset;
            line = n;
            stage = 3;
        }
        text += l + "\n";
    }
    REQUIRE(line > 0);
    return text;
}

// The tiny clip with the text of line `prefix...` replaced; `line` gets its number.
std::string tiny_with_line(const std::string &prefix, const std::string &replacement, int &line)
{
    std::istringstream in(simtest::default_skeleton_bvh(
        121, 1.0 / 120, [](int, const std::string &) { return Eigen::Vector3d::Zero(); }));
    std::string text, l;
    int n = 0;
    line = 0;
    while (std::getline(in, l)) {
        ++n;
        if (line == 0 && l.rfind(prefix, 0) == 0) {
            l = replacement;
            line = n;
        }
        text += l + "\n";
    }
    REQUIRE(line > 0);
    return text;
}

} // namespace

// A zero OFFSET on a limb's joint built a zero-length body, which ODE's
// dMassCheck answers with SIGABRT: track, render and run died. Now every verb
// refuses the file with exit 1 at FILE:LINE of that OFFSET, naming the joint.
TEST_CASE("ictusd: a zero-length limb is refused at its OFFSET's line, by every verb",
          "[sim][cli][bounds]")
{
    int line = 0;
    const std::string bvh =
        simtest::write_temp("zero_forearm.bvh", with_offset("LeftHand", "0 0 0", line));
    const std::string where = bvh + ":" + std::to_string(line) +
                              ": joint 'LeftHand': expected the "
                              "l_forearm segment to be 0.05 to "
                              "1 m (a human limb), got 0 m";
    const std::string dir = simtest::temp_path("zero_out");
    for (const std::string &args :
         {"track --mode joint --quiet --duration 0.05 --mocap " + bvh,
          "track --mode cartesian --quiet --duration 0.05 --mocap " + bvh, "limits " + bvh,
          "render --mocap " + bvh + " --duration 0.05 --bvh-rate 0 --out " + dir,
          "run --mocap " + bvh + " --duration 0.05 --port 0 --target osc.udp://127.0.0.1:9"}) {
        const Run r = ictusd(args);
        INFO(args << " -> " << r.status << "\n" << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(where) != std::string::npos);
    }
}

// Property over the whole skeleton: a zero OFFSET on any one joint either runs
// (segments that carry no body, zero End Sites, the pelvis) or is refused at
// that joint's OFFSET line (the eight limbs). Never a crash.
TEST_CASE("ictusd track: a zero OFFSET on any joint runs or names that joint, never aborts",
          "[sim][cli][bounds]")
{
    int refused = 0;
    for (const ictus::SkeletonJoint &joint : ictus::default_skeleton().joints) {
        if (joint.parent < 0)
            continue; // the root's OFFSET is a position, not a segment
        int line = 0;
        const std::string name = joint.name;
        const std::string bvh =
            simtest::write_temp("zero_one.bvh", with_offset(name, "0 0 0", line));
        const Run r = ictusd("track --mode joint --quiet --duration 0.02 --mocap " + bvh);
        INFO(name << " -> " << r.status << "\n" << r.output);
        CHECK((r.status == 0 || r.status == 1));
        if (r.status == 1) {
            ++refused;
            CHECK(r.output.find(bvh + ":" + std::to_string(line) + ": joint '" + name + "'") !=
                  std::string::npos);
        }
    }
    CHECK(refused == 8);
    // Zero End Sites carry no body of their own: the clip runs.
    for (const char *site : {"Head_end", "LeftToeBase_end", "LThumb_end", "RightHandIndex1_end"}) {
        int line = 0;
        const std::string bvh =
            simtest::write_temp("zero_site.bvh", with_offset(site, "0 0 0", line));
        const Run r = ictusd("track --mode joint --quiet --duration 0.05 --mocap " + bvh);
        INFO(site << "\n" << r.output);
        CHECK(r.status == 0);
    }
}

// Frame Time: 60 read as 60 s per frame: a 121-frame clip became a 2-hour run
// (rc 0, no word), render's default duration too. Refused now at its line,
// with --force (track, limits) to insist.
TEST_CASE("ictusd: a frame time out of bounds is refused at its line, and --force reads it",
          "[sim][cli][bounds]")
{
    int line = 0;
    const std::string bvh =
        simtest::write_temp("slow.bvh", tiny_with_line("Frame Time:", "Frame Time: 60", line));
    const std::string where = bvh + ":" + std::to_string(line) +
                              ": expected a frame time in [0.0005, 0.5] s (a capture at 2 Hz to "
                              "2 kHz), got '60'";
    const std::string dir = simtest::temp_path("slow_out");
    for (const std::string &args : {"track --mode joint --quiet --duration 0.05 --mocap " + bvh,
                                    "limits " + bvh + " --out " + dir + ".json",
                                    "render --mocap " + bvh + " --duration 0.05 --out " + dir}) {
        const Run r = ictusd(args);
        INFO(args << " -> " << r.status << "\n" << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(where) != std::string::npos);
    }
    Run r = ictusd("track --mode joint --quiet --duration 0.05 --mocap " + bvh);
    CHECK(r.output.find("(--force reads it anyway)") != std::string::npos);
    for (const std::string &args :
         {"track --mode joint --quiet --duration 0.05 --force --mocap " + bvh,
          "limits " + bvh + " --force --out " + dir + ".json"}) {
        r = ictusd(args);
        INFO(args << " -> " << r.status << "\n" << r.output);
        CHECK(r.status == 0);
        CHECK(r.output.find("ictusd: warning: " + where) != std::string::npos);
        CHECK(r.output.find("read anyway") != std::string::npos);
    }
    // A root position 1e9 units away (56,000 km at the CMU scale), frame 10.
    int frame_time_line = 0;
    std::string text = tiny_with_line("Frame Time:", "Frame Time: 0.0083333", frame_time_line);
    const int far_line = frame_time_line + 10;
    {
        std::istringstream in(text);
        std::string l, out;
        for (int n = 1; std::getline(in, l); ++n)
            out += (n == far_line ? "1e9" + l.substr(l.find(' ')) : l) + "\n";
        text = out;
    }
    const std::string far = simtest::write_temp("far.bvh", text);
    r = ictusd("track --mode joint --quiet --duration 0.05 --mocap " + far);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(far + ":" + std::to_string(far_line) +
                        ": expected |position| * scale <= 100 m in column 0 (Hips Xposition") !=
          std::string::npos);
}

namespace
{
// The stick-only capture of stick_csv() with its clock multiplied by
// `time_unit` (1000: ms) and, when `far_row` >= 0, stick_l.z of that row set to 1e9.
std::string stick_csv_with(double time_unit, int far_row = -1)
{
    std::ostringstream out;
    out << "time,stick_l.x,stick_l.y,stick_l.z,stick_r.x,stick_r.y,stick_r.z\n";
    for (int f = 0; f < 400; ++f) {
        const double t = f / 200.0;
        out << t * time_unit;
        for (int s = 0; s < 2; ++s) {
            const double h = 60.0 * (1 - std::cos(2 * M_PI * 2 * t + (s == 0 ? 0 : M_PI)));
            out << ',' << (s == 0 ? 150.0 : -150.0) + 1000.0 << ',' << 2000.0 << ',';
            if (s == 0 && f == far_row)
                out << "1e9";
            else
                out << 700.0 + h;
        }
        out << '\n';
    }
    return out.str();
}
} // namespace

// A time column in ms made a 2 s take a 33-minute run; a 1e9 mm cell put the
// stick (and the auto drum) 1000 km away; both ran with rc 0 and no word.
TEST_CASE("ictusd track: a stick capture in ms, or 1e9 mm away, is refused at its row",
          "[sim][cli][bounds][cartesian]")
{
    const std::string base = "track --mode cartesian --quiet --units mm --up z --duration 0.05 ";
    const std::string ms = simtest::write_temp("sticks_ms.csv", stick_csv_with(1000.0));
    Run r = ictusd(base + "--mocap " + ms);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(ms + ":3: expected a median time step in [0.0005, 0.5] s") !=
          std::string::npos);
    CHECK(r.output.find("got 5 s") != std::string::npos);
    CHECK(r.output.find("a time column in ms or us?") != std::string::npos);
    CHECK(r.output.find("--force") != std::string::npos);
    r = ictusd(base + "--force --mocap " + ms);
    CHECK(r.status == 0);
    CHECK(r.output.find("ictusd: warning: " + ms + ":3: expected a median time step") !=
          std::string::npos);

    const std::string far = simtest::write_temp("sticks_far.csv", stick_csv_with(1.0, 4));
    r = ictusd(base + "--mocap " + far);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(far + ":6: expected |coordinate| <= 100 m (100000 mm) in column 4 "
                              "(stick_l.z), got '1e9' mm") != std::string::npos);
    // The same capture without that cell runs.
    CHECK(ictusd(base + "--mocap " + simtest::write_temp("sticks_ok.csv", stick_csv_with(1.0)))
              .status == 0);
}

// `limits` learned from a single frame (zero spreads, floored to the minimum
// width) and said nothing. Now it needs kMinLimitFrames (30) frames, or --force.
TEST_CASE("ictusd limits needs 30 frames to learn from, or --force", "[sim][cli][bounds]")
{
    const std::string out = simtest::temp_path("few.json");
    // tiny_bvh: 121 frames; --skip-frames 91 leaves 30, 92 leaves 29, 120 leaves 1.
    Run r = ictusd("limits " + tiny_bvh() + " --skip-frames 91 --out " + out);
    INFO(r.output);
    CHECK(r.status == 0);
    for (const char *skip : {"92", "120"}) {
        r = ictusd("limits " + tiny_bvh() + " --skip-frames " + skip + " --out " + out);
        INFO(skip << ": " << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(tiny_bvh() + ": " + std::to_string(121 - std::stoi(skip)) +
                            " frame(s) after --skip-frames " + skip +
                            ", fewer than the 30 that limits are learned from") !=
              std::string::npos);
        CHECK(r.output.find("--force") != std::string::npos);
    }
    r = ictusd("limits " + tiny_bvh() + " --skip-frames 120 --force --out " + out);
    INFO(r.output);
    CHECK(r.status == 0);
    CHECK(r.output.find("ictusd: warning: " + tiny_bvh() + ": 1 frame(s)") != std::string::npos);
    std::ifstream js(out);
    const nlohmann::json j = nlohmann::json::parse(js);
    CHECK(j.at("joints").size() == 19u);
    // track learns its limits the same way: a warning, the run goes on.
    r = ictusd("track --mode joint --quiet --duration 0.05 --skip-frames 100 --mocap " +
               tiny_bvh());
    INFO(r.output);
    CHECK(r.status == 0);
    CHECK(r.output.find("joint limits learned from 21 frame(s), fewer than 30") !=
          std::string::npos);
    r = ictusd("track --mode joint --quiet --duration 0.05 --skip-frames 100 --limits none "
               "--mocap " +
               tiny_bvh());
    CHECK(r.output.find("fewer than 30") == std::string::npos);
}

TEST_CASE("ictusd track and limits --help document --force and the bounds", "[sim][cli][bounds]")
{
    for (const char *verb : {"track", "limits"}) {
        const Run r = ictusd(std::string(verb) + " --help");
        INFO(r.output);
        CHECK(r.status == 0);
        for (const char *text :
             {"--force", "0.0005..0.5 s", "3 h", "100 m", "0.05 m", "1 m", "30 frames"})
            CHECK(r.output.find(text) != std::string::npos);
    }
}

namespace
{

// The version the top CMakeLists.txt declares, read from the source: the
// number `ictusd --version` must print.
std::string declared_version()
{
    std::ifstream in(std::string(ICTUS_SOURCE_DIR) + "/CMakeLists.txt");
    REQUIRE(in);
    std::stringstream text;
    text << in.rdbuf();
    std::smatch m;
    const std::string s = text.str();
    REQUIRE(
        std::regex_search(s, m, std::regex(R"(project\(ictus VERSION ([0-9]+\.[0-9]+\.[0-9]+))")));
    return m[1];
}

// The options a --help text defines: a `--name` that starts an entry, i.e. at
// the start of a line after two spaces, after ", " (`--units mm|m, --up y|z`)
// or after three spaces in a line that holds two entries
// (`--stick-length M  (default 0.406)   --stick-mass KG`). Mentions inside a
// description (`(after --scale or --units)`) are not entries.
std::vector<std::string> defined_options(const std::string &help)
{
    std::vector<std::string> found;
    static const std::regex entry(R"((?:^  |, |   )(--[a-z][a-z0-9-]*))");
    std::istringstream lines(help);
    std::string line;
    while (std::getline(lines, line)) {
        // A continuation line (deeply indented description) defines nothing.
        if (line.compare(0, 3, "  -") != 0)
            continue;
        for (std::sregex_iterator it(line.begin(), line.end(), entry), end; it != end; ++it)
            found.push_back((*it)[1]);
    }
    return found;
}

const char *const kVerbs[] = {"track", "limits", "run", "render", "gestures"};

} // namespace

TEST_CASE("ictusd --version prints the project's version, for the program and each verb",
          "[sim][cli]")
{
    const std::string expected = "ictusd " + declared_version() + "\n";
    Run r = ictusd("--version");
    CHECK(r.status == 0);
    CHECK(r.output == expected);
    for (const char *verb : kVerbs) {
        r = ictusd(std::string(verb) + " --version");
        INFO(verb);
        CHECK(r.status == 0);
        CHECK(r.output == expected);
    }
    // Among a verb's other options it is an unknown option, as any other.
    r = ictusd("render --out /nonexistent/x --version");
    CHECK(r.status == 2);
    CHECK(r.output.find("unknown option '--version'") != std::string::npos);
    // The main help names it.
    CHECK(ictusd("--help").output.find("--version") != std::string::npos);
}

TEST_CASE("ictusd: a score or database that cannot be read is a file error (exit 1), as the "
          "help says",
          "[sim][cli]")
{
    const Run help = ictusd("--help");
    REQUIRE(help.output.find("1 error in a file or the data, 2 usage error") != std::string::npos);
    const std::string empty = simtest::write_temp("empty.score", "");
    const std::string out = simtest::write_temp("unused.txt", "") + ".out";
    struct Case {
        std::string args, names;
    };
    // run stops after a hundredth of a second, on any free port, should it start at all.
    const std::string run = "run --port 0 --pose-rate 0 --duration 0.01 ";
    for (const Case &c : std::vector<Case>{
             {run + "--score /nonexistent/a.score", "/nonexistent/a.score"},
             {run + "--score " + empty, empty},
             {run + "--gestures /nonexistent/db.json", "/nonexistent/db.json"},
             {"render --score /nonexistent/a.score --out " + out, "/nonexistent/a.score"},
             {"render --score " + empty + " --out " + out, empty},
             {"render --gestures /nonexistent/db.json --out " + out, "/nonexistent/db.json"},
             {"render --mocap /nonexistent/clip.bvh --out " + out, "/nonexistent/clip.bvh"},
             {"limits /nonexistent/clip.bvh", "/nonexistent/clip.bvh"},
             {"gestures --list --db /nonexistent/db.json", "/nonexistent/db.json"},
             {"gestures --export /nonexistent/dir/db.json", "/nonexistent/dir/db.json"},
             {"track --mode joint --quiet --mocap /nonexistent/clip.bvh", "/nonexistent/clip.bvh"},
         }) {
        const Run r = ictusd(c.args);
        INFO(c.args << "\n" << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(c.names) != std::string::npos);
    }
}

TEST_CASE("ictusd: every --help lists each option once, and its examples name files that exist",
          "[sim][cli]")
{
    std::vector<std::string> helps = {"--help"};
    for (const char *verb : kVerbs)
        helps.push_back(std::string(verb) + " --help");
    for (const std::string &args : helps) {
        const Run r = ictusd(args);
        INFO(args << "\n" << r.output);
        REQUIRE(r.status == 0);
        const std::vector<std::string> options = defined_options(r.output);
        if (args != "--help")
            CHECK(options.size() >= 3); // the parser sees the entries at all
        std::set<std::string> seen;
        for (const std::string &o : options) {
            INFO("option " << o);
            CHECK(seen.insert(o).second);
        }
        // A path into the repository's examples/ must be there (the CMU clip
        // under ../shared/data is data, not part of the repository).
        static const std::regex example(R"(examples/[A-Za-z0-9_./-]+)");
        for (std::sregex_iterator it(r.output.begin(), r.output.end(), example), end; it != end;
             ++it) {
            const std::string path = std::string(ICTUS_SOURCE_DIR) + "/" + it->str();
            INFO("example file " << path);
            CHECK(std::filesystem::is_regular_file(path));
        }
    }
    // run's and render's help between them name an example score.
    CHECK((ictusd("run --help").output + ictusd("render --help").output).find("examples/scores/") !=
          std::string::npos);
}
