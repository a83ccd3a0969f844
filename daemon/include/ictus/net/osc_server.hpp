// osc_server.hpp -- the OSC link's way in: a UDP server (loopback by default,
// allow-listed peers) that validates commands (fixed type tags, ranges) and
// hands them to the physics thread through a lock-free queue; malformed
// packets are counted and dropped. The namespace is in docs/osc.md.
#pragma once

#include "ictus/base/async_log.hpp"
#include "ictus/base/spsc_queue.hpp"
#include "ictus/net/osc_sender.hpp" // OscError
#include "ictus/perform/commands.hpp"

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace ictus
{

struct OscServerOptions {
    std::string bind_address = "127.0.0.1";         // numeric IPv4
    int port = 9001;                                // 0: any free port
    std::vector<std::string> allow = {"127.0.0.1"}; // peers (numeric IPv4), not empty
    bool allow_any = false;              // every peer (--allow any); `allow` is then ignored
    std::string reply_url;               // default: reply to the sender
    std::size_t max_packet_bytes = 4096; // larger packets are refused
    AsyncLog *log = nullptr;             // where the server's log lines go; null: stderr
};

// Error replies (/ictus/error) to one peer address: a bucket of
// kErrorReplyBurst, refilled at kErrorRepliesPerSecond; past it an error is
// counted (errors_unanswered) and not answered, so that junk sent to the port
// (a 1-byte packet earns a 60-byte reply) cannot be reflected at a volume.
// All peers together: kErrorRepliesPerSecondTotal. docs/osc.md.
constexpr double kErrorRepliesPerSecond = 10.0;
constexpr double kErrorReplyBurst = 20.0;
constexpr double kErrorRepliesPerSecondTotal = 100.0;

struct OscServerCounters {
    unsigned long packets = 0, accepted = 0;
    unsigned long unknown_address = 0, bad_type_tags = 0, bad_values = 0, malformed = 0,
                  oversized = 0, refused_peers = 0, bundles = 0, queue_full = 0;
    unsigned long replies = 0, errors_sent = 0;
    // Errors counted but not answered: over the peer's error-reply budget.
    unsigned long errors_unanswered = 0;
    unsigned long score_lines = 0;
    // Commands accepted here and refused by the physics (a gains past the
    // stability bounds, a play of a score that cannot be planned ...).
    unsigned long refused_commands = 0;
    // Commands taken by the physics whose /ictus/reply was not sent: the
    // confirmation queue was full (a flood faster than the server drains it).
    unsigned long replies_dropped = 0;
    unsigned long errors() const
    {
        return unknown_address + bad_type_tags + bad_values + malformed + oversized + bundles +
               queue_full + refused_commands;
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
    // A refusal found after the command was acknowledged (by the physics
    // thread or the planner), sent by the server's thread as /ictus/error
    // <address> <why> to the command's peer (no peer: the last one heard
    // from), within the error-reply budget. Producer: one thread (the
    // physics thread); lock-free, false when the queue is full.
    bool post_refusal(const Refusal &refusal) { return refusals_.push(refusal); }
    // A command the physics thread took: the server's thread answers its
    // peer with /ictus/reply <address> <arguments> (a command with no peer,
    // the daemon's own, is not answered). Same producer as post_refusal;
    // lock-free; a full queue drops the reply and counts it.
    void post_accepted(const Command &command);
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
    SpscQueue<Refusal, 64> refusals_;
    SpscQueue<Command, 512> confirmations_;
    void send_verdicts();
    std::thread thread_;

  public:
    // For tests and fuzzing (fuzz/fuzz_osc_server.cpp): handles one datagram on
    // the caller's thread as if it came from the first allowed peer (127.0.0.1
    // when any peer is allowed), counted as the server's thread counts one.
    // Replies go to reply_url, else to that peer's port 0 (dropped by the
    // kernel). Call it after stop(), or while nothing sends to the port: the
    // command queue has one producer. True when the packet was accepted (a
    // command queued or a query answered), false when refused (counters()).
    bool dispatch_packet(const void *data, std::size_t size);
};

} // namespace ictus
