// OSC out: strike bundles and the pose stream (osc_sender.hpp, docs/osc.md).
#include "ictus/net/osc_sender.hpp"
#include "ictus/base/realtime.hpp"

#include <lo/lo.h>

#include <netdb.h>
#include <semaphore.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>

namespace ictus
{

// ---- time ---------------------------------------------------------------------

namespace
{
constexpr std::uint64_t kNtpUnixOffset = 2208988800ull; // 1900 -> 1970, s

lo_timetag to_lo(NtpTime t)
{
    lo_timetag tt;
    tt.sec = static_cast<std::uint32_t>(t >> 32);
    tt.frac = static_cast<std::uint32_t>(t & 0xffffffffu);
    return tt;
}

// Waits on a semaphore for at most `ms` (the consumers' idle wait: the
// producers only sem_post, which never blocks).
void wait_ms(sem_t *sem, long ms)
{
    timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += ms * 1000000L;
    ts.tv_sec += ts.tv_nsec / 1000000000L;
    ts.tv_nsec %= 1000000000L;
    while (sem_timedwait(sem, &ts) == -1 && errno == EINTR) {
    }
}
} // namespace

NtpTime ntp_now()
{
    timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    const std::uint64_t sec = static_cast<std::uint64_t>(ts.tv_sec) + kNtpUnixOffset;
    const std::uint64_t frac = (static_cast<std::uint64_t>(ts.tv_nsec) << 32) / 1000000000ull;
    return (sec << 32) | frac;
}

NtpTime ntp_add_seconds(NtpTime t, double seconds)
{
    // 2^32 units per second; exact in integers, so strike times keep their
    // sub-microsecond spacing whatever the epoch.
    const double units = std::round(seconds * 4294967296.0);
    return static_cast<NtpTime>(static_cast<std::int64_t>(t) + static_cast<std::int64_t>(units));
}

double ntp_diff_seconds(NtpTime a, NtpTime b)
{
    return static_cast<double>(static_cast<std::int64_t>(a - b)) / 4294967296.0;
}

// ---- the target ---------------------------------------------------------------

// --target (and --reply) must be osc.udp://HOST:PORT (a trailing '/' aside), checked here
// because liblo takes more and fails later, at every send: a port past 65535
// wraps (99999 -> 34463), "9000x" is port 9000, an IPv6 host needs an IPv6
// socket (liblo's sending socket is IPv4), and osc.tcp:// is not what Pd
// listens on ([netreceive -u -b], docs/pd-osc.md) and would block the sending
// threads on a stalled peer.
void check_osc_udp_url(const char *option, const std::string &url)
{
    auto refuse = [&](const std::string &why) {
        return OscError(std::string(option) + " '" + url + "': " + why +
                        " (expected osc.udp://HOST:PORT, e.g. osc.udp://127.0.0.1:9000)");
    };
    const std::string udp = "osc.udp://";
    if (url.compare(0, udp.size(), udp) != 0) {
        const std::size_t scheme_end = url.find("://");
        if (url.compare(0, 4, "osc.") == 0 && scheme_end != std::string::npos)
            throw refuse("protocol '" + url.substr(4, scheme_end - 4) +
                         "' is not supported: the link is UDP only");
        throw refuse("not an OSC URL");
    }
    std::string rest = url.substr(udp.size());
    if (!rest.empty() && rest.back() == '/')
        rest.pop_back();
    if (rest.find('[') != std::string::npos || std::count(rest.begin(), rest.end(), ':') > 1)
        throw refuse("IPv6 is not supported: give an IPv4 address or a host name that "
                     "resolves to one");
    const std::size_t colon = rest.find(':');
    if (colon == std::string::npos)
        throw refuse("no port");
    const std::string host = rest.substr(0, colon), port = rest.substr(colon + 1);
    if (host.empty())
        throw refuse("no host");
    const bool digits =
        !port.empty() && port.size() <= 5 &&
        std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || std::stoi(port) < 1 || std::stoi(port) > 65535)
        throw refuse("port: expected 1 to 65535, got '" + port + "'");
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    addrinfo *found = nullptr;
    const int status = getaddrinfo(host.c_str(), port.c_str(), &hints, &found);
    if (status != 0)
        throw refuse("host '" + host + "' does not resolve to an IPv4 address (" +
                     gai_strerror(status) + ")");
    freeaddrinfo(found);
}

// ---- sender -------------------------------------------------------------------

struct OscSender::Impl {
    lo_address strike_target = nullptr;
    lo_address pose_target = nullptr;
    sem_t strike_ready, pose_ready;
    ~Impl()
    {
        if (strike_target)
            lo_address_free(strike_target);
        if (pose_target)
            lo_address_free(pose_target);
    }
};

OscSender::OscSender(const OscSenderOptions &options) : impl_(new Impl), options_(options)
{
    if (!(std::isfinite(options.lookahead_s) && options.lookahead_s >= 0.0 &&
          options.lookahead_s <= 10.0))
        throw OscError("lookahead: expected 0 to 10 s, got " + std::to_string(options.lookahead_s));
    check_osc_udp_url("--target", options.target_url);
    impl_->strike_target = lo_address_new_from_url(options.target_url.c_str());
    impl_->pose_target = lo_address_new_from_url(options.target_url.c_str());
    if (!impl_->strike_target || !impl_->pose_target)
        throw OscError("--target: liblo refused '" + options.target_url + "'");
    sem_init(&impl_->strike_ready, 0, 0);
    sem_init(&impl_->pose_ready, 0, 0);
    epoch_.store(ntp_now());
    pedal_sent_.fill(-1.0);
    strike_thread_ = std::thread(&OscSender::strike_loop, this);
    pose_thread_ = std::thread(&OscSender::pose_loop, this);
}

OscSender::~OscSender()
{
    stop();
    sem_destroy(&impl_->strike_ready);
    sem_destroy(&impl_->pose_ready);
}

void OscSender::stop()
{
    if (running_.exchange(false)) {
        sem_post(&impl_->strike_ready);
        sem_post(&impl_->pose_ready);
    }
    if (strike_thread_.joinable())
        strike_thread_.join();
    if (pose_thread_.joinable())
        pose_thread_.join();
}

bool OscSender::post_strike(const StrikeEvent &event)
{
    if (!strikes_.push(StrikeMessage{event, false}))
        return false;
    sem_post(&impl_->strike_ready);
    return true;
}

bool OscSender::post_strike_end(const StrikeEvent &event)
{
    if (!strikes_.push(StrikeMessage{event, true}))
        return false;
    sem_post(&impl_->strike_ready);
    return true;
}

void OscSender::set_kit(const std::string &kit_name, const std::vector<KitDrumSound> &drums)
{
    if (kit_set_.load(std::memory_order_acquire))
        return; // once: the strike thread may be reading it
    kit_name_ = kit_name;
    kit_ = drums;
    kit_set_.store(true, std::memory_order_release);
}

void OscSender::send_kit()
{
    kit_wanted_.store(true, std::memory_order_release);
    sem_post(&impl_->strike_ready);
}

bool OscSender::post_pose(const PoseSnapshot &pose)
{
    if (!poses_.push(pose))
        return false;
    sem_post(&impl_->pose_ready);
    return true;
}

bool OscSender::post_tip(const TipState &tip)
{
    if (!tips_.push(tip))
        return false;
    sem_post(&impl_->pose_ready);
    return true;
}

OscSenderCounters OscSender::counters() const
{
    OscSenderCounters c;
    c.strikes_sent = strikes_sent_.load();
    c.strike_ends_sent = strike_ends_sent_.load();
    c.poses_sent = poses_sent_.load();
    c.tips_sent = tips_sent_.load();
    c.kits_sent = kits_sent_.load();
    c.send_errors = send_errors_.load();
    c.strikes_dropped = strikes_.dropped();
    c.poses_dropped = poses_.dropped();
    c.tips_dropped = tips_.dropped();
    return c;
}

namespace
{
// A strike's fields as the arguments of an OSC message, in the field table's
// order: those whose `in_message` column (StrikeFieldInfo::in_osc or
// in_osc_end) is set, integers as int32, reals as float32.
void add_strike_fields(lo_message m, const StrikeEvent &e, bool StrikeFieldInfo::*in_message)
{
    for (int i = 0; i < kStrikeFieldCount; ++i) {
        const StrikeField f = static_cast<StrikeField>(i);
        const StrikeFieldInfo &info = strike_field_info(f);
        if (!(info.*in_message))
            continue;
        if (info.integer)
            lo_message_add_int32(m, static_cast<std::int32_t>(strike_field_integer(e, f)));
        else
            lo_message_add_float(m, static_cast<float>(strike_field(e, f)));
    }
}

template <std::size_t N> void add_floats(lo_message m, const float (&values)[N])
{
    for (float v : values)
        lo_message_add_float(m, v);
}

// What a send did: the message counted as sent, or the send error.
void count_send(int result, std::atomic<unsigned long> &sent, std::atomic<unsigned long> &errors)
{
    if (result < 0)
        errors.fetch_add(1);
    else
        sent.fetch_add(1);
}
} // namespace

// The kit: /ictus/kit ,si name count, then /ictus/kit/drum ,issfffi index name
// preset radius tension pan midi_note per drum, in one bundle to be handled at once.
void OscSender::send_kit_now()
{
    if (!kit_set_.load(std::memory_order_acquire) || kit_.empty())
        return;
    lo_bundle b = lo_bundle_new(LO_TT_IMMEDIATE);
    lo_message head = lo_message_new();
    lo_message_add_string(head, kit_name_.c_str());
    lo_message_add_int32(head, static_cast<std::int32_t>(kit_.size()));
    lo_bundle_add_message(b, "/ictus/kit", head);
    for (const KitDrumSound &d : kit_) {
        lo_message m = lo_message_new();
        lo_message_add_int32(m, d.index);
        lo_message_add_string(m, d.name.c_str());
        lo_message_add_string(m, d.preset.c_str());
        lo_message_add_float(m, static_cast<float>(d.radius_m));
        lo_message_add_float(m, static_cast<float>(d.tension_n_per_m));
        lo_message_add_float(m, static_cast<float>(d.pan));
        lo_message_add_int32(m, d.midi_note);
        lo_bundle_add_message(b, "/ictus/kit/drum", m);
    }
    count_send(lo_send_bundle(impl_->strike_target, b), kits_sent_, send_errors_);
    lo_bundle_free_recursive(b);
    pedal_sent_.fill(-1.0); // the kit's drums are set anew: the next pedal goes out
}

void OscSender::strike_loop()
{
    if (options_.realtime)
        set_realtime_priority(kStrikeSenderPriority);
    StrikeMessage sm;
    for (;;) {
        const bool running = running_.load();
        // Before the strikes queued after the request: they may play on it.
        if (kit_wanted_.exchange(false, std::memory_order_acq_rel))
            send_kit_now();
        while (strikes_.pop(sm)) {
            const StrikeEvent &e = sm.event;
            // The strike sounds at its simulation time plus the lookahead, on
            // the wall clock that simulation time 0 was anchored to; its end
            // is due at the release.
            const double due_s = e.time_s + (sm.end ? 1e-3 * e.duration_ms : 0.0);
            lo_timetag tt = LO_TT_IMMEDIATE;
            if (options_.lookahead_s > 0.0)
                tt = to_lo(ntp_add_seconds(epoch(), due_s + options_.lookahead_s));
            lo_bundle b = lo_bundle_new(tt);
            // A hi-hat's pedal, when it changes, before the strike that plays
            // it, in its bundle: Pd schedules both at the strike's time.
            if (!sm.end && e.pedal_openness >= 0.0 && e.drum >= 0 && e.drum < kMaxDrums &&
                e.pedal_openness != pedal_sent_[static_cast<size_t>(e.drum)]) {
                lo_message p = lo_message_new();
                lo_message_add_int32(p, e.drum);
                lo_message_add_float(p, static_cast<float>(e.pedal_openness));
                lo_bundle_add_message(b, "/ictus/kit/pedal", p);
                pedal_sent_[static_cast<size_t>(e.drum)] = e.pedal_openness;
            }
            lo_message m = lo_message_new();
            add_strike_fields(m, e,
                              sm.end ? &StrikeFieldInfo::in_osc_end : &StrikeFieldInfo::in_osc);
            lo_bundle_add_message(b, sm.end ? "/ictus/strike/end" : "/ictus/strike", m);
            count_send(lo_send_bundle(impl_->strike_target, b),
                       sm.end ? strike_ends_sent_ : strikes_sent_, send_errors_);
            lo_bundle_free_recursive(b);
        }
        if (!running)
            return;
        wait_ms(&impl_->strike_ready, 100);
    }
}

void OscSender::pose_loop()
{
    PoseSnapshot p;
    TipState t;
    for (;;) {
        const bool running = running_.load();
        while (poses_.pop(p)) {
            // One bundle per frame, "immediately": graphics draws the latest.
            lo_bundle b = lo_bundle_new(LO_TT_IMMEDIATE);
            lo_message frame = lo_message_new();
            lo_message_add_float(frame, static_cast<float>(p.time_s));
            lo_bundle_add_message(b, "/ictus/pose/frame", frame);
            for (int i = 0; i < p.bodies && i < PoseSnapshot::kMaxBodies; ++i) {
                lo_message m = lo_message_new();
                lo_message_add_int32(m, i);
                add_floats(m, p.position_m[i]);
                add_floats(m, p.rotation_wxyz[i]);
                lo_bundle_add_message(b, "/ictus/pose/body", m);
            }
            for (int hand = 0; hand < 2; ++hand) {
                lo_message m = lo_message_new();
                lo_message_add_int32(m, hand);
                add_floats(m, p.stick_tip_m[hand]);
                add_floats(m, p.stick_butt_m[hand]);
                lo_bundle_add_message(b, "/ictus/pose/stick", m);
            }
            lo_message d = lo_message_new();
            lo_message_add_int32(d, 0);
            add_floats(d, p.drum_center_m);
            lo_message_add_float(d, p.drum_radius_m);
            lo_bundle_add_message(b, "/ictus/pose/drum", d);
            count_send(lo_send_bundle(impl_->pose_target, b), poses_sent_, send_errors_);
            lo_bundle_free_recursive(b);
        }
        while (tips_.pop(t)) {
            lo_message m = lo_message_new();
            lo_message_add_int32(m, t.hand);
            add_floats(m, t.position_m);
            add_floats(m, t.velocity_mps);
            lo_message_add_float(m, static_cast<float>(t.time_s));
            count_send(lo_send_message(impl_->pose_target, "/ictus/tip", m), tips_sent_,
                       send_errors_);
            lo_message_free(m);
        }
        if (!running)
            return;
        wait_ms(&impl_->pose_ready, 100);
    }
}

} // namespace ictus
