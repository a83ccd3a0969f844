// The real ictusd binary on bad input: captures out of physical bounds, zero
// limbs, frame times and units refused at their line (exit 1), --force, and the
// version of the program and each verb.
#include "ictus/cli/args.hpp"
#include "ictus/cli/options.hpp"
#include "ictus/perform/performance.hpp"
#include "support/cli_test_util.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
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
          "[cli][bounds]")
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
          "[cli][bounds]")
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
          "[cli][bounds]")
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
                        ": expected |position| * scale <= 100 m in column 1 (Hips Xposition") !=
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
          "[cli][bounds][cartesian]")
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
TEST_CASE("ictusd limits needs 30 frames to learn from, or --force", "[cli][bounds]")
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

TEST_CASE("ictusd track and limits --help document --force and the bounds", "[cli][bounds]")
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

TEST_CASE("ictusd --version prints the project's version, for the program and each verb", "[cli]")
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
          "[cli]")
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

TEST_CASE("ictusd: a capture, score or MIDI file that cannot be read says why: no such file, or "
          "a folder",
          "[cli]")
{
    // "nope.bvh: expected a readable BVH file, got one that cannot be opened" for a
    // file that is not there, "/tmp: expected a readable stream, got a read error"
    // for a folder given as --mocap: the reason was left for the user to guess.
    const std::string out = simtest::write_temp("unused-why.txt", "") + ".out";
    const std::string folder = std::filesystem::path(out).parent_path().string();
    struct Case {
        std::string args, says;
    };
    for (const Case &c : std::vector<Case>{
             {"render --mocap /nonexistent/clip.bvh --out " + out,
              "/nonexistent/clip.bvh: expected a readable BVH file, got one that cannot be "
              "opened (No such file or directory)"},
             {"render --mocap " + folder + " --out " + out,
              folder + ": expected a readable BVH file, got a folder"},
             {"track --mode cartesian --quiet --mocap /nonexistent/sticks.csv",
              "/nonexistent/sticks.csv: expected a readable CSV file, got one that cannot be "
              "opened (No such file or directory)"},
             {"render --midi /nonexistent/part.mid --out " + out,
              "/nonexistent/part.mid: cannot be read (No such file or directory)"},
             {"render --midi " + folder + " --out " + out, folder + ": a folder, not a MIDI file"},
             {"render --score /nonexistent/a.score --out " + out,
              "--score: cannot read '/nonexistent/a.score' (No such file or directory)"},
         }) {
        const Run r = ictusd(c.args);
        INFO(c.args << "\n" << r.output);
        CHECK(r.status == 1);
        CHECK(r.output.find(c.says) != std::string::npos);
    }
}

TEST_CASE("ictusd: every --help lists each option once, and its examples name files that exist",
          "[cli]")
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

// --drum-preset NAME: the head of externals/core/membrane_presets.c in the physics and
// in render.json (a 26-inch timpani: radius 13 x 0.0254 m, 0.19 mm Mylar at
// 1380 kg/m^3), an explicit --drum-tension winning whatever the order, and an unknown
// name a usage error (exit 2) that lists the presets.
TEST_CASE("ictusd render --drum-preset: the preset's head, recorded in render.json",
          "[cli][bounds]")
{
    const std::string bvh = tiny_bvh();
    int renders = 0;
    auto drum_of = [&](const std::string &extra) {
        const std::string dir = simtest::temp_path("preset_out" + std::to_string(renders++));
        const Run r =
            ictusd("render --mocap " + bvh + " --duration 0.05 --out " + dir + " " + extra);
        INFO(extra << " -> " << r.status << "\n" << r.output);
        REQUIRE(r.status == 0);
        std::ifstream in(dir + "/render.json");
        return nlohmann::json::parse(in)["drum"];
    };
    nlohmann::json d = drum_of("--drum-preset timpani");
    CHECK(d["preset"] == "timpani");
    CHECK(d["radius_m"].get<double>() == Approx(13 * 0.0254).epsilon(1e-9));
    CHECK(d["density_kg_per_m2"].get<double>() == Approx(1380 * 0.19e-3).epsilon(2e-3));
    d = drum_of("--drum-tension 2000 --drum-preset timpani");
    CHECK(d["tension_n_per_m"].get<double>() == 2000.0);
    CHECK(d["radius_m"].get<double>() == Approx(13 * 0.0254).epsilon(1e-9));
    d = drum_of("");
    CHECK(d["preset"].is_null());
    CHECK(d["radius_m"].get<double>() == 0.178);

    const Run r = ictusd("render --mocap " + bvh + " --duration 0.05 --drum-preset bongo --out " +
                         simtest::temp_path("preset_bad"));
    INFO(r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find("--drum-preset: unknown preset 'bongo'") != std::string::npos);
    CHECK(r.output.find("floor-tom") != std::string::npos);
    // a cymbal preset of membrane~ is refused as a drum, naming why and the drums
    const Run c = ictusd("render --mocap " + bvh + " --duration 0.05 --drum-preset crash --out " +
                         simtest::temp_path("preset_plate"));
    INFO(c.output);
    CHECK(c.status == 2);
    CHECK(c.output.find("--drum-preset: 'crash' is a cymbal") != std::string::npos);
    CHECK(
        c.output.find("the drum presets are paper, snare, tom, floor-tom, timpani, frame, kick") !=
        std::string::npos);
    const Run h = ictusd("render --mocap " + bvh + " --duration 0.05 --drum-preset hihat --out " +
                         simtest::temp_path("preset_hihat"));
    INFO(h.output);
    CHECK(h.status == 2);
    CHECK(h.output.find("--drum-preset: 'hihat' is a cymbal") != std::string::npos);
}

// With --kit the first drum's head and sound are the kit's (docs/kit.md): --drum-radius and
// --drum-tension were dropped without a word, and --drum-preset kept or dropped by its place
// before or after --kit (after it, render.json's drum said the preset while its head and the
// kit's stayed the snare's). Refused in either order, a usage error (exit 2) naming both
// options, before --out is made; seeded kits and values, --drum-pos still the kit's anchor.
TEST_CASE("ictusd render --kit with --drum-preset, --drum-radius or --drum-tension is refused",
          "[cli][bounds]")
{
    const char *const kits[] = {"standard", "standard-cymbals", "full", "standard-timpani",
                                "timpani"};
    const char *const presets[] = {"paper", "snare", "tom", "floor-tom", "timpani", "frame"};
    std::mt19937 rng(20261202);
    int n = 0;
    for (const std::string option : {"--drum-preset", "--drum-radius", "--drum-tension"}) {
        for (const bool kit_first : {true, false}) {
            const std::string kit = std::string("--kit ") + kits[rng() % 5];
            std::string value = presets[rng() % 6];
            if (option == "--drum-radius")
                value = std::to_string(0.1 + 0.01 * static_cast<double>(rng() % 20));
            else if (option == "--drum-tension")
                value = std::to_string(1000 + rng() % 4000);
            const std::string drum = option + " " + value;
            const std::string dir = simtest::temp_path("kit_drum" + std::to_string(n++));
            const Run r = ictusd("render --out " + dir + " " +
                                 (kit_first ? kit + " " + drum : drum + " " + kit));
            INFO(kit << " " << drum << " -> " << r.status << "\n" << r.output);
            CHECK(r.status == 2);
            CHECK(r.output.find(option + ": ") != std::string::npos);
            CHECK(r.output.find("--kit") != std::string::npos);
            CHECK_FALSE(std::filesystem::exists(dir));
        }
    }
    const std::string dir = simtest::temp_path("kit_drum_pos");
    const Run ok = ictusd("render --kit standard --drum-pos 0,0.75,0.45 --drum-density 0.3 "
                          "--duration 0.05 --out " +
                          dir);
    INFO(ok.output);
    CHECK(ok.status == 0);
}

// The sound's options set the WAV that --wav FILE writes: without --wav they did nothing,
// without a word (`--wav-bits 24` gave no WAV at all). Each alone and two together are a
// usage error (exit 2) naming the first and --wav, before --out is made.
TEST_CASE("ictusd render: a sound option without --wav is refused, naming it", "[cli][bounds]")
{
    const char *const given[][2] = {{"--wav-mix pickups", "--wav-mix"},
                                    {"--wav-bits 24", "--wav-bits"},
                                    {"--wav-gain -6", "--wav-gain"},
                                    {"--wav-rate 44100", "--wav-rate"},
                                    {"--pd pd", "--pd"},
                                    {"--pd-lib .", "--pd-lib"},
                                    {"--wav-rate 96000 --wav-bits 16", "--wav-rate"}};
    int n = 0;
    for (const auto &g : given) {
        const std::string dir = simtest::temp_path("sound_no_wav" + std::to_string(n++));
        const Run r = ictusd("render --duration 0.05 " + std::string(g[0]) + " --out " + dir);
        INFO(g[0] << " -> " << r.status << "\n" << r.output);
        CHECK(r.status == 2);
        CHECK(r.output.find(std::string(g[1]) + ": ") != std::string::npos);
        CHECK(r.output.find("--wav FILE") != std::string::npos);
        CHECK_FALSE(std::filesystem::exists(dir));
    }
}

// A score's options (render --help's "score mode") did nothing with --mocap, without a word:
// the clip played to the same bytes with --humanize 4 --seed 7 as without. Each, with a
// valid value, is a usage error (exit 2) naming it and --mocap, before --out is made; the
// physics' and the drum's options still go with a clip.
TEST_CASE("ictusd render --mocap: a score's option is refused, naming it", "[cli][bounds]")
{
    const std::string bvh = tiny_bvh();
    const char *const given[][2] = {{"--humanize", "1"},
                                    {"--seed", "7"},
                                    {"--lead-in", "2"},
                                    {"--mode", "cartesian"},
                                    {"--strike-depth", "0.001"},
                                    {"--strike-aim", "0.002"},
                                    {"--move-margins", "0.1,0.1"},
                                    {"--strike-aim-from", "1"},
                                    {"--strike-aim-max", "0.003"},
                                    {"--advance", "0.01"},
                                    {"--ik-gain", "5"},
                                    {"--ik-velocity-gain", "0.02"},
                                    {"--ik-rotation-weight", "0.5"},
                                    {"--ik-max-joint-speed", "30"},
                                    {"--ik-limit-margin", "2"},
                                    {"--rebound", "0.01"},
                                    {"--rehearse", "1"}};
    int n = 0;
    for (const auto &g : given) {
        const std::string dir = simtest::temp_path("mocap_score_opt" + std::to_string(n++));
        const Run r = ictusd("render --mocap " + bvh + " --duration 0.05 " + g[0] + " " + g[1] +
                             " --out " + dir);
        INFO(g[0] << " -> " << r.status << "\n" << r.output);
        CHECK(r.status == 2);
        CHECK(r.output.find(std::string(g[0]) + ": a score's option") != std::string::npos);
        CHECK(r.output.find("--mocap") != std::string::npos);
        CHECK_FALSE(std::filesystem::exists(dir));
    }
    const Run ok = ictusd("render --mocap " + bvh +
                          " --duration 0.05 --iterations 20 --sor-w 1.2 --mode joint "
                          "--grip german --drum-tension 2500 --out " +
                          simtest::temp_path("mocap_score_opt_ok"));
    INFO(ok.output);
    CHECK(ok.status == 0);
}

// --tempo was a clip's alone: with a score it was ignored without a word. Seeded tempi:
// the notes (one beat each from the 1 s lead-in) at --tempo until the score's own
// `tempo`, which wins from beat 0 when the score starts with it.
TEST_CASE("ictusd render --tempo: a score's tempo until the score's own first `tempo`",
          "[cli][bounds]")
{
    std::mt19937 rng(20261203);
    for (int trial = 0; trial < 3; ++trial) {
        const int tempo = std::uniform_int_distribution<int>(50, 200)(rng);
        const int later = std::uniform_int_distribution<int>(50, 200)(rng);
        const int before = std::uniform_int_distribution<int>(1, 3)(rng);
        std::ostringstream score;
        if (trial == 0)
            score << "tempo " << later << "\n";
        for (int k = 0; k < before; ++k)
            score << (k % 2 ? "L" : "R") << "\n";
        score << "tempo " << later << "\nR\nL\n";
        const std::string file =
            simtest::write_temp("tempo" + std::to_string(trial) + ".score", score.str());
        const std::string dir = simtest::temp_path("tempo_out" + std::to_string(trial));
        const Run r = ictusd("render --score " + file + " --tempo " + std::to_string(tempo) +
                             " --bvh-rate 0 --tips-rate 0 --out " + dir);
        INFO("--tempo " << tempo << ", then tempo " << later << " after " << before << " notes\n"
                        << r.output);
        REQUIRE(r.status == 0);
        const double first = trial == 0 ? later : tempo;
        std::vector<double> expect;
        double t = 1.0;
        for (int k = 0; k < before + 2; ++k) {
            expect.push_back(t);
            t += 60.0 / (k < before ? first : later);
        }
        std::ifstream in(dir + "/notes.csv");
        std::string row;
        std::getline(in, row); // the header
        std::vector<double> got;
        while (std::getline(in, row))
            got.push_back(std::stod(row.substr(row.find(',') + 1)));
        REQUIRE(got.size() == expect.size());
        for (size_t k = 0; k < expect.size(); ++k)
            CHECK(got[k] == Approx(expect[k]).margin(1e-6));
    }
}

// A refused score left its --out folder behind, created and empty; a folder that was
// there before stays.
TEST_CASE("ictusd render: a refused score leaves no --out folder of its own", "[cli][bounds]")
{
    const std::string file = simtest::write_temp("refused.score", "R legato\nQ nonsense\n");
    const std::string dir = simtest::temp_path("refused_out");
    std::filesystem::remove_all(dir);
    const Run r = ictusd("render --score " + file + " --out " + dir);
    INFO(r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(":2:1: unknown statement 'Q'") != std::string::npos);
    CHECK(!std::filesystem::exists(dir));
    std::filesystem::create_directories(dir);
    const Run again = ictusd("render --score " + file + " --out " + dir);
    CHECK(again.status == 1);
    CHECK(std::filesystem::is_directory(dir));
}

// The score's words are case-insensitive (docs/score.md) and so was --grip (French), but
// every other option that is one of a few words refused a capital: --kit Standard,
// --mode Joint, --drum-preset Snare, gestures --nuance Legato. Seeded casings of every
// such option's words, on every verb that has it: taken as the lower-case word (the
// value's error would come first; a misspelling still names the option), and the same
// options parsed as the lower-case word's.
TEST_CASE("ictusd: an option that is one of a few words takes them in any case", "[cli]")
{
    std::mt19937 rng(20261202);
    auto any_case = [&](const std::string &w) {
        std::string out = w;
        for (char &c : out)
            if (rng() % 2)
                c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        if (out == w) // at least one capital
            out[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[0])));
        return out;
    };
    struct Words {
        std::string verb, option;
        std::vector<std::string> words;
    };
    const std::vector<Words> table = {
        {"render", "--mode", {"joint", "cartesian"}},
        {"render", "--grip", {"french", "german"}},
        {"render",
         "--kit",
         {"standard", "standard-cymbals", "full", "standard-timpani", "timpani"}},
        {"render",
         "--drum-preset",
         {"paper", "snare", "tom", "floor-tom", "timpani", "frame", "kick"}},
        {"render", "--stick-tip", {"wood", "nylon", "felt"}},
        {"render", "--sticks", {"fulcrum", "rigid"}},
        {"render", "--wav-mix", {"stereo", "pickups"}},
        {"track", "--mode", {"joint", "cartesian"}},
        {"track", "--ik-start", {"simulated", "kinematic"}},
        {"track", "--drum", {"auto"}},
        {"track", "--stepper", {"quick", "direct"}},
        {"track", "--limits", {"none", "euler", "quaternion"}},
        {"track", "--smooth-kernel", {"butterworth", "gaussian"}},
        {"track", "--units", {"mm", "m"}},
        {"track", "--up", {"y", "z"}},
        {"limits", "--smooth-kernel", {"butterworth", "gaussian"}}};
    for (const Words &t : table)
        for (const std::string &w : t.words) {
            const std::string cased = any_case(w);
            Run r = ictusd(t.verb + " " + t.option + " " + cased + " --not-an-option");
            INFO(t.verb << " " << t.option << " " << cased << " -> " << r.output);
            CHECK(r.status == 2);
            CHECK(r.output.find("unknown option '--not-an-option'") != std::string::npos);
            r = ictusd(t.verb + " " + t.option + " " + cased + "x --not-an-option");
            CHECK(r.status == 2);
            CHECK(r.output.find(t.option + ": ") != std::string::npos);
        }
    // gestures --import checks its words before it reads the capture (here: none).
    const std::vector<std::string> nuances = {
        "legato", "tenuto", "accent", "vertical_accent", "staccato", "buzz", "vertical-accent"};
    for (const std::string &n : nuances) {
        const std::string words = " --grip " + any_case(rng() % 2 ? "french" : "german") +
                                  " --nuance " + any_case(n) + " --hand " +
                                  any_case(rng() % 2 ? "left" : "right");
        const Run r =
            ictusd("gestures --import /nonexistent/take.csv --out /nonexistent/g.json" + words);
        INFO(words << " -> " << r.output);
        CHECK(r.status == 1); // the capture, not a word
        CHECK(r.output.find("/nonexistent/take.csv") != std::string::npos);
    }
    // Parsed in the process: the same options as the lower-case word's.
    auto parse = [](const std::string &option, const std::string &word) {
        std::vector<std::string> items = {"render", option, word};
        std::vector<char *> argv;
        for (std::string &s : items)
            argv.push_back(s.data());
        ictus::cli::Args args(static_cast<int>(argv.size()), argv.data());
        ictus::PerformanceOptions o;
        double duration = 0.0;
        const std::string a = args.next();
        REQUIRE(ictus::cli::parse_performance_option(a, args, o, duration));
        return o;
    };
    for (const Words &t : table) {
        if (t.verb != "render" || t.option == "--wav-mix")
            continue;
        for (const std::string &w : t.words) {
            const ictus::PerformanceOptions want = parse(t.option, w);
            const ictus::PerformanceOptions got = parse(t.option, any_case(w));
            INFO(t.option << " " << w);
            CHECK(got.score.mode == want.score.mode);
            CHECK(got.character.grip == want.character.grip);
            CHECK(got.kit.name == want.kit.name);
            CHECK(got.kit.drums.size() == want.kit.drums.size());
            CHECK(got.drum_preset == want.drum_preset);
            CHECK(got.scene.drum.stick_tip == want.scene.drum.stick_tip);
            CHECK(got.scene.drum.radius_m == want.scene.drum.radius_m);
            CHECK(got.scene.sticks == want.scene.sticks);
        }
    }
}

// A score that parses but cannot be planned (a hand's two strokes closer than 40 ms, a drum
// the performance lacks) was refused by render and by run --autoplay at once, exit 1; run
// waiting for play started anyway and refused it only when play was pressed. Seeded such
// scores: run refuses each at start, exit 1, with render's very line (file:line:column).
TEST_CASE("ictusd run refuses at start a score that cannot be planned, as render does", "[cli]")
{
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 6; ++trial) {
        std::string text, extra;
        if (trial % 3 == 2) {
            text = "R\nL on tom" + std::to_string(1 + rng() % 2) + "\n"; // no kit
        } else {
            const int bpm = 200 + static_cast<int>(rng() % 201);
            int d = 8;
            while (60.0 / bpm / d >= 0.04)
                d *= 2;
            const char *hand = rng() % 2 ? "R" : "L";
            text = "tempo " + std::to_string(bpm) + "\nbeats 1/" + std::to_string(d) + "\n" + hand +
                   "\n" + hand + " accent\n";
            if (trial % 3 == 1)
                extra = " --kit standard";
        }
        const std::string score =
            simtest::write_temp("unplannable-" + std::to_string(trial) + ".score", text);
        const std::string out = simtest::write_temp("unplannable-out", "").substr(0) + "-dir";
        std::filesystem::remove_all(out);
        const Run render = ictusd("render --score " + score + extra + " --out " + out);
        INFO(text << " render -> " << render.output);
        REQUIRE(render.status == 1);
        const std::string line = render.output.substr(render.output.find(score));
        const Run run = ictusd("run --score " + score + extra + " --port 0 --duration 1");
        INFO("run -> " << run.output);
        CHECK(run.status == 1);
        CHECK(run.output.find(line) != std::string::npos);
        CHECK(run.output.find("commands on") == std::string::npos); // never listened
    }
}
