// The verbs as processes: `render` twice gives the same bytes and a
// consistent events file; `run` in real time sends every strike it records
// to oscdump and answers oscsend. They need the CMU clip (ICTUS_DATA_DIR).
#include "osc_test_util.hpp"

#include "ictus/perform/performance.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using osctest::Child;

namespace
{

std::string data_dir()
{
    const char *env = std::getenv("ICTUS_DATA_DIR");
    return env && *env ? env : ICTUS_DATA_DIR_DEFAULT;
}

// The clip, or "" after SKIP (FAIL when CI=true: the data must be there).
std::string clip_or_skip()
{
    const std::string path = data_dir() + "/cmu/80_13.bvh";
    if (fs::exists(path))
        return path;
    const char *ci = std::getenv("CI");
    if (ci && std::string(ci) == "true")
        FAIL("CI=true and the CMU clip is missing: " << path);
    WARN("SKIPPED: the CMU clip is missing (" << path << "); set ICTUS_DATA_DIR");
    return "";
}

std::string slurp(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<std::string> lines(const std::string &text)
{
    std::vector<std::string> out;
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l))
        out.push_back(l);
    return out;
}

fs::path scratch(const std::string &name)
{
    const fs::path p =
        fs::temp_directory_path() / ("ictus-osc-" + name + "-" + std::to_string(getpid()));
    fs::remove_all(p);
    return p;
}

} // namespace

TEST_CASE("render: two renders give identical bytes, the events add up to the strike times",
          "[osc][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    const fs::path dir = scratch("render");
    for (const char *sub : {"a", "b"})
        REQUIRE(osctest::run({ICTUSD_OSC_PATH, "render", "--mocap", clip, "--duration", "4",
                              "--out", (dir / sub).string()}) == 0);
    for (const char *f : {"strikes.csv", "events.txt", "render.json"})
        CHECK(slurp((dir / "a" / f).string()) == slurp((dir / "b" / f).string()));

    const std::vector<std::string> csv = lines(slurp((dir / "a/strikes.csv").string()));
    const std::vector<std::string> ev = lines(slurp((dir / "a/events.txt").string()));
    REQUIRE(csv.size() >= 2);
    REQUIRE(ev.size() == csv.size() - 1); // one line per strike, header aside
    // Each events line: delay since the previous, then "hit"; the running sum
    // of delays is the onset time in the CSV (to the microsecond).
    double sum_ms = 0.0;
    for (size_t i = 0; i < ev.size(); ++i) {
        std::istringstream e(ev[i]);
        double delay_ms;
        std::string hit;
        int hand, drum, bounce;
        e >> delay_ms >> hit >> hand >> drum >> bounce;
        CHECK(hit == "hit");
        CHECK(delay_ms >= 0.0);
        sum_ms += delay_ms;
        std::istringstream c(csv[i + 1]);
        std::string field;
        std::vector<std::string> f;
        while (std::getline(c, field, ','))
            f.push_back(field);
        REQUIRE(f.size() == 18);
        CHECK(std::stol(f[0]) == static_cast<long>(i)); // seq in onset order
        CHECK(std::stoi(f[1]) == hand);
        CHECK(std::stoi(f[3]) == bounce);
        CHECK(sum_ms == Approx(std::stod(f[5]) * 1e3).margin(1e-6 * (i + 1) + 1e-9));
        CHECK(ev[i].back() == ';');
        // Physics of each contact of the real scene: it lasts, it pushes the
        // membrane down, its peak is at least its mean force (impulse /
        // duration), it starts on the disk (bead centre within the radius:
        // r/a <= 1 + r_tip/R at the lowest point), the direction is a unit vector.
        const double duration_ms = std::stod(f[14]), impulse = std::stod(f[13]);
        const double peak = std::stod(f[12]);
        CHECK(duration_ms > 0.0);
        CHECK(impulse > 0.0);
        CHECK(peak * 1.001 + 1e-3 >= impulse / (duration_ms * 1e-3));
        CHECK(std::stod(f[8]) <= 1.0 + 0.007 / 0.178 + 1e-4);
        const double fx = std::stod(f[15]), fy = std::stod(f[16]), fz = std::stod(f[17]);
        CHECK(std::sqrt(fx * fx + fy * fy + fz * fz) == Approx(1.0).margin(1e-3));
        CHECK(fy < 0.0);
    }
    // The contact law of the drum in render.json is the membrane's:
    // k = 2 pi T / ln(R / r_tip), r_tip = 7 mm (the default stick).
    const std::string js = slurp((dir / "a/render.json").string());
    auto number_after = [&](const std::string &key) {
        const size_t at = js.find("\"" + key + "\":");
        REQUIRE(at != std::string::npos);
        return std::stod(js.substr(at + key.size() + 3));
    };
    const double tension = number_after("tension_n_per_m"), radius = number_after("radius_m");
    CHECK(number_after("contact_stiffness_n_per_m") ==
          Approx(2.0 * M_PI * tension / std::log(radius / 0.007)).epsilon(1e-9));
    fs::remove_all(dir);
}

TEST_CASE("run: every strike recorded reaches oscdump, with poses at the asked rate, and oscsend "
          "drives it",
          "[osc][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    const fs::path dir = scratch("run");
    const int dump_port = osctest::free_udp_port();
    Child dump({"oscdump", "-L", std::to_string(dump_port)});
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const int port = osctest::free_udp_port();
    const double seconds = 4.0;
    std::atomic<bool> done{false};
    std::thread daemon([&]() {
        osctest::run(
            {ICTUSD_OSC_PATH, "run", "--mocap", clip, "--duration", std::to_string(seconds),
             "--target", "osc.udp://127.0.0.1:" + std::to_string(dump_port), "--port",
             std::to_string(port), "--reply", "osc.udp://127.0.0.1:" + std::to_string(dump_port),
             "--out", dir.string(), "--pose-rate", "30"});
        done = true;
    });
    // Commands while it runs, repeated until each has been answered or the
    // daemon has ended (loading the clip may take a while under a sanitizer
    // or a loaded machine before the port is bound): a handshake, not a
    // fixed number of tries.
    std::atomic<int> pongs{0}, replies{0};
    std::thread commands([&]() {
        while (!done && (pongs == 0 || replies == 0)) {
            std::this_thread::sleep_for(std::chrono::milliseconds(250));
            if (pongs == 0)
                osctest::run({"oscsend", "127.0.0.1", std::to_string(port), "/ictus/ping"});
            if (replies == 0)
                osctest::run(
                    {"oscsend", "127.0.0.1", std::to_string(port), "/ictus/tempo", "f", "130"});
        }
    });

    // Read oscdump while the daemon runs (a full pipe would stall oscdump
    // and make it lose packets), until it has been quiet for a second after.
    std::set<long> seqs;
    int frames = 0;
    std::string line;
    for (;;) {
        if (!dump.line(line, 1000)) {
            if (done)
                break;
            continue;
        }
        std::istringstream in(line);
        std::string tt, path, types;
        in >> tt >> path >> types;
        if (path == "/ictus/strike") {
            long seq;
            in >> seq;
            seqs.insert(seq);
        } else if (path == "/ictus/pose/frame") {
            ++frames;
        } else if (path == "/ictus/pong") {
            ++pongs;
        } else if (path == "/ictus/reply") {
            ++replies;
        }
    }
    daemon.join();
    commands.join();
    const std::vector<std::string> csv = lines(slurp((dir / "strikes.csv").string()));
    REQUIRE(csv.size() >= 2);
    std::set<long> recorded;
    for (size_t i = 1; i < csv.size(); ++i) {
        // In onset order, as track and render write it: seq 0, 1, 2 ...
        CHECK(std::stol(csv[i]) == static_cast<long>(i - 1));
        recorded.insert(std::stol(csv[i]));
    }
    std::printf("run: %zu strikes recorded, %zu received by oscdump, %d pose frames in %.1f s\n",
                recorded.size(), seqs.size(), frames, seconds);
    CHECK(seqs == recorded);
    // 30 Hz over the run: one frame every 33 steps of 1 ms.
    CHECK(std::abs(frames - static_cast<int>(std::ceil(seconds * 1000.0 / 33.0))) <= 1);
    CHECK(pongs >= 1);
    CHECK(replies >= 1); // a tempo accepted
    fs::remove_all(dir);
}

// docs/osc.md: drum parameters sent while a clip plays take effect at once (not at
// the next play): the scene's contact law and the detector's membrane follow.
TEST_CASE("clip mode: drum radius and tension apply at once, to the scene and the detector",
          "[osc][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    ictus::PerformanceOptions o;
    o.mocap = clip;
    ictus::Performance perf(o);
    ictus::StrikeEvent ev[2];
    for (int n = 0; n < 50; ++n)
        perf.step(ev);
    const double t_before = perf.time_s();
    ictus::Command c;
    c.kind = ictus::CommandKind::drum_tension;
    c.value = 6000.0;
    std::string why;
    REQUIRE(perf.apply(c, &why));
    c.kind = ictus::CommandKind::drum_radius;
    c.value = 0.2;
    REQUIRE(perf.apply(c, &why));
    const double r_tip = perf.model().options().stick.tip_radius_m;
    // Static point-load stiffness of a membrane, k = 2 pi T / ln(R / r) (scene.hpp).
    const double k = 2.0 * M_PI * 6000.0 / std::log(0.2 / r_tip);
    CHECK(perf.scene().drum().tension_n_per_m == 6000.0);
    CHECK(perf.scene().drum().radius_m == 0.2);
    CHECK(perf.scene().drum_contact_stiffness_n_per_m() == Approx(k).epsilon(1e-12));
    CHECK(perf.detector().membrane().radius_m == 0.2);
    CHECK(perf.detector().membrane().stiffness_n_per_m == Approx(k).epsilon(1e-12));
    // No rebuild: the clock and the scene go on.
    CHECK(perf.time_s() == Approx(t_before));
    perf.step(ev);
    CHECK(perf.time_s() == Approx(t_before + perf.step_s()));
    c.kind = ictus::CommandKind::drum_radius;
    c.value = 0.001; // smaller than the bead
    CHECK_FALSE(perf.apply(c, &why));
    CHECK(why.find("drum radius") != std::string::npos);
    CHECK(perf.scene().drum().radius_m == 0.2);
}
