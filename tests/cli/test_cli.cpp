// The real ictusd binary: help, usage errors, bad values for every option,
// the files `track --out` writes, limits and gestures as processes.
#include "support/cli_test_util.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <regex>
#include <set>
#include <thread>

#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <sstream>

using clitest::ictusd;
using clitest::Run;
using clitest::tiny_bvh;

TEST_CASE("ictusd --help and per-verb help exit 0 with examples", "[cli]")
{
    for (const char *args : {"--help", "track --help", "limits --help"}) {
        const Run r = ictusd(args);
        INFO(args << "\n" << r.output);
        CHECK(r.status == 0);
        CHECK(r.output.find("usage: ictusd") != std::string::npos);
        CHECK(r.output.find("example") != std::string::npos);
    }
}

TEST_CASE("ictusd: unknown verbs and options are usage errors (exit 2)", "[cli]")
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
    // Two motion sources, or a kit with a clip, for render and run alike.
    for (const char *verb : {"render --out /nonexistent-dir/x", "run"}) {
        const std::string clip = " --mocap " + tiny_bvh();
        const std::string score = simtest::write_temp("two-sources.txt", "R\n");
        for (const std::string &extra :
             {" --score " + score, std::string(" --midi x.mid"), std::string(" --kit full")}) {
            r = ictusd(std::string(verb) + clip + extra);
            INFO(verb << clip << extra << " -> " << r.status << ": " << r.output);
            CHECK(r.status == 2);
            CHECK(r.output.find(extra.substr(1, extra.find(' ', 1) - 1)) != std::string::npos);
        }
    }
}

TEST_CASE("ictusd track: every option refuses a bad value, naming it", "[cli]")
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

TEST_CASE("ictusd: missing and malformed files are errors naming the file (exit 1)", "[cli]")
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

TEST_CASE("ictusd track --out writes the CSV and a summary with the required fields", "[cli]")
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
    // --despike-deg's default, 5 degrees exactly (not a rounded radian value).
    CHECK(s.at("despike_deg").get<double>() == 5.0);
    // A BVH: the errors against the unfiltered capture are measured.
    CHECK(s.at("tip_rms_raw_mm").at("right").get<double>() >= 0.0);
    CHECK(s.at("joint_rms_raw_deg_all").is_number());
    CHECK(s.at("skip_frames").get<int>() == 1);
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
          "[cli][cartesian]")
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
          "[cli][cartesian]")
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
    // The capture's 400 samples (not the default body's frames); no raw capture to
    // measure against, no BVH scale, skip or joint clean-up: null, not 0.
    CHECK(s.at("frames").get<int>() == 400);
    for (const char *key : {"tip_rms_raw_mm", "tip_rms_raw_free_mm", "tip_rms_raw_contact_mm",
                            "joint_rms_raw_deg_all", "scale_m_per_unit", "skip_frames", "smooth_hz",
                            "despike_deg", "smooth_kernel", "spikes_removed"}) {
        INFO(key);
        CHECK(s.at(key).is_null());
    }
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

    // A stick named in another casing than the capture's (stick_l, stick_r) is that object.
    const Run cased = ictusd("track --mode cartesian --quiet --mocap " + csv +
                             " --units mm --up z --duration 0.3 --left-stick STICK_L "
                             "--right-stick Stick_R --out " +
                             dir_none + "_cased");
    INFO(cased.output);
    CHECK(cased.status == 0);

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

TEST_CASE("ictusd gestures --import: sticks named in another casing, and a level far from "
          "the stroke's height said",
          "[cli]")
{
    // Two sticks bouncing off the head (|sin|: a V at each strike), 12 cm, 2 strokes/s
    // each, z up, mm, the objects named Stick_L and Stick_R.
    std::ostringstream out;
    out << "time,Stick_L.x,Stick_L.y,Stick_L.z,Stick_R.x,Stick_R.y,Stick_R.z\n";
    for (int f = 0; f < 800; ++f) {
        const double t = f / 200.0;
        out << t;
        for (int s = 0; s < 2; ++s)
            out << ',' << (s == 0 ? 1150.0 : 850.0) << ",2000,"
                << 700.0 + 120.0 * std::abs(std::sin(2 * M_PI * t + (s == 0 ? 0 : M_PI / 2)));
        out << '\n';
    }
    const std::string csv = simtest::write_temp("bouncing_sticks.csv", out.str());
    const std::string base = "gestures --import " + csv +
                             " --units mm --up z --grip french --nuance legato --hand right "
                             "--left-stick stick_l --right-stick STICK_R --out " +
                             simtest::temp_path("cased_sticks.json");
    const Run mf = ictusd(base);
    INFO(mf.output);
    REQUIRE(mf.status == 0);
    CHECK(mf.output.find("importing stroke") != std::string::npos);
    CHECK(mf.output.find("warning") == std::string::npos); // 12 cm: about the model's mf
    // --dynamics 0 (ppp): the model's softest stroke rises 1.5 cm; played at mf this one
    // rises its height x 0.36 x 0.6^1.3 / 0.015 (docs/gestures.md), and that is said.
    const Run ppp = ictusd(base + " --dynamics 0");
    INFO(ppp.output);
    REQUIRE(ppp.status == 0);
    std::smatch prep, rise;
    REQUIRE(std::regex_search(ppp.output, prep, std::regex("preparation ([0-9.e-]+) m")));
    REQUIRE(std::regex_search(ppp.output, rise,
                              std::regex("warning: --dynamics 0: .* played at mf \\(0.6\\) it "
                                         "will rise ([0-9.e-]+) m")));
    CHECK(std::stod(rise[1]) ==
          Approx(std::stod(prep[1]) * 0.36 * std::pow(0.6, 1.3) / 0.015).epsilon(1e-4));
}

TEST_CASE("ictusd track --gains overrides one joint and refuses bad files", "[cli]")
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

TEST_CASE("ictusd track stops cleanly on SIGINT and writes what it simulated", "[cli]")
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

TEST_CASE("ictusd limits prints the 19 joints and writes JSON", "[cli]")
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
    // A marker or stick .csv capture has no joint rotations to learn from: said so up front
    // (it read as a BVH, "expected 'HIERARCHY', got 'time,...'"), a usage error as in render.
    const std::string csv = simtest::temp_path("sticks.CSV");
    std::ofstream(csv) << "time,stick_l.x,stick_l.y,stick_l.z\n0,0,1,0\n0.01,0,1,0\n";
    const Run sticks = ictusd("limits " + csv);
    INFO(sticks.output);
    CHECK(sticks.status == 2);
    CHECK(sticks.output.find("ictusd limits: " + csv + ": limits are learned from a BVH") !=
          std::string::npos);
    CHECK(sticks.output.find("HIERARCHY") == std::string::npos);
    std::remove(csv.c_str());
}

TEST_CASE("ictusd gestures is a verb of ictusd: help, export of the built-in database, usage "
          "errors",
          "[cli]")
{
    Run r = ictusd("--help");
    CHECK(r.output.find("gestures") != std::string::npos);
    r = ictusd("gestures --help");
    INFO(r.output);
    CHECK(r.status == 0);
    CHECK(r.output.find("usage: ictusd gestures") != std::string::npos);
    // The help names every nuance the database holds (`--list`'s second column; the
    // buzz was left out).
    const std::string help = r.output;
    const Run list = ictusd("gestures --list");
    REQUIRE(list.status == 0);
    std::set<std::string> nuances;
    std::istringstream rows(list.output);
    std::string row;
    std::getline(rows, row); // the header
    while (std::getline(rows, row)) {
        std::istringstream cells(row);
        std::string grip, nuance;
        if (cells >> grip >> nuance)
            nuances.insert(nuance);
    }
    CHECK(nuances.size() == 6);
    for (const std::string &n : nuances) {
        INFO("nuance " << n);
        CHECK(std::regex_search(help, std::regex("Nuances:[^.]*\\b" + n + "\\b")));
    }
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
TEST_CASE("ictusd track --out writes strikes.csv, the same strikes render finds", "[cli]")
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

// `ictusd --help`: exit status 3, the simulation diverged (and was reset). A physics
// step ten times the default (--step 0.01) makes the arms' PD servos overshoot:
// the scene diverges, and render says so on stderr and exits 3, as track does;
// the files are still written, render.json counting the same divergences.
TEST_CASE("ictusd render: a divergence is a warning and exit status 3", "[cli]")
{
    const std::string dir = simtest::temp_path("render-diverged");
    const Run r =
        ictusd("render --step 0.01 --duration 3 --bvh-rate 0 --progress-every 0 --out " + dir);
    INFO(r.output);
    CHECK(r.status == 3);
    std::ifstream in(dir + "/render.json");
    REQUIRE(in.good());
    const long divergences = nlohmann::json::parse(in).at("divergences").get<long>();
    CHECK(divergences > 0);
    CHECK(r.output.find("ictusd render: warning: the simulation diverged " +
                        std::to_string(divergences) + " time(s)") != std::string::npos);
    // At the default step the same score does not diverge: exit 0, no such warning.
    const std::string ok_dir = simtest::temp_path("render-default-step");
    const Run ok = ictusd("render --duration 3 --bvh-rate 0 --progress-every 0 --out " + ok_dir);
    INFO(ok.output);
    CHECK(ok.status == 0);
    CHECK(ok.output.find("simulation diverged") == std::string::npos);
}

// A clip whose sticks never reach the drum (placed 3 m above the floor, 3 m in
// front) plays nothing: a warning says so; exit 0 (not an error in the data).
TEST_CASE("ictusd render --mocap: no strike at all is a warning", "[cli]")
{
    const std::string dir = simtest::temp_path("render-no-strike");
    const Run r = ictusd("render --mocap " + tiny_bvh() +
                         " --drum-pos 0,3,3 --bvh-rate 0 --progress-every 0 --out " + dir);
    INFO(r.output);
    CHECK(r.status == 0);
    CHECK(r.output.find(" 0 strikes") != std::string::npos);
    CHECK(r.output.find("ictusd render: warning: no stick struck the drum") != std::string::npos);
}

// track took every turn of a capture at 30 Hz for a one-frame spike (a fixed
// 5 degrees; a turn lies a h^2 / 2 off its neighbours), and cleaned the
// strokes away: 80_13 at 30 Hz had 179 replacements and its cleaned tips
// 47 mm from the raw ones.
TEST_CASE("ictusd track: a capture at 25-60 Hz keeps its strokes' turns, a glitch is still "
          "removed",
          "[cli]")
{
    for (const double rate : {25.0, 30.0, 60.0}) {
        // The right elbow strokes 40 degrees at 4 Hz: a turn lies at most
        // 40 (2 pi 4)^2 / (2 rate^2) degrees off its neighbours, 5.1 at
        // 25 Hz, 1.8 at 60 Hz (a 120 Hz threshold of 5 degrees means 115
        // and 20); one glitch of 60 degrees about another axis at frame 31.
        const int frames = static_cast<int>(3 * rate);
        for (const bool glitch : {false, true}) {
            const std::string bvh = simtest::write_temp(
                "strokes_" + std::to_string(static_cast<int>(rate)) + (glitch ? "_g" : "") + ".bvh",
                simtest::default_skeleton_bvh(frames, 1.0 / rate, [&](int f, const std::string &j) {
                    if (j != "RightForeArm")
                        return Eigen::Vector3d(0, 0, 0);
                    return Eigen::Vector3d(glitch && f == 31 ? 60.0 : 0.0,
                                           40.0 * std::cos(2 * M_PI * 4.0 * f / rate), 0);
                }));
            const std::string dir = simtest::temp_path("strokes_out");
            const Run r =
                ictusd("track --mode joint --quiet --limits none --duration 0.2 --mocap " + bvh +
                       " --out " + dir);
            INFO(rate << " Hz, glitch " << glitch << "\n" << r.output);
            REQUIRE(r.status == 0);
            std::ifstream js(dir + "/summary.json");
            const nlohmann::json s = nlohmann::json::parse(js);
            // 60 degrees is beyond what a turn can be at 60 Hz only.
            CHECK(s.at("spikes_removed").get<int>() == (glitch && rate == 60.0 ? 1 : 0));
        }
    }
}

// A stick capture of one row, or of sticks held still, was refused without
// the file's name ("stick capture: expected at least two frames of both
// tips", "--drum auto: no strokes in the stick capture").
TEST_CASE("ictusd track: a stick-only capture of one row or of no stroke is refused, naming "
          "the file",
          "[cli][cartesian]")
{
    const std::string header = "time,stick_l.x,stick_l.y,stick_l.z,stick_r.x,stick_r.y,stick_r.z\n";
    const std::string one_row =
        simtest::write_temp("one_row.csv", header + "0,0.15,0.7,0.4,-0.15,0.7,0.4\n");
    Run r = ictusd("track --mode cartesian --quiet --mocap " + one_row);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(one_row +
                        ": expected at least two frames (data rows) of the sticks, got 1") !=
          std::string::npos);

    // Sticks held still, a wobble under 1 mm (seeded): no turnaround 1 cm deep.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> wobble(-0.0005, 0.0005);
    std::ostringstream still;
    still << header;
    for (int f = 0; f < 120; ++f) {
        still << f / 120.0;
        for (const double x : {0.15, -0.15})
            still << ',' << x + wobble(rng) << ',' << 0.7 + wobble(rng) << ',' << 0.4 + wobble(rng);
        still << '\n';
    }
    const std::string csv = simtest::write_temp("still_sticks.csv", still.str());
    r = ictusd("track --mode cartesian --quiet --mocap " + csv);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(csv + ": --drum auto: no strokes in the stick capture") !=
          std::string::npos);
    CHECK(r.output.find("--drum X,Y,Z") != std::string::npos);
    // With the drum given it runs.
    const std::string dir = simtest::temp_path("still_sticks_out");
    r = ictusd("track --mode cartesian --quiet --mocap " + csv + " --drum 0,0.5,0.4 --out " + dir);
    INFO(r.output);
    CHECK(r.status == 0);
}

// A skeleton without a joint the character needs: every verb names the file (the
// joint has no line of its own), and gestures --import says it once, without ':0:'.
TEST_CASE("ictusd: a BVH missing a required joint is named in the error", "[cli]")
{
    std::ifstream in(tiny_bvh());
    std::stringstream text;
    text << in.rdbuf();
    const std::string renamed =
        std::regex_replace(text.str(), std::regex("JOINT RightForeArm\\b"), "JOINT RightLowerArm");
    const std::string bvh = simtest::write_temp("no_forearm.bvh", renamed);
    const std::string expected = bvh + ": no joint named 'RightForeArm'";
    const std::string dir = simtest::temp_path("no-forearm-out");
    for (const std::string &args :
         {"render --mocap " + bvh + " --out " + dir, "track --mode joint --quiet --mocap " + bvh,
          "limits " + bvh,
          "gestures --import " + bvh + " --grip french --nuance legato --hand right --out " + dir +
              ".json"}) {
        const Run r = ictusd(args);
        INFO(args << "\n" << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(expected) != std::string::npos);
        CHECK(r.output.find(":0:") == std::string::npos);
    }
    // A scale error points at the OFFSET's line, the file named once.
    const Run scale =
        ictusd("gestures --import " + tiny_bvh() +
               " --scale 1 --grip french --nuance legato --hand right --out " + dir + ".json");
    INFO(scale.output);
    CHECK(scale.status == 1);
    CHECK(scale.output.find(tiny_bvh() + ":") != std::string::npos);
    CHECK(scale.output.find(tiny_bvh() + ": " + tiny_bvh()) == std::string::npos);
    CHECK(scale.output.find(":0:") == std::string::npos);
}
