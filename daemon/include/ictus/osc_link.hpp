// osc_link.hpp -- the OSC link between ictusd and Pd (paper, Figure 3: the
// physics, graphics, interaction and sound managers run asynchronously and
// talk OSC). Out: strike bundles, time-tagged for exact scheduling, and a pose
// stream for graphics, each sent by its own thread from lock-free queues fed
// by the physics thread. In: a UDP server (loopback by default, allow-listed
// peers) that validates commands and hands them to the physics thread through
// another queue. The namespace, type tags and units are in docs/osc.md.
#pragma once

#include "ictus/spsc_queue.hpp"
#include "ictus/strike.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace ictus
{

// Bad option, unbindable address, unresolvable target; what() names it.
class OscError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

// NTP time (OSC timetags) as 32.32 fixed point, and the current wall clock in it.
using NtpTime = std::uint64_t;
NtpTime ntp_now();
NtpTime ntp_add_seconds(NtpTime t, double seconds);
double ntp_diff_seconds(NtpTime a, NtpTime b); // a - b

// ---- out --------------------------------------------------------------------

// A snapshot of the scene for graphics (world frame, y up, metres).
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

struct OscSenderOptions {
    std::string target_url = "osc.udp://127.0.0.1:9000";
    // Strike bundles carry the timetag epoch + time_s + lookahead_s. A
    // lookahead of 0 sends them as "immediately" (timetag 1).
    double lookahead_s = 0.010;
};

struct OscSenderCounters {
    unsigned long strikes_sent = 0, poses_sent = 0, tips_sent = 0;
    unsigned long send_errors = 0;
    unsigned long strikes_dropped = 0, poses_dropped = 0, tips_dropped = 0; // queue full
};

// Two threads: strikes (urgent) and the pose / tip stream, each with its own
// liblo address. post_* are for one producer thread (the physics thread):
// lock-free, never block, false when the queue is full (counted).
class OscSender
{
  public:
    explicit OscSender(const OscSenderOptions &options); // throws OscError
    ~OscSender();                                        // stops and joins
    OscSender(const OscSender &) = delete;
    OscSender &operator=(const OscSender &) = delete;

    // The wall-clock (NTP) time of simulation time 0; may be moved while
    // running (the physics thread re-anchors after falling behind).
    void set_epoch(NtpTime epoch) { epoch_.store(epoch, std::memory_order_release); }
    NtpTime epoch() const { return epoch_.load(std::memory_order_acquire); }

    bool post_strike(const StrikeEvent &event);
    bool post_pose(const PoseSnapshot &pose);
    bool post_tip(const TipState &tip);

    // Sends what is queued and joins the threads.
    void stop();
    OscSenderCounters counters() const;
    const OscSenderOptions &options() const { return options_; }

  private:
    void strike_loop();
    void pose_loop();
    struct Impl;
    std::unique_ptr<Impl> impl_;
    OscSenderOptions options_;
    std::atomic<NtpTime> epoch_{0};
    std::atomic<bool> running_{true};
    std::atomic<unsigned long> strikes_sent_{0}, poses_sent_{0}, tips_sent_{0}, send_errors_{0};
    SpscQueue<StrikeEvent, 1024> strikes_;
    SpscQueue<PoseSnapshot, 16> poses_;
    SpscQueue<TipState, 1024> tips_;
    std::thread strike_thread_, pose_thread_;
};

// ---- in -----------------------------------------------------------------------

enum class CommandKind {
    play,
    stop,
    tempo,        // value = bpm
    grip,         // text = french | german
    nuance,       // text
    mode,         // text = joint | cartesian
    gains,        // value = stiffness scale, value2 = damping scale
    drum_radius,  // value = m
    drum_tension, // value = N/m
    drum_density, // value = kg/m^2
    score,        // text = one score statement, e.g. "L accent 0.8" (docs/score.md)
    score_clear,  // forget the statements received so far
};

struct Command {
    // Room for one score statement: the longest text accepted is
    // kMaxText - 1 bytes (the server refuses longer ones with an error naming
    // the limit). Fixed size: commands cross a lock-free queue by value.
    static constexpr std::size_t kMaxText = 256;
    CommandKind kind = CommandKind::play;
    double value = 0.0, value2 = 0.0;
    char text[kMaxText] = {};
};

// What the physics thread publishes for /ictus/status (atomics only).
struct LiveStatus {
    std::atomic<double> time_s{0.0};
    std::atomic<int> playing{0};
    std::atomic<double> tempo_bpm{120.0};
    std::atomic<long> strikes{0};
    std::atomic<long> overruns{0}; // physics steps that started late by > 1 step
};

struct OscServerOptions {
    std::string bind_address = "127.0.0.1";         // numeric IPv4
    int port = 9001;                                // 0: any free port
    std::vector<std::string> allow = {"127.0.0.1"}; // peers (numeric IPv4); empty: any
    std::string reply_url;                          // default: reply to the sender
    std::size_t max_packet_bytes = 4096;            // larger packets are refused
};

struct OscServerCounters {
    unsigned long packets = 0, accepted = 0;
    unsigned long unknown_address = 0, bad_type_tags = 0, bad_values = 0, malformed = 0,
                  oversized = 0, refused_peers = 0, bundles = 0, queue_full = 0;
    unsigned long replies = 0, errors_sent = 0;
    unsigned long score_lines = 0;
    unsigned long errors() const
    {
        return unknown_address + bad_type_tags + bad_values + malformed + oversized + bundles +
               queue_full;
    }
};

class OscServer
{
  public:
    // Binds the socket (throws OscError naming the address) and starts its thread.
    OscServer(const OscServerOptions &options, LiveStatus *status);
    ~OscServer(); // stops and joins
    OscServer(const OscServer &) = delete;
    OscServer &operator=(const OscServer &) = delete;

    int port() const { return port_; }
    // Consumer side (the physics thread).
    bool pop_command(Command &command) { return commands_.pop(command); }
    OscServerCounters counters() const;
    void stop();

  private:
    void loop();
    void handle(const unsigned char *data, std::size_t size, const void *peer);
    struct Impl;
    std::unique_ptr<Impl> impl_;
    OscServerOptions options_;
    LiveStatus *status_;
    int port_ = 0;
    std::atomic<bool> running_{true};
    SpscQueue<Command, 256> commands_;
    std::thread thread_;
};

} // namespace ictus
