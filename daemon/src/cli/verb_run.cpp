// `ictusd run`: the performance in real time: physics paced by the wall
// clock, strikes and poses out over OSC (each strike time-tagged for exact
// scheduling), commands in. The physics loop never waits on the network and
// never touches the disk: strikes.csv is written by a thread of its own.
// docs/osc.md, docs/perform.md.
#include "ictus/base/spsc_queue.hpp"
#include "ictus/cli/verbs.hpp"
#include "ictus/net/osc_sender.hpp"
#include "ictus/net/osc_server.hpp"
#include "ictus/perform/strike_log.hpp"
#include "ictus/sim/strike_event.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
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
           "  --target URL        where strikes and poses go (default osc.udp://127.0.0.1:9000)\n"
           "  --port N            UDP port for commands (default 9001; 0: any free port)\n"
           "  --bind ADDR         address to listen on (default 127.0.0.1; another only when\n"
           "                      asked, e.g. --bind 0.0.0.0 with --allow)\n"
           "  --allow A,B,...     peers allowed to send commands (default 127.0.0.1; 'any')\n"
           "  --reply URL         send replies here instead of to the sender\n"
           "  --lookahead S       strike timetag = start + time + S (default 0.02; 0: immediate)\n"
           "  --pose-rate HZ      pose stream rate (default 30; 0: off)\n"
           "  --tip-rate HZ       stick-tip state stream rate (default 0: off)\n"
           "  --paused            wait for /ictus/play\n"
           "  --duration S        stop after S simulated seconds (default: until SIGINT)\n"
           "  --out DIR           also write DIR/strikes.csv\n"
           "  common options: see ictusd render --help\n"
           "\n"
           "examples:\n"
           "  ictusd run --mocap ../shared/data/cmu/80_13.bvh\n"
           "  ictusd run --score examples/scores/figure5.score --mode cartesian\n"
           "  ictusd run --mocap clip.bvh --target osc.udp://10.0.0.2:9000 --bind 10.0.0.1 \\\n"
           "             --allow 10.0.0.2 --lookahead 0.05\n"
           "  oscsend localhost 9001 /ictus/tempo f 96\n";
}

// strikes.csv of a run, written by a thread of its own: the physics thread
// only posts (never blocks, never touches the file). Stopped and joined on
// every way out of cmd_run.
class CsvWriter
{
  public:
    explicit CsvWriter(std::ostream *out) : out_(out), thread_([this] { loop(); }) {}
    ~CsvWriter() { stop(); }
    CsvWriter(const CsvWriter &) = delete;
    CsvWriter &operator=(const CsvWriter &) = delete;
    void post(const StrikeEvent &e)
    {
        if (out_ && !queue_.push(e))
            ++dropped_;
    }
    void stop()
    {
        running_ = false;
        if (thread_.joinable())
            thread_.join();
    }
    long written() const { return written_; }
    long dropped() const { return dropped_; }

  private:
    void loop()
    {
        StrikeEvent e;
        for (;;) {
            const bool running = running_.load();
            while (queue_.pop(e)) {
                write_strike_csv_row(*out_, e);
                ++written_;
            }
            if (!running)
                return;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    }
    std::ostream *out_;
    SpscQueue<StrikeEvent, 1024> queue_;
    std::atomic<bool> running_{true};
    long written_ = 0; // the writer thread's; read after stop()
    long dropped_ = 0; // the physics thread's
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
    bool paused = false;
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
            io.port = static_cast<int>(parse_number(a, value(), 0, 65535));
        } else if (a == "--bind") {
            io.bind_address = value();
        } else if (a == "--allow") {
            const std::string v = value();
            io.allow = v == "any" ? std::vector<std::string>{} : split(v, ',');
        } else if (a == "--reply") {
            io.reply_url = value();
        } else if (a == "--lookahead") {
            so.lookahead_s = parse_number(a, value(), 0, 10);
        } else if (a == "--pose-rate") {
            pose_rate = parse_number(a, value(), 0, 1000);
        } else if (a == "--tip-rate") {
            tip_rate = parse_number(a, value(), 0, 1000);
        } else if (a == "--paused") {
            paused = true;
        } else if (a == "--out") {
            out_dir = value();
        } else if (!parse_performance_option(a, args, o, duration)) {
            throw UsageError("unknown option '" + a + "' (see ictusd run --help)");
        }
    }
    if (!o.mocap.empty() && !o.score.score_text.empty())
        throw UsageError("--score and --mocap are two motion sources: give one");
    std::unique_ptr<OutputFile> csv;
    if (!out_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(out_dir, ec);
        if (ec)
            throw std::runtime_error("--out: cannot create '" + out_dir + "': " + ec.message());
        csv = std::make_unique<OutputFile>(out_dir + "/strikes.csv");
        write_strikes_csv_header(csv->stream());
    }

    Performance perf(o);
    if (paused) {
        Command stop;
        stop.kind = CommandKind::stop;
        perf.apply(stop);
    } else if (perf.score_mode()) {
        perf.start_score(); // a score that cannot be played ends here, exit 1
    }
    LiveStatus status;
    status.tempo_bpm = o.tempo_bpm;
    OscServer server(io, &status);
    OscSender sender(so);
    // strikes.csv is written by a thread of its own: the physics thread
    // never touches a file.
    CsvWriter writer(csv ? &csv->stream() : nullptr);
    std::cerr << "ictusd run: commands on " << io.bind_address << ":" << server.port()
              << ", strikes and poses to " << so.target_url << "\n";
    g_interrupted = 0;
    install_interrupt_handler(true);

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
        if (g_interrupted)
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
                std::fprintf(stderr, "ictusd run: %s\n", why.c_str());
        }
        const int k = perf.step(ev);
        for (int i = 0; i < k; ++i) {
            sender.post_strike(ev[i]);
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
    }
    StrikeEvent last;
    while (perf.flush(last)) {
        sender.post_strike(last);
        order.push(last, to_file);
    }
    order.flush(to_file);
    sender.stop();
    server.stop();
    writer.stop();
    if (csv)
        csv->close();
    const OscSenderCounters sc = sender.counters();
    const OscServerCounters rc = server.counters();
    std::cout << "run: " << perf.time_s() << " s simulated, " << sc.strikes_sent
              << " strikes sent (" << sc.strikes_dropped << " dropped), " << sc.poses_sent
              << " poses, " << sc.send_errors << " send errors; " << rc.packets << " packets in, "
              << rc.accepted << " accepted, " << rc.errors() << " errors, " << rc.refused_peers
              << " refused; " << status.overruns.load() << " overruns";
    if (csv)
        std::cout << "; strikes.csv: " << writer.written() << " rows, " << writer.dropped()
                  << " dropped (queue full), " << order.early() << " out of order";
    std::cout << "\n";
    return g_interrupted ? 130 : 0;
}

} // namespace cli
} // namespace ictus
