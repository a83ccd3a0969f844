// Pd in batch mode as a child process (render --wav, docs/main-job.md).
#include "ictus/cli/pd_render.hpp"

#include "ictus/cli/args.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

extern char **environ;

namespace ictus
{
namespace cli
{

namespace fs = std::filesystem;

namespace
{

std::string self_dir()
{
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string() : exe.parent_path().string();
}

bool is_library(const fs::path &dir)
{
    std::error_code ec;
    return fs::is_regular_file(dir / "ictus-render.pd", ec);
}

std::string format(const char *fmt, double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
}

} // namespace

void check_pd_path(const char *what, const std::string &path)
{
    if (path.find_first_of(" \t\n,;$\\{}") != std::string::npos)
        throw std::runtime_error(std::string(what) + ": '" + path +
                                 "' has a space or one of , ; $ \\ { } that Pd's messages "
                                 "cannot carry: choose another path");
}

void check_wav_path(const std::string &path, const std::string &made_dir)
{
    // The suffixes Pd's soundfiler keeps as given (d_soundfile_wave.c's
    // wave_hasextension); to any other name, `.Wav` too, it adds .wav.
    const std::string name = fs::path(path).filename().string();
    auto ends_in = [&name](const std::string &suffix) {
        return name.size() > suffix.size() &&
               name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    if (!ends_in(".wav") && !ends_in(".WAV") && !ends_in(".wave") && !ends_in(".WAVE"))
        throw std::runtime_error("--wav: '" + path +
                                 "' does not end in .wav (or .WAV): Pd writes a WAV file by "
                                 "that name, and to any other adds .wav");
    std::error_code ec;
    if (fs::is_directory(path, ec))
        throw std::runtime_error("--wav: '" + path + "' is a folder: give a file NAME.wav");
    check_pd_path("--wav", path);
    // "out/" normalises to "out/": its trailing empty name is not the folder's.
    auto folder_of = [](const fs::path &p) {
        const fs::path n = p.lexically_normal();
        return n.has_filename() ? n : n.parent_path();
    };
    const fs::path folder = fs::path(path).parent_path();
    if (!fs::is_directory(folder, ec) &&
        (made_dir.empty() || folder_of(folder) != folder_of(made_dir)))
        throw std::runtime_error("--wav: no folder '" + folder.string() + "' for '" + path +
                                 "' (Pd makes none: create it, or write the WAV in --out's)");
}

std::string find_pd_library(const std::string &given)
{
    if (!given.empty()) {
        if (!is_library(given))
            throw std::runtime_error("--pd-lib: no ictus-render.pd in '" + given +
                                     "' (give the folder of the Pd library, e.g. build/ictus)");
        return fs::absolute(given).lexically_normal().string();
    }
    const std::string self = self_dir();
    std::vector<fs::path> tried;
    // The layouts ictusd ships in: inside the library folder (the deken
    // package), beside it (the build folder), or in <prefix>/bin with the
    // library in <prefix>/lib/pd-externals/ictus (cmake --install).
    if (!self.empty()) {
        tried.push_back(fs::path(self));
        tried.push_back(fs::path(self) / "ictus");
        tried.push_back(fs::path(self) / ".." / "lib" / "pd-externals" / "ictus");
    }
    for (const fs::path &dir : tried)
        if (is_library(dir))
            return dir.lexically_normal().string();
    std::string list;
    for (const fs::path &dir : tried)
        list += (list.empty() ? "" : ", ") + dir.lexically_normal().string();
    throw std::runtime_error(
        "--wav: the Pd library (ictus-render.pd and the externals) is not in " +
        (list.empty() ? std::string("ictusd's folder") : list) +
        ": unpack the whole deken package, build the library (cmake --build build) or give "
        "--pd-lib DIR");
}

std::string find_pd_binary(const std::string &pd)
{
    if (pd.find('/') != std::string::npos) {
        if (::access(pd.c_str(), X_OK) != 0)
            throw std::runtime_error("--pd: '" + pd + "' is not an executable file");
        return pd;
    }
    const char *path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + pd;
        if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate))
            return candidate;
    }
    throw std::runtime_error("--wav: no '" + pd +
                             "' on PATH: install Pure Data (Debian: apt install puredata-core, "
                             "or bash scripts/deps.sh) or give --pd /path/to/pd");
}

namespace
{

// Pd's command line: batch mode, the render patch, and the drum, the mix
// and the files as -send messages to it. -nrt: run as root, Pd takes SCHED_FIFO
// (priority 6) unless told not to, and a batch render, which never waits, would then
// hold a core against every ordinary process, a live Pd's equal-priority scheduler
// included, for as long as it renders.
std::vector<std::string> pd_command_line(const PdRenderOptions &o, const std::string &pd,
                                         const std::string &lib)
{
    std::vector<std::string> argv = {pd,
                                     "-nogui",
                                     "-nosound",
                                     "-nomidi",
                                     "-batch",
                                     "-nrt",
                                     "-stderr",
                                     "-r",
                                     std::to_string(o.sample_rate),
                                     "-path",
                                     lib,
                                     "-open",
                                     lib + "/ictus-render.pd"};
    std::vector<std::string> sends;
    if (!o.preset.empty()) // first: radius, tension and density below win over it
        sends.push_back("render-drum preset " + o.preset);
    const std::vector<std::string> rest = {
        "render-drum radius " + format("%.9g", o.radius_m),
        "render-drum tension " + format("%.9g", o.tension_n_per_m),
        "render-drum density " + format("%.9g", o.density_kg_per_m2),
        "render-mix " + o.mix,
        "render-bits " + std::to_string(o.bits),
        "render-gain " + format("%.9g", o.gain_db),
        "render-file " + o.events,
        "render-out " + o.wav,
        "render-seconds " + format("%.3f", o.seconds)};
    sends.insert(sends.end(), rest.begin(), rest.end());
    for (size_t i = 0; i < o.kit.size(); ++i) {
        const std::string to = "render-kit-" + std::to_string(i + 1) + " ";
        const PdRenderOptions::KitDrumSound &k = o.kit[i];
        if (!k.preset.empty())
            sends.push_back(to + "preset " + k.preset);
        sends.push_back(to + "radius " + format("%.9g", k.radius_m));
        if (k.tension_n_per_m > 0.0) // a cymbal has none (its preset made it a plate)
            sends.push_back(to + "tension " + format("%.9g", k.tension_n_per_m));
        sends.push_back(to + "pan " + format("%.6g", k.pan));
        if (!k.foot_tip.empty()) { // the kick's beater
            sends.push_back(to + "right tip " + k.foot_tip);
        } else if (!o.stick_tip.empty()) { // the sticks play every drum with their tip
            sends.push_back(to + "left tip " + o.stick_tip);
            sends.push_back(to + "right tip " + o.stick_tip);
        }
        sends.push_back(to + "dsp 1");
    }
    if (o.stretch_n_per_m3 > 0.0) { // the physics' head stretching on both sticks
        sends.push_back("render-drum left stretch " + format("%.9g", o.stretch_n_per_m3));
        sends.push_back("render-drum right stretch " + format("%.9g", o.stretch_n_per_m3));
    }
    if (!o.stick_tip.empty()) { // the physics' tip on both sticks (contact~ tip NAME)
        sends.push_back("render-drum left tip " + o.stick_tip);
        sends.push_back("render-drum right tip " + o.stick_tip);
    }
    for (const std::string &s : sends) {
        argv.push_back("-send");
        argv.push_back(s);
    }
    return argv;
}

// A running Pd: its process and the read end of the pipe that carries its
// stdout and stderr.
struct PdProcess {
    pid_t pid = -1;
    int output_fd = -1;
};

// Pd as a child that ends with ictusd: fork and exec (posix_spawn cannot ask
// for PR_SET_PDEATHSIG), SIGKILL to it when ictusd's thread that started it
// ends, however it ends (SIGKILL included). Its signals as a new program's:
// SIGXFSZ, ignored by ictusd, back to its default.
PdProcess spawn_pd(const std::string &pd, std::vector<std::string> &argv)
{
    std::vector<char *> cargv;
    for (std::string &a : argv)
        cargv.push_back(a.data());
    cargv.push_back(nullptr);

    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
        throw std::runtime_error(std::string("--wav: pipe: ") + std::strerror(errno));
    const pid_t parent = ::getpid();
    PdProcess p;
    p.pid = ::fork();
    if (p.pid == 0) { // the child: async-signal-safe calls only
        ::prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (::getppid() != parent) // ictusd ended before prctl
            ::_exit(127);
        std::signal(SIGXFSZ, SIG_DFL);
        const int null_fd = ::open("/dev/null", O_RDONLY);
        if (null_fd < 0 || ::dup2(null_fd, 0) < 0 || ::dup2(fds[1], 1) < 0 || ::dup2(fds[1], 2) < 0)
            ::_exit(127);
        ::execve(pd.c_str(), cargv.data(), environ);
        static const char msg[] = "ictusd: cannot execute pd\n";
        const ssize_t ignored = ::write(2, msg, sizeof msg - 1);
        (void)ignored;
        ::_exit(127);
    }
    const int fork_error = errno;
    ::close(fds[1]);
    if (p.pid < 0) {
        ::close(fds[0]);
        throw std::runtime_error("--wav: cannot start '" + pd + "': " + std::strerror(fork_error));
    }
    g_child_pid = p.pid;
    p.output_fd = fds[0];
    return p;
}

// How Pd ended: its output, its wait status, and why it was stopped ("" when
// it ended by itself).
struct PdEnd {
    std::string output;
    int status = 0;
    std::string stop_reason;
};

// Collects Pd's output until it ends. Pd in batch mode renders many times
// faster than real time; a patch that never quits (the library half loaded)
// must not hang render: it is killed after `timeout_s`, and stopped on SIGINT,
// SIGTERM or SIGHUP (g_interrupted).
PdEnd wait_for_pd(const PdProcess &p, double timeout_s, const std::function<double()> &elapsed,
                  const std::function<void(double)> &progress)
{
    PdEnd end;
    double next_progress = 2.0;
    bool reaped = false;
    for (;;) {
        pollfd poll_fd{p.output_fd, POLLIN, 0};
        const int r = ::poll(&poll_fd, 1, 250);
        if (r == 0 && ::waitpid(p.pid, &end.status, WNOHANG) == p.pid) {
            reaped = true; // gone, though something it started may hold the pipe
            break;
        }
        if (r > 0) {
            char buf[4096];
            const ssize_t n = ::read(p.output_fd, buf, sizeof buf);
            if (n > 0)
                end.output.append(buf, static_cast<size_t>(n));
            else if (n == 0 || errno != EINTR)
                break; // Pd closed its output: it is ending
        }
        if (g_interrupted && end.stop_reason.empty()) {
            end.stop_reason = "interrupted";
            ::kill(p.pid, SIGTERM);
        } else if (elapsed() > timeout_s && end.stop_reason.empty()) {
            end.stop_reason = "timed out after " + format("%.0f", timeout_s) + " s";
            ::kill(p.pid, SIGKILL);
        }
        if (elapsed() >= next_progress) {
            progress(elapsed());
            next_progress += 2.0;
        }
    }
    ::close(p.output_fd);
    if (g_interrupted && end.stop_reason.empty()) {
        end.stop_reason = "interrupted"; // pd ended by the same Ctrl-C, or first
        ::kill(p.pid, SIGTERM);
    }
    while (!reaped && ::waitpid(p.pid, &end.status, 0) < 0 && errno == EINTR) {
    }
    g_child_pid = 0;
    return end;
}

// Pd's error lines and its report line (ictus-render's peaks) into `result`;
// false when there was no report.
bool read_pd_report(const std::string &output, PdRenderResult &result)
{
    std::istringstream lines(output);
    std::string line;
    bool reported = false;
    while (std::getline(lines, line)) {
        if (line.find("error") != std::string::npos || line.find("couldn't") != std::string::npos)
            result.errors += line + "\n";
        double in = 0.0, out = 0.0;
        if (std::sscanf(line.c_str(), "ictus-render: peak_in_dbfs %lf peak_out_dbfs %lf", &in,
                        &out) == 2) {
            result.peak_in_dbfs = in;
            result.peak_out_dbfs = out;
            reported = true;
        }
    }
    return reported;
}

} // namespace

PdRenderResult run_pd_render(const PdRenderOptions &o, const std::function<void(double)> &progress)
{
    const std::string pd = find_pd_binary(o.pd);
    const std::string lib = find_pd_library(o.library);
    check_pd_path("--wav", o.wav);
    check_pd_path("--out", o.events);
    check_pd_path("--pd-lib", lib);
    std::vector<std::string> argv = pd_command_line(o, pd, lib);
    check_wav_path(o.wav);
    // So that an earlier file never passes for this one: unlink(2), which
    // never removes a folder.
    if (::unlink(o.wav.c_str()) != 0 && errno != ENOENT)
        throw std::runtime_error("--wav: cannot replace '" + o.wav + "': " + std::strerror(errno));
    const PdProcess process = spawn_pd(pd, argv);

    const double timeout_s = 120.0 + 10.0 * o.seconds;
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    const PdEnd end = wait_for_pd(process, timeout_s, elapsed, progress);

    PdRenderResult result;
    result.wall_s = elapsed();
    if (!o.log.empty()) {
        std::ofstream log(o.log, std::ios::binary);
        log << end.output;
        if (!log.flush())
            throw std::runtime_error("--wav: cannot write '" + o.log + "'");
    }
    const std::string log_note = o.log.empty() ? "" : " (log: " + o.log + ")";
    if (!end.stop_reason.empty())
        ::unlink(o.wav.c_str()); // the cut WAV's header does not say its length
    if (end.stop_reason == "interrupted") {
        result.interrupted = true;
        return result;
    }
    if (!end.stop_reason.empty())
        throw std::runtime_error("--wav: pd " + end.stop_reason + log_note);
    const int status = end.status;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw std::runtime_error("--wav: pd failed (" +
                                 (WIFEXITED(status)
                                      ? "exit status " + std::to_string(WEXITSTATUS(status))
                                      : "signal " + std::to_string(WTERMSIG(status))) +
                                 ")" + log_note);
    const bool reported = read_pd_report(end.output, result);
    std::error_code ec;
    if (!reported || !fs::is_regular_file(o.wav, ec))
        throw std::runtime_error("--wav: pd wrote no '" + o.wav + "'" + log_note + ":\n" +
                                 end.output);
    return result;
}

} // namespace cli
} // namespace ictus
