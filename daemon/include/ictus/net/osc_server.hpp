// osc_server.hpp -- the OSC link's way in: a UDP server (loopback by default,
// allow-listed peers) that validates commands (fixed type tags, ranges) and
// hands them to the physics thread through a lock-free queue; malformed
// packets are counted and dropped. The namespace is in docs/osc.md.
#pragma once

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
