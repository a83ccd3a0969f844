// The verbs as processes: `render` twice gives the same bytes and a
// consistent events file; `run` in real time sends every strike it records
// to oscdump and answers oscsend (these need the CMU clip, ICTUS_DATA_DIR).
// Their options and files under stress (the built-in score, no data needed):
// --allow, --target and --port checked up front, error replies within their
// budget, strikes.csv whole line by line on a full disk and after SIGKILL,
// render's --out folder and write errors.
#include "support/osc_test_util.hpp"

#include "ictus/perform/performance.hpp"

#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
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

// ictusd as a process of its own, its stdout and stderr kept apart (pipes,
// which a file-size limit on it does not reach). file_size_limit > 0: the
// child's RLIMIT_FSIZE in bytes, SIGXFSZ ignored, so that a write past it
// fails (EFBIG) as one on a full disk does (ENOSPC), short write first.
class Daemon
{
  public:
    explicit Daemon(const std::vector<std::string> &args, long file_size_limit = 0)
    {
        int out[2], err[2];
        REQUIRE(pipe(out) == 0);
        REQUIRE(pipe(err) == 0);
        pid_ = fork();
        REQUIRE(pid_ >= 0);
        if (pid_ == 0) {
            prctl(PR_SET_PDEATHSIG, SIGKILL);
            dup2(out[1], STDOUT_FILENO);
            dup2(err[1], STDERR_FILENO);
            for (int fd : {out[0], out[1], err[0], err[1]})
                close(fd);
            if (file_size_limit > 0) {
                const rlimit limit{static_cast<rlim_t>(file_size_limit),
                                   static_cast<rlim_t>(file_size_limit)};
                setrlimit(RLIMIT_FSIZE, &limit);
                signal(SIGXFSZ, SIG_IGN); // kept across exec
            }
            std::vector<std::string> all = {ICTUSD_PATH};
            all.insert(all.end(), args.begin(), args.end());
            std::vector<char *> argv;
            for (std::string &a : all)
                argv.push_back(a.data());
            argv.push_back(nullptr);
            execv(argv[0], argv.data());
            _exit(127);
        }
        close(out[1]);
        close(err[1]);
        out_fd_ = out[0];
        err_fd_ = err[0];
    }
    ~Daemon()
    {
        if (pid_ > 0) {
            kill(pid_, SIGKILL);
            waitpid(pid_, nullptr, 0);
        }
        for (int fd : {out_fd_, err_fd_})
            if (fd >= 0)
                close(fd);
    }
    Daemon(const Daemon &) = delete;
    Daemon &operator=(const Daemon &) = delete;
    pid_t pid() const { return pid_; }
    // Reads stdout and stderr to their end, reaps: the exit status, or minus
    // the signal that ended it.
    int wait()
    {
        for (;;) {
            pollfd p[2] = {{out_fd_, POLLIN, 0}, {err_fd_, POLLIN, 0}};
            int open = 0;
            for (pollfd &q : p)
                open += q.fd >= 0;
            if (open == 0)
                break;
            if (poll(p, 2, -1) < 0 && errno != EINTR)
                break;
            for (int i = 0; i < 2; ++i) {
                if (p[i].fd < 0 || !(p[i].revents & (POLLIN | POLLHUP | POLLERR)))
                    continue;
                char buf[4096];
                const ssize_t n = read(p[i].fd, buf, sizeof buf);
                int &fd = i == 0 ? out_fd_ : err_fd_;
                if (n <= 0) {
                    close(fd);
                    fd = -1;
                } else {
                    (i == 0 ? out : err).append(buf, static_cast<size_t>(n));
                }
            }
        }
        int status = 0;
        waitpid(pid_, &status, 0);
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
    }
    std::string out, err;

  private:
    pid_t pid_ = -1;
    int out_fd_ = -1, err_fd_ = -1;
};

// A short score (four notes, about 3 s with its lead-in), so that render is quick.
fs::path four_notes(const fs::path &dir)
{
    fs::create_directories(dir);
    const fs::path path = dir / "four.score";
    std::ofstream(path) << "tempo 144\ngrip german\nR accent f, L legato, R tenuto p, L staccato\n";
    return path;
}

// strikes.csv: every line ends with its newline and has the header's columns.
void check_whole_lines(const std::string &text, size_t &rows)
{
    REQUIRE(!text.empty());
    CHECK(text.back() == '\n');
    const std::vector<std::string> all = lines(text);
    REQUIRE(!all.empty());
    const auto columns = std::count(all[0].begin(), all[0].end(), ',');
    CHECK(columns == 20); // ... stick_tip, zone (docs/osc.md)
    for (size_t i = 1; i < all.size(); ++i) {
        INFO("row " << i << ": " << all[i]);
        CHECK(std::count(all[i].begin(), all[i].end(), ',') == columns);
        CHECK(std::stol(all[i]) == static_cast<long>(i - 1)); // seq, in onset order
    }
    rows = all.size() - 1;
}

} // namespace

TEST_CASE("render: two renders give identical bytes, the events add up to the strike times",
          "[cli][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    const fs::path dir = scratch("render");
    for (const char *sub : {"a", "b"})
        REQUIRE(osctest::run({ICTUSD_PATH, "render", "--mocap", clip, "--duration", "4", "--out",
                              (dir / sub).string()}) == 0);
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
        REQUIRE(f.size() == 21);
        CHECK(std::stol(f[0]) == static_cast<long>(i)); // seq in onset order
        CHECK(f[19] == "0");                            // stick_tip: none without --stick-tip
        CHECK((f[20] == "0" || f[20] == "1"));          // zone: head or rim
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
          "[cli][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    const fs::path dir = scratch("run");
    const int dump_port = osctest::free_udp_port();
    Child dump({"oscdump", "-L", std::to_string(dump_port)});
    REQUIRE(osctest::wait_until_bound(dump_port)); // before the daemon's first strike
    const int port = osctest::free_udp_port();
    const double seconds = 4.0;
    std::atomic<bool> done{false};
    std::thread daemon([&]() {
        osctest::run({ICTUSD_PATH, "run", "--mocap", clip, "--autoplay", "--duration",
                      std::to_string(seconds), "--target",
                      "osc.udp://127.0.0.1:" + std::to_string(dump_port), "--port",
                      std::to_string(port), "--reply",
                      "osc.udp://127.0.0.1:" + std::to_string(dump_port), "--out", dir.string(),
                      "--pose-rate", "30"});
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
          "[cli][verbs]")
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

// CI, stop 21: `ictusd run` of the CMU clip with /ictus/tempo 130 sent early
// tripped the runaway guard (a tip at 45 m/s, the strikes held back). The drum
// placed for the clip's strokes lies across the arms' path from rest; the
// rising stick met the shell's bottom, was turned 50 degrees round its
// fulcrum and the scene diverged again and again. Now a stick passes through
// the shell (docs/character.md, "Drum"). Seeded tempi and command times over
// the whole clip: no runaway, no divergence, the mimed strokes still strike.
TEST_CASE("clip mode: a tempo change at any time leaves the physics sound (no runaway, no "
          "divergence)",
          "[cli][verbs]")
{
    const std::string clip = clip_or_skip();
    if (clip.empty())
        return;
    std::mt19937 rng(2112);
    std::uniform_real_distribution<double> tempo(90.0, 160.0);
    std::uniform_int_distribution<int> at(0, 1500);
    for (int trial = 0; trial < 3; ++trial) {
        ictus::PerformanceOptions o;
        o.mocap = clip;
        ictus::Performance perf(o);
        const double bpm = tempo(rng);
        const int step = at(rng);
        INFO("tempo " << bpm << " bpm from step " << step);
        ictus::StrikeEvent ev[2];
        long strikes = 0, n = 0;
        for (; n == 0 || perf.time_s() < perf.clip_duration_s() + 0.25; ++n) {
            if (n == step) {
                ictus::Command c;
                c.kind = ictus::CommandKind::tempo;
                c.value = bpm;
                REQUIRE(perf.apply(c));
            }
            strikes += perf.step(ev);
        }
        CHECK(perf.runaways() == 0);
        CHECK(perf.divergences() == 0);
        CHECK(perf.scene().shell_passes() >= 1); // the arms rise through the shell
        CHECK(strikes >= 10);
    }
}

// --allow "" gave an empty list, which the server took for "every peer"; and
// --bind 0.0.0.0 --allow any opened the performance to the network without a
// word. Now an empty list or item is a usage error, 'any' is said in full,
// and 'any' beyond the loopback warns.
TEST_CASE("run: --allow refuses an empty list (exit 2), 'any' beyond the loopback warns",
          "[cli][verbs]")
{
    osctest::Peer sink;
    const std::string target = "osc.udp://127.0.0.1:" + std::to_string(sink.port());
    for (const char *allow : {"", ",", "127.0.0.1,", ",127.0.0.1", "127.0.0.1,,127.0.0.2"}) {
        Daemon d({"run", "--allow", allow, "--duration", "0.5", "--port", "0", "--pose-rate", "0",
                  "--target", target});
        INFO("--allow '" << allow << "': " << d.err);
        CHECK(d.wait() == 2);
        CHECK(d.err.find("--allow") != std::string::npos);
        CHECK(d.err.find("empty") != std::string::npos);
    }
    Daemon wide({"run", "--allow", "any", "--bind", "0.0.0.0", "--duration", "0.1", "--port", "0",
                 "--pose-rate", "0", "--target", target});
    CHECK(wide.wait() == 0);
    INFO(wide.err);
    CHECK(wide.err.find("warning: --allow any with --bind 0.0.0.0") != std::string::npos);
    Daemon local({"run", "--allow", "any", "--duration", "0.1", "--port", "0", "--pose-rate", "0",
                  "--target", target});
    CHECK(local.wait() == 0);
    CHECK(local.err.find("warning") == std::string::npos);
}

// --target osc.udp://127.0.0.1:99999 sent to port 34463, osc.tcp:// and
// [::1] were taken and every send failed, exit 0. Now the URL is checked
// before the clip or score loads: a usage error naming the option.
TEST_CASE("run: --target and --port are checked up front (exit 2, naming the option)",
          "[cli][verbs]")
{
    const std::pair<std::vector<std::string>, std::string> bad[] = {
        {{"--target", "osc.udp://127.0.0.1:99999"}, "--target 'osc.udp://127.0.0.1:99999': port"},
        {{"--target", "osc.udp://127.0.0.1:9000x"}, "--target 'osc.udp://127.0.0.1:9000x': port"},
        {{"--target", "osc.tcp://127.0.0.1:9000"}, "protocol 'tcp' is not supported"},
        {{"--target", "osc.udp://[::1]:9000"}, "IPv6 is not supported"},
        {{"--target", "osc.udp://no-such-host.invalid:9000"}, "does not resolve"},
        {{"--target", "127.0.0.1:9000"}, "--target '127.0.0.1:9000': not an OSC URL"},
        {{"--port", "99999"}, "--port: expected an integer in [0, 65535]"},
        {{"--port", "9001.5"}, "--port: expected an integer"},
    };
    for (const auto &[option, message] : bad) {
        std::vector<std::string> args = {"run", "--duration", "0.5", "--pose-rate", "0"};
        args.insert(args.end(), option.begin(), option.end());
        Daemon d(args);
        const int status = d.wait();
        INFO(option[0] << " " << option[1] << " -> " << status << ": " << d.err);
        CHECK(status == 2);
        CHECK(d.err.find(message) != std::string::npos);
    }
}

// With --allow any, each 1-byte packet earned a 64-byte error reply. Now one
// address gets at most kErrorReplyBurst (20) + kErrorRepliesPerSecond (10)
// per second; the rest are counted, and the summary says how many.
TEST_CASE("run: error replies to a flooding peer stay within its budget, the rest are counted "
          "in the summary",
          "[cli][verbs]")
{
    osctest::Peer sink, flooder("127.0.0.1"), other("127.0.0.2");
    const int port = osctest::free_udp_port();
    Daemon d({"run", "--duration", "5", "--port", std::to_string(port), "--allow", "any",
              "--pose-rate", "0", "--target",
              "osc.udp://127.0.0.1:" + std::to_string(sink.port())});
    // Ready when it answers a ping (a handshake with a deadline).
    osctest::Peer::Message m;
    bool pong = false;
    for (int i = 0; i < 600 && !pong; ++i) {
        flooder.send(port, "/ictus/ping", lo_message_new());
        pong = flooder.receive(m, 100) && m.path == "/ictus/pong";
    }
    REQUIRE(pong);
    const auto t0 = std::chrono::steady_clock::now();
    const unsigned char junk = 'x';
    for (int i = 0; i < 1000; ++i)
        flooder.send_raw(port, &junk, 1);
    // Another address: its own budget, answered although the flooder's is spent.
    bool answered = false;
    for (int i = 0; i < 20 && !answered; ++i) {
        other.send_raw(port, &junk, 1);
        answered = other.receive(m, 100) && m.path == "/ictus/error";
    }
    CHECK(answered);
    REQUIRE(d.wait() == 0);
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    long flooder_errors = 0, other_errors = answered ? 1 : 0;
    while (flooder.receive(m, 0))
        flooder_errors += m.path == "/ictus/error";
    while (other.receive(m, 0))
        other_errors += m.path == "/ictus/error";
    INFO(d.out << d.err);
    CHECK(flooder_errors <= 20 + 10.0 * elapsed_s + 1.0);
    std::smatch found;
    REQUIRE(std::regex_search(d.out, found,
                              std::regex("(\\d+) packets in, (\\d+) accepted, (\\d+) errors "
                                         "\\((\\d+) unanswered")));
    const long packets = std::stol(found[1]), accepted = std::stol(found[2]),
               errors = std::stol(found[3]), unanswered = std::stol(found[4]);
    std::printf("run flood: %ld packets, %ld errors, %ld answered to the flooder in %.2f s, %ld "
                "unanswered\n",
                packets, errors, flooder_errors, elapsed_s, unanswered);
    CHECK(errors == packets - accepted); // every junk packet counted
    CHECK(unanswered > 0);
    CHECK(flooder_errors + other_errors + unanswered == errors);
}

// run's strikes.csv went through a buffered stream whose errors were seen at
// the end, if at all: on a full disk a cut line, and the run played on. Now a
// write error stops the run at once, exit 1, naming the file and the reason;
// the file keeps whole lines only.
TEST_CASE("run: a full disk under strikes.csv stops the run, exit 1, naming the file and the "
          "error, the rows written are whole",
          "[cli][verbs]")
{
    const fs::path dir = scratch("run-full");
    osctest::Peer sink;
    const std::string target = "osc.udp://127.0.0.1:" + std::to_string(sink.port());
    // /dev/full: ENOSPC at the first write (the header).
    fs::create_directories(dir / "devfull");
    fs::create_symlink("/dev/full", dir / "devfull" / "strikes.csv");
    {
        Daemon d({"run", "--autoplay", "--duration", "2", "--port", "0", "--pose-rate", "0",
                  "--target", target, "--out", (dir / "devfull").string()});
        CHECK(d.wait() == 1);
        INFO(d.err);
        CHECK(d.err.find("/devfull/strikes.csv': " + std::string(std::strerror(ENOSPC))) !=
              std::string::npos);
    }
    // A file-size limit of 500 bytes: the header and a few rows fit, then a
    // short write; the run stops there, long before its 60 s.
    {
        const long limit = 500;
        Daemon d({"run", "--autoplay", "--duration", "60", "--port", "0", "--pose-rate", "0",
                  "--target", target, "--out", (dir / "limit").string()},
                 limit);
        CHECK(d.wait() == 1);
        INFO(d.out << d.err);
        CHECK(d.err.find("/limit/strikes.csv': " + std::string(std::strerror(EFBIG))) !=
              std::string::npos);
        std::smatch simulated;
        REQUIRE(std::regex_search(d.out, simulated, std::regex("run: ([0-9.e+-]+) s simulated")));
        CHECK(std::stod(simulated[1]) < 30.0);
        const std::string csv = slurp((dir / "limit" / "strikes.csv").string());
        CHECK(csv.size() <= static_cast<size_t>(limit));
        size_t rows = 0;
        check_whole_lines(csv, rows);
        CHECK(rows >= 1);
    }
    fs::remove_all(dir);
}

// After a SIGKILL the last row of strikes.csv was cut (a buffered stream).
// Now each row is one write(2) of the whole line, made as it is released.
TEST_CASE("run: killed with SIGKILL mid-run, strikes.csv holds whole lines only", "[cli][verbs]")
{
    const fs::path dir = scratch("run-kill");
    osctest::Peer sink;
    Daemon d({"run", "--autoplay", "--duration", "600", "--port", "0", "--pose-rate", "0",
              "--target", "osc.udp://127.0.0.1:" + std::to_string(sink.port()), "--out",
              dir.string()});
    // Killed once the file holds the header and three rows (a deadline, not a sleep).
    const fs::path csv = dir / "strikes.csv";
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    size_t newlines = 0;
    while (newlines < 4 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        const std::string text = fs::exists(csv) ? slurp(csv.string()) : "";
        newlines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
    }
    kill(d.pid(), SIGKILL);
    CHECK(d.wait() == -SIGKILL);
    REQUIRE(newlines >= 4);
    size_t rows = 0;
    check_whole_lines(slurp(csv.string()), rows);
    CHECK(rows >= 3);
    fs::remove_all(dir);
}

// render --out DIR into a used folder kept an earlier render's files beside
// the new ones (a score's notes.csv beside a clip's strikes). Now a used
// folder is refused (exit 1, as other file errors), and --force removes
// render's own files there, never another.
TEST_CASE("render: --out refuses a used folder, --force replaces render's own files only",
          "[cli][verbs]")
{
    const fs::path dir = scratch("render-out");
    const std::string score = four_notes(dir).string();
    const fs::path out = dir / "out";
    REQUIRE(osctest::run({ICTUSD_PATH, "render", "--score", score, "--bvh-rate", "10", "--out",
                          out.string()}) == 0);
    for (const char *f :
         {"strikes.csv", "events.txt", "render.json", "tips.csv", "notes.csv", "performance.bvh"})
        REQUIRE(fs::exists(out / f));
    std::ofstream(out / "mine.txt") << "kept\n";
    std::ofstream(out / "performance.wav") << "an earlier render's sound (--wav)\n";
    std::ofstream(dir / "elsewhere.csv") << "the target of a link, kept\n";
    fs::remove(out / "notes.csv");
    fs::create_symlink(dir / "elsewhere.csv", out / "notes.csv");
    const std::string strikes_before = slurp((out / "strikes.csv").string());

    Daemon refused({"render", "--score", score, "--bvh-rate", "0", "--tips-rate", "50", "--out",
                    out.string()});
    CHECK(refused.wait() == 1);
    INFO(refused.err);
    CHECK(refused.err.find("'" + out.string() + "' is not empty") != std::string::npos);
    CHECK(refused.err.find("--force") != std::string::npos);
    CHECK(slurp((out / "strikes.csv").string()) == strikes_before); // nothing touched
    CHECK(fs::exists(out / "performance.bvh"));

    Daemon forced({"render", "--score", score, "--bvh-rate", "0", "--tips-rate", "50", "--out",
                   out.string(), "--force"});
    CHECK(forced.wait() == 0);
    CHECK_FALSE(fs::exists(out / "performance.bvh")); // the earlier render's, not this one's
    CHECK_FALSE(fs::exists(out / "performance.wav")); // this one has no --wav
    CHECK(forced.err.find("not struck") == std::string::npos); // all four notes played
    CHECK(slurp((out / "mine.txt").string()) == "kept\n");
    CHECK(slurp((dir / "elsewhere.csv").string()) == "the target of a link, kept\n");
    CHECK_FALSE(fs::is_symlink(out / "notes.csv"));
    CHECK(lines(slurp((out / "notes.csv").string())).size() == 5); // header and four notes
    size_t rows = 0;
    check_whole_lines(slurp((out / "strikes.csv").string()), rows);

    // An empty folder is as good as a new one.
    fs::create_directories(dir / "empty");
    CHECK(osctest::run({ICTUSD_PATH, "render", "--score", score, "--bvh-rate", "0", "--out",
                        (dir / "empty").string()}) == 0);
    fs::remove_all(dir);
}

// A drum out of the sticks' reach played nothing, and render said only "0
// strikes" on stdout (the count of missed notes was in render.json alone).
TEST_CASE("render: missed and off-time notes, strikes of no note and a score without notes are "
          "said on stderr, exit 0",
          "[cli][verbs]")
{
    const fs::path dir = scratch("render-missed");
    const std::string score = four_notes(dir).string();
    // 5 m behind the performer: no stick reaches it.
    Daemon far({"render", "--score", score, "--bvh-rate", "0", "--tips-rate", "0", "--drum-pos",
                "0,-5,0", "--out", (dir / "far").string()});
    CHECK(far.wait() == 0);
    INFO(far.err);
    CHECK(far.err.find("4 of 4 notes of the score were not struck") != std::string::npos);
    // Each missed note where it was written (all four on line 3), with its hand and time.
    CHECK(far.err.find("not struck: line 3 (the right hand at ") != std::string::npos);
    CHECK(far.err.find(", line 3 (the left hand at ") != std::string::npos);
    // A grace stroke is said as one: its line is its note's, where a flam or a drag
    // writes one to three strokes. 120 bpm, the note on beat 0 (1 s): the drag's graces
    // at 0.93 and 0.97 s, the flam's (line 2, 1.5 s) at 1.47 s (docs/score.md).
    std::ofstream(dir / "graces.score") << "L drag\nR flam\n";
    Daemon graces({"render", "--score", (dir / "graces.score").string(), "--bvh-rate", "0",
                   "--tips-rate", "0", "--drum-pos", "0,-5,0", "--out", (dir / "graces").string()});
    CHECK(graces.wait() == 0);
    INFO(graces.err);
    CHECK(
        graces.err.find("5 of 5 notes of the score were not struck: line 1 (the right hand's "
                        "drag grace stroke at 0.93 s), line 1 (the right hand's drag grace "
                        "stroke at 0.97 s), line 1 (the left hand at 1.00 s), line 2 (the left "
                        "hand's flam grace stroke at 1.47 s), line 2 (the right hand at 1.50 s)") !=
        std::string::npos);
    // On a kit, a hand's note lost after a move from another piece says the move: the right
    // hand from the ride to the crash, 1.19 m in a 16th at 112 bpm (0.13 s; the crash's spot
    // turned toward the ride, kCymbalFaceMostDeg), a move no arm makes (10 m/s).
    std::ofstream(dir / "cross.score") << "tempo 112\nbeats 1/4\nR on ride\nR on crash\n";
    Daemon cross({"render", "--kit", "full", "--score", (dir / "cross.score").string(),
                  "--bvh-rate", "0", "--tips-rate", "0", "--out", (dir / "cross").string()});
    CHECK(cross.wait() == 0);
    INFO(cross.err);
    CHECK(cross.err.find("1 of 2 notes of the score were not struck: line 4 (the right hand on "
                         "crash at ") != std::string::npos);
    CHECK(cross.err.find(", from ride 1.19") != std::string::npos);
    CHECK(cross.err.find(" m away 0.13 s before)") != std::string::npos);
    // A note struck, but far from its time, is said too, with its error: the right hand
    // from the floor tom to the hi-hat, 0.97 m in a 16th at 112 bpm (the spot turned toward
    // the floor tom), lands 0.12 s late.
    std::ofstream(dir / "late.score") << "tempo 112\nbeats 1/4\nR on floor\nR on hihat\n";
    Daemon late({"render", "--kit", "full", "--score", (dir / "late.score").string(), "--bvh-rate",
                 "0", "--tips-rate", "0", "--out", (dir / "late").string()});
    CHECK(late.wait() == 0);
    INFO(late.err);
    CHECK(late.err.find("1 of 2 notes of the score were struck more than 5 ms from their time: "
                        "line 4 (the right hand on hihat at 1.13 s, +") != std::string::npos);
    CHECK(late.err.find(" ms, from floor 0.97 m away 0.13 s before) (error_ms in notes.csv)") !=
          std::string::npos);
    CHECK(late.err.find("not struck") == std::string::npos);
    // A strike of no note is said too, by its seq, hand, piece and time: the right hand
    // crossing from the ride to the crash above meets tom2 on its way.
    const std::string cross_json = slurp((dir / "cross" / "render.json").string());
    CHECK(cross_json.find("\"extra_strikes\": 1,") != std::string::npos);
    CHECK(cross.err.find("warning: 1 of 2 strikes (bounces aside) were of no note of the score: "
                         "seq ") != std::string::npos);
    CHECK(cross.err.find(" (the right hand on tom2 at 1.") != std::string::npos);
    CHECK(cross.err.find("(seq in strikes.csv; render.json's performance.extra_strikes)\n") !=
          std::string::npos);
    // The default score on the default drum: every note within 5 ms, nothing said.
    Daemon near(
        {"render", "--bvh-rate", "0", "--tips-rate", "0", "--out", (dir / "near").string()});
    CHECK(near.wait() == 0);
    CHECK(near.err.find("warning") == std::string::npos);
    CHECK(far.err.find("--drum-pos") != std::string::npos);
    CHECK(lines(slurp((dir / "far" / "strikes.csv").string())).size() == 1); // the header only
    CHECK(slurp((dir / "far" / "render.json").string()).find("\"missed_notes\": 4") !=
          std::string::npos);

    std::ofstream(dir / "none.score") << "tempo 100 # no notes\n";
    Daemon none({"render", "--score", (dir / "none.score").string(), "--bvh-rate", "0",
                 "--tips-rate", "0", "--out", (dir / "none").string()});
    CHECK(none.wait() == 0);
    CHECK(none.err.find("the score has no notes") != std::string::npos);
    fs::remove_all(dir);
}

// A --duration shorter than the score left its last notes unplayed, and render said
// they "were not struck", when none was, adding "is the drum within the sticks' reach?
// --drum-pos". Now the notes after the render's end are said as such, and the others
// are judged alone. Seeded scores: N alternating notes at a random tempo, cut midway
// between two of them (the lead-in 1 s: note k at 1 + 60 k / tempo s).
TEST_CASE("render: notes after --duration's end are said as such, not as notes missed",
          "[cli][verbs]")
{
    const fs::path dir = scratch("render-duration");
    fs::create_directories(dir);
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 3; ++trial) {
        const int tempo = std::uniform_int_distribution<int>(60, 180)(rng);
        const int notes = std::uniform_int_distribution<int>(3, 6)(rng);
        // Played: the first `kept` notes (none in the first trial: the cut before beat 0).
        const int kept = trial == 0 ? 0 : std::uniform_int_distribution<int>(1, notes - 1)(rng);
        const double beat_s = 60.0 / tempo;
        const double end_s = 1.0 + (kept - 0.5) * beat_s;
        std::ostringstream score;
        score << "tempo " << tempo << "\n";
        for (int k = 0; k < notes; ++k)
            score << (k % 2 ? "L" : "R") << "\n";
        const fs::path file = dir / ("cut" + std::to_string(trial) + ".score");
        std::ofstream(file) << score.str();
        char duration[32];
        std::snprintf(duration, sizeof duration, "%g", std::round(end_s * 1e3) / 1e3);
        Daemon cut({"render", "--score", file.string(), "--duration", duration, "--bvh-rate", "0",
                    "--tips-rate", "0", "--out", (dir / ("out" + std::to_string(trial))).string()});
        CHECK(cut.wait() == 0);
        INFO("tempo " << tempo << ", " << notes << " notes, --duration " << duration << "\n"
                      << cut.err);
        const int after = notes - kept;
        char first[96];
        std::snprintf(first, sizeof first, "line %d (the %s hand at %.2f s)", kept + 2,
                      kept % 2 ? "left" : "right", 1.0 + kept * beat_s);
        CHECK(cut.err.find("warning: " + std::to_string(after) + " of " + std::to_string(notes) +
                           " notes of the score come after the end of the render (--duration " +
                           duration + " s): " + first) != std::string::npos);
        CHECK(cut.err.find("not struck") == std::string::npos); // the notes played were struck
        CHECK(cut.err.find("--drum-pos") == std::string::npos);
        CHECK(
            lines(slurp((dir / ("out" + std::to_string(trial)) / "strikes.csv").string())).size() ==
            static_cast<size_t>(kept) + 1);
    }
    fs::remove_all(dir);
}

// --wav-bits 8 was refused as "got '8.000000'", --wav-rate 44100.5 was cut to
// 44100 without a word, --score given a folder said it was empty, and an empty score
// file was refused while one of comments only played nothing with a warning.
TEST_CASE("render: a bad value is quoted as typed, a fractional count or rate refused, a folder is "
          "no score, nor a file with no statement, a stick capture is track's",
          "[cli][verbs]")
{
    const fs::path dir = scratch("render-values");
    fs::create_directories(dir);
    // No statement: empty, blank lines, comments only; each refused as having no notes.
    const std::string empty = (dir / "empty.score").string(),
                      blank = (dir / "blank.score").string(),
                      comments = (dir / "comments.score").string();
    std::ofstream(empty, std::ios::binary) << "";
    std::ofstream(blank, std::ios::binary) << " \n\t\r\n\n";
    std::ofstream(comments, std::ios::binary) << "# a groove, to write\n\n  # tempo 100\n";
    const struct {
        std::vector<std::string> args;
        int status;
        std::string said;
    } cases[] = {
        {{"--wav-bits", "8"}, 2, "--wav-bits: expected 16, 24 or 32, got '8'"},
        {{"--wav-rate", "44100.5"}, 2, "--wav-rate: expected a whole number of Hz, got '44100.5'"},
        {{"--midi-channel", "2.5"}, 2, "--midi-channel: expected a whole number 1..16, got '2.5'"},
        {{"--rehearse", "1.5"}, 2, "--rehearse: expected a whole number 0..5, got '1.5'"},
        {{"--score", dir.string()}, 1, "--score: '" + dir.string() + "' is a folder"},
        {{"--score", empty}, 1, "--score: '" + empty + "' has no notes (the file is empty)\n"},
        {{"--score", blank},
         1,
         "--score: '" + blank + "' has no notes (nothing but blank lines and comments)\n"},
        {{"--score", comments},
         1,
         "--score: '" + comments + "' has no notes (nothing but blank lines and comments)\n"},
        // A stick-only capture is track's, not render's: said before any file is read.
        {{"--mocap", "take.CSV"},
         2,
         "--mocap take.CSV: run and render play a BVH capture of the whole body; a stick-only "
         ".csv capture is played by `ictusd track --mode cartesian --mocap take.CSV`"},
    };
    int k = 0;
    for (const auto &c : cases) {
        std::vector<std::string> argv = {"render", "--bvh-rate", "0", "--out",
                                         (dir / ("out" + std::to_string(k++))).string()};
        argv.insert(argv.end(), c.args.begin(), c.args.end());
        Daemon d(argv);
        INFO(c.said << "\n" << d.err);
        CHECK(d.wait() == c.status);
        CHECK(d.err.find(c.said) != std::string::npos);
    }
    fs::remove_all(dir);
}

TEST_CASE("render: a write error names the file and the system's reason, exit 1", "[cli][verbs]")
{
    const fs::path dir = scratch("render-full");
    const std::string score = four_notes(dir).string();
    Daemon d({"render", "--score", score, "--bvh-rate", "0", "--out", (dir / "out").string()}, 300);
    CHECK(d.wait() == 1);
    INFO(d.err);
    CHECK(d.err.find("/out/strikes.csv': " + std::string(std::strerror(EFBIG))) !=
          std::string::npos);
    fs::remove_all(dir);
}
