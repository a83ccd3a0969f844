// commands.hpp -- what can be done to a performance while it runs, and what it
// reports: the commands the network (net/osc_server.hpp) hands to the physics
// thread, the pose and tip snapshots it streams out, and the live status the
// server answers pings with. Plain data: no network here (docs/osc.md lists
// the OSC addresses that carry them).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace ictus
{

struct PoseSnapshot {
    static constexpr int kMaxBodies = 24;
    double time_s = 0.0;
    int bodies = 0;
    float position_m[kMaxBodies][3] = {};
    float rotation_wxyz[kMaxBodies][4] = {};
    float stick_tip_m[2][3] = {};  // the stick's end point [hand]
    float stick_butt_m[2][3] = {}; // its other end
    float drum_center_m[3] = {};
    float drum_radius_m = 0.0f;
};

// The state of one stick tip (end point), for the optional /ictus/tip stream.
struct TipState {
    double time_s = 0.0;
    int hand = 0;
    float position_m[3] = {};
    float velocity_mps[3] = {};
};

enum class CommandKind {
    play,
    stop,
    tempo,         // value = bpm
    grip,          // text = french | german
    nuance,        // text
    mode,          // text = joint | cartesian
    gains,         // value = stiffness scale, value2 = damping scale
    drum_radius,   // value = m
    drum_tension,  // value = N/m
    drum_density,  // value = kg/m^2
    score,         // text = one score statement, e.g. "L accent 0.8" (docs/score.md)
    score_clear,   // forget the statements received so far
    grip_firmness, // value = 0 (loose) .. 1 (firm): the notes' default grip
    humanize,      // value = motor noise amount 0..4 (docs/humanize.md)
};

struct Command {
    // Room for one score statement: the longest text accepted is
    // kMaxText - 1 bytes (the server refuses longer ones with an error naming
    // the limit). Fixed size: commands cross a lock-free queue by value.
    static constexpr std::size_t kMaxText = 256;
    CommandKind kind = CommandKind::play;
    double value = 0.0, value2 = 0.0;
    char text[kMaxText] = {};
    // Who sent it and to which address, so that a refusal found later (by
    // the physics thread or the planner) is answered to that peer as
    // /ictus/error <address> <why>. IPv4 address and port in network byte
    // order; peer_port 0: no peer (a command from the daemon itself).
    std::uint32_t peer_ipv4 = 0;
    std::uint16_t peer_port = 0;
    char address[32] = {};
    // The type tags it came with ("f", "ff", "s" or ""), for the echo in
    // /ictus/reply once the physics thread has taken it.
    char types[4] = {};
};

// A refusal on its way back to the client (see Command's peer fields).
struct Refusal {
    std::uint32_t peer_ipv4 = 0;
    std::uint16_t peer_port = 0;
    char address[32] = {};
    char why[Command::kMaxText] = {};
};

// What the physics thread publishes for /ictus/status (atomics only).

struct LiveStatus {
    std::atomic<double> time_s{0.0};
    std::atomic<int> playing{0};
    std::atomic<double> tempo_bpm{120.0};
    std::atomic<long> strikes{0};
    // Stalls: steps that started more than 50 steps late, after which the
    // loop moved its anchor on the wall clock (docs/osc.md).
    std::atomic<long> overruns{0};
    std::atomic<long> runaways{0}; // times the runaway guard stopped the strikes
    std::atomic<int> mode{0};      // TrackMode, as an int (/ictus/status: its name)
    std::atomic<int> grip{0};      // Grip, as an int
    std::atomic<int> score{0};     // 1: a score plays (score mode), 0: a clip
};

} // namespace ictus
