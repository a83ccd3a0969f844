// The real-time loop of `ictusd run` (realtime_loop.hpp): physics paced by
// the wall clock, commands in, strikes (each at its onset and its release),
// poses and tip states out, through RealtimeIo. The loop never waits on
// anything but the clock.
#include "ictus/perform/realtime_loop.hpp"

#include "ictus/base/realtime.hpp"
#include "ictus/perform/strike_log.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

namespace ictus
{

namespace
{

// Every refusal goes to the log and, through `io`, to the client.
void refuse(RealtimeIo &io, std::uint32_t ipv4, std::uint16_t port, const char *address,
            const char *why)
{
    char line[320];
    std::snprintf(line, sizeof line, "ictusd run: %s%s%s", address, address[0] ? ": " : "", why);
    io.log(line);
    Refusal f;
    f.peer_ipv4 = ipv4;
    f.peer_port = port;
    std::snprintf(f.address, sizeof f.address, "%s", address);
    std::snprintf(f.why, sizeof f.why, "%s", why);
    io.refused(f);
}

// One step of the loop: the physics and what it hands out.
class LoopStep
{
  public:
    LoopStep(Performance &performance, RealtimeIo &io, LiveStatus &status,
             const RealtimeLoopOptions &options)
        : perf_(performance), io_(io), status_(status)
    {
        const double h = perf_.step_s();
        pose_every_ = options.pose_rate_hz > 0.0
                          ? std::max(1L, std::lround(1.0 / (options.pose_rate_hz * h)))
                          : 0;
        tip_every_ = options.tip_rate_hz > 0.0
                         ? std::max(1L, std::lround(1.0 / (options.tip_rate_hz * h)))
                         : 0;
    }

    void run(long n)
    {
        apply_commands();
        const int k = perf_.step(ev_);
        // Refusals found later (a score the worker could not plan, the
        // runaway guard) reach the client too.
        for (Refusal f; perf_.pop_refusal(f);)
            refuse(io_, f.peer_ipv4, f.peer_port, f.address, f.why);
        for (Command c; perf_.pop_confirmation(c);)
            io_.accepted(c);
        send_strikes(k);
        if (pose_every_ && n % pose_every_ == 0) {
            PoseSnapshot p;
            perf_.pose(p);
            io_.pose(p);
        }
        if (tip_every_ && n % tip_every_ == 0)
            for (int hand = 0; hand < 2; ++hand) {
                TipState t;
                perf_.tip(hand, t);
                io_.tip(t);
            }
        status_.time_s = perf_.time_s();
        status_.playing = perf_.playing() ? 1 : 0;
        status_.tempo_bpm = perf_.tempo_bpm();
        status_.strikes += k;
        status_.runaways = perf_.runaways();
        status_.mode = static_cast<int>(perf_.mode());
        status_.grip = static_cast<int>(perf_.options().character.grip);
    }

    // Ends the contacts still open and logs every strike held.
    void finish()
    {
        auto to_log = [this](const StrikeEvent &e) { io_.strike_logged(e); };
        StrikeEvent last;
        while (perf_.flush(last)) {
            io_.strike_end(last);
            order_.push(last, to_log);
        }
        order_.flush(to_log);
    }

    long out_of_order() const { return order_.early(); }

  private:
    void apply_commands()
    {
        Command c;
        while (io_.next_command(c)) {
            std::string why;
            if (!perf_.apply(c, &why))
                refuse(io_, c.peer_ipv4, c.peer_port, c.address, why.c_str());
            else if (!perf_.deferred()) // else its verdict comes with the work's result
                io_.accepted(c);
        }
    }

    // A strike leaves at its onset with what the sound needs, so that the
    // lookahead covers only transport and jitter; its force and duration
    // follow at the release. The log has them in onset order.
    void send_strikes(int k)
    {
        auto to_log = [this](const StrikeEvent &e) { io_.strike_logged(e); };
        StrikeEvent onset[kStepStrikes];
        const int ons = perf_.take_onsets(onset);
        for (int i = 0; i < ons; ++i)
            io_.strike_onset(onset[i]);
        for (int i = 0; i < k; ++i) {
            io_.strike_end(ev_[i]);
            order_.push(ev_[i], to_log);
        }
        order_.release(perf_.detector().first_open_seq(), to_log);
    }

    Performance &perf_;
    RealtimeIo &io_;
    LiveStatus &status_;
    long pose_every_ = 0, tip_every_ = 0;
    StrikeEvent ev_[kStepStrikes];
    StrikeOrder order_;
};

} // namespace

void begin_status(const Performance &performance, LiveStatus &status)
{
    status.tempo_bpm = performance.options().tempo_bpm;
    status.score = performance.score_mode() ? 1 : 0;
    status.mode = static_cast<int>(performance.mode());
    status.grip = static_cast<int>(performance.options().character.grip);
}

RealtimeLoopResult run_realtime(Performance &performance, RealtimeIo &io, LiveStatus &status,
                                const RealtimeLoopOptions &options)
{
    // The physics loop keeps time: real-time scheduling when the system
    // grants it (docs/osc.md, "Real time"). Asked for by this thread alone:
    // the others keep ordinary scheduling.
    if (options.realtime) {
        std::string why;
        if (!set_realtime_priority(kPhysicsPriority, &why))
            io.log(("ictusd run: note: no real-time scheduling (" + why +
                    "); on a busy machine strikes may arrive late (raise --lookahead, or allow "
                    "rtprio)")
                       .c_str());
    }
    using clock = std::chrono::steady_clock;
    const double h = performance.step_s();
    const auto period =
        std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(h));
    const long steps = options.duration_s > 0.0 ? std::lround(options.duration_s / h) : -1;
    LoopStep step(performance, io, status, options);
    // Simulation time 0 is now.
    auto wall0 = clock::now();
    io.clock_started();
    long n = 0;
    for (; steps < 0 || n < steps; ++n) {
        if (io.stop_requested())
            break;
        // Pace: step n starts at wall0 + n h. Far behind (a stall), move the
        // anchor, so that timetags stay ahead of the wall clock.
        const auto due = wall0 + n * period;
        const auto now = clock::now();
        if (now < due) {
            std::this_thread::sleep_until(due);
        } else if (now - due > 50 * period) {
            const auto lag = now - due;
            wall0 += lag;
            io.clock_slipped(std::chrono::duration<double>(lag).count());
            status.overruns++;
        }
        step.run(n);
    }
    step.finish();
    RealtimeLoopResult result;
    result.steps = n;
    result.out_of_order = step.out_of_order();
    return result;
}

} // namespace ictus
