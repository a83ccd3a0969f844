// The OSC link with real peers: liblo's oscdump receives what the sender
// emits, oscsend drives the server, raw UDP sockets fuzz it.
#include "ictus/character/character.hpp"
#include "ictus/net/osc_sender.hpp"
#include "ictus/net/osc_server.hpp"
#include "ictus/perform/tracker.hpp"
#include "ictus/score/score.hpp"
#include "support/osc_test_util.hpp"
#include "support/score_test_util.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <thread>

using namespace std::chrono_literals;
using osctest::Child;
using osctest::Peer;

namespace
{

// oscdump prints "<sec hex>.<frac hex> <path> <types> <args...>".
struct DumpLine {
    std::string timetag, path, types;
    std::vector<std::string> args;
};

DumpLine parse_dump(const std::string &line)
{
    DumpLine d;
    std::istringstream in(line);
    in >> d.timetag >> d.path >> d.types;
    std::string a;
    while (in >> a)
        d.args.push_back(a);
    return d;
}

std::string hex_timetag(ictus::NtpTime t)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%08" PRIx32 ".%08" PRIx32, static_cast<uint32_t>(t >> 32),
                  static_cast<uint32_t>(t & 0xffffffffu));
    return buf;
}

// Starts oscdump on a free port and waits until it prints a probe message.
std::unique_ptr<Child> start_oscdump(int &port)
{
    port = osctest::free_udp_port();
    auto dump =
        std::make_unique<Child>(std::vector<std::string>{"oscdump", "-L", std::to_string(port)});
    REQUIRE(dump->started());
    lo_address a = lo_address_new("127.0.0.1", std::to_string(port).c_str());
    std::string line;
    bool ready = false;
    for (int i = 0; i < 100 && !ready; ++i) {
        lo_send(a, "/probe", "");
        ready = dump->line(line, 100) && line.find("/probe") != std::string::npos;
    }
    lo_address_free(a);
    REQUIRE(ready);
    // Drain the extra probes.
    while (dump->line(line, 100)) {
    }
    return dump;
}

bool next_dump(Child &dump, const std::string &path, DumpLine &out, int timeout_ms = 3000)
{
    std::string line;
    while (dump.line(line, timeout_ms)) {
        out = parse_dump(line);
        if (out.path == path)
            return true;
    }
    return false;
}

ictus::StrikeEvent sample_strike(long seq, double time_s)
{
    ictus::StrikeEvent e;
    e.seq = seq;
    e.hand = static_cast<int>(seq % 2);
    e.bounce = seq == 2;
    e.time_s = time_s;
    e.x_m = 0.05;
    e.y_m = -0.03;
    e.r_over_a = 0.3277;
    e.theta_deg = -30.96;
    e.normal_velocity_mps = 2.5;
    e.tangential_velocity_mps = 0.4;
    e.peak_force_n = 47.25;
    e.impulse_n_s = 0.125;
    e.duration_ms = 4.5;
    e.force_dir = Eigen::Vector3d(0.6, -0.8, 0.0);
    e.stick_mass_kg = 0.0125;
    e.stick_tip = static_cast<int>(seq % 4); // none, wood, nylon, felt
    e.zone = seq == 3 ? ictus::kZoneRim : ictus::kZoneHead;
    return e;
}

} // namespace

TEST_CASE("osc out: strike bundles reach oscdump with the fixed layout and timetag = epoch + "
          "time + lookahead",
          "[net][link]")
{
    int port = 0;
    auto dump = start_oscdump(port);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(port);
    o.lookahead_s = 0.02;
    ictus::OscSender sender(o);
    // An epoch in the past, so that oscdump (a liblo server, which holds
    // bundles until their time) prints them at once.
    const ictus::NtpTime epoch = ictus::ntp_add_seconds(ictus::ntp_now(), -1000.0);
    sender.set_epoch(epoch);
    const double times[] = {0.5, 1.25, 1.2505, 3.0};
    for (long i = 0; i < 4; ++i)
        REQUIRE(sender.post_strike(sample_strike(i, times[i])));
    for (long i = 0; i < 4; ++i) {
        DumpLine d;
        REQUIRE(next_dump(*dump, "/ictus/strike", d));
        CHECK(d.types == "iiiiffffffffffffffi");
        REQUIRE(d.args.size() == 19);
        CHECK(std::stol(d.args[0]) == i);
        CHECK(std::stoi(d.args[1]) == i % 2);
        CHECK(std::stoi(d.args[2]) == 0);
        CHECK(std::stoi(d.args[3]) == (i == 2 ? 1 : 0));
        const double expected[] = {times[i], 0.05,  -0.03, 0.3277, -30.96, 2.5, 0.4,
                                   47.25,    0.125, 4.5,   0.6,    -0.8,   0.0};
        for (int k = 0; k < 13; ++k)
            CHECK(std::stod(d.args[4 + k]) ==
                  Approx(expected[k]).margin(2e-6 * (1 + std::fabs(expected[k]))));
        CHECK(std::stod(d.args[17]) == Approx(0.0125).margin(1e-9)); // stick_mass_kg
        CHECK(std::stoi(d.args[18]) == i % 4);                       // stick_tip
        // The timetag, to the last bit of the fraction: 2^-32 s steps.
        CHECK(d.timetag == hex_timetag(ictus::ntp_add_seconds(epoch, times[i] + 0.02)));
    }
    // Two strikes 0.5 ms apart keep their spacing in the timetags (float
    // time_s could not: the timetag is the exact clock).
    CHECK(ictus::ntp_diff_seconds(ictus::ntp_add_seconds(epoch, 1.2505),
                                  ictus::ntp_add_seconds(epoch, 1.25)) ==
          Approx(0.0005).margin(1e-9));

    // Pose stream: frame first, then bodies, sticks, drum.
    ictus::PoseSnapshot p;
    p.time_s = 2.5;
    p.bodies = 2;
    p.position_m[1][1] = 1.25f;
    p.rotation_wxyz[1][0] = 1.0f;
    p.stick_tip_m[1][2] = 0.5f;
    p.drum_center_m[1] = 0.75f;
    p.drum_radius_m = 0.178f;
    REQUIRE(sender.post_pose(p));
    DumpLine d;
    REQUIRE(next_dump(*dump, "/ictus/pose/frame", d));
    CHECK(d.types == "f");
    CHECK(std::stod(d.args[0]) == Approx(2.5));
    for (int b = 0; b < 2; ++b) {
        REQUIRE(next_dump(*dump, "/ictus/pose/body", d));
        CHECK(d.types == "ifffffff");
        CHECK(std::stoi(d.args[0]) == b);
    }
    CHECK(std::stod(d.args[2]) == Approx(1.25));
    CHECK(std::stod(d.args[4]) == Approx(1.0));
    for (int hand = 0; hand < 2; ++hand) {
        REQUIRE(next_dump(*dump, "/ictus/pose/stick", d));
        CHECK(d.types == "iffffff");
        CHECK(std::stoi(d.args[0]) == hand);
    }
    CHECK(std::stod(d.args[3]) == Approx(0.5));
    REQUIRE(next_dump(*dump, "/ictus/pose/drum", d));
    CHECK(d.types == "iffff");
    CHECK(std::stod(d.args[2]) == Approx(0.75));
    CHECK(std::stod(d.args[4]) == Approx(0.178));

    ictus::TipState t;
    t.hand = 1;
    t.time_s = 2.5;
    t.velocity_mps[1] = -3.0f;
    REQUIRE(sender.post_tip(t));
    REQUIRE(next_dump(*dump, "/ictus/tip", d));
    CHECK(d.types == "ifffffff");
    CHECK(std::stod(d.args[5]) == Approx(-3.0));
    CHECK(std::stod(d.args[7]) == Approx(2.5));
    sender.stop();
    const ictus::OscSenderCounters c = sender.counters();
    CHECK(c.strikes_sent == 4);
    CHECK(c.poses_sent == 1);
    CHECK(c.tips_sent == 1);
    CHECK(c.send_errors == 0);
}

TEST_CASE("osc out: /ictus/strike/end carries the field table's end fields, at the release",
          "[net][link]")
{
    int port = 0;
    auto dump = start_oscdump(port);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(port);
    o.lookahead_s = 0.02;
    ictus::OscSender sender(o);
    const ictus::NtpTime epoch = ictus::ntp_add_seconds(ictus::ntp_now(), -1000.0);
    sender.set_epoch(epoch);
    const ictus::StrikeEvent e = sample_strike(3, 1.25);
    REQUIRE(sender.post_strike_end(e));
    DumpLine d;
    REQUIRE(next_dump(*dump, "/ictus/strike/end", d));
    // The message is the table's in_osc_end fields in the table's order ...
    std::string types;
    std::vector<ictus::StrikeField> fields;
    for (int i = 0; i < ictus::kStrikeFieldCount; ++i) {
        const auto f = static_cast<ictus::StrikeField>(i);
        if (!ictus::strike_field_info(f).in_osc_end)
            continue;
        fields.push_back(f);
        types += ictus::strike_field_info(f).integer ? 'i' : 'f';
    }
    // ... which docs/osc.md names: seq, hand, peak_force_n, impulse_n_s,
    // duration_ms, force_dir_x, _y, _z, zone (last: a reader of the first
    // eight still parses it).
    CHECK(types == "iiffffffi");
    CHECK(d.types == types);
    REQUIRE(d.args.size() == fields.size());
    for (std::size_t k = 0; k < fields.size(); ++k) {
        INFO(ictus::strike_field_info(fields[k]).name);
        const double expected = ictus::strike_field(e, fields[k]);
        CHECK(std::stod(d.args[k]) == Approx(expected).margin(2e-6 * (1 + std::fabs(expected))));
    }
    // Due at the release: onset + duration + lookahead.
    CHECK(d.args.back() == "1"); // sample_strike(3, ...) landed on the rim
    CHECK(d.timetag ==
          hex_timetag(ictus::ntp_add_seconds(epoch, e.time_s + 1e-3 * e.duration_ms + 0.02)));
    sender.stop();
    CHECK(sender.counters().strike_ends_sent == 1);
    CHECK(sender.counters().strikes_sent == 0);
}

TEST_CASE("osc out: the kit goes out as /ictus/kit and one /ictus/kit/drum per drum, at once "
          "and again on request, never without a kit",
          "[net][link]")
{
    int port = 0;
    auto dump = start_oscdump(port);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(port);
    {
        // No kit: a request sends nothing (the strike queued after it comes first).
        ictus::OscSender bare(o);
        bare.send_kit();
        REQUIRE(bare.post_strike(sample_strike(0, 0.5)));
        std::string line;
        REQUIRE(dump->line(line, 3000));
        CHECK(parse_dump(line).path == "/ictus/strike");
        bare.stop();
        CHECK(bare.counters().kits_sent == 0);
    }
    ictus::OscSender sender(o);
    sender.set_kit("standard", {{0, "snare", "snare", 0.1778, 3603.0, 0.0, 38},
                                {1, "tom1", "tom", 0.127, 1231.0, 0.1875, 48}});
    // Set once: a second kit is ignored (the strike thread may be reading the first).
    sender.set_kit("other", {{0, "x", "paper", 0.2, 3000.0, 0.0}});
    for (int round = 0; round < 2; ++round) {
        sender.send_kit();
        DumpLine d;
        REQUIRE(next_dump(*dump, "/ictus/kit", d));
        CHECK(d.types == "si");
        REQUIRE(d.args.size() == 2);
        CHECK(d.args[0].find("standard") != std::string::npos);
        CHECK(std::stoi(d.args[1]) == 2);
        const char *names[] = {"tom1", "tom"};
        const double radius[] = {0.1778, 0.127}, tension[] = {3603.0, 1231.0},
                     pan[] = {0.0, 0.1875};
        const int note[] = {38, 48};
        for (int i = 0; i < 2; ++i) {
            REQUIRE(next_dump(*dump, "/ictus/kit/drum", d));
            CHECK(d.types == "issfffi");
            REQUIRE(d.args.size() == 7);
            CHECK(std::stoi(d.args[0]) == i);
            CHECK(d.args[2].find(i ? names[1] : "snare") != std::string::npos);
            if (i == 1)
                CHECK(d.args[1].find(names[0]) != std::string::npos);
            CHECK(std::stod(d.args[3]) == Approx(radius[i]).epsilon(1e-6));
            CHECK(std::stod(d.args[4]) == Approx(tension[i]).epsilon(1e-6));
            CHECK(std::stod(d.args[5]) == Approx(pan[i]).margin(1e-6));
            CHECK(std::stoi(d.args[6]) == note[i]);
        }
    }
    sender.stop();
    CHECK(sender.counters().kits_sent == 2);
}

TEST_CASE("osc out: a hi-hat's pedal goes first in its strike's bundle when it changes, and "
          "again after the kit is sent",
          "[net][link][hihat]")
{
    int port = 0;
    auto dump = start_oscdump(port);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(port);
    o.lookahead_s = 0.5;
    ictus::OscSender sender(o);
    sender.set_kit(
        "k", {{0, "snare", "snare", 0.1778, 3603.0, 0.0}, {1, "hihat", "hihat", 0.1778, 0.0, 0.5}});
    sender.set_epoch(ictus::ntp_now());
    // Strikes: hi-hat closed, closed, snare (no pedal), hi-hat open; then the kit
    // again and the hi-hat open once more.
    auto strike = [](long seq, int drum, double pedal) {
        ictus::StrikeEvent e = sample_strike(seq, 0.1 * static_cast<double>(seq + 1));
        e.drum = drum;
        e.pedal_openness = pedal;
        return e;
    };
    struct Seen {
        std::string path, timetag, arg0, arg1;
    };
    std::vector<Seen> seen;
    auto read_until_strike = [&](long seq) {
        DumpLine d;
        for (;;) {
            std::string line;
            REQUIRE(dump->line(line, 3000));
            d = parse_dump(line);
            seen.push_back({d.path, d.timetag, d.args.empty() ? "" : d.args[0],
                            d.args.size() < 2 ? "" : d.args[1]});
            if (d.path == "/ictus/strike" && std::stol(d.args[0]) == seq)
                return;
        }
    };
    REQUIRE(sender.post_strike(strike(0, 1, 0.0)));
    REQUIRE(sender.post_strike(strike(1, 1, 0.0)));
    REQUIRE(sender.post_strike(strike(2, 0, -1.0)));
    REQUIRE(sender.post_strike(strike(3, 1, 1.0)));
    read_until_strike(3);
    sender.send_kit();
    REQUIRE(sender.post_strike(strike(4, 1, 1.0)));
    read_until_strike(4);
    std::vector<std::string> paths;
    for (const Seen &x : seen)
        paths.push_back(x.path);
    const std::vector<std::string> want = {
        "/ictus/kit/pedal", "/ictus/strike",    "/ictus/strike", "/ictus/strike",
        "/ictus/kit/pedal", "/ictus/strike",    "/ictus/kit",    "/ictus/kit/drum",
        "/ictus/kit/drum",  "/ictus/kit/pedal", "/ictus/strike"};
    REQUIRE(paths == want);
    // Each pedal: the hi-hat's index and openness, its strike's timetag.
    for (size_t i : {size_t(0), size_t(4), size_t(9)}) {
        INFO(i);
        CHECK(std::stoi(seen[i].arg0) == 1);
        CHECK(std::stod(seen[i].arg1) == (i == 0 ? 0.0 : 1.0));
        CHECK(seen[i].timetag == seen[i + 1].timetag);
    }
    sender.stop();
}

TEST_CASE("osc out: a receiver holds a strike bundle until its timetag", "[net][link]")
{
    // liblo's server (oscdump) dispatches a bundle at its timetag: the
    // strike at simulation time 0.05 s with 0.25 s lookahead arrives at
    // epoch + 0.3 s, however early it was sent.
    int port = 0;
    auto dump = start_oscdump(port);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(port);
    o.lookahead_s = 0.25;
    ictus::OscSender sender(o);
    const auto t0 = std::chrono::steady_clock::now();
    sender.set_epoch(ictus::ntp_now());
    REQUIRE(sender.post_strike(sample_strike(0, 0.05)));
    DumpLine d;
    REQUIRE(next_dump(*dump, "/ictus/strike", d));
    const double arrived =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("strike due 0.300 s after the epoch, printed by oscdump after %.4f s\n", arrived);
    // liblo's server releases a queued bundle once it is less than about
    // 10 ms away (measured here: 8-9 ms early, every run); Pd's scheduler in
    // the pd helper's patch is sample-exact instead.
    CHECK(arrived >= 0.3 - 0.010 - 0.005);
    CHECK(arrived < 0.6);
}

TEST_CASE("osc in: oscsend drives the server, replies and errors go back over OSC", "[net][link]")
{
    int dump_port = 0;
    auto dump = start_oscdump(dump_port);
    ictus::LiveStatus status;
    ictus::OscServerOptions so;
    so.port = 0;
    so.reply_url = "osc.udp://127.0.0.1:" + std::to_string(dump_port);
    ictus::OscServer server(so, &status);
    const std::string port = std::to_string(server.port());
    auto oscsend = [&](std::vector<std::string> args) {
        args.insert(args.begin(), {"oscsend", "127.0.0.1", port});
        REQUIRE(osctest::run(args) == 0);
    };
    // The physics thread's part: take the next command and confirm it (the
    // server replies once the physics took it).
    auto pop = [&](ictus::Command &c) {
        if (!osctest::poll_until([&] { return server.pop_command(c); }))
            return false;
        server.post_accepted(c);
        return true;
    };
    ictus::Command c;
    DumpLine d;

    oscsend({"/ictus/tempo", "f", "96"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::tempo);
    CHECK(c.value == 96.0);
    REQUIRE(next_dump(*dump, "/ictus/reply", d));
    CHECK(d.types == "sf");
    CHECK(d.args[0] == "\"/ictus/tempo\"");

    oscsend({"/ictus/gains", "ff", "0.5", "2"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::gains);
    CHECK(c.value == 0.5);
    CHECK(c.value2 == 2.0);
    oscsend({"/ictus/grip", "s", "german"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::grip);
    CHECK(std::string(c.text) == "german");
    oscsend({"/ictus/drum/tension", "f", "2500"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::drum_tension);
    oscsend({"/ictus/play"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::play);

    // Refusals: each answered with /ictus/error naming the address and the
    // problem, and nothing reaches the physics thread.
    struct Bad {
        std::vector<std::string> args;
        std::string address, message_part;
    };
    const Bad bad[] = {
        {{"/ictus/tempo", "i", "96"}, "/ictus/tempo", "expected ,f, got ,i"},
        {{"/ictus/tempo", "f", "1000"}, "/ictus/tempo", "tempo (bpm): expected 20 to 400"},
        {{"/ictus/tempo", "f", "nan"}, "/ictus/tempo", "tempo (bpm)"},
        {{"/ictus/drum/radius", "f", "-1"}, "/ictus/drum/radius", "drum radius (m)"},
        {{"/ictus/grip", "s", "matched"}, "/ictus/grip", "expected french or german"},
        {{"/ictus/mode", "s", "inverse"}, "/ictus/mode", "expected joint or cartesian"},
        {{"/ictus/score", "i", "4"}, "/ictus/score", "expected ,s, got ,i"},
        {{"/ictus/volume", "f", "1"}, "/ictus/volume", "unknown address"},
        // An address without arguments: a command as a query.
        {{"/ictus/play", "f", "1"}, "/ictus/play", "type tags: expected none, got ,f"},
        {{"/ictus/ping", "f", "1"}, "/ictus/ping", "type tags: expected none, got ,f"},
    };
    for (const Bad &b : bad) {
        oscsend(b.args);
        REQUIRE(next_dump(*dump, "/ictus/error", d));
        CHECK(d.types == "ss");
        CHECK(d.args[0] == "\"" + b.address + "\"");
        std::string message;
        for (size_t i = 1; i < d.args.size(); ++i)
            message += d.args[i] + " ";
        INFO(message);
        CHECK(message.find(b.message_part) != std::string::npos);
    }
    CHECK_FALSE(server.pop_command(c));
    const ictus::OscServerCounters k = server.counters();
    CHECK(k.accepted == 5);
    CHECK(k.bad_type_tags == 4);
    CHECK(k.unknown_address == 1);
    CHECK(k.bad_values == 5);

    // Status: the physics thread's numbers.
    status.time_s = 12.5;
    status.strikes = 42;
    status.score = 1;
    status.mode = static_cast<int>(ictus::TrackMode::cartesian);
    status.grip = static_cast<int>(ictus::Grip::german);
    oscsend({"/ictus/status"});
    REQUIRE(next_dump(*dump, "/ictus/reply", d));
    CHECK(d.types == "sfifiiiiiisss");
    CHECK(std::stod(d.args[1]) == Approx(12.5));
    CHECK(std::stoi(d.args[4]) == 42);
    // Packets received, accepted, errors: each count includes this request
    // (received before it is accepted): 5 commands, 10 refused, the status.
    CHECK(std::stoi(d.args[5]) == 16);
    CHECK(std::stoi(d.args[6]) == 6);
    CHECK(std::stoi(d.args[7]) == 10);
    REQUIRE(d.args.size() == 13);
    CHECK(d.args[10] == "\"score\""); // oscdump quotes strings
    CHECK(d.args[11] == "\"cartesian\"");
    CHECK(d.args[12] == "\"german\"");
}

TEST_CASE("osc in: score statements, score clear and the cartesian mode pass through to the "
          "physics thread, too-long statements and wrong type tags are refused",
          "[net][link]")
{
    // oscsend (liblo's tool) sends, a plain socket receives the replies.
    Peer replies;
    ictus::OscServerOptions so;
    so.port = 0;
    so.reply_url = "osc.udp://127.0.0.1:" + std::to_string(replies.port());
    ictus::OscServer server(so, nullptr);
    const std::string port = std::to_string(server.port());
    auto oscsend = [&](std::vector<std::string> args) {
        args.insert(args.begin(), {"oscsend", "127.0.0.1", port});
        REQUIRE(osctest::run(args) == 0);
    };
    // The physics thread's part: take the next command and confirm it (the
    // server replies once the physics took it).
    auto pop = [&](ictus::Command &c) {
        if (!osctest::poll_until([&] { return server.pop_command(c); }))
            return false;
        server.post_accepted(c);
        return true;
    };
    auto reply = [&](Peer::Message &m) {
        REQUIRE(replies.receive(m, 3000));
        return m;
    };
    ictus::Command c;
    Peer::Message m;

    // Accepted: queued with their text, echoed back.
    oscsend({"/ictus/score", "s", "L accent 0.8"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::score);
    CHECK(std::string(c.text) == "L accent 0.8");
    reply(m);
    CHECK(m.path == "/ictus/reply");
    CHECK(m.types == "ss");
    CHECK(m.strings == std::vector<std::string>{"/ictus/score", "L accent 0.8"});

    oscsend({"/ictus/score/clear"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::score_clear);
    reply(m);
    CHECK(m.path == "/ictus/reply");
    CHECK(m.strings == std::vector<std::string>{"/ictus/score/clear"});

    oscsend({"/ictus/mode", "s", "cartesian"});
    REQUIRE(pop(c));
    CHECK(c.kind == ictus::CommandKind::mode);
    CHECK(std::string(c.text) == "cartesian");
    reply(m);
    CHECK(m.path == "/ictus/reply");

    // The longest statement that fits Command::text (255 characters + NUL)
    // arrives whole.
    const size_t limit = ictus::Command::kMaxText - 1;
    REQUIRE(limit == 255);
    std::string longest;
    while (longest.size() < limit)
        longest += longest.size() % 10 == 9 ? ',' : 'R';
    oscsend({"/ictus/score", "s", longest});
    REQUIRE(pop(c));
    CHECK(std::string(c.text) == longest);
    reply(m);
    CHECK(m.path == "/ictus/reply");

    // Refused, with the address and the reason; nothing is queued.
    struct Bad {
        std::vector<std::string> args;
        std::string message_part;
    };
    const Bad bad[] = {
        {{"/ictus/score", "s", longest + "R"}, "256 characters exceed the limit of 255"},
        {{"/ictus/score", "s", std::string(3000, 'L')}, "3000 characters exceed the limit of 255"},
        {{"/ictus/score", "s", ""}, "score statement: empty"},
        {{"/ictus/score", "s", "R legato\x1bL accent"}, "control character 27 at column 9"},
        {{"/ictus/score", "i", "96"}, "type tags: expected ,s, got ,i"},
        {{"/ictus/score", "f", "0.8"}, "type tags: expected ,s, got ,f"},
        {{"/ictus/score", "ss", "R", "legato"}, "type tags: expected ,s, got ,ss"},
        {{"/ictus/score"}, "type tags: expected ,s, got none"},
        {{"/ictus/score/clear", "s", "all"}, "type tags: expected none, got ,s"},
        {{"/ictus/mode", "s", "cartesien"}, "mode: expected joint or cartesian, got 'cartesien'"},
    };
    for (const Bad &b : bad) {
        oscsend(b.args);
        reply(m);
        INFO(b.args[0] << " " << (m.strings.size() > 1 ? m.strings[1] : std::string("?")));
        CHECK(m.path == "/ictus/error");
        CHECK(m.types == "ss");
        REQUIRE(m.strings.size() == 2);
        CHECK(m.strings[0] == b.args[0]);
        CHECK(m.strings[1].find(b.message_part) != std::string::npos);
    }
    // A statement beyond the packet limit (4096 bytes) never reaches parsing.
    oscsend({"/ictus/score", "s", std::string(5000, 'R')});
    reply(m);
    CHECK(m.path == "/ictus/error");
    CHECK(m.strings[1].find("exceeds the limit of 4096") != std::string::npos);

    CHECK_FALSE(server.pop_command(c));
    const ictus::OscServerCounters k = server.counters();
    CHECK(k.accepted == 4);
    CHECK(k.score_lines == 2);
    CHECK(k.bad_type_tags == 5);
    CHECK(k.bad_values == 5);
    CHECK(k.oversized == 1);
    CHECK(k.errors_sent == 11);
}

// docs/score.md: statements are separated by line breaks "in a file and in one
// /ictus/score string alike"; the parser took them, but the server refused any line
// break as a control character, so a client's multi-line string never reached it.
// Seeded statements joined by LF, CRLF or CR (some with a comment) go through the
// server whole and give the notes of the same statements one per line of a file.
TEST_CASE("osc in: a score statement string with line breaks passes whole and parses as the "
          "same lines of a file",
          "[net][link]")
{
    Peer replies;
    ictus::OscServerOptions so;
    so.port = 0;
    so.reply_url = "osc.udp://127.0.0.1:" + std::to_string(replies.port());
    ictus::OscServer server(so, nullptr);
    const std::string port = std::to_string(server.port());
    const std::vector<std::string> lines = {
        "R legato", "L accent 0.8", "tempo 90",    "R+L tenuto f",      "rest 1/4",
        "L 1/2",    "dynamics 0.3", "grip german", "R vertical-accent", "beats 1/2"};
    std::mt19937 rng(20261202);
    for (int trial = 0; trial < 20; ++trial) {
        std::string file, message;
        const int n = std::uniform_int_distribution<int>(2, 6)(rng);
        ictus_test::join_statements(rng, lines, n, " # a comment", file, message);
        INFO("trial " << trial << ": " << file);
        REQUIRE(osctest::run({"oscsend", "127.0.0.1", port, "/ictus/score", "s", message}) == 0);
        ictus::Command c;
        REQUIRE(osctest::poll_until([&] {
            if (server.pop_command(c))
                return true;
            Peer::Message m;
            if (replies.receive(m, 5)) // an error reply: the statement was refused
                FAIL(m.path << " " << (m.strings.size() > 1 ? m.strings[1] : ""));
            return false;
        }));
        CHECK(c.kind == ictus::CommandKind::score);
        CHECK(std::string(c.text) == message);
        server.post_accepted(c);
        Peer::Message m;
        REQUIRE(replies.receive(m, 3000));
        CHECK(m.path == "/ictus/reply");

        ictus_test::check_same_notes(c.text, file);
    }
    CHECK(server.counters().score_lines == 20);
}

// docs/osc.md: /ictus/nuance N is "as the statement `nuance N`", which takes the
// score's spelling vertical-accent too; the server refused it.
TEST_CASE("osc in: /ictus/nuance takes vertical-accent as the score statement does", "[net][link]")
{
    ictus::OscServerOptions so;
    so.port = 0;
    ictus::OscServer server(so, nullptr);
    const std::string port = std::to_string(server.port());
    for (const char *word : {"vertical-accent", "vertical_accent"}) {
        REQUIRE(osctest::run({"oscsend", "127.0.0.1", port, "/ictus/nuance", "s", word}) == 0);
        ictus::Command c;
        REQUIRE(osctest::poll_until([&] { return server.pop_command(c); }));
        CHECK(c.kind == ictus::CommandKind::nuance);
        CHECK(ictus::nuance_from_string(c.text) == ictus::Nuance::vertical_accent);
        CHECK(ictus::parse_score(std::string("nuance ") + word + "\nR", "t").notes.at(0).nuance ==
              ictus::Nuance::vertical_accent);
    }
    CHECK(server.counters().bad_values == 0);
}

// docs/osc.md gives each float's range, ends included; a float of OSC holds 0.01 as
// 0.0099999998, and /ictus/drum/density 0.01 was refused as "expected 0.01 to 10, got
// 0.01". Every ranged command at both ends of its range, as a client types them (oscsend
// reads the text into a float), is taken, within the range; the next float beyond each
// end is refused.
TEST_CASE("osc in: every documented range takes its ends as a float of OSC holds them",
          "[net][link]")
{
    ictus::OscServerOptions so;
    so.port = 0;
    ictus::OscServer server(so, nullptr);
    const std::string port = std::to_string(server.port());
    struct Range {
        const char *address;
        int floats;
        double lo, hi; // docs/osc.md
    };
    const Range ranges[] = {
        {"/ictus/tempo", 1, 20, 400},         {"/ictus/gains", 2, 0.05, 4},
        {"/ictus/drum/radius", 1, 0.05, 1},   {"/ictus/drum/tension", 1, 10, 1e5},
        {"/ictus/drum/density", 1, 0.01, 10}, {"/ictus/grip/firmness", 1, 0, 1},
        {"/ictus/humanize", 1, 0, 4}};
    auto text = [](double v) {
        std::ostringstream o;
        o.precision(9);
        o << v;
        return o.str();
    };
    auto send = [&](const Range &r, const std::string &value) {
        std::vector<std::string> args = {"oscsend", "127.0.0.1", port, r.address,
                                         std::string(static_cast<size_t>(r.floats), 'f')};
        for (int i = 0; i < r.floats; ++i)
            args.push_back(value);
        REQUIRE(osctest::run(args) == 0);
    };
    auto popped = [&](ictus::Command &c) {
        return osctest::poll_until([&] { return server.pop_command(c); });
    };
    unsigned long refused = 0;
    for (const Range &r : ranges)
        for (const double end : {r.lo, r.hi}) {
            INFO(r.address << " " << end);
            send(r, text(end));
            ictus::Command c;
            REQUIRE(popped(c));
            // the end, to a float's precision, and never outside the range
            CHECK(c.value == Approx(end).epsilon(1e-7));
            CHECK((c.value >= r.lo && c.value <= r.hi));
            if (r.floats == 2)
                CHECK(c.value2 == c.value);
            const float beyond =
                std::nextafter(static_cast<float>(end), end == r.lo ? -1e30f : 1e30f);
            send(r, text(beyond));
            ++refused;
            osctest::poll_until([&] { return server.counters().bad_values >= refused; });
            CHECK(server.counters().bad_values == refused);
        }
    ictus::Command c;
    CHECK_FALSE(server.pop_command(c));
}

// The score's words and the CLI's take any case (--grip German, `grip German`), but
// /ictus/grip German, /ictus/mode Joint and /ictus/nuance Accent were refused. Seeded
// casings of every word of the three: queued (and echoed) as the lower-case word.
TEST_CASE("osc in: grip, mode and nuance take their words in any case", "[net][link]")
{
    Peer replies;
    ictus::OscServerOptions so;
    so.port = 0;
    so.reply_url = "osc.udp://127.0.0.1:" + std::to_string(replies.port());
    ictus::OscServer server(so, nullptr);
    const std::string port = std::to_string(server.port());
    struct Words {
        const char *address;
        std::vector<std::string> words;
    };
    const Words table[] = {
        {"/ictus/grip", {"french", "german"}},
        {"/ictus/mode", {"joint", "cartesian"}},
        {"/ictus/nuance",
         {"legato", "tenuto", "accent", "vertical_accent", "vertical-accent", "staccato", "buzz"}}};
    std::mt19937 rng(20261203);
    for (const Words &t : table)
        for (const std::string &w : t.words) {
            std::string cased = w;
            for (char &ch : cased)
                if (rng() % 2)
                    ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
            if (cased == w)
                cased[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(cased[0])));
            INFO(t.address << " " << cased);
            REQUIRE(osctest::run({"oscsend", "127.0.0.1", port, t.address, "s", cased}) == 0);
            ictus::Command c;
            REQUIRE(osctest::poll_until([&] { return server.pop_command(c); }));
            CHECK(std::string(c.text) == w);
            server.post_accepted(c);
            Peer::Message m;
            REQUIRE(replies.receive(m, 3000));
            CHECK(m.path == "/ictus/reply");
            CHECK(m.strings == std::vector<std::string>{t.address, w});
        }
    CHECK(server.counters().bad_values == 0);
}

TEST_CASE("osc in: 10^5 random and malformed packets are counted, each answered or counted "
          "unanswered (the error-reply budget), the server keeps answering",
          "[net][link]")
{
    ictus::LiveStatus status;
    ictus::OscServerOptions so;
    so.port = 0;
    ictus::OscServer server(so, &status);
    Peer peer;
    std::mt19937 rng(1234);
    std::uniform_int_distribution<int> byte(0, 255);
    const int total = 100000;
    long oversized = 0, bundles = 0, wrong_tags = 0;
    std::vector<unsigned char> pkt;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < total; ++i) {
        pkt.clear();
        switch (i % 5) {
        case 0: { // random bytes, 1..600 long, not starting with '/' or '#'
            const int n = 1 + static_cast<int>(rng() % 600);
            for (int k = 0; k < n; ++k)
                pkt.push_back(static_cast<unsigned char>(byte(rng)));
            if (pkt[0] == '/' || pkt[0] == '#')
                pkt[0] = 'x';
            break;
        }
        case 1: { // a valid message truncated or with its tail scrambled
            lo_message m = lo_message_new();
            lo_message_add_float(m, 96.0f);
            lo_message_add_string(m, "german");
            size_t size = 0;
            void *data = lo_message_serialise(m, "/ictus/tempo", nullptr, &size);
            lo_message_free(m);
            pkt.assign(static_cast<unsigned char *>(data),
                       static_cast<unsigned char *>(data) + size);
            std::free(data);
            const size_t cut = 1 + rng() % (pkt.size() - 1);
            pkt.resize(cut);
            if (rng() % 2)
                for (size_t k = cut / 2; k < cut; ++k)
                    pkt[k] = static_cast<unsigned char>(byte(rng));
            break;
        }
        case 2: { // a well-formed message with wrong type tags
            lo_message m = lo_message_new();
            lo_message_add_int32(m, static_cast<int32_t>(rng()));
            size_t size = 0;
            void *data = lo_message_serialise(m, "/ictus/tempo", nullptr, &size);
            lo_message_free(m);
            pkt.assign(static_cast<unsigned char *>(data),
                       static_cast<unsigned char *>(data) + size);
            std::free(data);
            ++wrong_tags;
            break;
        }
        case 3: // oversized
            pkt.assign(4097 + rng() % 4000, 'a');
            pkt[0] = '/';
            ++oversized;
            break;
        case 4: // a bundle
            pkt.assign({'#', 'b', 'u', 'n', 'd', 'l', 'e', 0, 0, 0, 0, 0, 0, 0, 0, 1});
            ++bundles;
            break;
        }
        peer.send_raw(server.port(), pkt.data(), pkt.size());
        // Pace the flood so that the kernel's buffer never drops one: every
        // packet must be counted.
        if (i % 32 == 31) {
            for (int w = 0;
                 w < 20000 && server.counters().packets < static_cast<unsigned long>(i + 1); ++w)
                std::this_thread::sleep_for(100us);
            peer.drain();
        }
    }
    for (int w = 0; w < 5000 && server.counters().packets < static_cast<unsigned long>(total); ++w)
        std::this_thread::sleep_for(1ms);
    peer.drain();
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const ictus::OscServerCounters k = server.counters();
    std::printf("fuzz: %lu packets, %lu malformed, %lu unknown address, %lu wrong type tags, "
                "%lu bad values, %lu oversized, %lu bundles, %lu error replies, %lu unanswered "
                "in %.2f s\n",
                k.packets, k.malformed, k.unknown_address, k.bad_type_tags, k.bad_values,
                k.oversized, k.bundles, k.errors_sent, k.errors_unanswered, elapsed_s);
    CHECK(k.packets == static_cast<unsigned long>(total));
    CHECK(k.accepted == 0);
    CHECK(k.errors() == static_cast<unsigned long>(total)); // each counted once
    CHECK(k.oversized == static_cast<unsigned long>(oversized));
    CHECK(k.bundles == static_cast<unsigned long>(bundles));
    CHECK(k.bad_type_tags >= static_cast<unsigned long>(wrong_tags));
    // One peer: its budget answers the first kErrorReplyBurst, then
    // kErrorRepliesPerSecond; every other error is counted unanswered.
    CHECK(k.errors_sent + k.errors_unanswered == static_cast<unsigned long>(total));
    CHECK(k.errors_sent >= static_cast<unsigned long>(ictus::kErrorReplyBurst));
    CHECK(k.errors_sent <=
          ictus::kErrorReplyBurst + ictus::kErrorRepliesPerSecond * elapsed_s + 1.0);
    ictus::Command c;
    CHECK_FALSE(server.pop_command(c));

    // Still answering.
    peer.send(server.port(), "/ictus/ping", lo_message_new());
    Peer::Message reply;
    bool pong = false;
    for (int i = 0; i < 20 && !pong; ++i)
        pong = peer.receive(reply, 100) && reply.path == "/ictus/pong";
    CHECK(pong);
}

// A 1-byte packet earned a 64-byte /ictus/error, and with --allow any every
// packet was answered: the port was a 64x amplifier. Now each address has a
// budget (kErrorReplyBurst, refilled at kErrorRepliesPerSecond): past it an
// error is counted and not answered; another address keeps its own budget;
// pings are answered still; and no reply grows with what it answers.
TEST_CASE("osc in: error replies are limited per peer address, the rest counted, replies stay "
          "small",
          "[net][link]")
{
    ictus::OscServerOptions so;
    so.port = 0;
    so.allow_any = true;
    ictus::OscServer server(so, nullptr);
    Peer flooder("127.0.0.1"), other("127.0.0.2");
    const int total = 2000;
    const unsigned char junk = 'x';
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < total; ++i) {
        flooder.send_raw(server.port(), &junk, 1);
        // Paced so that the kernel drops none: every packet must be counted.
        if (i % 32 == 31 || i == total - 1)
            for (int w = 0;
                 w < 20000 && server.counters().packets < static_cast<unsigned long>(i + 1); ++w)
                std::this_thread::sleep_for(100us);
    }
    ictus::OscServerCounters k = server.counters();
    // Every reply sent reaches the flooder (loopback, a 1 MB buffer).
    long replies = 0, largest = 0;
    std::string path;
    for (long n;
         replies < static_cast<long>(k.errors_sent) && (n = flooder.receive_size(path, 2000)) >= 0;
         ++replies) {
        CHECK(path == "/ictus/error");
        largest = std::max(largest, n);
    }
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("flood: %d one-byte packets in %.2f s, %lu error replies (largest %ld bytes), "
                "%lu unanswered\n",
                total, elapsed_s, k.errors_sent, largest, k.errors_unanswered);
    CHECK(k.packets == static_cast<unsigned long>(total));
    CHECK(k.malformed == static_cast<unsigned long>(total)); // still counted, each one
    CHECK(k.errors_sent + k.errors_unanswered == static_cast<unsigned long>(total));
    CHECK(k.errors_sent >= static_cast<unsigned long>(ictus::kErrorReplyBurst));
    CHECK(k.errors_sent <=
          ictus::kErrorReplyBurst + ictus::kErrorRepliesPerSecond * elapsed_s + 1.0);
    CHECK(replies == static_cast<long>(k.errors_sent));
    CHECK(largest <= 64);
    CHECK_FALSE(flooder.receive_size(path, 0) >= 0); // nothing beyond the counted replies

    // Another address has its own budget: answered at once.
    other.send_raw(server.port(), &junk, 1);
    REQUIRE(other.receive_size(path, 2000) > 0);
    CHECK(path == "/ictus/error");
    // An unknown address of 3000 characters: the reply names it in 64 (it
    // was over 3 kB, too long for the reply buffer, and never sent).
    {
        lo_message m = lo_message_new();
        size_t size = 0;
        const std::string long_path = "/" + std::string(2999, 'v');
        void *data = lo_message_serialise(m, long_path.c_str(), nullptr, &size);
        lo_message_free(m);
        other.send_raw(server.port(), data, size);
        std::free(data);
        const long n = other.receive_size(path, 2000);
        REQUIRE(n > 0);
        CHECK(path == "/ictus/error");
        CHECK(n <= 128);
    }
    // The flooder is out of budget, but a ping is not an error: answered.
    {
        lo_message m = lo_message_new();
        size_t size = 0;
        void *data = lo_message_serialise(m, "/ictus/ping", nullptr, &size);
        lo_message_free(m);
        flooder.send_raw(server.port(), data, size);
        std::free(data);
        REQUIRE(flooder.receive_size(path, 2000) > 0);
        CHECK(path == "/ictus/pong");
    }
    // The budget refills: junk resent until it is answered again (a token
    // every 1 / kErrorRepliesPerSecond s), within a deadline.
    bool answered = false;
    for (int i = 0; i < 100 && !answered; ++i) {
        flooder.send_raw(server.port(), &junk, 1);
        answered = flooder.receive_size(path, 50) > 0 && path == "/ictus/error";
    }
    CHECK(answered);
    k = server.counters();
    CHECK(k.malformed + k.unknown_address == k.errors());
}

TEST_CASE("osc in: the allow-list refuses other peers without answering them", "[net][link]")
{
    ictus::OscServerOptions so;
    so.port = 0;
    so.allow = {"127.0.0.2"};
    ictus::OscServer server(so, nullptr);
    Peer stranger("127.0.0.1"), friend_peer("127.0.0.2");
    stranger.send(server.port(), "/ictus/ping", lo_message_new());
    friend_peer.send(server.port(), "/ictus/ping", lo_message_new());
    Peer::Message m;
    REQUIRE(friend_peer.receive(m, 2000));
    CHECK(m.path == "/ictus/pong");
    CHECK_FALSE(stranger.receive(m, 200));
    const ictus::OscServerCounters k = server.counters();
    CHECK(k.refused_peers == 1);
    CHECK(k.accepted == 1);
    CHECK(k.replies == 1);
}

TEST_CASE("osc in: the server listens on its bind address only", "[net][link]")
{
    ictus::OscServerOptions so;
    so.port = 0;
    so.bind_address = "127.0.0.2";
    so.allow_any = true;
    ictus::OscServer server(so, nullptr);
    Peer peer("127.0.0.1");
    peer.send(server.port(), "/ictus/ping", lo_message_new()); // to 127.0.0.1: nobody there
    Peer::Message m;
    CHECK_FALSE(peer.receive(m, 200));
    CHECK(server.counters().packets == 0);

    so.bind_address = "localhost"; // not numeric
    CHECK_THROWS_WITH(ictus::OscServer(so, nullptr), Catch::Contains("--bind"));
    so.bind_address = "127.0.0.1";
    so.allow_any = false;
    so.allow = {"10.0.0.300"};
    CHECK_THROWS_WITH(ictus::OscServer(so, nullptr), Catch::Contains("--allow"));
    // An empty list is not "any" (--allow "" admitted every peer): refused.
    so.allow = {};
    CHECK_THROWS_WITH(ictus::OscServer(so, nullptr), Catch::Contains("--allow: empty list"));
    ictus::OscSenderOptions o;
    o.target_url = "not a url";
    CHECK_THROWS_WITH(ictus::OscSender(o), Catch::Contains("target"));
    // What liblo takes and then fails to send to (or sends elsewhere): refused
    // at once, naming the option and the fault.
    const std::pair<const char *, const char *> bad_targets[] = {
        {"osc.udp://127.0.0.1:99999", "port: expected 1 to 65535"}, // wrapped to 34463
        {"osc.udp://127.0.0.1:0", "port: expected 1 to 65535"},
        {"osc.udp://127.0.0.1:90x", "port: expected 1 to 65535"}, // read as 90
        {"osc.udp://127.0.0.1", "no port"},
        {"osc.udp://:9000", "no host"},
        {"osc.tcp://127.0.0.1:9000", "protocol 'tcp' is not supported"},
        {"osc.udp://[::1]:9000", "IPv6 is not supported"},
        {"osc.udp://no-such-host.invalid:9000", "does not resolve to an IPv4 address"},
    };
    for (const auto &[url, why] : bad_targets) {
        o.target_url = url;
        CHECK_THROWS_WITH(ictus::OscSender(o),
                          Catch::Contains("--target '" + std::string(url) + "'") &&
                              Catch::Contains(why));
    }
    for (const char *url : {"osc.udp://127.0.0.1:9000", "osc.udp://localhost:65535/"}) {
        o.target_url = url;
        CHECK_NOTHROW(ictus::OscSender(o));
    }
}
