// `ictusd run`: the performance in real time: physics paced by the wall
// clock, strikes and poses out over OSC (each strike time-tagged for exact
// scheduling), commands in. The physics loop never waits on the network and
// never touches the disk: strikes.csv is written by a thread of its own, a
// whole line at a time. docs/osc.md, docs/perform.md.
#include "ictus/base/realtime.hpp"
#include "ictus/base/spsc_queue.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/net/osc_sender.hpp"
#include "ictus/net/osc_server.hpp"
#include "ictus/perform/strike_log.hpp"
#include "ictus/sim/strike_event.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

namespace ictus
{
namespace cli
{

namespace
{

void run_usage(std::ostream &out)
{
    out << "usage: ictusd run [--mocap FILE | --score FILE] [options]\n"
           "\n"
           "Plays in real time, sends every strike to Pd as an OSC bundle time-tagged for\n"
           "exact scheduling, streams poses for graphics, and listens for commands (play,\n"
           "stop, score statements, mode, grip, drum ...). See docs/osc.md, docs/perform.md.\n"
           "With --mocap: the clip in joint space (eq. 1). Otherwise score mode: the score\n"
           "(--score FILE, default: the built-in score) is planned into stick-tip targets and\n"
           "performed (Cartesian mode by default); /ictus/score statements replace it at the\n"
           "next /ictus/play.\n"
           "\n"
           "The performer waits, sticks at rest (a clip: on its first frame), for\n"
           "/ictus/play (the patch's play button, or a score box), so that nothing is over\n"
           "before the patch is open; --autoplay starts at once.\n"
           "\n"
           "  --target URL        where strikes and poses go: osc.udp://HOST:PORT, an IPv4\n"
           "                      address or a name that resolves to one, port 1 to 65535\n"
           "                      (default osc.udp://127.0.0.1:9000)\n"
           "  --port N            UDP port for commands (default 9001; 0: any free port)\n"
           "  --bind ADDR         address to listen on (default 127.0.0.1; another only when\n"
           "                      asked, e.g. --bind 0.0.0.0 with --allow)\n"
           "  --allow A,B,...     peers allowed to send commands, numeric IPv4 (default\n"
           "                      127.0.0.1); 'any': every peer (a warning unless --bind is\n"
           "                      a loopback address). Error replies: at most 20 at once\n"
           "                      and 10 a second to one address, the rest counted only\n"
           "  --reply URL         send replies here instead of to the sender\n"
           "  --lookahead S       strike timetag = start + time + S (default 0.02; 0: immediate)\n"
           "  --pose-rate HZ      pose stream rate (default 30; 0: off)\n"
           "  --tip-rate HZ       stick-tip state stream rate (default 0: off)\n"
           "  --autoplay          play at once (the score or the clip), without waiting for\n"
           "                      /ictus/play; stop it with /ictus/stop\n"
           "  --paused            wait for /ictus/play (the default; kept for old scripts)\n"
           "  --realtime          SCHED_FIFO for the physics loop and the strike sender (when\n"
           "                      the system allows it): no late strike on a busy machine, but\n"
           "                      a physics loop slower than real time then holds a core\n"
           "  --duration S        stop after S simulated seconds (default: until SIGINT)\n"
           "  --out DIR           also write DIR/strikes.csv, each row whole as it is\n"
           "                      released; a write error (disk full) ends the run, exit 1\n"
           "  common options: see ictusd render --help\n"
           "\n"
           "examples:\n"
           "  ictusd run --reply osc.udp://127.0.0.1:9000   (then press play in patches/ictus.pd)\n"
           "  ictusd run --mocap ../shared/data/cmu/80_13.bvh --autoplay\n"
           "  ictusd run --score examples/scores/figure5.txt --mode cartesian\n"
           "  ictusd run --mocap clip.bvh --target osc.udp://10.0.0.2:9000 --bind 10.0.0.1 \\\n"
           "             --allow 10.0.0.2 --lookahead 0.05\n"
           "  oscsend localhost 9001 /ictus/tempo f 96\n";
}

// DIR/strikes.csv of a run, written by a thread of its own: the physics
// thread only posts (never blocks, never touches the file). Each row is
// formatted whole and handed to the kernel in one write(2) on an O_APPEND
// descriptor as soon as it is released, so that the file holds whole lines
// only, however the daemon ends (SIGKILL included). A failed or short write
// (ENOSPC, EIO, EFBIG) is fatal: the cut row is taken back, the writer stops,
// and failed() tells the physics loop to end the run. Stopped and joined on
// every way out of cmd_run. An empty path: no file.
class CsvWriter
{
  public:
    explicit CsvWriter(const std::string &path) : path_(path)
    {
        if (!path_.empty()) {
            fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
            if (fd_ < 0)
                throw std::runtime_error("--out: cannot open '" + path_ +
                                         "': " + std::strerror(errno));
            std::ostringstream header;
            write_strikes_csv_header(header);
            if (!append(header.str()))
                throw std::runtime_error("--out: cannot write '" + path_ +
                                         "': " + std::strerror(error_number_));
        }
        thread_ = std::thread([this] { loop(); });
    }
    ~CsvWriter() { stop(); }
    CsvWriter(const CsvWriter &) = delete;
    CsvWriter &operator=(const CsvWriter &) = delete;
    void post(const StrikeEvent &e)
    {
        if (fd_ >= 0 && !queue_.push(e))
            ++dropped_;
    }
    // Joins the thread and closes the file (a close error counts as a write error).
    void stop()
    {
        running_ = false;
        if (thread_.joinable())
            thread_.join();
        if (fd_ >= 0) {
            if (::close(fd_) != 0 && !failed_)
                fail(errno);
            fd_ = -1;
        }
    }
    bool failed() const { return failed_.load(std::memory_order_acquire); }
    // What failed, once failed() and stop().
    std::string error() const
    {
        return "--out: cannot write '" + path_ + "': " + std::strerror(error_number_) + " (after " +
               std::to_string(written_) + " rows; the run stopped)";
    }
    long written() const { return written_; }
    long dropped() const { return dropped_; }

  private:
    void loop()
    {
        StrikeEvent e;
        std::ostringstream row;
        for (;;) {
            const bool running = running_.load();
            while (!failed() && queue_.pop(e)) {
                row.str("");
                write_strike_csv_row(row, e);
                if (!append(row.str()))
                    break;
                ++written_;
            }
            if (!running || failed())
                return;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    }
    // One write(2) of the whole line; a second only after a short one, to
    // learn the error (a regular file writes all of a line or fails).
    bool append(const std::string &line)
    {
        std::size_t done = 0;
        while (done < line.size()) {
            const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
            if (n > 0) {
                done += static_cast<std::size_t>(n);
                continue;
            }
            if (n < 0 && errno == EINTR)
                continue;
            const int error = n < 0 ? errno : EIO;
            if (done > 0 && ::ftruncate(fd_, size_) != 0) {
                // /dev/full and pipes cannot be cut back: nothing more to do.
            }
            fail(error);
            return false;
        }
        size_ += static_cast<off_t>(line.size());
        return true;
    }
    void fail(int error_number)
    {
        error_number_ = error_number;
        failed_.store(true, std::memory_order_release);
    }
    std::string path_;
    int fd_ = -1;
    off_t size_ = 0; // bytes of whole lines written
    SpscQueue<StrikeEvent, 1024> queue_;
    std::atomic<bool> running_{true}, failed_{false};
    int error_number_ = 0; // the writer thread's until failed_ is set
    long written_ = 0;     // the writer thread's; read after stop()
    long dropped_ = 0;     // the physics thread's
    std::thread thread_;
};

} // namespace

int cmd_run(Args &args)
{
    PerformanceOptions o;
    OscSenderOptions so;
    so.lookahead_s = 0.02;
    OscServerOptions io;
    double duration = 0.0, pose_rate = 30.0, tip_rate = 0.0;
    bool autoplay = false, realtime = false;
    std::string out_dir;
    while (!args.done()) {
        const std::string a = args.next();
        auto value = [&]() { return args.value(a); };
        if (a == "--help" || a == "-h") {
            run_usage(std::cout);
            return 0;
        } else if (a == "--target") {
            so.target_url = value();
        } else if (a == "--port") {
            io.port = parse_int(a, value(), 0, 65535);
        } else if (a == "--bind") {
            io.bind_address = value();
        } else if (a == "--allow") {
            const std::string v = value();
            // An empty list (or item) must not mean "every peer": that is 'any'.
            if (v.empty() || v.front() == ',' || v.back() == ',' ||
                v.find(",,") != std::string::npos)
                throw UsageError("--allow: expected numeric IPv4 addresses A,B,... or 'any', "
                                 "got '" +
                                 v + "' (an empty list or item)");
            io.allow_any = v == "any";
            io.allow = io.allow_any ? std::vector<std::string>{} : split(v, ',');
        } else if (a == "--reply") {
            io.reply_url = value();
        } else if (a == "--lookahead") {
            so.lookahead_s = parse_number(a, value(), 0, 10);
        } else if (a == "--pose-rate") {
            pose_rate = parse_number(a, value(), 0, 1000);
        } else if (a == "--tip-rate") {
            tip_rate = parse_number(a, value(), 0, 1000);
        } else if (a == "--realtime") {
            realtime = true;
        } else if (a == "--paused") {
            autoplay = false;
        } else if (a == "--autoplay") {
            autoplay = true;
        } else if (a == "--out") {
            out_dir = value();
        } else if (!parse_performance_option(a, args, o, duration)) {
            throw UsageError("unknown option '" + a + "' (see ictusd run --help)");
        }
    }
    if (!o.mocap.empty() && !o.score.score_text.empty())
        throw UsageError("--score and --mocap are two motion sources: give one");
    // A numeric IPv4 address (the server checks it) in 127.0.0.0/8.
    if (io.allow_any && io.bind_address.compare(0, 4, "127.") != 0)
        std::cerr << "ictusd run: warning: --allow any with --bind " << io.bind_address
                  << ": every host that reaches this address may play, stop and change the "
                     "performance; list the peers with --allow A,B\n";
    // The target is checked before the clip loads: a bad URL is a usage error
    // at once (exit 2), not a run whose every send fails.
    so.realtime = realtime; // the strike thread asks for itself
    OscSender sender(so);
    std::string csv_path;
    if (!out_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(out_dir, ec);
        if (ec)
            throw std::runtime_error("--out: cannot create '" + out_dir + "': " + ec.message());
        csv_path = out_dir + "/strikes.csv";
    }
    // Opened (and its header written) before the clip loads: an unwritable
    // folder or a full disk shows at once.
    CsvWriter writer(csv_path);

    Performance perf(o);
    // Every refusal goes to stderr and, as /ictus/error, to the client.
    OscServer *server_ptr = nullptr;
    auto refuse = [&](std::uint32_t ipv4, std::uint16_t port, const char *address,
                      const char *why) {
        std::fprintf(stderr, "ictusd run: %s%s%s\n", address, address[0] ? ": " : "", why);
        Refusal f;
        f.peer_ipv4 = ipv4;
        f.peer_port = port;
        std::snprintf(f.address, sizeof f.address, "%s", address);
        std::snprintf(f.why, sizeof f.why, "%s", why);
        if (server_ptr)
            server_ptr->post_refusal(f);
    };
    // Waits for /ictus/play unless --autoplay (docs/osc.md, "Starting").
    if (!autoplay) {
        Command stop;
        stop.kind = CommandKind::stop;
        perf.apply(stop);
    } else if (perf.score_mode()) {
        perf.start_score(); // a score that cannot be played ends here, exit 1
    }
    LiveStatus status;
    status.tempo_bpm = o.tempo_bpm;
    status.score = perf.score_mode() ? 1 : 0;
    status.mode = static_cast<int>(perf.mode());
    status.grip = static_cast<int>(perf.options().character.grip);
    OscServer server(io, &status);
    server_ptr = &server;
    // Planning and rebuilds from now on run beside the physics loop.
    perf.set_background_work(true);
    std::cerr << "ictusd run: commands on " << io.bind_address << ":" << server.port()
              << ", strikes and poses to " << so.target_url << "\n";
    g_interrupted = 0;
    install_interrupt_handler(true);

    // The physics loop and the strike sender keep time: real-time
    // scheduling when the system grants it (docs/osc.md, "Real time"). Asked
    // for after the other threads exist, which keep ordinary scheduling.
    if (realtime) {
        std::string why;
        if (!set_realtime_priority(kPhysicsPriority, &why))
            std::fprintf(stderr,
                         "ictusd run: note: no real-time scheduling (%s); on a busy machine "
                         "strikes may arrive late (raise --lookahead, or allow rtprio)\n",
                         why.c_str());
    }
    using clock = std::chrono::steady_clock;
    const double h = perf.step_s();
    const auto period =
        std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(h));
    const long pose_every = pose_rate > 0.0 ? std::max(1L, std::lround(1.0 / (pose_rate * h))) : 0;
    const long tip_every = tip_rate > 0.0 ? std::max(1L, std::lround(1.0 / (tip_rate * h))) : 0;
    const long steps = duration > 0.0 ? std::lround(duration / h) : -1;
    // Simulation time 0 is now, on the wall clock and in NTP.
    auto wall0 = clock::now();
    sender.set_epoch(ntp_now());
    // strikes.csv in onset order, as track and render write it.
    StrikeOrder order;
    auto to_file = [&](const StrikeEvent &e) { writer.post(e); };
    StrikeEvent ev[2];
    long n = 0;
    for (; steps < 0 || n < steps; ++n) {
        if (g_interrupted || writer.failed())
            break;
        // Pace: step n starts at wall0 + n h. Far behind (a stall), move
        // the anchor, so that timetags stay ahead of the wall clock.
        const auto due = wall0 + n * period;
        const auto now = clock::now();
        if (now < due) {
            std::this_thread::sleep_until(due);
        } else if (now - due > 50 * period) {
            const auto lag = now - due;
            wall0 += lag;
            sender.set_epoch(
                ntp_add_seconds(sender.epoch(), std::chrono::duration<double>(lag).count()));
            status.overruns++;
        }
        Command c;
        while (server.pop_command(c)) {
            std::string why;
            if (!perf.apply(c, &why))
                refuse(c.peer_ipv4, c.peer_port, c.address, why.c_str());
        }
        const int k = perf.step(ev);
        // Refusals found later (a score the worker could not plan, the
        // runaway guard) reach the client too.
        for (Refusal f; perf.pop_refusal(f);)
            refuse(f.peer_ipv4, f.peer_port, f.address, f.why);
        // A strike leaves at its onset with what the sound needs, so that
        // the lookahead covers only transport and jitter; its force and
        // duration follow at the release.
        StrikeEvent onset[2];
        const int ons = perf.take_onsets(onset);
        for (int i = 0; i < ons; ++i)
            sender.post_strike(onset[i]);
        for (int i = 0; i < k; ++i) {
            sender.post_strike_end(ev[i]);
            order.push(ev[i], to_file);
        }
        order.release(perf.detector().first_open_seq(), to_file);
        if (pose_every && n % pose_every == 0) {
            PoseSnapshot p;
            perf.pose(p);
            sender.post_pose(p);
        }
        if (tip_every && n % tip_every == 0)
            for (int hand = 0; hand < 2; ++hand) {
                TipState t;
                perf.tip(hand, t);
                sender.post_tip(t);
            }
        status.time_s = perf.time_s();
        status.playing = perf.playing() ? 1 : 0;
        status.tempo_bpm = perf.tempo_bpm();
        status.strikes += k;
        status.runaways = perf.runaways();
        status.mode = static_cast<int>(perf.mode());
        status.grip = static_cast<int>(perf.options().character.grip);
    }
    StrikeEvent last;
    while (perf.flush(last)) {
        sender.post_strike_end(last);
        order.push(last, to_file);
    }
    order.flush(to_file);
    sender.stop();
    server.stop();
    writer.stop();
    const OscSenderCounters sc = sender.counters();
    const OscServerCounters rc = server.counters();
    std::cout << "run: " << perf.time_s() << " s simulated, " << sc.strikes_sent
              << " strikes sent (" << sc.strikes_dropped << " dropped), " << sc.poses_sent
              << " poses, " << sc.send_errors << " send errors; " << rc.packets << " packets in, "
              << rc.accepted << " accepted, " << rc.errors() << " errors (" << rc.errors_unanswered
              << " unanswered: error-reply budget), " << rc.refused_peers << " refused; "
              << status.overruns.load() << " overruns, " << perf.runaways() << " runaways";
    if (!csv_path.empty())
        std::cout << "; strikes.csv: " << writer.written() << " rows, " << writer.dropped()
                  << " dropped (queue full), " << order.early() << " out of order";
    std::cout << "\n";
    if (writer.failed())
        throw std::runtime_error(writer.error()); // exit 1
    return g_interrupted ? 130 : 0;
}

} // namespace cli
} // namespace ictus
