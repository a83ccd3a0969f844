// The real ictusd as a hostile user drives it: signals in every verb and
// phase (docs/perform.md, "Signals": SIGINT, SIGTERM and SIGHUP end a verb at
// its next step with exit 130, files whole, no pd left behind), a file-size
// limit (exit 1, a message, whole rows), an endless score, the paths and
// URLs run and render must refuse before they start, and track's --gains file
// held to the stability check of /ictus/gains.
#include "support/cli_test_util.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace
{

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true; // no address-space limit under a sanitizer
#else
constexpr bool kSanitized = false;
#endif

double since(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ictusd (or `sh -c SCRIPT`) as a child, stdout and stderr in one pipe read
// line by line; killed and reaped on destruction.
class Proc
{
  public:
    explicit Proc(const std::vector<std::string> &args)
    {
        int fds[2];
        REQUIRE(::pipe(fds) == 0);
        pid_ = ::fork();
        REQUIRE(pid_ >= 0);
        if (pid_ == 0) {
            ::prctl(PR_SET_PDEATHSIG, SIGKILL);
            ::dup2(fds[1], 1);
            ::dup2(fds[1], 2);
            ::close(fds[0]);
            ::close(fds[1]);
            std::vector<char *> argv;
            for (const std::string &a : args)
                argv.push_back(const_cast<char *>(a.c_str()));
            argv.push_back(nullptr);
            ::execvp(argv[0], argv.data());
            ::_exit(127);
        }
        ::close(fds[1]);
        fd_ = fds[0];
    }
    ~Proc()
    {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        ::close(fd_);
    }
    pid_t pid() const { return pid_; }
    // Reads until a line containing `text`, up to `deadline_s`.
    bool wait_for(const std::string &text, double deadline_s)
    {
        const auto t0 = std::chrono::steady_clock::now();
        while (output_.find(text) == std::string::npos) {
            const double left = deadline_s - since(t0);
            if (left <= 0.0 || !read_some(static_cast<int>(left * 1000)))
                return false;
        }
        return true;
    }
    // The exit status (-1: ended by a signal), or -2 when it did not end
    // within `deadline_s`; the output is read meanwhile.
    int wait_exit(double deadline_s)
    {
        const auto t0 = std::chrono::steady_clock::now();
        while (read_some(std::max(1, static_cast<int>((deadline_s - since(t0)) * 1000)))) {
        }
        int status = 0;
        for (;;) {
            const pid_t r = ::waitpid(pid_, &status, WNOHANG);
            if (r == pid_)
                break;
            if (since(t0) > deadline_s)
                return -2;
            pollfd none{-1, 0, 0};
            ::poll(&none, 0, 20); // the process closed its output: it is ending
        }
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    const std::string &output() const { return output_; }

  private:
    bool read_some(int timeout_ms)
    {
        pollfd p{fd_, POLLIN, 0};
        if (timeout_ms <= 0 || ::poll(&p, 1, timeout_ms) <= 0)
            return false;
        char buf[4096];
        const ssize_t n = ::read(fd_, buf, sizeof buf);
        if (n <= 0)
            return false;
        output_.append(buf, static_cast<size_t>(n));
        return true;
    }
    pid_t pid_ = -1;
    int fd_ = -1;
    std::string output_;
};

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string &name)
        : path(fs::temp_directory_path() /
               ("ictus_signals_" + name + "_" + std::to_string(::getpid())))
    {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    std::string operator/(const std::string &name) const { return (path / name).string(); }
};

std::string slurp(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Every file of `dir` is not empty (events.txt is, when there was no
// strike) and, for a text of lines, ends with a whole line; strikes.csv's
// rows have the header's number of fields.
void check_no_debris(const std::string &dir)
{
    const std::string strikes = slurp(dir + "/strikes.csv");
    const bool no_strike = std::count(strikes.begin(), strikes.end(), '\n') <= 1;
    for (const auto &e : fs::directory_iterator(dir)) {
        INFO(e.path());
        if (no_strike && e.path().filename() == "events.txt")
            continue;
        CHECK(fs::file_size(e.path()) > 0);
        const std::string ext = e.path().extension().string();
        if (ext == ".csv" || ext == ".txt")
            CHECK(slurp(e.path().string()).back() == '\n');
    }
    const std::string csv = dir + "/strikes.csv";
    if (!fs::exists(csv))
        return;
    std::istringstream lines(slurp(csv));
    std::string line;
    std::getline(lines, line);
    const auto fields = std::count(line.begin(), line.end(), ',');
    while (std::getline(lines, line))
        CHECK(std::count(line.begin(), line.end(), ',') == fields);
}

const char *signal_name(int s)
{
    return s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : "SIGHUP";
}

// The write end of the FIFO `path`, opened once a reader (ictusd loading its
// input) has opened it: the handshake that the process is in its loading
// phase. -1 past 30 s.
int open_fifo_writer(const std::string &path)
{
    const auto t0 = std::chrono::steady_clock::now();
    while (since(t0) < 30.0) {
        const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) {
            ::fcntl(fd, F_SETFL, 0); // blocking writes from here on
            return fd;
        }
        pollfd none{-1, 0, 0};
        ::poll(&none, 0, 20);
    }
    return -1;
}

// Writes all of `text` to `fd` and closes it.
bool write_all_and_close(int fd, const std::string &text)
{
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n <= 0)
            break;
        done += static_cast<std::size_t>(n);
    }
    ::close(fd);
    return done == text.size();
}

} // namespace

TEST_CASE("ictusd render: SIGINT, SIGTERM or SIGHUP while simulating: exit 130, whole files",
          "[cli][signals]")
{
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        INFO(signal_name(sig));
        TempDir dir(std::string("render_") + signal_name(sig));
        Proc p({ICTUSD_PATH, "render", "--out", dir / "out", "--duration", "60", "--progress-every",
                "0.05"});
        REQUIRE(p.wait_for("s simulated", 30.0));
        REQUIRE(::kill(p.pid(), sig) == 0);
        CHECK(p.wait_exit(30.0) == 130);
        INFO(p.output());
        check_no_debris(dir / "out");
        CHECK(fs::exists(dir / "out/strikes.csv"));
    }
}

TEST_CASE("ictusd render --wav: a signal in the Pd phase stops pd with exit 130 and no WAV and pd dies with "
          "a killed ictusd",
          "[cli][signals]")
{
    TempDir dir("pd");
    // A pd that writes its pid and waits (it would render for a minute),
    // and a library folder with the render patch's name.
    const std::string pid_file = dir / "pd.pid", fake = dir / "pd";
    std::ofstream(fake) << "#!/bin/sh\necho $$ > " << pid_file << ".tmp\nmv " << pid_file << ".tmp "
                        << pid_file << "\necho pd: rendering\nexec sleep 60\n";
    fs::permissions(fake, fs::perms::owner_all);
    fs::create_directories(dir / "lib");
    std::ofstream(dir / "lib/ictus-render.pd") << "#N canvas 0 0 100 100 10;\n";
    auto pd_pid = [&]() {
        const auto t0 = std::chrono::steady_clock::now();
        while (since(t0) < 30.0) {
            std::ifstream in(pid_file);
            pid_t pid = 0;
            if (in >> pid && pid > 0)
                return pid;
            pollfd none{-1, 0, 0};
            ::poll(&none, 0, 20);
        }
        return pid_t{-1};
    };
    auto gone_within = [](pid_t pid, double deadline_s) {
        const auto t0 = std::chrono::steady_clock::now();
        while (since(t0) < deadline_s) {
            if (::kill(pid, 0) != 0 && errno == ESRCH)
                return true;
            pollfd none{-1, 0, 0};
            ::poll(&none, 0, 20);
        }
        ::kill(pid, SIGKILL); // no orphan of the test's either
        return false;
    };
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGKILL}) {
        INFO((sig == SIGKILL ? "SIGKILL" : signal_name(sig)));
        fs::remove(pid_file);
        const std::string out = dir / ("out" + std::to_string(sig));
        Proc p({ICTUSD_PATH, "render", "--out", out, "--duration", "0.5", "--wav",
                out + "/performance.wav", "--pd", fake, "--pd-lib", dir / "lib"});
        const pid_t pd = pd_pid();
        REQUIRE(pd > 0);
        REQUIRE(::kill(p.pid(), sig) == 0);
        const int status = p.wait_exit(30.0);
        INFO(p.output());
        CHECK(status == (sig == SIGKILL ? -1 : 130));
        CHECK(gone_within(pd, 10.0));
        CHECK_FALSE(fs::exists(out + "/performance.wav"));
        if (sig != SIGKILL)
            check_no_debris(out);
    }
}

TEST_CASE("ictusd run: a Ctrl-C while the score is still loading ends the run, exit 130",
          "[cli][signals]")
{
    TempDir dir("run_startup");
    const std::string fifo = dir / "score.fifo";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    Proc p({ICTUSD_PATH, "run", "--score", fifo, "--autoplay", "--port", "0", "--pose-rate", "0"});
    const int fd = open_fifo_writer(fifo);
    REQUIRE(fd >= 0);
    REQUIRE(::kill(p.pid(), SIGINT) == 0); // while it reads the score
    const std::string score = "tempo 120\nR accent\nL accent\n";
    REQUIRE(::write(fd, score.data(), score.size()) == static_cast<ssize_t>(score.size()));
    ::close(fd);
    CHECK(p.wait_exit(20.0) == 130);
}

TEST_CASE("ictusd limits and gestures: a signal while the input loads finishes the verb, exit 130, "
          "its output whole",
          "[cli][signals]")
{
    // A capture of 120 frames of the default skeleton, arms swinging: enough
    // for limits (30 frames at least).
    const std::string bvh =
        simtest::default_skeleton_bvh(120, 1.0 / 120.0, [](int f, const std::string &joint) {
            const double a = 20.0 * std::sin(2.0 * M_PI * f / 60.0);
            return joint.find("Arm") != std::string::npos ? Eigen::Vector3d(a, 0.5 * a, 0.0)
                                                          : Eigen::Vector3d::Zero();
        });
    TempDir dir("one_step");
    const std::string db = dir / "db.json";
    {
        Proc e({ICTUSD_PATH, "gestures", "--export", db});
        REQUIRE(e.wait_exit(60.0) == 0);
    }
    const std::string db_text = slurp(db);
    // ictusd with its input a FIFO (`{fifo}` in args): the signal once it has
    // opened it, then the input written; its output after it exited 130.
    auto interrupted = [&](std::vector<std::string> args, const std::string &fifo,
                           const std::string &input, int sig) {
        REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
        for (std::string &a : args)
            if (a == "{fifo}")
                a = fifo;
        Proc p(args);
        const int fd = open_fifo_writer(fifo);
        REQUIRE(fd >= 0);
        REQUIRE(::kill(p.pid(), sig) == 0);
        CHECK(write_all_and_close(fd, input));
        CHECK(p.wait_exit(60.0) == 130);
        INFO(p.output());
        CHECK(p.output().find("interrupted") != std::string::npos);
        return p.output();
    };
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        const std::string name = signal_name(sig);
        INFO(name);
        // limits: the signal while the capture is read, the JSON written whole.
        const std::string out = dir / ("limits_" + name + ".json");
        interrupted({ICTUSD_PATH, "limits", "{fifo}", "--out", out},
                    dir / ("clip_" + name + ".bvh"), bvh, sig);
        const nlohmann::json limits = nlohmann::json::parse(slurp(out)); // whole: it parses
        CHECK_FALSE(limits.empty());
        // gestures: the signal while the database is read, the list printed whole.
        const std::string listed =
            interrupted({ICTUSD_PATH, "gestures", "--list", "--db", "{fifo}"},
                        dir / ("db_" + name + ".json"), db_text, sig);
        CHECK(listed.find("legato") != std::string::npos); // the units were listed
    }
}

TEST_CASE("ictusd run and render under a file-size limit: exit 1, a message, whole rows",
          "[cli][signals]")
{
    TempDir dir("xfsz");
    SECTION("render")
    {
        Proc p({"/bin/sh", "-c",
                std::string("ulimit -f 2; exec ") + ICTUSD_PATH + " render --out " + (dir / "r")});
        CHECK(p.wait_exit(120.0) == 1);
        CHECK_THAT(p.output(), Catch::Contains("cannot write '" + (dir / "r/strikes.csv") +
                                               "': File too large"));
        check_no_debris(dir / "r");
    }
    SECTION("run")
    {
        Proc p({"/bin/sh", "-c",
                std::string("ulimit -f 1; exec ") + ICTUSD_PATH +
                    " run --autoplay --duration 30 --port 0 --pose-rate 0 --out " + (dir / "u")});
        CHECK(p.wait_exit(60.0) == 1);
        CHECK_THAT(p.output(), Catch::Contains("cannot write '" + (dir / "u/strikes.csv") +
                                               "': File too large"));
        check_no_debris(dir / "u");
    }
}

TEST_CASE("ictusd render --score /dev/zero is refused at its 16 MiB bound, not read on",
          "[cli][bounds]")
{
    // An endless file: read on, it would not end before the deadline (or would run out of
    // the 3 GB of address space); refused at the bound, it ends with the error line.
    TempDir dir("zero");
    const std::string limit = kSanitized ? "" : "ulimit -v 3000000; ";
    Proc p({"/bin/sh", "-c",
            limit + "exec " + ICTUSD_PATH + " render --score /dev/zero --out " + (dir / "o")});
    const int status = p.wait_exit(60.0);
    CHECK(status == 1);
    CHECK_THAT(p.output(), Catch::Contains("--score: '/dev/zero' is larger than 16 MiB"));
}

TEST_CASE("ictusd render --wav takes only a NAME.wav it will write, never a folder",
          "[cli][bounds]")
{
    TempDir dir("wav");
    const std::string fake = dir / "pd"; // a pd that writes nothing
    std::ofstream(fake) << "#!/bin/sh\nexit 0\n";
    fs::permissions(fake, fs::perms::owner_all);
    fs::create_directories(dir / "lib");
    std::ofstream(dir / "lib/ictus-render.pd") << "#N canvas 0 0 100 100 10;\n";
    fs::create_directories(dir / "empty");
    fs::create_directories(dir / "folder.wav");
    const std::string out = dir / "out";
    for (const std::string &wav : {out + "/strikes.csv", out + "/events.txt", out + "/render.json",
                                   dir / "take", dir / "take.aiff", dir / "empty"}) {
        INFO(wav);
        Proc p({"timeout", "60", ICTUSD_PATH, "render", "--out", out, "--duration", "0.5", "--wav",
                wav, "--pd", fake, "--pd-lib", dir / "lib"});
        CHECK(p.wait_exit(90.0) == 1);
        CHECK_THAT(p.output(), Catch::Contains("--wav: '" + wav + "' does not end in .wav"));
        CHECK_FALSE(fs::exists(out)); // refused before anything is written
    }
    Proc p({"timeout", "60", ICTUSD_PATH, "render", "--out", out, "--duration", "0.5", "--wav",
            dir / "folder.wav", "--pd", fake, "--pd-lib", dir / "lib"});
    CHECK(p.wait_exit(90.0) == 1);
    CHECK_THAT(p.output(), Catch::Contains("'" + (dir / "folder.wav") + "' is a folder"));
    CHECK(fs::is_directory(dir / "empty"));
    CHECK(fs::is_directory(dir / "folder.wav"));
    // A NAME.wav in a folder that does not exist (Pd makes none) was found after the
    // physics, when Pd could not write it: refused before, naming the folder; in --out's
    // folder, which render makes, it is taken (the fake pd then writes no WAV).
    for (const std::string &missing : {dir / "nowhere", out + "/sub"}) {
        const std::string wav = missing + "/take.wav";
        INFO(wav);
        Proc q({"timeout", "60", ICTUSD_PATH, "render", "--out", out, "--duration", "0.5", "--wav",
                wav, "--pd", fake, "--pd-lib", dir / "lib"});
        CHECK(q.wait_exit(90.0) == 1);
        CHECK_THAT(q.output(), Catch::Contains("--wav: no folder '" + missing + "' for '" + wav));
        CHECK_FALSE(fs::exists(out));
        CHECK_FALSE(fs::exists(missing));
    }
    const std::string made = dir / "made";
    Proc in_out({"timeout", "60", ICTUSD_PATH, "render", "--out", made, "--duration", "0.5",
                 "--wav", made + "/take.wav", "--pd", fake, "--pd-lib", dir / "lib"});
    CHECK(in_out.wait_exit(90.0) == 1);
    CHECK_THAT(in_out.output(), Catch::Contains("pd wrote no '" + made + "/take.wav'"));
}

TEST_CASE("ictusd run --reply is checked as --target is", "[cli][bounds]")
{
    for (const std::string url :
         {"osc.tcp://127.0.0.1:9000", "osc.unix:///tmp/ictus.sock", "osc.udp://127.0.0.1:9000x",
          "osc.udp://127.0.0.1:9000/x", "osc.udp://127.0.0.1:99999"}) {
        INFO(url);
        const clitest::Run r = clitest::ictusd("run --duration 0.2 --port 0 --reply " + url);
        CHECK(r.status == 2);
        CHECK_THAT(r.output, Catch::StartsWith("ictusd run: --reply '" + url + "': "));
    }
}

TEST_CASE("ictusd run --out: a render's folder is refused, --force clears render's files",
          "[cli][bounds]")
{
    TempDir dir("run_out");
    const std::string out = dir / "r";
    REQUIRE(clitest::ictusd("render --duration 0.5 --bvh-rate 0 --out " + out).status == 0);
    const std::string events = slurp(out + "/events.txt");
    clitest::Run r = clitest::ictusd("run --duration 0.3 --port 0 --pose-rate 0 --out " + out);
    CHECK(r.status == 1);
    CHECK_THAT(r.output, Catch::Contains("--out: '" + out + "' holds a render's"));
    CHECK(slurp(out + "/events.txt") == events); // untouched
    r = clitest::ictusd("run --duration 0.3 --port 0 --pose-rate 0 --force --out " + out);
    CHECK(r.status == 0);
    CHECK_FALSE(fs::exists(out + "/events.txt"));
    CHECK_FALSE(fs::exists(out + "/render.json"));
    CHECK(fs::exists(out + "/strikes.csv"));
}

TEST_CASE("ictusd render --duration is at most 900 s", "[cli][bounds]")
{
    TempDir dir("duration");
    Proc p({"timeout", "30", ICTUSD_PATH, "render", "--duration", "1e7", "--out", dir / "o"});
    CHECK(p.wait_exit(60.0) == 2);
    CHECK_THAT(p.output(), Catch::Contains("--duration: render keeps its outputs in memory") &&
                               Catch::Contains("at most 900 s, got 1e+07"));
    CHECK_FALSE(fs::exists(dir / "o"));
}

TEST_CASE("ictusd track --gains FILE passes the stability check of /ictus/gains", "[cli][bounds]")
{
    TempDir dir("gains");
    const std::string base =
        std::string("track --mode joint --quiet --duration 0.3 --mocap ") + clitest::tiny_bvh();
    REQUIRE(clitest::ictusd(base + " --out " + (dir / "d")).status == 0);
    const nlohmann::json defaults =
        nlohmann::json::parse(slurp(dir / "d/summary.json")).at("gains").at("r_wrist");
    const double kp0 = defaults.at("kp_nm_per_rad"), kd0 = defaults.at("kd_nm_s_per_rad");
    REQUIRE(kp0 / kd0 < 500.0); // the default rate kp/kd, well inside 1000/s at 1 ms
    auto with = [&](double kp, double kd) {
        const std::string f = dir / "g.json";
        std::ofstream(f)
            << nlohmann::json{{"r_wrist", {{"kp_nm_per_rad", kp}, {"kd_nm_s_per_rad", kd}}}}.dump();
        return clitest::ictusd(base + " --gains " + f);
    };
    // The damping ratio scales as kd / sqrt(kp): zeta 1 (the default) x 1/10.
    clitest::Run r = with(100.0 * kp0, kd0);
    CHECK(r.status == 1);
    CHECK_THAT(r.output, Catch::Contains("g.json: joint 'r_wrist'") &&
                             Catch::Contains("damping ratio of 0.10, under 0.71"));
    // Stiffness x4 with damping x2 keeps zeta at 1: accepted.
    r = with(4.0 * kp0, 2.0 * kd0);
    CHECK(r.status == 0);
    // Stiffness x10000, damping x100: zeta 1 but kp/kd 100 times the default's,
    // past 1000/s at the 1 ms step.
    r = with(1e4 * kp0, 100.0 * kd0);
    CHECK(r.status == 1);
    CHECK_THAT(r.output, Catch::Contains("joint 'r_wrist'") && Catch::Contains("PD rate kp/kd"));
}

TEST_CASE("ictusd run: a command the physics refuses counts among the summary's errors",
          "[cli][bounds]")
{
    // /ictus/gains 4 0.05 (docs/perform.md: a damping ratio of 0.025, refused
    // by the performance, not by the server's type and range checks).
    const int sock = ::socket(AF_INET, SOCK_DGRAM, 0);
    REQUIRE(sock >= 0);
    sockaddr_in me{};
    me.sin_family = AF_INET;
    me.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(::bind(sock, reinterpret_cast<sockaddr *>(&me), sizeof me) == 0);
    Proc p({ICTUSD_PATH, "run", "--port", "0", "--pose-rate", "0"});
    REQUIRE(p.wait_for(", strikes and poses to", 30.0)); // the port whole
    const std::string &out = p.output();
    const size_t at = out.find("commands on 127.0.0.1:") + 22;
    sockaddr_in daemon{};
    daemon.sin_family = AF_INET;
    daemon.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    daemon.sin_port = htons(static_cast<uint16_t>(std::stoi(out.substr(at))));
    std::string packet("/ictus/gains\0\0\0\0,ff\0", 20);
    for (float v : {4.0f, 0.05f}) {
        uint32_t bits;
        std::memcpy(&bits, &v, 4);
        bits = htonl(bits);
        packet.append(reinterpret_cast<const char *>(&bits), 4);
    }
    // Sent until the refusal comes back (a handshake: the physics loop runs).
    bool refused = false;
    const auto t0 = std::chrono::steady_clock::now();
    while (!refused && since(t0) < 30.0) {
        ::sendto(sock, packet.data(), packet.size(), 0, reinterpret_cast<sockaddr *>(&daemon),
                 sizeof daemon);
        pollfd pf{sock, POLLIN, 0};
        for (char buf[1024]; ::poll(&pf, 1, 200) > 0;) {
            const ssize_t n = ::recv(sock, buf, sizeof buf, 0);
            if (n > 0 && std::string(buf, static_cast<size_t>(n)).find("damping ratio") !=
                             std::string::npos) {
                refused = true;
                break;
            }
        }
    }
    ::close(sock);
    CHECK(refused);
    REQUIRE(::kill(p.pid(), SIGINT) == 0);
    CHECK(p.wait_exit(30.0) == 130);
    INFO(p.output());
    // Every packet was a gains the physics refuses (or had not yet taken at
    // the stop): errors between 1 and the packets.
    const std::string &o = p.output();
    const size_t accepted = o.find(" accepted, ");
    REQUIRE(accepted != std::string::npos);
    const long errors = std::stol(o.substr(accepted + 11));
    const size_t in = o.rfind(" packets in, ", accepted);
    REQUIRE(in != std::string::npos);
    const long packets = std::stol(o.substr(o.rfind(' ', in - 1) + 1));
    CHECK(errors >= 1);
    CHECK(errors <= packets);
}
