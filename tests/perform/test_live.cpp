// Live abuse of a running performance: scores that would hang the planner,
// refusals that must reach the client, a drum slider, gains past the
// controller's stability bound (docs/perform.md, "Live changes"). The daemon
// is the real ictusd; the client is a raw UDP peer; waits are handshakes with
// deadlines.
#include "support/osc_test_util.hpp"
#include "support/sim_test_util.hpp"

#include "ictus/perform/performance.hpp"
#include "ictus/score/score.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>

namespace fs = std::filesystem;
using namespace ictus;
using osctest::Child;
using osctest::Peer;

namespace
{

using Clock = std::chrono::steady_clock;

lo_message strings(std::initializer_list<const char *> args)
{
    lo_message m = lo_message_new();
    for (const char *a : args)
        lo_message_add_string(m, a);
    return m;
}

// Pings until a pong comes back (the server is up), up to `seconds`.
bool ping_until_pong(Peer &client, int port, double seconds)
{
    const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    Peer::Message m;
    while (Clock::now() < deadline) {
        client.send(port, "/ictus/ping", lo_message_new());
        while (client.receive(m, 200))
            if (m.path == "/ictus/pong")
                return true;
    }
    return false;
}

// A daemon in score mode and a client peer that has had its pong.
struct LiveDaemon {
    int port = osctest::free_udp_port();
    int dump_port = osctest::free_udp_port();
    Peer client;
    std::unique_ptr<Child> daemon;
    explicit LiveDaemon(std::vector<std::string> extra = {})
    {
        std::vector<std::string> args = {
            ICTUSD_PATH,      "run",      "--port",
            std::to_string(port), "--target", "osc.udp://127.0.0.1:" + std::to_string(dump_port),
            "--pose-rate",        "0"};
        args.insert(args.end(), extra.begin(), extra.end());
        daemon = std::make_unique<Child>(args);
        // Ping until pong: the server is up.
        REQUIRE(ping_until_pong(client, port, 60.0));
    }
    // The next /ictus/error for `address`, or false at the deadline.
    bool error_for(const std::string &address, std::string &why, double seconds = 20.0)
    {
        const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
        Peer::Message m;
        while (Clock::now() < deadline)
            if (client.receive(m, 100) && m.path == "/ictus/error" && m.strings.size() == 2 &&
                m.strings[0] == address) {
                why = m.strings[1];
                return true;
            }
        return false;
    }
    // The first verdict on `address`: "reply" or "error" (why: the error's
    // reason), "" at the deadline.
    std::string verdict_for(const std::string &address, std::string &why, double seconds = 20.0)
    {
        const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
        Peer::Message m;
        while (Clock::now() < deadline) {
            if (!client.receive(m, 100) || m.strings.empty() || m.strings[0] != address)
                continue;
            if (m.path == "/ictus/reply")
                return "reply";
            if (m.path == "/ictus/error" && m.strings.size() == 2) {
                why = m.strings[1];
                return "error";
            }
        }
        return "";
    }
    bool pong_within(double seconds) { return ping_until_pong(client, port, seconds); }
    // Polls /ictus/status until it says playing, or false at the deadline.
    bool status_playing(double seconds)
    {
        const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
        Peer::Message m;
        while (Clock::now() < deadline) {
            client.send(port, "/ictus/status", lo_message_new());
            while (client.receive(m, 100))
                if (m.path == "/ictus/reply" && !m.strings.empty() &&
                    m.strings[0] == "/ictus/status" && m.ints.size() >= 1 && m.ints[0] == 1)
                    return true;
        }
        return false;
    }
};

// Sends SIGTERM and waits for the exit, up to `seconds`; the exit status, or
// -1 when it was still running (then killed).
int terminate_within(pid_t pid, double seconds)
{
    kill(pid, SIGTERM);
    const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    int status = 0;
    while (Clock::now() < deadline) {
        if (waitpid(pid, &status, WNOHANG) == pid)
            return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    return -1;
}

// Steps until the worker has handed back what it was given (deadline 60 s),
// then one step more: a result is installed at the start of a step.
void settle_work(Performance &perf, StrikeEvent ev[2])
{
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    while (perf.work_pending() && Clock::now() < deadline)
        perf.step(ev);
    REQUIRE_FALSE(perf.work_pending());
    perf.step(ev);
}

} // namespace

TEST_CASE("run: repeats nested around no note are refused to the client, the daemon keeps "
          "playing and answering, and SIGTERM ends it",
          "[perform][live]")
{
    // The score of the report: repeat 1000 four deep around a grip line,
    // sent ten times, then play. Before the statement budget the planner
    // spun for ever on the physics thread: pings answered, nothing else.
    const int port = osctest::free_udp_port();
    Peer client;
    const pid_t pid = fork();
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        const int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, STDOUT_FILENO);
        dup2(devnull, STDERR_FILENO);
        execl(ICTUSD_PATH, ICTUSD_PATH, "run", "--paused", "--port",
              std::to_string(port).c_str(), "--pose-rate", "0", "--target", "osc.udp://127.0.0.1:9",
              static_cast<char *>(nullptr));
        _exit(127);
    }
    REQUIRE(pid > 0);
    REQUIRE(ping_until_pong(client, port, 60.0));
    Peer::Message m;
    for (int i = 0; i < 10; ++i) {
        for (int d = 0; d < 4; ++d)
            client.send(port, "/ictus/score", strings({"repeat 1000"}));
        client.send(port, "/ictus/score", strings({"grip german"}));
        for (int d = 0; d < 4; ++d)
            client.send(port, "/ictus/score", strings({"end"}));
    }
    client.send(port, "/ictus/play", lo_message_new());
    std::string why;
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    bool refused = false;
    while (!refused && Clock::now() < deadline)
        if (client.receive(m, 100) && m.path == "/ictus/error" && m.strings.size() == 2 &&
            m.strings[0] == "/ictus/play") {
            refused = true;
            why = m.strings[1];
        }
    INFO(why);
    REQUIRE(refused);
    CHECK(why.find("more than 1000000 statements") != std::string::npos);
    // Still alive and answering: a plain score plays after a clear.
    client.send(port, "/ictus/score/clear", lo_message_new());
    client.send(port, "/ictus/score", strings({"R legato, L legato"}));
    client.send(port, "/ictus/play", lo_message_new());
    bool playing = false;
    const auto play_deadline = Clock::now() + std::chrono::seconds(30);
    while (!playing && Clock::now() < play_deadline) {
        client.send(port, "/ictus/status", lo_message_new());
        while (client.receive(m, 100))
            if (m.path == "/ictus/reply" && !m.strings.empty() && m.strings[0] == "/ictus/status" &&
                m.ints.size() >= 2)
                playing = playing || m.ints[0] == 1;
    }
    CHECK(playing);
    // SIGTERM is honoured (a clean stop, exit 130) within a few seconds.
    CHECK(terminate_within(pid, 10.0) == 130);
}

TEST_CASE("run: without --autoplay the performer waits for /ictus/play: the clock runs, nothing "
          "plays, no strike, then play starts the score",
          "[perform][live]")
{
    LiveDaemon d;
    // Status until the simulation clock has passed 1.5 s (the built-in
    // score's first beat is at 1 s of its plan): not playing, no strike.
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    Peer::Message m;
    float time_s = 0.0f;
    int playing = -1, strikes = -1;
    while (time_s < 1.5f && Clock::now() < deadline) {
        d.client.send(d.port, "/ictus/status", lo_message_new());
        while (d.client.receive(m, 100))
            if (m.path == "/ictus/reply" && !m.strings.empty() && m.strings[0] == "/ictus/status" &&
                m.floats.size() >= 2 && m.ints.size() >= 2) {
                time_s = m.floats[0];
                playing = m.ints[0];
                strikes = m.ints[1];
                CHECK(playing == 0);
                CHECK(strikes == 0);
                // The tempo the next play starts at: the built-in score's first.
                CHECK(m.floats[1] == Approx(90.0));
            }
    }
    REQUIRE(time_s >= 1.5f);
    d.client.send(d.port, "/ictus/play", lo_message_new());
    CHECK(d.status_playing(20.0));
}

TEST_CASE("run: refusals of the physics thread and of the planner reach the client as "
          "/ictus/error",
          "[perform][live]")
{
    LiveDaemon d;
    std::string why;
    // Score mode: a live tempo that would take the score past 400 bpm
    // (refused by the planner, in the background: a score under way).
    d.client.send(d.port, "/ictus/score/clear", lo_message_new());
    d.client.send(d.port, "/ictus/score",
                  strings({"tempo 100, repeat 8, R, L, end, tempo 300, R"}));
    d.client.send(d.port, "/ictus/play", lo_message_new());
    REQUIRE(d.status_playing(20.0));
    lo_message t = lo_message_new();
    lo_message_add_float(t, 200.0f);
    d.client.send(d.port, "/ictus/tempo", t);
    REQUIRE(d.error_for("/ictus/tempo", why));
    CHECK(why.find("600 bpm") != std::string::npos);
    d.client.send(d.port, "/ictus/stop", lo_message_new());
    // Gains inside the server's ranges but past the stability bound.
    lo_message g = lo_message_new();
    lo_message_add_float(g, 4.0f);
    lo_message_add_float(g, 0.05f);
    d.client.send(d.port, "/ictus/gains", g);
    // The verdict is the error alone: no /ictus/reply comes before it.
    REQUIRE(d.verdict_for("/ictus/gains", why) == "error");
    CHECK(why.find("unstable") != std::string::npos);
    // Gains within the bounds: the reply, echoing them.
    g = lo_message_new();
    lo_message_add_float(g, 1.5f);
    lo_message_add_float(g, 1.0f);
    d.client.send(d.port, "/ictus/gains", g);
    CHECK(d.verdict_for("/ictus/gains", why) == "reply");
    // A score one hand cannot play (refused by the planner, in the
    // background): the play's verdict waits for it, an error and no reply.
    d.client.send(d.port, "/ictus/score/clear", lo_message_new());
    d.client.send(d.port, "/ictus/score", strings({"tempo 400"}));
    d.client.send(d.port, "/ictus/score", strings({"R 1/4, R 1/4, R 1/4"}));
    d.client.send(d.port, "/ictus/play", lo_message_new());
    REQUIRE(d.verdict_for("/ictus/play", why) == "error");
    CHECK(why.find("line") != std::string::npos);
    // A score it can play: the play's reply once its plan is installed.
    d.client.send(d.port, "/ictus/score/clear", lo_message_new());
    d.client.send(d.port, "/ictus/score", strings({"tempo 100, R, L"}));
    d.client.send(d.port, "/ictus/play", lo_message_new());
    CHECK(d.verdict_for("/ictus/play", why) == "reply");
    // A statement the parser refuses names its column.
    d.client.send(d.port, "/ictus/score", strings({"R lgato"}));
    REQUIRE(d.error_for("/ictus/score", why));
    CHECK(why.find("lgato") != std::string::npos);
    CHECK(d.pong_within(10.0));
}

TEST_CASE("run: a drum slider at 20 messages a second loses no strike", "[perform][live]")
{
    // Eight notes, one primary strike each, while /ictus/drum/radius sweeps
    // 0.15 -> 0.30 -> 0.15 m at 20 messages per second: each message is
    // applied to the live scene and replanned on the worker, so every note is struck.
    const fs::path dir = fs::temp_directory_path() / ("ictus_live_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string score = (dir / "eight.score").string();
    std::ofstream(score) << "tempo 100\nR legato, L legato, R accent f, L legato\n"
                            "R legato, L accent f, R tenuto, L legato\n";
    const int dump_port = osctest::free_udp_port();
    Child dump({"oscdump", "-L", std::to_string(dump_port)});
    // oscdump is listening when its port is taken.
    REQUIRE(osctest::wait_until_bound(dump_port));
    const int port = osctest::free_udp_port();
    Peer client;
    Child daemon({ICTUSD_PATH, "run", "--score", score, "--paused", "--port",
                  std::to_string(port), "--target",
                  "osc.udp://127.0.0.1:" + std::to_string(dump_port), "--pose-rate", "0"});
    REQUIRE(ping_until_pong(client, port, 60.0));
    Peer::Message m;
    client.send(port, "/ictus/play", lo_message_new());
    // The slider, until the performance is over (status: playing 0 after 1).
    bool seen_playing = false, over = false;
    int messages = 0;
    const auto start = Clock::now();
    while (!over && Clock::now() - start < std::chrono::seconds(50)) {
        const double t = std::chrono::duration<double>(Clock::now() - start).count();
        const double phase = std::fmod(t / 4.0, 1.0); // a 4 s triangle
        const double radius = 0.15 + 0.15 * (phase < 0.5 ? 2.0 * phase : 2.0 - 2.0 * phase);
        lo_message r = lo_message_new();
        lo_message_add_float(r, static_cast<float>(radius));
        client.send(port, "/ictus/drum/radius", r);
        ++messages;
        client.send(port, "/ictus/status", lo_message_new());
        const auto next = Clock::now() + std::chrono::milliseconds(50);
        while (client.receive(m, 10) || Clock::now() < next)
            if (m.path == "/ictus/reply" && !m.strings.empty() && m.strings[0] == "/ictus/status" &&
                !m.ints.empty()) {
                seen_playing = seen_playing || m.ints[0] == 1;
                over = over || (seen_playing && m.ints[0] == 0);
                m.path.clear();
            }
    }
    CHECK(over);
    // The strikes oscdump received: one primary (non-bounce) strike per note,
    // four of each hand.
    std::string line;
    int primary[2] = {0, 0};
    const auto quiet = Clock::now() + std::chrono::seconds(20);
    while (primary[0] + primary[1] < 8 && Clock::now() < quiet && dump.line(line, 2000)) {
        std::istringstream in(line);
        std::string tt, path, types;
        long seq;
        int hand, drum, bounce;
        in >> tt >> path >> types;
        if (path != "/ictus/strike")
            continue;
        in >> seq >> hand >> drum >> bounce;
        if (!bounce)
            ++primary[hand & 1];
    }
    // A moment for any extra strike, then stop the daemon.
    while (dump.line(line, 500)) {
        std::istringstream in(line);
        std::string tt, path, types;
        long seq;
        int hand, drum, bounce;
        in >> tt >> path >> types;
        if (path == "/ictus/strike" && (in >> seq >> hand >> drum >> bounce) && !bounce)
            ++primary[hand & 1];
    }
    std::printf("drum slider: %d radius messages, primary strikes L %d R %d\n", messages,
                primary[0], primary[1]);
    CHECK(messages >= 60);
    CHECK(primary[0] == 4);
    CHECK(primary[1] == 4);
    fs::remove_all(dir);
}

TEST_CASE("perform: gains are refused past the controller's stability bounds, within them no "
          "runaway, a controller past them runs away and the guard stops the strikes",
          "[perform][live]")
{
    // Two bounds (performance.hpp), computed here from the theory:
    // - ODE's motor rows make eq. 1's damping implicit and its stiffness
    //   explicit (a velocity target (kp/kd) e): the error decays by
    //   (1 - (kp/kd) h) per step, stable for (kp/kd) h < 2, half allowed. The
    //   default gains have kp/kd = w / (2 zeta) = 2 pi 30 / 2 = 94.2 /s.
    // - A joint's damping ratio, zeta = 1 x damping / sqrt(stiffness) after
    //   scaling, must stay >= 1/sqrt(2) (no resonant peak).
    const double h = 0.001, base_rate = 2.0 * M_PI * 30.0 / 2.0;
    auto stable = [&](double sk, double sd) {
        return base_rate * sk / sd * h <= 1.0 &&
               sd / std::sqrt(sk) >= std::sqrt(0.5) * (1.0 - 1e-9);
    };
    std::mt19937 rng(1306);
    std::uniform_real_distribution<double> scale(0.05, 4.0);
    const char *score = "tempo 160\nR vertical_accent ff, L vertical_accent ff, R staccato p, "
                        "L staccato, R+L accent ff\n";
    PerformanceOptions o;
    o.score.score_text = score;
    {
        Performance perf(o);
        int accepted = 0;
        for (int trial = 0; trial < 200; ++trial) {
            Command c;
            c.kind = CommandKind::gains;
            c.value = scale(rng);
            c.value2 = scale(rng);
            std::string why;
            INFO("trial " << trial << ": x" << c.value << " x" << c.value2);
            const bool ok = stable(c.value, c.value2);
            accepted += ok ? 1 : 0;
            CHECK(perf.apply(c, &why) == ok);
            if (!ok)
                CHECK(why.find("raise the damping") != std::string::npos);
        }
        CHECK(accepted > 20);
        CHECK(accepted < 180);
    }
    // Gains on the damping bound, stiffness at random: the performance runs
    // with no runaway and every tip below the guard's speed.
    for (int trial = 0; trial < 4; ++trial) {
        Performance perf(o);
        perf.start_score();
        Command c;
        c.kind = CommandKind::gains;
        c.value = std::uniform_real_distribution<double>(0.1, 4.0)(rng);
        c.value2 = std::sqrt(0.5) * std::sqrt(c.value) * 1.0001;
        REQUIRE(perf.apply(c));
        StrikeEvent ev[2];
        double fastest = 0.0;
        while (perf.plan_active()) {
            perf.step(ev);
            for (int s = 0; s < 2; ++s)
                fastest = std::max(fastest, perf.scene().tip_velocity(static_cast<Side>(s)).norm());
        }
        INFO("stiffness x" << c.value << " damping x" << c.value2);
        CHECK(perf.runaways() == 0);
        CHECK(fastest < Performance::kRunawayTipSpeed_mps);
    }

    // A controller built far past the rate bound (damping ratio 0.01:
    // (kp/kd) h = 9.4) oscillates and grows: the guard notices, puts the
    // gains back, and no strike leaves for kRunawayQuiet_s. The guard is a
    // speed threshold, so it catches blow-ups, not every controller past the
    // bound: the oscillation saturates at the joints' torque limits, and on
    // this score at 0.02-0.03 ((kp/kd) h = 3.1-4.7) it peaks at 36-37 m/s,
    // under the guard's 40 m/s (measured; docs/perform.md, "Runaway guard").
    // The joints' stops are off here: since score mode's stop holds all three
    // axes of a joint at its range's edge (2026-11-25) they catch this
    // oscillation themselves (no runaway at damping ratios 0.001-0.02), and
    // this test is of the guard behind them.
    PerformanceOptions bad = o;
    bad.gains.damping_ratio = 0.01;
    bad.scene.limit_stops = false;
    Performance wild(bad);
    wild.start_score();
    double first_runaway_s = -1.0;
    std::vector<double> sent_times;
    StrikeEvent ev[2];
    while (wild.plan_active()) {
        const int k = wild.step(ev);
        for (int i = 0; i < k; ++i)
            sent_times.push_back(ev[i].time_s);
        if (first_runaway_s < 0.0 && wild.runaways() > 0)
            first_runaway_s = wild.time_s();
    }
    REQUIRE(wild.runaways() >= 1);
    Refusal f;
    REQUIRE(wild.pop_refusal(f));
    // No command caused it: no address (none was sent), the guard and the
    // gains it ran away with named.
    CHECK(std::string(f.address).empty());
    CHECK(f.peer_port == 0);
    INFO(f.why);
    CHECK(std::string(f.why).find("runaway guard: ") == 0);
    CHECK(std::string(f.why).find("damping ratio 0.01") != std::string::npos);
    CHECK(std::string(f.why).find("gains back") == std::string::npos); // they were not scaled
    for (double t : sent_times)
        CHECK_FALSE(
            (t >= first_runaway_s && t < first_runaway_s + Performance::kRunawayQuiet_s - 0.05));
}

TEST_CASE("live: a stop cancels a play still being planned, and a later play starts",
          "[perform][live]")
{
    PerformanceOptions o;
    std::string score = "tempo 200\n";
    for (int i = 0; i < 500; ++i)
        score += "R 1/4, L 1/4\n";
    o.score.score_text = score;
    Performance perf(o);
    perf.set_background_work(true);
    StrikeEvent ev[2];
    auto settle = [&] { settle_work(perf, ev); };
    Command play, stop;
    play.kind = CommandKind::play;
    stop.kind = CommandKind::stop;
    // The stop right after the play (the plan is being computed): nothing starts.
    REQUIRE(perf.apply(play));
    REQUIRE(perf.apply(stop));
    settle();
    CHECK_FALSE(perf.playing());
    CHECK_FALSE(perf.plan_active());
    // Ten plays and stops in a row, ending in stop: still stopped.
    for (int i = 0; i < 10; ++i) {
        REQUIRE(perf.apply(play));
        perf.step(ev);
        REQUIRE(perf.apply(stop));
    }
    settle();
    CHECK_FALSE(perf.playing());
    // A play with no stop after it plays.
    REQUIRE(perf.apply(play));
    settle();
    CHECK(perf.playing());
    CHECK(perf.plan_active());
}

TEST_CASE("live: in clip mode a stop cancels the play of a rebuild still being planned",
          "[perform][live]")
{
    // A clip: the default skeleton, arms swinging at 2 Hz, 4 s.
    const std::string bvh = simtest::write_temp(
        "live_clip.bvh",
        simtest::default_skeleton_bvh(480, 1.0 / 120.0, [](int f, const std::string &joint) {
            const double a = 25.0 * std::sin(2.0 * M_PI * 2.0 * f / 120.0);
            return joint.find("Arm") != std::string::npos ? Eigen::Vector3d(a, 0.5 * a, 0.0)
                                                          : Eigen::Vector3d::Zero();
        }));
    PerformanceOptions o;
    o.mocap = bvh;
    Performance perf(o);
    perf.set_background_work(true);
    StrikeEvent ev[2];
    auto settle = [&] { settle_work(perf, ev); };
    Command play, stop, grip;
    play.kind = CommandKind::play;
    stop.kind = CommandKind::stop;
    grip.kind = CommandKind::grip;
    std::snprintf(grip.text, sizeof grip.text, "german");
    REQUIRE(perf.apply(stop));
    perf.step(ev);
    CHECK_FALSE(perf.playing());
    // A grip change waits for the next play, which rebuilds the character in
    // the background; the stop right after it: the rebuilt clip waits.
    REQUIRE(perf.apply(grip));
    REQUIRE(perf.apply(play));
    CHECK(perf.deferred()); // its verdict comes with the rebuild
    REQUIRE(perf.apply(stop));
    settle();
    CHECK_FALSE(perf.playing());
    Command confirmed;
    CHECK(perf.pop_confirmation(confirmed) == false); // no peer: nobody to confirm to
    // A play with no stop after it plays (nothing left to rebuild: at once).
    REQUIRE(perf.apply(play));
    CHECK_FALSE(perf.deferred());
    perf.step(ev);
    CHECK(perf.playing());
}

TEST_CASE("live: in clip mode /ictus/mode cartesian is refused as a clip's limit, naming the "
          "score mode that has it",
          "[perform][live]")
{
    // docs/osc.md: "a clip plays in joint space only (`cartesian` is refused
    // there)". The refusal said "only joint is implemented", as if Cartesian
    // tracking did not exist; it is score mode's default.
    const std::string bvh = simtest::write_temp(
        "live_clip_mode.bvh",
        simtest::default_skeleton_bvh(
            120, 1.0 / 120.0, [](int, const std::string &) { return Eigen::Vector3d::Zero(); }));
    PerformanceOptions o;
    o.mocap = bvh;
    Performance perf(o);
    Command mode;
    mode.kind = CommandKind::mode;
    std::snprintf(mode.text, sizeof mode.text, "cartesian");
    std::string why;
    CHECK_FALSE(perf.apply(mode, &why));
    CHECK(why == "mode: a clip plays in joint space only (eq. 1); cartesian tracks a score's "
                 "stick tips: start ictusd without --mocap");
    std::snprintf(mode.text, sizeof mode.text, "joint");
    why.clear();
    CHECK(perf.apply(mode, &why));
    CHECK(why.empty());
}

TEST_CASE("live: score statements over OSC wait at most kMaxPendingStatements, the rest refused",
          "[perform][live]")
{
    PerformanceOptions o;
    Performance perf(o);
    Command c;
    c.kind = CommandKind::score;
    std::snprintf(c.text, sizeof c.text, "R, L"); // two statements a line
    std::string why;
    for (int i = 0; i < Performance::kMaxPendingStatements / 2; ++i)
        REQUIRE(perf.apply(c, &why));
    CHECK_FALSE(perf.apply(c, &why));
    CHECK(why.find("10000 statements are waiting") != std::string::npos);
    CHECK(perf.refused_statements() == 1);
    Command clear;
    clear.kind = CommandKind::score_clear;
    REQUIRE(perf.apply(clear));
    CHECK(perf.apply(c, &why));
    // a faulty statement is refused with its error and counted too
    Command bad = c;
    std::snprintf(bad.text, sizeof bad.text, "R legatto");
    why.clear();
    CHECK_FALSE(perf.apply(bad, &why));
    CHECK(why.find("legatto") != std::string::npos);
    CHECK(perf.refused_statements() == 2);
}

TEST_CASE("live: a stop just after a stroke sends its stick to rest without striking again",
          "[perform][live]")
{
    // /ictus/stop: "the sticks return to rest" (docs/osc.md). A stick stopped
    // within 60 ms of its stroke, rebounding from the head, was turned at once
    // to the rest direction: the turn threw it back on the head, a new stroke
    // at 0.9-2.6 m/s 11-23 ms after the stop (a bounce at 2.1-2.5 m/s right
    // after the strike). Now nothing strikes after the stop but the rebounding
    // stick's own bounce, slower than a third of the mf stroke it follows.
    for (int hand = 0; hand < 2; ++hand)
        for (int delay_ms = 0; delay_ms <= 50; delay_ms += 10) {
            PerformanceOptions o;
            o.score.score_text = "tempo 100\nbeats 1/2\nrepeat 16\nR, L\nend\n";
            Performance perf(o);
            StrikeEvent ev[kStepStrikes];
            Command play, stop;
            play.kind = CommandKind::play;
            stop.kind = CommandKind::stop;
            REQUIRE(perf.apply(play));
            int strokes = 0;
            double last_s = 0.0, last_mps = 0.0;
            while (strokes < 4 && perf.time_s() < 10.0) {
                const int n = perf.step(ev);
                for (int i = 0; i < n; ++i)
                    if (ev[i].hand == hand && !ev[i].bounce) {
                        ++strokes;
                        last_s = ev[i].time_s;
                        last_mps = ev[i].normal_velocity_mps;
                    }
            }
            REQUIRE(strokes == 4);
            REQUIRE(last_mps > 2.5); // an mf stroke (docs/score.md: ~3 m/s)
            while (perf.time_s() < last_s + 1e-3 * delay_ms)
                perf.step(ev);
            REQUIRE(perf.apply(stop));
            const double stop_s = perf.time_s();
            while (perf.time_s() < stop_s + 1.5) {
                const int n = perf.step(ev);
                for (int i = 0; i < n; ++i) {
                    INFO("hand " << hand << ", stopped " << delay_ms
                                 << " ms after its stroke: " << (ev[i].bounce ? "bounce" : "stroke")
                                 << " of hand " << ev[i].hand << " " << ev[i].time_s - stop_s
                                 << " s after the stop at " << ev[i].normal_velocity_mps << " m/s");
                    CHECK(ev[i].bounce);
                    CHECK(ev[i].normal_velocity_mps < last_mps / 3.0);
                }
            }
            CHECK_FALSE(perf.playing());
        }
}
