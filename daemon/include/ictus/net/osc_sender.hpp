// osc_sender.hpp -- the OSC link between ictusd and Pd, way out (paper,
// Figure 3: the physics, graphics, interaction and sound managers run
// asynchronously and talk OSC): strike bundles, time-tagged for exact
// scheduling, and a pose stream for graphics, each sent by its own thread from
// lock-free queues fed by the physics thread. The way in is osc_server.hpp.
// The namespace, type tags and units are in docs/osc.md.
#pragma once

#include "ictus/base/spsc_queue.hpp"
#include "ictus/perform/commands.hpp"
#include "ictus/sim/strike_detector.hpp"

#include <array>
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

// `url` is osc.udp://HOST:PORT: UDP, a port 1..65535 in digits, a host that
// resolves to an IPv4 address; else OscError "OPTION 'url': why" (--target,
// --reply: docs/osc.md).
void check_osc_udp_url(const char *option, const std::string &url);

struct OscSenderOptions {
    std::string target_url = "osc.udp://127.0.0.1:9000";
    // Strike bundles carry the timetag epoch + time_s + lookahead_s. A
    // lookahead of 0 sends them as "immediately" (timetag 1).
    double lookahead_s = 0.010;
    // The strike thread asks for real-time scheduling (base/realtime.hpp);
    // refused quietly (the verb says whether its own request succeeded).
    bool realtime = false;
};

// One drum of a kit as the sound needs it (/ictus/kit/drum, docs/osc.md): its
// index (the strikes' `drum`), name, membrane preset, head, pan (-1..1, + to
// the left channel), and its General MIDI note (the kit's, as performance.mid
// writes its strikes: docs/midi.md).
struct KitDrumSound {
    int index = 0;
    std::string name, preset;
    double radius_m = 0.0, tension_n_per_m = 0.0, pan = 0.0;
    int midi_note = 38;
};

struct OscSenderCounters {
    unsigned long strikes_sent = 0, strike_ends_sent = 0, poses_sent = 0, tips_sent = 0;
    unsigned long kits_sent = 0;
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

    // A strike at its onset (/ictus/strike: the sound's fields; peak force,
    // impulse and duration 0), and the same strike at its release
    // (/ictus/strike/end: seq, hand and the contact's measures), each in a
    // bundle time-tagged epoch + its time + lookahead (docs/osc.md).
    bool post_strike(const StrikeEvent &event);
    bool post_strike_end(const StrikeEvent &event);
    bool post_pose(const PoseSnapshot &pose);
    // The kit the sound plays (none: empty). Set once, before the first
    // send_kit(); `kit_name` "" with no drums sends nothing.
    void set_kit(const std::string &kit_name, const std::vector<KitDrumSound> &drums);
    // Sends the kit (/ictus/kit and one /ictus/kit/drum per drum, one bundle,
    // "immediately") from the strike thread before the strikes queued after
    // this call. Lock-free, never blocks: for the physics thread.
    void send_kit();
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
    std::atomic<unsigned long> strikes_sent_{0}, strike_ends_sent_{0}, poses_sent_{0},
        tips_sent_{0}, kits_sent_{0}, send_errors_{0};
    void send_kit_now();
    std::string kit_name_;
    std::vector<KitDrumSound> kit_;
    std::atomic<bool> kit_set_{false}, kit_wanted_{false};
    // Each drum's pedal as last sent (/ictus/kit/pedal; -1: not yet since the
    // kit was sent), the strike thread's own.
    std::array<double, kMaxDrums> pedal_sent_{}; // filled with -1 by the constructor
    struct StrikeMessage {
        StrikeEvent event;
        bool end = false; // /ictus/strike/end
    };
    SpscQueue<StrikeMessage, 1024> strikes_;
    SpscQueue<PoseSnapshot, 16> poses_;
    SpscQueue<TipState, 1024> tips_;
    std::thread strike_thread_, pose_thread_;
};

// ---- in -----------------------------------------------------------------------

} // namespace ictus
