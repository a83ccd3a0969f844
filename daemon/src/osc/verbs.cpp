// `ictusd run` and `ictusd render` (verbs_osc.hpp, docs/osc.md).
#include "ictus/verbs_osc.hpp"

#include "ictus/mocap_error.hpp"

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace ictus
{

namespace
{

volatile std::sig_atomic_t g_osc_interrupted = 0;
void on_sigint(int)
{
    g_osc_interrupted = 1;
}

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

void run_usage(std::ostream &out)
{
    out << "usage: ictusd run --mocap FILE [options]\n"
           "\n"
           "Plays the clip in real time (joint space, eq. 1), sends every strike to Pd as an\n"
           "OSC bundle time-tagged for exact scheduling, streams poses for graphics, and\n"
           "listens for commands (play, stop, tempo, grip, drum ...). See docs/osc.md.\n"
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
           "  ictusd run --mocap clip.bvh --target osc.udp://10.0.0.2:9000 --bind 10.0.0.1 \\\n"
           "             --allow 10.0.0.2 --lookahead 0.05\n"
           "  oscsend localhost 9001 /ictus/tempo f 96\n";
}

void render_usage(std::ostream &out)
{
    out << "usage: ictusd render --mocap FILE --out DIR [options]\n"
           "\n"
           "Plays the clip offline, as fast as possible and deterministically (same input,\n"
           "same bytes), and writes DIR/strikes.csv, DIR/events.txt (qlist lines for a Pd\n"
           "batch patch) and DIR/render.json (drum parameters for membrane~). docs/osc.md.\n"
           "\n"
           "common options (run and render):\n"
           "  --mocap FILE        BVH file with CMU joint names\n"
           "  --scale M           metres per BVH unit (default 0.056444)\n"
           "  --skip-frames N     frames dropped at the start (default 1)\n"
           "  --duration S        simulated seconds (render default: the clip's length)\n"
           "  --step S            physics step (default 0.001)\n"
           "  --grip G            french | german\n"
           "  --tempo BPM         playback tempo (default 120)\n"
           "  --clip-bpm BPM      tempo at which the clip plays at its own speed (default 120)\n"
           "  --drum-pos X,Y,Z    membrane centre (default: under the clip's lowest tips)\n"
           "  --drum-radius M     (default 0.178)\n"
           "  --drum-tension N/M  (default 3000)\n"
           "  --drum-density KG/M2  for the sound (default 0.26)\n"
           "  --bounce-height M   bounce rule height (default 0.01)\n"
           "  --bounce-window S   bounce rule window (default 0.15)\n"
           "\n"
           "example:\n"
           "  ictusd render --mocap ../shared/data/cmu/80_13.bvh --duration 10 --out out/r1\n";
}

double parse_number(const std::string &option, const std::string &text, double lo, double hi)
{
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v) || v < lo || v > hi) {
        std::ostringstream s;
        s << option << ": expected a number in [" << lo << ", " << hi << "], got '" << text << "'";
        throw UsageError(s.str());
    }
    return v;
}

std::vector<std::string> split(const std::string &text, char sep)
{
    std::vector<std::string> parts;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, sep))
        parts.push_back(part);
    return parts;
}

// Options shared by run and render. Returns false when `a` is not one of them.
bool common_option(const std::string &a, int &i, int argc, char **argv, PerformanceOptions &o,
                   double &duration)
{
    auto value = [&]() -> std::string {
        if (i + 1 >= argc)
            throw UsageError(a + ": missing value");
        return argv[++i];
    };
    if (a == "--mocap")
        o.mocap = value();
    else if (a == "--scale")
        o.scale_m_per_unit = parse_number(a, value(), 1e-6, 1e3);
    else if (a == "--skip-frames")
        o.skip_frames = static_cast<int>(parse_number(a, value(), 0, 1e8));
    else if (a == "--duration")
        duration = parse_number(a, value(), 1e-3, 1e7);
    else if (a == "--step")
        o.scene.step_s = parse_number(a, value(), 1e-5, 0.01);
    else if (a == "--grip") {
        const std::string g = value();
        if (g != "french" && g != "german")
            throw UsageError("--grip: expected french or german, got '" + g + "'");
        o.character.grip = grip_from_string(g);
    } else if (a == "--tempo")
        o.tempo_bpm = parse_number(a, value(), 20, 400);
    else if (a == "--clip-bpm")
        o.clip_bpm = parse_number(a, value(), 20, 400);
    else if (a == "--drum-pos") {
        const std::vector<std::string> p = split(value(), ',');
        if (p.size() != 3)
            throw UsageError("--drum-pos: expected X,Y,Z");
        for (int k = 0; k < 3; ++k)
            o.scene.drum.center_m[k] = parse_number(a, p[k], -100, 100);
        o.drum_auto = false;
    } else if (a == "--drum-radius")
        o.scene.drum.radius_m = parse_number(a, value(), 0.05, 1.0);
    else if (a == "--drum-tension")
        o.scene.drum.tension_n_per_m = parse_number(a, value(), 10, 1e5);
    else if (a == "--drum-density")
        o.drum_density_kg_per_m2 = parse_number(a, value(), 0.01, 10);
    else if (a == "--bounce-height")
        o.strikes.bounce_height_m = parse_number(a, value(), 0, 1);
    else if (a == "--bounce-window")
        o.strikes.bounce_window_s = parse_number(a, value(), 0, 10);
    else
        return false;
    return true;
}

nlohmann::json drum_json(const Performance &p)
{
    const DrumParams &d = p.scene().options().drum;
    nlohmann::json j;
    j["center_m"] = {d.center_m.x(), d.center_m.y(), d.center_m.z()};
    j["radius_m"] = d.radius_m;
    j["tension_n_per_m"] = d.tension_n_per_m;
    j["density_kg_per_m2"] = p.options().drum_density_kg_per_m2;
    j["contact_stiffness_n_per_m"] = p.detector().membrane().stiffness_n_per_m;
    j["contact_damping_n_s_per_m"] = d.contact_damping_n_s_per_m;
    return j;
}

template <typename Fn> int guarded(const char *verb, Fn fn)
{
    try {
        return fn();
    } catch (const UsageError &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 2;
    } catch (const OscError &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 2;
    } catch (const std::exception &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 1;
    }
}

} // namespace

int cmd_render(int argc, char **argv)
{
    return guarded("render", [&]() {
        PerformanceOptions o;
        double duration = 0.0;
        std::string out_dir;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "--help" || a == "-h") {
                render_usage(std::cout);
                return 0;
            } else if (a == "--out") {
                if (i + 1 >= argc)
                    throw UsageError("--out: missing value");
                out_dir = argv[++i];
            } else if (!common_option(a, i, argc, argv, o, duration)) {
                throw UsageError("unknown option '" + a + "' (see ictusd render --help)");
            }
        }
        if (o.mocap.empty())
            throw UsageError("--mocap FILE is required");
        if (out_dir.empty())
            throw UsageError("--out DIR is required");
        std::error_code ec;
        std::filesystem::create_directories(out_dir, ec);
        if (ec)
            throw std::runtime_error("--out: cannot create '" + out_dir + "': " + ec.message());

        Performance perf(o);
        if (duration <= 0.0)
            duration = perf.clip_duration_s();
        std::ofstream csv(out_dir + "/strikes.csv"), events(out_dir + "/events.txt");
        if (!csv || !events)
            throw std::runtime_error("--out: cannot write in '" + out_dir + "'");
        write_strikes_csv_header(csv);
        const auto wall0 = std::chrono::steady_clock::now();
        std::signal(SIGINT, on_sigint);
        const double h = perf.step_s();
        const long steps = std::max(1L, std::lround(duration / h));
        StrikeEvent ev[2];
        double previous = 0.0;
        long strikes = 0, bounces = 0;
        // Strikes end (and are reported) at their release, not in onset order
        // across the two hands: collected and written in onset order (seq).
        std::vector<StrikeEvent> all;
        auto emit = [&](const StrikeEvent &e) { all.push_back(e); };
        bool interrupted = false;
        for (long n = 0; n < steps; ++n) {
            if (g_osc_interrupted) {
                interrupted = true;
                break;
            }
            const int k = perf.step(ev);
            for (int i = 0; i < k; ++i)
                emit(ev[i]);
        }
        StrikeEvent last;
        while (perf.flush(last))
            emit(last);
        std::sort(all.begin(), all.end(),
                  [](const StrikeEvent &a, const StrikeEvent &b) { return a.seq < b.seq; });
        for (const StrikeEvent &e : all) {
            write_strike_csv_row(csv, e);
            write_events_line(events, e, previous);
            previous = e.time_s;
            ++strikes;
            bounces += e.bounce ? 1 : 0;
        }
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        nlohmann::json j;
        j["mocap"] = o.mocap;
        j["duration_s"] = perf.time_s();
        j["step_s"] = h;
        j["strikes"] = strikes;
        j["bounces"] = bounces;
        j["divergences"] = perf.divergences();
        j["side_entries"] = perf.detector().side_entries();
        j["grip"] = to_string(o.character.grip);
        j["tempo_bpm"] = o.tempo_bpm;
        j["drum"] = drum_json(perf);
        std::ofstream js(out_dir + "/render.json");
        js << j.dump(2) << "\n";
        csv.close();
        events.close();
        if (!js || !csv || !events)
            throw std::runtime_error("--out: error writing in '" + out_dir + "'");
        std::cout << "render: " << perf.time_s() << " s simulated in " << wall << " s ("
                  << perf.time_s() / std::max(wall, 1e-9) << "x real time), " << strikes
                  << " strikes (" << bounces << " bounces), wrote " << out_dir
                  << "/{strikes.csv,events.txt,render.json}\n";
        return interrupted ? 130 : 0;
    });
}

int cmd_run(int argc, char **argv)
{
    return guarded("run", [&]() {
        PerformanceOptions o;
        OscSenderOptions so;
        so.lookahead_s = 0.02;
        OscServerOptions io;
        double duration = 0.0, pose_rate = 30.0, tip_rate = 0.0;
        bool paused = false;
        std::string out_dir;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc)
                    throw UsageError(a + ": missing value");
                return argv[++i];
            };
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
            } else if (!common_option(a, i, argc, argv, o, duration)) {
                throw UsageError("unknown option '" + a + "' (see ictusd run --help)");
            }
        }
        if (o.mocap.empty())
            throw UsageError("--mocap FILE is required");
        std::ofstream csv;
        if (!out_dir.empty()) {
            std::error_code ec;
            std::filesystem::create_directories(out_dir, ec);
            csv.open(out_dir + "/strikes.csv");
            if (ec || !csv)
                throw std::runtime_error("--out: cannot write '" + out_dir + "/strikes.csv'");
            write_strikes_csv_header(csv);
        }

        Performance perf(o);
        LiveStatus status;
        status.tempo_bpm = o.tempo_bpm;
        OscServer server(io, &status);
        OscSender sender(so);
        // strikes.csv is written by a thread of its own: the physics thread
        // never touches a file.
        SpscQueue<StrikeEvent, 1024> to_csv;
        std::atomic<bool> csv_running{true};
        std::thread csv_thread([&]() {
            StrikeEvent e;
            for (;;) {
                const bool running = csv_running.load();
                while (to_csv.pop(e))
                    if (csv.is_open())
                        write_strike_csv_row(csv, e);
                if (!running)
                    return;
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
            }
        });
        if (paused) {
            Command stop;
            stop.kind = CommandKind::stop;
            perf.apply(stop);
        }
        std::cerr << "ictusd run: commands on " << io.bind_address << ":" << server.port()
                  << ", strikes and poses to " << so.target_url << "\n";
        g_osc_interrupted = 0;
        std::signal(SIGINT, on_sigint);
        std::signal(SIGTERM, on_sigint);

        using clock = std::chrono::steady_clock;
        const double h = perf.step_s();
        const auto period =
            std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(h));
        const long pose_every =
            pose_rate > 0.0 ? std::max(1L, std::lround(1.0 / (pose_rate * h))) : 0;
        const long tip_every = tip_rate > 0.0 ? std::max(1L, std::lround(1.0 / (tip_rate * h))) : 0;
        const long steps = duration > 0.0 ? std::lround(duration / h) : -1;
        // Simulation time 0 is now, on the wall clock and in NTP.
        auto wall0 = clock::now();
        sender.set_epoch(ntp_now());
        StrikeEvent ev[2];
        long n = 0;
        for (; steps < 0 || n < steps; ++n) {
            if (g_osc_interrupted)
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
                to_csv.push(ev[i]);
            }
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
            to_csv.push(last);
        }
        sender.stop();
        server.stop();
        csv_running = false;
        csv_thread.join();
        const OscSenderCounters sc = sender.counters();
        const OscServerCounters rc = server.counters();
        std::cout << "run: " << perf.time_s() << " s simulated, " << sc.strikes_sent
                  << " strikes sent (" << sc.strikes_dropped << " dropped), " << sc.poses_sent
                  << " poses, " << sc.send_errors << " send errors; " << rc.packets
                  << " packets in, " << rc.accepted << " accepted, " << rc.errors() << " errors, "
                  << rc.refused_peers << " refused; " << status.overruns.load() << " overruns\n";
        return g_osc_interrupted ? 130 : 0;
    });
}

} // namespace ictus
