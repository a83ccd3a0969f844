// fuzz_osc_server.cpp -- libFuzzer harness of the OSC server's packet handling
// (net/osc_server.hpp): each input is one UDP datagram, handed to the server
// through OscServer::dispatch_packet as if it came from the allowed peer.
// The server is made once (bound to a free loopback port, its thread
// stopped so that this thread is its only producer); replies go to a port-0
// peer and are dropped by the kernel. The commands it queues are drained and
// checked, and a score statement goes on into a ScoreBuilder as on the
// physics thread (perform/performance.cpp).
//
// A crash, a sanitizer report, a run over the -timeout, a packet counted
// other than once, or a queued command outside its address's type and range
// (docs/osc.md) is a finding. See docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/net/osc_server.hpp"
#include "ictus/score/score.hpp"

#include <cstring>

using namespace ictus;

namespace
{

// A little above the server's packet limit (4096), so that oversized
// packets are tried too.
constexpr std::size_t kMaxInputBytes = 5000;

bool one_of(const char *text, std::initializer_list<const char *> words)
{
    for (const char *w : words)
        if (std::strcmp(text, w) == 0)
            return true;
    return false;
}

bool in_range(double v, double lo, double hi)
{
    return std::isfinite(v) && v >= lo && v <= hi;
}

void check_command(const Command &c, ScoreBuilder &score)
{
    ICTUS_FUZZ_CHECK(std::memchr(c.text, '\0', Command::kMaxText) != nullptr,
                     "command text without its terminator");
    switch (c.kind) {
    case CommandKind::play:
    case CommandKind::stop:
        break;
    case CommandKind::tempo:
        ICTUS_FUZZ_CHECK(in_range(c.value, 20.0, 400.0), "tempo outside 20..400 queued");
        break;
    case CommandKind::grip:
        ICTUS_FUZZ_CHECK(one_of(c.text, {"french", "german"}), "unknown grip queued");
        break;
    case CommandKind::nuance:
        ICTUS_FUZZ_CHECK(
            one_of(c.text, {"legato", "tenuto", "accent", "vertical_accent", "staccato"}),
            "unknown nuance queued");
        break;
    case CommandKind::mode:
        ICTUS_FUZZ_CHECK(one_of(c.text, {"joint", "cartesian"}), "unknown mode queued");
        break;
    case CommandKind::gains:
        ICTUS_FUZZ_CHECK(in_range(c.value, 0.05, 4.0) && in_range(c.value2, 0.05, 4.0),
                         "gain scale outside 0.05..4 queued");
        break;
    case CommandKind::drum_radius:
        ICTUS_FUZZ_CHECK(in_range(c.value, 0.05, 1.0), "drum radius outside 0.05..1 queued");
        break;
    case CommandKind::drum_tension:
        ICTUS_FUZZ_CHECK(in_range(c.value, 10.0, 1e5), "drum tension outside 10..1e5 queued");
        break;
    case CommandKind::drum_density:
        ICTUS_FUZZ_CHECK(in_range(c.value, 0.01, 10.0), "drum density outside 0.01..10 queued");
        break;
    case CommandKind::score: {
        const std::size_t length = std::strlen(c.text);
        ICTUS_FUZZ_CHECK(length > 0 && length < Command::kMaxText, "score statement length");
        try {
            score.add_statement(c.text);
        } catch (const ScoreError &) {
            score.reset(); // as after a faulty score: start again
        }
        break;
    }
    case CommandKind::score_clear:
        score.reset();
        break;
    default:
        ICTUS_FUZZ_CHECK(false, "a command of no known kind");
    }
}

struct Server {
    LiveStatus status;
    OscServer server;
    Server() : server(options(), &status) { server.stop(); }
    static OscServerOptions options()
    {
        OscServerOptions o;
        o.port = 0; // any free port: nothing sends to it
        return o;
    }
};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    static Server s;
    // A fresh score per input, so that a finding replays from its input alone.
    ScoreBuilder score("osc");
    const OscServerCounters before = s.server.counters();
    const bool accepted = s.server.dispatch_packet(data, size);
    const OscServerCounters after = s.server.counters();
    ICTUS_FUZZ_CHECK(after.packets == before.packets + 1, "a packet not counted");
    ICTUS_FUZZ_CHECK(after.accepted + after.errors() == before.accepted + before.errors() + 1,
                     "a packet counted other than once (accepted or one error)");
    ICTUS_FUZZ_CHECK(accepted == (after.accepted == before.accepted + 1),
                     "dispatch_packet's result is not the count");
    Command c;
    int queued = 0;
    while (s.server.pop_command(c)) {
        check_command(c, score);
        ++queued;
    }
    ICTUS_FUZZ_CHECK(queued <= 1, "one packet queued several commands");
    // The statement as a score, as /ictus/play would take it (refused while a repeat is open).
    try {
        (void)score.finish();
    } catch (const ScoreError &) {
    }
    return 0;
}
