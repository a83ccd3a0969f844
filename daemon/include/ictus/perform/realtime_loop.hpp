// realtime_loop.hpp -- the real-time loop of `ictusd run`: the performance
// stepped at the pace of the wall clock, the commands received applied
// between steps, strikes, poses, tip states and refusals handed out as they
// happen, the live status published. What comes in and goes out is reached
// through RealtimeIo (cli wires the network to it): perform never sees net.
// The loop runs on the calling thread (the physics thread): it never waits
// on the network and never touches the disk; RealtimeIo's methods must not
// either (hand the data to a queue). docs/osc.md, docs/perform.md.
#pragma once

#include "ictus/perform/commands.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/sim/strike_event.hpp"

namespace ictus
{

// What the loop receives and sends, called from the physics thread.
class RealtimeIo
{
  public:
    virtual ~RealtimeIo() = default;
    // The next command received, false when none waits.
    virtual bool next_command(Command &out) = 0;
    // A command the performance took, for its sender's /ictus/reply: the
    // reply comes after the physics thread's verdict, never before a refusal.
    virtual void accepted(const Command &command) = 0;
    // A refusal of a command (at once, or found later), for its sender
    // (the loop has logged it too).
    virtual void refused(const Refusal &refusal) = 0;
    // A line for the daemon's log (stderr), without its newline: posted,
    // never written here (base/async_log.hpp), so that a stderr nobody reads
    // cannot hold the loop.
    virtual void log(const char *line) = 0;
    // A strike at its onset (what the sound needs: time, hand, position,
    // velocity), and the same strike at its release (force, impulse,
    // duration).
    virtual void strike_onset(const StrikeEvent &strike) = 0;
    virtual void strike_end(const StrikeEvent &strike) = 0;
    // Every strike again, whole, in onset order (strikes.csv).
    virtual void strike_logged(const StrikeEvent &strike) = 0;
    virtual void pose(const PoseSnapshot &pose) = 0;
    virtual void tip(const TipState &tip) = 0;
    // Simulation time 0 is now (called once, before the first step).
    virtual void clock_started() = 0;
    // The loop fell far behind (a stall): from now on, simulation time t
    // is `lag_s` later on the wall clock than it was.
    virtual void clock_slipped(double lag_s) = 0;
    // Whether the run ends now (SIGINT, a failed strikes.csv).
    virtual bool stop_requested() = 0;
};

struct RealtimeLoopOptions {
    double duration_s = 0.0;    // simulated seconds; 0: until stop_requested()
    double pose_rate_hz = 30.0; // 0: no poses
    double tip_rate_hz = 0.0;   // 0: no tip states
    bool realtime = false;      // SCHED_FIFO for the loop, when the system allows it
};

struct RealtimeLoopResult {
    long steps = 0;
    long out_of_order = 0; // strikes logged out of onset order (StrikeOrder::early)
};

// The live status before the first step: the performance's options.
void begin_status(const Performance &performance, LiveStatus &status);

// Runs `performance` in real time until the duration is over or `io` asks
// to stop, then ends the contacts still open. `status` is what the network
// answers /ictus/status with, updated every step (overruns: the stalls
// after which the loop moved its anchor on the wall clock).
RealtimeLoopResult run_realtime(Performance &performance, RealtimeIo &io, LiveStatus &status,
                                const RealtimeLoopOptions &options);

} // namespace ictus
