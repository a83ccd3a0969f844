// `ictusd run`: the performance in real time (perform/realtime_loop.hpp),
// wired to the network: strikes and poses out over OSC (each strike
// time-tagged for exact scheduling), commands in. The physics loop never
// waits on the network and never touches the disk: strikes.csv is written by
// a thread of its own, a whole line at a time. docs/osc.md, docs/perform.md.
#include "ictus/base/spsc_queue.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/net/osc_sender.hpp"
#include "ictus/net/osc_server.hpp"
#include "ictus/perform/kit.hpp"
#include "ictus/perform/realtime_loop.hpp"
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
    out << "usage: ictusd run [--mocap FILE | --score FILE | --midi FILE] [options]\n"
           "\n"
           "Plays in real time, sends every strike to Pd as an OSC bundle time-tagged for\n"
           "exact scheduling, streams poses for graphics, and listens for commands (play,\n"
           "stop, score statements, mode, grip, drum ...). See docs/osc.md, docs/perform.md.\n"
           "With --mocap: the clip in joint space (eq. 1). Otherwise score mode: the score\n"
           "(--score FILE, or --midi FILE: a Standard MIDI File's drum part, docs/midi.md;\n"
           "default: the built-in score) is planned into stick-tip targets and\n"
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
           "  --duration S        stop after S simulated seconds (default: until SIGINT,\n"
           "                      SIGTERM or SIGHUP: exit 130)\n"
           "  --out DIR           also write DIR/strikes.csv, each row whole as it is\n"
           "                      released; a write error (disk full) ends the run, exit 1;\n"
           "                      a render's folder is refused (its other files would\n"
           "                      pass for this run's)\n"
           "  --force             take a render's folder as --out: render's own files\n"
           "                      there are removed first\n"
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

// What `ictusd run` gives the real-time loop: commands from the OSC server,
// refusals back to it, strikes, poses and tip states to the OSC sender,
// strikes.csv rows to the writer. Each call only posts to a queue.
class OscIo : public RealtimeIo
{
  public:
    OscIo(OscSender &sender, OscServer &server, CsvWriter &writer, AsyncLog &log)
        : sender_(sender), server_(server), writer_(writer), log_(log)
    {
    }
    // A play sends the kit first (the sound's drums, docs/osc.md): a patch opened
    // after the daemon has it before the first strike.
    bool next_command(Command &out) override
    {
        if (!server_.pop_command(out))
            return false;
        if (out.kind == CommandKind::play)
            sender_.send_kit();
        return true;
    }
    void accepted(const Command &command) override { server_.post_accepted(command); }
    void refused(const Refusal &refusal) override { server_.post_refusal(refusal); }
    void log(const char *line) override { log_.post(line); }
    void strike_onset(const StrikeEvent &strike) override { sender_.post_strike(strike); }
    void strike_end(const StrikeEvent &strike) override { sender_.post_strike_end(strike); }
    void strike_logged(const StrikeEvent &strike) override { writer_.post(strike); }
    void pose(const PoseSnapshot &pose) override { sender_.post_pose(pose); }
    void tip(const TipState &tip) override { sender_.post_tip(tip); }
    void clock_started() override { sender_.set_epoch(ntp_now()); }
    void clock_slipped(double lag_s) override
    {
        sender_.set_epoch(ntp_add_seconds(sender_.epoch(), lag_s));
    }
    bool stop_requested() override { return g_interrupted || writer_.failed(); }

  private:
    OscSender &sender_;
    OscServer &server_;
    CsvWriter &writer_;
    AsyncLog &log_;
};

struct RunOptions {
    PerformanceOptions performance;
    OscSenderOptions sender;
    OscServerOptions server;
    RealtimeLoopOptions loop;
    bool autoplay = false;
    std::string out_dir;
    bool force = false; // --out: a render's folder taken, its files removed
    RunOptions() { sender.lookahead_s = 0.02; }
};

// --allow A,B,...: an empty list (or item) must not mean "every peer": that is 'any'.
void parse_allow(const std::string &v, OscServerOptions &io)
{
    if (v.empty() || v.front() == ',' || v.back() == ',' || v.find(",,") != std::string::npos)
        throw UsageError("--allow: expected numeric IPv4 addresses A,B,... or 'any', got '" + v +
                         "' (an empty list or item)");
    io.allow_any = v == "any";
    io.allow = io.allow_any ? std::vector<std::string>{} : split(v, ',');
}

// False: --help was given (the usage is printed).
// run's own options (parse_performance_option has the shared ones).
OptionTable run_options(RunOptions &r)
{
    return {
        {"--target", store_text(r.sender.target_url)},
        {"--port", store(r.server.port, parse_int, 0, 65535)},
        {"--bind", store_text(r.server.bind_address)},
        {"--allow",
         [&r](const std::string &a, Args &args) { parse_allow(args.value(a), r.server); }},
        {"--reply", store_text(r.server.reply_url)},
        {"--lookahead", store(r.sender.lookahead_s, parse_number, 0.0, 10.0)},
        {"--pose-rate", store(r.loop.pose_rate_hz, parse_number, 0.0, 1000.0)},
        {"--tip-rate", store(r.loop.tip_rate_hz, parse_number, 0.0, 1000.0)},
        {"--realtime", store_flag(r.loop.realtime)},
        {"--paused", [&r](const std::string &, Args &) { r.autoplay = false; }},
        {"--autoplay", [&r](const std::string &, Args &) { r.autoplay = true; }},
        {"--out", store_text(r.out_dir)},
        {"--force", store_flag(r.force)},
    };
}

bool parse_run_args(Args &args, RunOptions &r)
{
    const OptionTable options = run_options(r);
    const bool go_on = walk_args(args, run_usage, [&](const std::string &a) {
        if (!dispatch_option(options, a, args) &&
            !parse_performance_option(a, args, r.performance, r.loop.duration_s))
            throw UsageError("unknown option '" + a + "' (see ictusd run --help)");
    });
    if (!go_on)
        return false;
    load_midi_score(r.performance);
    if (!r.server.reply_url.empty()) // as --target's, before anything loads
        check_osc_udp_url("--reply", r.server.reply_url);
    return true;
}

// The kit's drums as the sound plays them (none without a kit): each drum's
// preset and head as the scene has them, panned by its place.
std::vector<KitDrumSound> kit_sounds(const Performance &perf)
{
    std::vector<KitDrumSound> drums;
    const Kit &kit = perf.options().kit;
    for (int i = 0; i < static_cast<int>(kit.drums.size()); ++i) {
        const KitDrum &k = kit.drums[static_cast<size_t>(i)];
        if (i < perf.scene().drum_count()) {
            const DrumParams &d = perf.scene().drum(i);
            drums.push_back(
                {i, k.name, k.preset, d.radius_m, d.tension_n_per_m, kit_drum_pan(k), k.midi_note});
        } else if (k.foot) { // the kick: not in the sticks' scene
            drums.push_back(
                {i, k.name, k.preset, k.radius_m, k.tension_n_per_m, kit_drum_pan(k), k.midi_note});
        }
    }
    return drums;
}

// DIR/strikes.csv, DIR created (a render's folder refused unless --force);
// empty without --out.
std::string strikes_csv_path(const std::string &out_dir, bool force)
{
    if (out_dir.empty())
        return "";
    prepare_run_out_dir(out_dir, force);
    return out_dir + "/strikes.csv";
}

void print_summary(const Performance &perf, const OscSender &sender, const OscServer &server,
                   const LiveStatus &status, const CsvWriter &writer, bool csv,
                   const RealtimeLoopResult &loop)
{
    const OscSenderCounters sc = sender.counters();
    const OscServerCounters rc = server.counters();
    std::cout << "run: " << perf.time_s() << " s simulated, " << sc.strikes_sent
              << " strikes sent (" << sc.strikes_dropped << " dropped), " << sc.poses_sent
              << " poses, " << sc.send_errors << " send errors; " << rc.packets << " packets in, "
              << rc.accepted << " accepted, " << rc.errors() << " errors (" << rc.errors_unanswered
              << " unanswered: error-reply budget), " << rc.refused_peers << " refused; "
              << status.overruns.load() << " overruns, " << perf.runaways() << " runaways, "
              << perf.whips() << " whips (" << perf.withheld_strikes() << " strikes held back), "
              << perf.refused_statements() << " score statements refused";
    if (csv)
        std::cout << "; strikes.csv: " << writer.written() << " rows, " << writer.dropped()
                  << " dropped (queue full), " << loop.out_of_order << " out of order";
    std::cout << "\n";
}

} // namespace

int cmd_run(Args &args)
{
    RunOptions r;
    if (!parse_run_args(args, r))
        return 0;
    const OscServerOptions &io = r.server;
    // A numeric IPv4 address (the server checks it) in 127.0.0.0/8.
    if (io.allow_any && io.bind_address.compare(0, 4, "127.") != 0)
        std::cerr << "ictusd run: warning: --allow any with --bind " << io.bind_address
                  << ": every host that reaches this address may play, stop and change the "
                     "performance; list the peers with --allow A,B\n";
    // The target is checked before the clip loads: a bad URL is a usage error
    // at once (exit 2), not a run whose every send fails.
    r.sender.realtime = r.loop.realtime; // the strike thread asks for itself
    OscSender sender(r.sender);
    const std::string csv_path = strikes_csv_path(r.out_dir, r.force);
    // Opened (and its header written) before the clip loads: an unwritable
    // folder or a full disk shows at once.
    CsvWriter writer(csv_path);

    Performance perf(r.performance);
    // Waits for /ictus/play unless --autoplay (docs/osc.md, "Starting").
    if (!r.autoplay) {
        // The score (--score, --midi, the built-in) is planned once now: one that
        // cannot be played ends here, exit 1, as with --autoplay and in render.
        if (perf.score_mode())
            perf.check_score();
        Command stop;
        stop.kind = CommandKind::stop;
        perf.apply(stop);
    } else if (perf.score_mode()) {
        perf.start_score(); // a score that cannot be played ends here, exit 1
    }
    sender.set_kit(perf.options().kit.name, kit_sounds(perf));
    sender.send_kit(); // for a patch already listening; again at each play
    LiveStatus status;
    begin_status(perf, status);
    // The log of the physics and server threads (base/async_log.hpp).
    AsyncLog log;
    r.server.log = &log;
    OscServer server(io, &status);
    // Planning and rebuilds from now on run beside the physics loop.
    perf.set_background_work(true);
    std::cerr << "ictusd run: commands on " << io.bind_address << ":" << server.port()
              << ", strikes and poses to " << r.sender.target_url << "\n";

    OscIo osc(sender, server, writer, log);
    const RealtimeLoopResult loop = run_realtime(perf, osc, status, r.loop);
    sender.stop();
    server.stop();
    writer.stop();
    log.stop();
    print_summary(perf, sender, server, status, writer, !csv_path.empty(), loop);
    if (writer.failed())
        throw std::runtime_error(writer.error()); // exit 1
    return g_interrupted ? 130 : 0;
}

} // namespace cli
} // namespace ictus
