// OSC in: Pd (or anything that speaks OSC) controls the daemon (osc_server.hpp,
// docs/osc.md). A plain UDP socket of our own, so that the bind address, the
// peer allow-list and the packet size are checked before any parsing; liblo
// deserialises and validates each message; a table of methods (address, type
// tags, handler: kMethods) dispatches it, and the handlers check the values,
// queue a Command for the physics thread and reply over OSC.
#include "ictus/net/osc_server.hpp"
#include "ictus/character/character.hpp"
#include "ictus/perform/tracker.hpp"
#include "ictus/score/score.hpp"

#include <lo/lo.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace ictus
{

namespace
{

// liblo's argument pointers are only 4-byte aligned, while lo_arg (a union
// with 64-bit members) asks for 8: read the bytes, never the union member.
float lo_arg_float(const lo_arg *a)
{
    float f;
    std::memcpy(&f, a, sizeof f);
    return f;
}
int32_t lo_arg_int(const lo_arg *a)
{
    int32_t i;
    std::memcpy(&i, a, sizeof i);
    return i;
}
const char *lo_arg_string(const lo_arg *a)
{
    return reinterpret_cast<const char *>(a);
}

struct Counters {
    std::atomic<unsigned long> packets{0}, accepted{0}, unknown_address{0}, bad_type_tags{0},
        bad_values{0}, malformed{0}, oversized{0}, refused_peers{0}, bundles{0}, queue_full{0},
        replies{0}, errors_sent{0}, errors_unanswered{0}, score_lines{0}, refused_commands{0},
        replies_dropped{0};
};

// The error-reply budget (osc_server.hpp): a token bucket per address the
// replies go to, in a small fixed table (nothing allocated on the server's
// thread; when it is full, the address heard from longest ago gives up its
// slot), and one bucket for all of them, which bounds the total however many
// addresses a flood comes from.
class ErrorReplyBudget
{
  public:
    using Clock = std::chrono::steady_clock;
    bool take(uint32_t address, Clock::time_point now)
    {
        Slot *slot = nullptr, *oldest = &slots_[0];
        for (Slot &s : slots_) {
            if (s.used && s.address == address) {
                slot = &s;
                break;
            }
            if (!s.used || (oldest->used && s.bucket.last < oldest->bucket.last))
                oldest = &s;
        }
        if (!slot) {
            slot = oldest;
            *slot = Slot{address, true, Bucket{kErrorReplyBurst, now}};
        }
        return slot->bucket.take(now, kErrorRepliesPerSecond, kErrorReplyBurst) &&
               total_.take(now, kErrorRepliesPerSecondTotal, kErrorRepliesPerSecondTotal);
    }

  private:
    struct Bucket {
        double tokens;
        Clock::time_point last;
        bool take(Clock::time_point now, double per_second, double burst)
        {
            tokens = std::min(
                burst, tokens + per_second * std::chrono::duration<double>(now - last).count());
            last = now;
            if (tokens < 1.0)
                return false;
            tokens -= 1.0;
            return true;
        }
    };
    struct Slot {
        uint32_t address;
        bool used;
        Bucket bucket;
    };
    std::array<Slot, 64> slots_{};
    Bucket total_{kErrorRepliesPerSecondTotal, Clock::now()};
};

bool parse_ipv4(const std::string &text, in_addr &out)
{
    return inet_pton(AF_INET, text.c_str(), &out) == 1;
}

OscServerCounters snapshot(const Counters &c)
{
    OscServerCounters o;
    o.packets = c.packets;
    o.accepted = c.accepted;
    o.unknown_address = c.unknown_address;
    o.bad_type_tags = c.bad_type_tags;
    o.bad_values = c.bad_values;
    o.malformed = c.malformed;
    o.oversized = c.oversized;
    o.refused_peers = c.refused_peers;
    o.bundles = c.bundles;
    o.queue_full = c.queue_full;
    o.replies = c.replies;
    o.errors_sent = c.errors_sent;
    o.errors_unanswered = c.errors_unanswered;
    o.score_lines = c.score_lines;
    o.refused_commands = c.refused_commands;
    o.replies_dropped = c.replies_dropped;
    return o;
}

// A rate-limited log: at most one line per second, with the count of the
// lines suppressed since; posted to the daemon's log when there is one (the
// server's thread then never waits on stderr), else written to stderr.
class RateLimitedLog
{
  public:
    AsyncLog *sink = nullptr;
    void operator()(const char *what, const std::string &detail)
    {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ < std::chrono::seconds(1)) {
            ++suppressed_;
            return;
        }
        if (suppressed_)
            emit("ictusd: osc: (" + std::to_string(suppressed_) + " similar lines suppressed)");
        suppressed_ = 0;
        last_ = now;
        emit(std::string("ictusd: osc: ") + what + ": " + detail);
    }

  private:
    void emit(const std::string &line)
    {
        if (sink)
            sink->post(line.c_str());
        else
            std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::chrono::steady_clock::time_point last_{};
    unsigned long suppressed_ = 0;
};

} // namespace

struct OscServer::Impl {
    int fd = -1;
    std::vector<in_addr> allow;
    bool reply_fixed = false;
    sockaddr_in reply_to{};
    Counters counters;
    ErrorReplyBudget error_budget;
    sockaddr_in last_peer{}; // the last allowed peer heard from (sin_port 0: none yet)
    RateLimitedLog log;
    unsigned char buffer[65536 + 1];
    ~Impl()
    {
        if (fd >= 0)
            close(fd);
    }
};

OscServer::OscServer(const OscServerOptions &options, LiveStatus *status)
    : impl_(new Impl), options_(options), status_(status)
{
    impl_->log.sink = options.log;
    in_addr bind_addr;
    if (!parse_ipv4(options.bind_address, bind_addr))
        throw OscError("--bind: expected a numeric IPv4 address, got '" + options.bind_address +
                       "'");
    if (options.port < 0 || options.port > 65535)
        throw OscError("--port: expected 0 to 65535, got " + std::to_string(options.port));
    if (options.max_packet_bytes < 64 || options.max_packet_bytes > 65536)
        throw OscError("max packet size: expected 64 to 65536 bytes");
    // An empty list would admit every peer unnoticed (--allow ""): "any" is
    // said with allow_any, and leaves `allow` empty.
    if (!options.allow_any && options.allow.empty())
        throw OscError("--allow: empty list (give numeric IPv4 addresses, or 'any')");
    for (const std::string &a : options.allow_any ? std::vector<std::string>{} : options.allow) {
        in_addr ia;
        if (!parse_ipv4(a, ia))
            throw OscError("--allow: expected numeric IPv4 addresses, got '" + a + "'");
        impl_->allow.push_back(ia);
    }
    if (!options.reply_url.empty()) {
        char *host = lo_url_get_hostname(options.reply_url.c_str());
        char *port = lo_url_get_port(options.reply_url.c_str());
        const bool ok = host && port && parse_ipv4(host, impl_->reply_to.sin_addr) &&
                        std::atoi(port) > 0 && std::atoi(port) < 65536;
        if (ok) {
            impl_->reply_to.sin_family = AF_INET;
            impl_->reply_to.sin_port = htons(static_cast<uint16_t>(std::atoi(port)));
        }
        std::free(host);
        std::free(port);
        if (!ok)
            throw OscError("--reply: expected osc.udp://IPV4:PORT, got '" + options.reply_url +
                           "'");
        impl_->reply_fixed = true;
    }
    impl_->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (impl_->fd < 0)
        throw OscError(std::string("socket: ") + std::strerror(errno));
    // Room for bursts (Pd sending a score): the kernel caps it at rmem_max.
    int rcvbuf = 1 << 20;
    setsockopt(impl_->fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_addr = bind_addr;
    sa.sin_port = htons(static_cast<uint16_t>(options.port));
    if (bind(impl_->fd, reinterpret_cast<sockaddr *>(&sa), sizeof sa) != 0)
        throw OscError("--bind/--port: cannot bind " + options.bind_address + ":" +
                       std::to_string(options.port) + ": " + std::strerror(errno));
    socklen_t len = sizeof sa;
    getsockname(impl_->fd, reinterpret_cast<sockaddr *>(&sa), &len);
    port_ = ntohs(sa.sin_port);
    thread_ = std::thread(&OscServer::loop, this);
}

OscServer::~OscServer()
{
    stop();
}

void OscServer::stop()
{
    running_.store(false);
    if (thread_.joinable())
        thread_.join();
}

OscServerCounters OscServer::counters() const
{
    return snapshot(impl_->counters);
}

void OscServer::loop()
{
    pollfd pfd{impl_->fd, POLLIN, 0};
    while (running_.load()) {
        // A short poll so that stop() is seen within 50 ms.
        send_verdicts();
        if (poll(&pfd, 1, 20) <= 0)
            continue;
        sockaddr_in peer{};
        socklen_t len = sizeof peer;
        // MSG_TRUNC: the real length of a datagram longer than the buffer.
        const ssize_t n = recvfrom(impl_->fd, impl_->buffer, sizeof impl_->buffer, MSG_TRUNC,
                                   reinterpret_cast<sockaddr *>(&peer), &len);
        if (n < 0)
            continue;
        handle(impl_->buffer, static_cast<std::size_t>(n), &peer);
        // Counted once handled: a reader that sees N packets sees their
        // categories counted too.
        impl_->counters.packets++;
    }
}

namespace
{

struct Reply {
    int fd;
    const sockaddr_in *to;
    Counters *counters;
    ErrorReplyBudget *error_budget;
    void send(const char *path, lo_message m)
    {
        unsigned char buf[1024];
        std::size_t size = sizeof buf;
        if (lo_message_length(m, path) <= sizeof buf &&
            lo_message_serialise(m, path, buf, &size) != nullptr)
            sendto(fd, buf, size, 0, reinterpret_cast<const sockaddr *>(to), sizeof *to);
        lo_message_free(m);
    }
    void error(const char *address, const std::string &text)
    {
        // Over the budget of the address it would go to: counted, unanswered.
        if (!error_budget->take(to->sin_addr.s_addr, std::chrono::steady_clock::now())) {
            counters->errors_unanswered++;
            return;
        }
        // The address and the reason no longer than it takes to recognise
        // them (ours are under 32 and 160 characters): an unknown address or
        // a list of type tags may be 4 kB long, the reply never is.
        std::string echoed(address), reason(text);
        echoed.resize(std::min<std::size_t>(echoed.size(), 64));
        reason.resize(std::min<std::size_t>(reason.size(), 200));
        lo_message m = lo_message_new();
        lo_message_add_string(m, echoed.c_str());
        lo_message_add_string(m, reason.c_str());
        // Counted before it leaves: a peer that has the reply sees it counted.
        counters->errors_sent++;
        send("/ictus/error", m);
    }
    void ok(const char *address, lo_message extra = nullptr)
    {
        lo_message m = extra ? extra : lo_message_new();
        // The replied-to address first: rebuild with it in front.
        lo_message r = lo_message_new();
        lo_message_add_string(r, address);
        const int argc = lo_message_get_argc(m);
        const char *types = lo_message_get_types(m);
        lo_arg **argv = lo_message_get_argv(m);
        for (int i = 0; i < argc; ++i) {
            switch (types[i]) {
            case 'f':
                lo_message_add_float(r, lo_arg_float(argv[i]));
                break;
            case 'i':
                lo_message_add_int32(r, lo_arg_int(argv[i]));
                break;
            case 's':
                lo_message_add_string(r, lo_arg_string(argv[i]));
                break;
            default:
                break;
            }
        }
        lo_message_free(m);
        counters->replies++;
        send("/ictus/reply", r);
    }
};

// What a command's value must be: a float's range, a word's list, or (no
// words, a string) a score statement.
struct CommandSpec {
    CommandKind kind = CommandKind::play;
    double lo = 0, hi = 0; // range of the floats
    const char *what = "";
    const char *const *words = nullptr; // the words a string may be (null-terminated)
    const char *expected = "";          // the words, as an error names them
};

constexpr const char *kGrips[] = {"french", "german", nullptr};
// vertical-accent: the score's other spelling (docs/score.md), as the statement `nuance N`
constexpr const char *kNuances[] = {"legato",          "tenuto",   "accent", "vertical_accent",
                                    "vertical-accent", "staccato", "buzz",   nullptr};
constexpr const char *kModes[] = {"joint", "cartesian", nullptr};

// Why a score statement cannot be queued, or "" when it can. The score's own
// syntax is the physics thread's business (its parser names the fault's
// position); here only what would not survive the trip: the length of
// Command::text and control characters. A line break (LF, CR) separates
// statements in one string as in a file (docs/score.md): the parser takes it.
std::string score_statement_problem(const char *text, std::size_t length)
{
    if (length == 0)
        return "score statement: empty (send one statement, e.g. \"R legato\")";
    if (length >= Command::kMaxText)
        return "score statement: " + std::to_string(length) + " characters exceed the limit of " +
               std::to_string(Command::kMaxText - 1) + " (send one statement per message)";
    for (std::size_t i = 0; i < length; ++i) {
        const unsigned char ch = static_cast<unsigned char>(text[i]);
        if ((ch < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') || ch == 0x7f)
            return "score statement: control character " + std::to_string(ch) + " at column " +
                   std::to_string(i + 1) + " (text, tabs and line breaks only)";
    }
    return "";
}

std::string format_range(const CommandSpec &s, double v)
{
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s: expected %g to %g, got %g", s.what, s.lo, s.hi, v);
    return buf;
}

// Why a string argument cannot be queued, or "" when it can.
std::string text_problem(const CommandSpec &s, const char *text, std::size_t length)
{
    if (!s.words)
        return score_statement_problem(text, length);
    for (const char *const *w = s.words; *w; ++w)
        if (strcasecmp(text, *w) == 0) // any case, as the score's words and the CLI's
            return "";
    return std::string(s.what) + ": expected " + s.expected + ", got '" +
           std::string(text, std::min<std::size_t>(length, 40)) + "'";
}

// One message as the methods see it: what arrived, from whom, and what the
// server lends them (the replies, the counters, the log, the status, the
// command queue).
struct Request {
    const char *path;
    const char *types;
    lo_arg **argv;
    const sockaddr_in &peer;
    Reply &reply;
    Counters &counters;
    RateLimitedLog &log;
    LiveStatus *status;
    SpscQueue<Command, 256> &commands;
};

// The OSC namespace (docs/osc.md) as a table of methods, in the manner of
// liblo's lo_server_add_method(server, path, types, handler, user_data): a
// message whose address and type tags match exactly goes to the handler,
// with the method's user data (here a command's kind and checks).
struct Method {
    const char *address;
    const char *types;
    void (*handler)(const Request &request, const CommandSpec &command);
    CommandSpec command; // the user data: a command's kind and checks (none for queries)
};

void handle_ping(const Request &r, const CommandSpec &)
{
    r.counters.accepted++;
    lo_message pong = lo_message_new();
    r.counters.replies++;
    r.reply.send("/ictus/pong", pong);
}

void handle_status(const Request &r, const CommandSpec &)
{
    Counters &c = r.counters;
    const LiveStatus *status = r.status;
    c.accepted++;
    lo_message s = lo_message_new();
    lo_message_add_float(s, status ? static_cast<float>(status->time_s.load()) : 0.0f);
    lo_message_add_int32(s, status ? status->playing.load() : 0);
    lo_message_add_float(s, status ? static_cast<float>(status->tempo_bpm.load()) : 0.0f);
    lo_message_add_int32(s, status ? static_cast<int>(status->strikes.load()) : 0);
    // This request is received and accepted: packets counts it only once
    // it is handled (loop()), so it is added here.
    lo_message_add_int32(s, static_cast<int>(c.packets.load() + 1));
    lo_message_add_int32(s, static_cast<int>(c.accepted.load()));
    const OscServerCounters snap = snapshot(c);
    lo_message_add_int32(s, static_cast<int>(snap.errors()));
    lo_message_add_int32(s, static_cast<int>(c.refused_peers.load()));
    lo_message_add_int32(s, status ? static_cast<int>(status->overruns.load()) : 0);
    // The performance's state, by name: source, control mode, grip.
    lo_message_add_string(s, status && status->score.load() ? "score" : "clip");
    // (the mode by its name here: TrackMode's to_string lives with the tracker,
    // which the OSC fuzz harness does not link)
    const bool cartesian = status && status->mode.load() == static_cast<int>(TrackMode::cartesian);
    lo_message_add_string(s, cartesian ? "cartesian" : "joint");
    lo_message_add_string(s, to_string(static_cast<Grip>(status ? status->grip.load() : 0)));
    r.reply.ok(r.path, s);
}

// The command's arguments into `cmd` (floats in the spec's range, a string
// that passes text_problem()), or the reason it is refused.
std::string read_arguments(const Request &r, const CommandSpec &s, Command &cmd)
{
    double *const floats[2] = {&cmd.value, &cmd.value2};
    for (int i = 0; i < 2 && r.types[i] == 'f'; ++i) {
        *floats[i] = lo_arg_float(r.argv[i]);
        // The range's ends as an OSC float can hold them: 0.01 arrives as
        // 0.0099999998, and the documented end is taken (as the end itself).
        const double lo = static_cast<float>(s.lo), hi = static_cast<float>(s.hi);
        if (!(std::isfinite(*floats[i]) && *floats[i] >= lo && *floats[i] <= hi))
            return format_range(s, *floats[i]);
        *floats[i] = std::clamp(*floats[i], s.lo, s.hi);
    }
    if (r.types[0] == 's') {
        const char *text = lo_arg_string(r.argv[0]);
        // liblo checked the string's terminator inside the packet; the
        // packet limit bounds its length.
        const std::size_t length = std::strlen(text);
        const std::string problem = text_problem(s, text, length);
        if (!problem.empty())
            return problem;
        std::memcpy(cmd.text, text, length + 1); // fits: checked above
        if (s.words) // a word in lower case: the physics and the echo see it so
            for (std::size_t i = 0; i < length; ++i)
                cmd.text[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
    }
    return "";
}

// A command: checked and queued for the physics thread, which answers with
// its verdict: /ictus/reply once it took the command (send_verdicts), or
// /ictus/error. Nothing is replied here, so a command the physics refuses
// never gets a reply before its error.
void handle_command(const Request &r, const CommandSpec &s)
{
    Counters &c = r.counters;
    Command cmd;
    cmd.kind = s.kind;
    cmd.peer_ipv4 = r.peer.sin_addr.s_addr;
    cmd.peer_port = r.peer.sin_port;
    std::snprintf(cmd.address, sizeof cmd.address, "%s", r.path);
    std::snprintf(cmd.types, sizeof cmd.types, "%s", r.types); // the method's: at most "ff"
    const std::string problem = read_arguments(r, s, cmd);
    if (!problem.empty()) {
        c.bad_values++;
        r.reply.error(r.path, problem);
        return;
    }
    if (!r.commands.push(cmd)) {
        c.queue_full++;
        r.reply.error(r.path, "command queue full (the physics thread is not reading)");
        return;
    }
    c.accepted++;
    if (s.kind == CommandKind::score)
        c.score_lines++;
}

// The echo of a command the physics took: its arguments as they came.
lo_message echo_of(const Command &cmd)
{
    lo_message echo = lo_message_new();
    const double floats[2] = {cmd.value, cmd.value2};
    int f = 0;
    for (int i = 0; i < static_cast<int>(sizeof cmd.types) && cmd.types[i]; ++i) {
        if (cmd.types[i] == 'f' && f < 2)
            lo_message_add_float(echo, static_cast<float>(floats[f++]));
        else if (cmd.types[i] == 's')
            lo_message_add_string(echo, cmd.text);
    }
    return echo;
}

// One method a line (clang-format would break the rows).
// clang-format off
const Method kMethods[] = {
    {"/ictus/ping",          "",   handle_ping,    {}},
    {"/ictus/status",        "",   handle_status,  {}},
    {"/ictus/play",          "",   handle_command, {CommandKind::play}},
    {"/ictus/stop",          "",   handle_command, {CommandKind::stop}},
    {"/ictus/tempo",         "f",  handle_command, {CommandKind::tempo, 20.0, 400.0, "tempo (bpm)"}},
    {"/ictus/grip",          "s",  handle_command, {CommandKind::grip, 0, 0, "grip", kGrips, "french or german"}},
    {"/ictus/nuance",        "s",  handle_command, {CommandKind::nuance, 0, 0, "nuance", kNuances,
                                                    "legato, tenuto, accent, vertical_accent, staccato or buzz"}},
    {"/ictus/mode",          "s",  handle_command, {CommandKind::mode, 0, 0, "mode", kModes, "joint or cartesian"}},
    {"/ictus/gains",         "ff", handle_command, {CommandKind::gains, 0.05, 4.0, "gain scale"}},
    {"/ictus/drum/radius",   "f",  handle_command, {CommandKind::drum_radius, 0.05, 1.0, "drum radius (m)"}},
    {"/ictus/drum/tension",  "f",  handle_command, {CommandKind::drum_tension, 10.0, 1e5, "drum tension (N/m)"}},
    {"/ictus/drum/density",  "f",  handle_command, {CommandKind::drum_density, 0.01, 10.0, "drum density (kg/m^2)"}},
    {"/ictus/score",         "s",  handle_command, {CommandKind::score, 0, 0, "score statement"}},
    {"/ictus/score/clear",   "",   handle_command, {CommandKind::score_clear}},
    {"/ictus/grip/firmness", "f",  handle_command, {CommandKind::grip_firmness, 0.0, 1.0, "grip firmness (0..1)"}},
    {"/ictus/humanize",      "f",  handle_command, {CommandKind::humanize, 0.0, kMaxHumanize, "humanize (0..4)"}},
};
// clang-format on

// The method for the request's address, its type tags checked: called, or the
// request refused (unknown address, wrong type tags) and counted.
void dispatch(const Request &r)
{
    const Method *method = nullptr;
    for (const Method &m : kMethods) {
        if (std::strcmp(r.path, m.address) == 0) {
            method = &m;
            break;
        }
    }
    if (!method) {
        r.counters.unknown_address++;
        std::string shown(r.path, strnlen(r.path, 80));
        r.log("unknown address", shown);
        r.reply.error(r.path, "unknown address (see docs/osc.md)");
        return;
    }
    if (std::strcmp(r.types, method->types) != 0) {
        r.counters.bad_type_tags++;
        if (method->handler == handle_command)
            r.log("wrong type tags", std::string(r.path) + " ," + r.types);
        // No arguments (a query, play, stop, score/clear) are "none", not an
        // empty tag string, on either side.
        auto tags = [](const char *types) {
            return types[0] ? std::string(",") + types : std::string("none");
        };
        r.reply.error(r.path,
                      "type tags: expected " + tags(method->types) + ", got " + tags(r.types));
        return;
    }
    method->handler(r, method->command);
}

} // namespace

void OscServer::post_accepted(const Command &command)
{
    if (command.peer_port == 0)
        return; // the daemon's own command: nobody to answer
    if (!confirmations_.push(command))
        impl_->counters.replies_dropped++;
}

void OscServer::send_verdicts()
{
    Impl &im = *impl_;
    // Where a verdict goes: --reply's address, else the command's peer, else
    // (a command of the daemon's own) the last peer heard from.
    auto reply_to = [&im](std::uint32_t ipv4, std::uint16_t port) {
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_addr.s_addr = ipv4;
        to.sin_port = port;
        if (port == 0)
            to = im.last_peer;
        if (im.reply_fixed)
            to = im.reply_to;
        return to;
    };
    for (Command cmd; confirmations_.pop(cmd);) {
        const sockaddr_in to = reply_to(cmd.peer_ipv4, cmd.peer_port);
        Reply reply{im.fd, &to, &im.counters, &im.error_budget};
        const std::string address(cmd.address, strnlen(cmd.address, sizeof cmd.address));
        reply.ok(address.c_str(), echo_of(cmd));
    }
    Refusal f;
    while (refusals_.pop(f)) {
        im.counters.refused_commands++; // an error, answered or not
        const sockaddr_in to = reply_to(f.peer_ipv4, f.peer_port);
        if (to.sin_port == 0)
            continue; // nobody to tell (the daemon's stderr has it)
        Reply reply{im.fd, &to, &im.counters, &im.error_budget};
        const std::string address(f.address, strnlen(f.address, sizeof f.address));
        reply.error(address.c_str(), std::string(f.why, strnlen(f.why, sizeof f.why)));
    }
}

// A datagram: from an allowed peer, not oversized, not a bundle, a message
// liblo accepts; then its method (dispatch()).
void OscServer::handle(const unsigned char *data, std::size_t size, const void *peer_ptr)
{
    const sockaddr_in &peer = *static_cast<const sockaddr_in *>(peer_ptr);
    Impl &im = *impl_;
    Counters &c = im.counters;
    if (!im.allow.empty()) {
        bool allowed = false;
        for (const in_addr &a : im.allow)
            allowed = allowed || a.s_addr == peer.sin_addr.s_addr;
        if (!allowed) {
            // No reply to a stranger: that would make us a reflector.
            c.refused_peers++;
            char ip[INET_ADDRSTRLEN];
            inet_ntop(AF_INET, &peer.sin_addr, ip, sizeof ip);
            im.log("refused peer", ip);
            return;
        }
    }
    im.last_peer = peer;
    Reply reply{im.fd, im.reply_fixed ? &im.reply_to : &peer, &c, &im.error_budget};
    if (size > options_.max_packet_bytes) {
        c.oversized++;
        im.log("oversized packet", std::to_string(size) + " bytes");
        reply.error("", "packet of " + std::to_string(size) + " bytes exceeds the limit of " +
                            std::to_string(options_.max_packet_bytes));
        return;
    }
    if (size >= 8 && std::memcmp(data, "#bundle", 8) == 0) {
        c.bundles++;
        im.log("bundle", "bundles are not accepted");
        reply.error("#bundle", "bundles are not accepted: send plain messages");
        return;
    }
    // liblo checks the whole packet: padding, type tags, argument sizes.
    int result = 0;
    std::vector<unsigned char> copy(data, data + size); // liblo may swap bytes in place
    lo_message m = lo_message_deserialise(copy.data(), size, &result);
    if (!m) {
        c.malformed++;
        im.log("malformed packet",
               std::to_string(size) + " bytes, liblo error " + std::to_string(result));
        reply.error("", "malformed OSC packet (liblo error " + std::to_string(result) + ")");
        return;
    }
    // The path is the packet's first string; deserialise validated it.
    const char *path = reinterpret_cast<const char *>(copy.data());
    struct Free {
        lo_message m;
        ~Free() { lo_message_free(m); }
    } free_m{m};
    dispatch(Request{path, lo_message_get_types(m), lo_message_get_argv(m), peer, reply, c, im.log,
                     status_, commands_});
}

bool OscServer::dispatch_packet(const void *data, std::size_t size)
{
    sockaddr_in peer{};
    peer.sin_family = AF_INET;
    peer.sin_addr.s_addr =
        impl_->allow.empty() ? htonl(INADDR_LOOPBACK) : impl_->allow.front().s_addr;
    const unsigned long accepted = impl_->counters.accepted.load();
    handle(static_cast<const unsigned char *>(data), size, &peer);
    impl_->counters.packets++;
    return impl_->counters.accepted.load() != accepted;
}

} // namespace ictus
