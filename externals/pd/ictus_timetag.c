/* ictus_timetag -- turns OSC bundle timetags into Pd logical-time delays.
 *
 * Vanilla Pd ignores OSC timetags ([oscparse] drops them) and has no object
 * that reads the wall clock, and its 32-bit floats cannot hold an NTP time.
 * This object takes the bytes of one UDP packet from [netreceive -u -b], checks
 * them, unwraps bundles (nested ones too) and, for every OSC message inside,
 * outputs first the delay (ms of logical time from now) at which the message
 * should take effect, then the message's bytes, ready for [oscparse]. The
 * patch schedules with that delay ([pipe], [delay]); membrane~/contact~ turn
 * the resulting logical time into an exact sample.
 *
 * Clock mapping. The timetag is wall-clock time (NTP, CLOCK_REALTIME). Pd's
 * logical time runs off the scheduler (the audio device, or the system clock
 * with -nosound), so the object estimates the offset
 *     O = wall - logical
 * from samples. Pd computes in ticks of 64 samples and starts the tick that
 * begins at logical time B no earlier than wall time B + O (never before, only
 * late: scheduling, polling, load); every clock and message handled in that tick
 * sees a logical time in [B, B + tick], ahead of the wall clock by up to one tick
 * (1.33 ms at 48 kHz). So a sample is (wall now - B), B the start of the tick
 * being computed, taken from the object's own clock in the middle of a tick
 * (where B is unambiguous: Pd's ticks start at multiples of the tick length),
 * about every ICTUS_TIMETAG_SAMPLE_MS: each is an upper bound of O at its time.
 * No sample is taken before the scheduler runs (at creation during a patch's
 * load the wall clock is not yet tied to logical time) nor between ticks (on a
 * packet, logical time is already the next tick's start). The two clocks may
 * drift apart by at most ICTUS_TIMETAG_DRIFT (ms per ms: 100 ppm, more than a
 * sound card's crystal), so a sample s taken at logical time t also bounds O
 * now:  O(now) <= s + DRIFT * (now - t). The estimate is the tightest such
 * bound over the samples of the last ICTUS_TIMETAG_BUCKETS buckets of
 * ICTUS_TIMETAG_BUCKET_MS (each bucket keeps its smallest sample and when it was
 * taken). It is never below the true O (no message fires early), it follows
 * any drift within DRIFT, and a stretch of load that delays every sample for a
 * while does not move it: a quiet sample a few seconds old still bounds O
 * within DRIFT * its age (0.1 ms per second). A wall clock step forward is
 * followed within min(step / DRIFT, window); one backwards at once. Until the
 * first sample (the first tick after creation or `reset`), the estimate is the
 * looser bound (wall now - (logical now - one tick)). A message in a bundle
 * with timetag T then takes effect at logical time T - O - latency, i.e. its
 * delay is
 *     delay = T - latency - O - logical_now  (ms)
 * where `latency` (message, default 0) is the audio output latency to subtract
 * so that the sound, not the computation, lands at T. A bundle already due
 * (delay < 0) is late: its messages get delay 0 (fire now) and the late count
 * goes up. Timetag 1 ("immediately") and plain messages get delay 0, not late.
 *
 * `expect ADDRESS TAGS` makes messages to ADDRESS with other type tags
 * malformed, so that a fixed namespace reaches the patch only as specified.
 *
 * `host NAME` answers whether [netreceive] could listen on NAME here: `host 1 NAME`
 * or `host 0 NAME` on the info outlet (ictus-receive checks its HOST so, to name a bad
 * one itself and listen on loopback instead).
 *
 * Outlets, right to left: info (`late <ms_late> <count>` per late bundle,
 * `malformed <count> <reason>` per bad packet, `status ...` on request), the
 * delay (float, ms), the message bytes (list). */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#ifdef _WIN32
#include <winsock2.h>
#include <ws2tcpip.h>
#define ictus_closesocket closesocket
#else
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#define ictus_closesocket close
#endif

#include "m_pd.h"

#include "ictus_export.h"

#define ICTUS_TIMETAG_SAMPLE_MS    2.0   /* offset sampling period (at least) */
#define ICTUS_TIMETAG_TICK_SAMPLES 64    /* Pd's scheduler tick (DEFDACBLKSIZE) */
#define ICTUS_TIMETAG_BUCKET_MS    500.0 /* one bucket of the offset history */
#define ICTUS_TIMETAG_BUCKETS      16    /* history = 15..16 buckets = 7.5..8 s */
#define ICTUS_TIMETAG_DRIFT        1e-4  /* largest wall/logical drift, ms per ms */
#define ICTUS_TIMETAG_MAX_BYTES    65536 /* larger than any UDP datagram */
#define ICTUS_TIMETAG_MAX_DEPTH    8     /* nested bundles */
#define ICTUS_TIMETAG_MAX_POSTS    5     /* malformed packets reported in full */
#define ICTUS_TIMETAG_MAX_EXPECT   16    /* `expect` rules */
/* Seconds from the NTP epoch (1900) to the Unix epoch (1970). */
#define ICTUS_NTP_UNIX_OFFSET 2208988800.0

static t_class *ictus_timetag_class;

typedef struct _ictus_timetag {
    t_object x_obj;
    t_outlet *x_bytes_out;
    t_outlet *x_delay_out;
    t_outlet *x_info_out;
    t_clock *x_sample_clock;
    double x_wall_base_s;                       /* CLOCK_REALTIME seconds at creation (whole) */
    double x_bucket_min[ICTUS_TIMETAG_BUCKETS]; /* min offset per bucket (ms) */
    double x_bucket_at[ICTUS_TIMETAG_BUCKETS];  /* logical time of that sample (ms) */
    long x_bucket_index;                        /* index of the current bucket */
    int x_have_offset;
    double x_latency_ms;
    double x_late_count;
    double x_malformed_count;
    double x_packet_count;
    unsigned char *x_buf; /* packet bytes */
    int x_buf_size;
    t_atom *x_atoms; /* one message's bytes as floats */
    int x_atoms_size;
    /* `expect ADDRESS TAGS`: messages to ADDRESS must have exactly these type
     * tags (a fixed namespace, docs/osc.md), else the packet is malformed. */
    t_symbol *x_expect_address[ICTUS_TIMETAG_MAX_EXPECT];
    t_symbol *x_expect_tags[ICTUS_TIMETAG_MAX_EXPECT];
    int x_expect_count;
} t_ictus_timetag;

/* Wall-clock milliseconds since x_wall_base_s (a double keeps ~0.1 us here). */
static double ictus_timetag_wall_ms(const t_ictus_timetag *x)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return ((double)ts.tv_sec - x->x_wall_base_s) * 1000.0 + (double)ts.tv_nsec * 1e-6;
}

/* Logical time in ms since Pd started (the origin of its tick grid). */
static double ictus_timetag_logical_ms(void)
{
    return clock_gettimesince(0);
}

/* Length of Pd's scheduler tick in ms, computed as Pd does (m_sched.c: the
 * block size over the sample rate in single precision). */
static double ictus_timetag_tick_ms(void)
{
    t_float sr = sys_getsr();
    if (!(sr > 0))
        sr = 44100;
    return (double)((t_float)ICTUS_TIMETAG_TICK_SAMPLES / sr) * 1000.0;
}

/* One offset sample (wall now - start of the tick being computed) into its
 * bucket of the history; called from the sample clock only, mid-tick. */
static void ictus_timetag_sample(t_ictus_timetag *x)
{
    double tick = ictus_timetag_tick_ms();
    double logical = floor(ictus_timetag_logical_ms() / tick) * tick;
    double offset = ictus_timetag_wall_ms(x) - logical;
    long bucket = (long)floor(logical / ICTUS_TIMETAG_BUCKET_MS);
    int i, slot = (int)(bucket % ICTUS_TIMETAG_BUCKETS);
    if (!x->x_have_offset || bucket - x->x_bucket_index >= ICTUS_TIMETAG_BUCKETS) {
        for (i = 0; i < ICTUS_TIMETAG_BUCKETS; i++) {
            x->x_bucket_min[i] = offset;
            x->x_bucket_at[i] = logical;
        }
        x->x_have_offset = 1;
    } else {
        /* buckets skipped since the last sample start empty (= this sample) */
        for (long b = x->x_bucket_index + 1; b <= bucket; b++) {
            x->x_bucket_min[b % ICTUS_TIMETAG_BUCKETS] = offset;
            x->x_bucket_at[b % ICTUS_TIMETAG_BUCKETS] = logical;
        }
    }
    x->x_bucket_index = bucket;
    if (offset < x->x_bucket_min[slot]) {
        x->x_bucket_min[slot] = offset;
        x->x_bucket_at[slot] = logical;
    }
}

/* The tightest bound of O now: min over the buckets of
 * (smallest sample + DRIFT * its age); before the first sample, the bound
 * from the wall clock now and the earliest start of the current tick. */
static double ictus_timetag_offset(const t_ictus_timetag *x)
{
    double now = ictus_timetag_logical_ms(), m = 0;
    int i;
    if (!x->x_have_offset)
        return ictus_timetag_wall_ms(x) - (now - ictus_timetag_tick_ms());
    for (i = 0; i < ICTUS_TIMETAG_BUCKETS; i++) {
        double age = now - x->x_bucket_at[i];
        double bound = x->x_bucket_min[i] + ICTUS_TIMETAG_DRIFT * (age > 0 ? age : 0);
        if (i == 0 || bound < m)
            m = bound;
    }
    return m;
}

/* Sets the sample clock to the middle of the tick that ends at least
 * `after_ms` from now (0: the next mid-tick point). */
static void ictus_timetag_schedule(t_ictus_timetag *x, double after_ms)
{
    double tick = ictus_timetag_tick_ms(), now = ictus_timetag_logical_ms();
    double at = ceil((now + after_ms) / tick) * tick - 0.5 * tick;
    if (at <= now)
        at += tick;
    clock_delay(x->x_sample_clock, at - now);
}

static void ictus_timetag_tick(t_ictus_timetag *x)
{
    ictus_timetag_sample(x);
    ictus_timetag_schedule(x, ICTUS_TIMETAG_SAMPLE_MS);
}

static void ictus_timetag_malformed(t_ictus_timetag *x, const char *reason, int offset)
{
    t_atom info[2];
    x->x_malformed_count++;
    if (x->x_malformed_count <= ICTUS_TIMETAG_MAX_POSTS)
        pd_error(x, "ictus_timetag: malformed OSC packet (%s at byte %d)%s", reason, offset,
                 x->x_malformed_count == ICTUS_TIMETAG_MAX_POSTS
                     ? "; further ones are only counted (info outlet)"
                     : "");
    SETFLOAT(&info[0], (t_float)x->x_malformed_count);
    SETSYMBOL(&info[1], gensym(reason));
    outlet_anything(x->x_info_out, gensym("malformed"), 2, info);
}

static uint32_t ictus_timetag_u32(const unsigned char *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

/* Length of the OSC string at p (with its 1..4 NUL padding bytes), or -1 if it
 * does not end inside n bytes. */
static int ictus_timetag_osc_string(const unsigned char *p, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (p[i] == 0)
            return (i + 4) & ~3;
    return -1;
}

/* Checks one OSC message (address, type tags, arguments) so that [oscparse]
 * only ever gets well-formed input. Returns NULL or the reason. */
static const char *ictus_timetag_check_message(const t_ictus_timetag *x, const unsigned char *p,
                                               int n)
{
    int pos, len, tags, t;
    if (n < 4 || (n & 3))
        return "message-size";
    if (p[0] != '/')
        return "message-start";
    if ((len = ictus_timetag_osc_string(p, n)) < 0 || len > n)
        return "address";
    pos = len;
    if (pos == n)
        return NULL; /* no type tag string: an old-style message without arguments */
    if (p[pos] != ',')
        return "type-tags";
    if ((len = ictus_timetag_osc_string(p + pos, n - pos)) < 0 || pos + len > n)
        return "type-tags";
    tags = pos + 1;
    for (t = 0; t < x->x_expect_count; t++)
        if (!strcmp((const char *)p, x->x_expect_address[t]->s_name) &&
            strcmp((const char *)p + tags, x->x_expect_tags[t]->s_name))
            return "unexpected-type-tags";
    pos += len;
    for (t = tags; p[t] != 0; t++) {
        int size;
        switch (p[t]) {
        case 'i':
        case 'f':
        case 'c':
        case 'r':
        case 'm':
            size = 4;
            break;
        case 'h':
        case 't':
        case 'd':
            size = 8;
            break;
        case 'T':
        case 'F':
        case 'N':
        case 'I':
            size = 0;
            break;
        case 's':
        case 'S':
            if ((size = ictus_timetag_osc_string(p + pos, n - pos)) < 0)
                return "string-argument";
            break;
        case 'b': {
            /* in 64 bits: a 32-bit size within 3 of 2^32 rounds up to 0 in 32 */
            uint64_t padded;
            if (pos + 4 > n)
                return "blob-size";
            padded = ((uint64_t)ictus_timetag_u32(p + pos) + 3u) & ~(uint64_t)3u;
            if (padded > (uint64_t)(n - pos - 4))
                return "blob-size";
            size = 4 + (int)padded;
            break;
        }
        default:
            return "unknown-type-tag";
        }
        if (size > n - pos)
            return "arguments-short";
        pos += size;
    }
    return pos == n ? NULL : "trailing-bytes";
}

/* Delay (ms of logical time) for a bundle with this NTP timetag; counts and
 * reports late bundles. */
static t_float ictus_timetag_delay(t_ictus_timetag *x, uint32_t seconds, uint32_t fraction)
{
    double tag_ms, delay;
    if (seconds == 0 && fraction <= 1)
        return 0; /* "immediately" */
    tag_ms = ((double)seconds - ICTUS_NTP_UNIX_OFFSET - x->x_wall_base_s) * 1000.0 +
             (double)fraction * (1000.0 / 4294967296.0);
    delay = tag_ms - x->x_latency_ms - ictus_timetag_offset(x) - ictus_timetag_logical_ms();
    if (delay < 0) {
        t_atom info[2];
        x->x_late_count++;
        SETFLOAT(&info[0], (t_float)-delay);
        SETFLOAT(&info[1], (t_float)x->x_late_count);
        outlet_anything(x->x_info_out, gensym("late"), 2, info);
        return 0;
    }
    return (t_float)delay;
}

/* Checks a whole element (message or bundle) before anything of it is output,
 * so that a bad packet never produces half its messages. */
static const char *ictus_timetag_check(const t_ictus_timetag *x, const unsigned char *p, int n,
                                       int depth, int *where)
{
    int pos;
    if (n >= 8 && !memcmp(p, "#bundle", 8)) {
        if (depth >= ICTUS_TIMETAG_MAX_DEPTH)
            return "bundle-depth";
        if (n < 16)
            return "bundle-timetag";
        for (pos = 16; pos < n;) {
            uint32_t size;
            const char *why;
            if (n - pos < 4)
                return "element-size";
            size = ictus_timetag_u32(p + pos);
            if (size == 0 || (size & 3) || size > (uint32_t)(n - pos - 4)) {
                *where = pos;
                return "element-size";
            }
            if ((why = ictus_timetag_check(x, p + pos + 4, (int)size, depth + 1, where))) {
                *where += pos + 4;
                return why;
            }
            pos += 4 + (int)size;
        }
        return NULL;
    }
    *where = 0;
    return ictus_timetag_check_message(x, p, n);
}

static void ictus_timetag_output_message(t_ictus_timetag *x, const unsigned char *p, int n,
                                         t_float delay)
{
    int i;
    if (n > x->x_atoms_size) {
        /* message domain: allocation is fine here (never in DSP) */
        t_atom *a =
            (t_atom *)resizebytes(x->x_atoms, sizeof(t_atom) * x->x_atoms_size, sizeof(t_atom) * n);
        if (!a) {
            pd_error(x, "ictus_timetag: out of memory for a %d-byte message", n);
            return;
        }
        x->x_atoms = a;
        x->x_atoms_size = n;
    }
    for (i = 0; i < n; i++)
        SETFLOAT(&x->x_atoms[i], p[i]);
    outlet_float(x->x_delay_out, delay);
    outlet_list(x->x_bytes_out, &s_list, n, x->x_atoms);
}

/* Outputs the messages of an already checked element; a nested bundle's own
 * timetag applies to its messages (OSC 1.0 says it must not be earlier than
 * the enclosing one; it is used as it is). */
static void ictus_timetag_output(t_ictus_timetag *x, const unsigned char *p, int n, t_float delay)
{
    int pos;
    if (n >= 8 && !memcmp(p, "#bundle", 8)) {
        t_float bundle_delay =
            ictus_timetag_delay(x, ictus_timetag_u32(p + 8), ictus_timetag_u32(p + 12));
        for (pos = 16; pos < n;) {
            int size = (int)ictus_timetag_u32(p + pos);
            ictus_timetag_output(x, p + pos + 4, size, bundle_delay);
            pos += 4 + size;
        }
        return;
    }
    ictus_timetag_output_message(x, p, n, delay);
}

static void ictus_timetag_list(t_ictus_timetag *x, t_symbol *s, int argc, t_atom *argv)
{
    int i, where = 0;
    const char *why;
    (void)s;
    x->x_packet_count++;
    if (argc < 1 || argc > ICTUS_TIMETAG_MAX_BYTES) {
        ictus_timetag_malformed(x, "packet-size", argc);
        return;
    }
    if (argc > x->x_buf_size) {
        unsigned char *b = (unsigned char *)resizebytes(x->x_buf, x->x_buf_size, argc);
        if (!b) {
            pd_error(x, "ictus_timetag: out of memory for a %d-byte packet", argc);
            return;
        }
        x->x_buf = b;
        x->x_buf_size = argc;
    }
    for (i = 0; i < argc; i++) {
        t_float f = atom_getfloatarg(i, argc, argv);
        if (argv[i].a_type != A_FLOAT || f < 0 || f > 255 || f != (t_float)(int)f) {
            ictus_timetag_malformed(x, "not-a-byte", i);
            return;
        }
        x->x_buf[i] = (unsigned char)f;
    }
    if ((why = ictus_timetag_check(x, x->x_buf, argc, 0, &where))) {
        ictus_timetag_malformed(x, why, where);
        return;
    }
    ictus_timetag_output(x, x->x_buf, argc, 0);
}

#define ICTUS_TIMETAG_LATENCY_MAX 10000.0 /* ms */

/* Sets the latency (ms), clamped into [0, 10000] with an error line (NaN: 0). */
static void ictus_timetag_set_latency(t_ictus_timetag *x, double ms)
{
    if (!(ms >= 0 && ms <= ICTUS_TIMETAG_LATENCY_MAX)) {
        double used = ms > ICTUS_TIMETAG_LATENCY_MAX ? ICTUS_TIMETAG_LATENCY_MAX : 0.0;
        pd_error(x, "ictus_timetag: latency must be in [0, %g] ms, got %g; using %g",
                 ICTUS_TIMETAG_LATENCY_MAX, ms, used);
        ms = used;
    }
    x->x_latency_ms = ms;
}

/* The latency from atom i of a message or the creation arguments ("what": where it came
 * from); a missing or non-number atom is said and leaves the latency as it is. */
static void ictus_timetag_latency_atom(t_ictus_timetag *x, const char *what, int argc, t_atom *argv)
{
    char got[MAXPDSTRING];
    if (argc < 1) {
        pd_error(x, "ictus_timetag: %s: missing the latency (ms)", what);
        return;
    }
    if (argv[0].a_type != A_FLOAT) {
        atom_string(&argv[0], got, sizeof(got));
        pd_error(x,
                 "ictus_timetag: %s: the latency (ms) must be a number, got '%s'; it stays %g ms",
                 what, got, x->x_latency_ms);
        return;
    }
    ictus_timetag_set_latency(x, atom_getfloat(&argv[0]));
    if (argc > 1)
        pd_error(x,
                 "ictus_timetag: %s takes one number, the latency (ms); extra arguments "
                 "ignored",
                 what);
}

/* latency <ms>: audio output latency to subtract from every delay. */
static void ictus_timetag_latency(t_ictus_timetag *x, t_symbol *s, int argc, t_atom *argv)
{
    (void)s;
    ictus_timetag_latency_atom(x, "latency", argc, argv);
}

/* status: `status offset_ms late malformed packets latency_ms` on the info outlet;
 * offset_ms is the current estimate of wall - logical time (wall time from the
 * whole second before the object's creation, logical time from Pd's start). */
static void ictus_timetag_status(t_ictus_timetag *x)
{
    t_atom info[5];
    SETFLOAT(&info[0], (t_float)ictus_timetag_offset(x));
    SETFLOAT(&info[1], (t_float)x->x_late_count);
    SETFLOAT(&info[2], (t_float)x->x_malformed_count);
    SETFLOAT(&info[3], (t_float)x->x_packet_count);
    SETFLOAT(&info[4], (t_float)x->x_latency_ms);
    outlet_anything(x->x_info_out, gensym("status"), 5, info);
}

/* expect ADDRESS TAGS: e.g. `expect /ictus/strike iiiiffffffffffffff` (tags
 * without the comma; an empty symbol for none). A new rule for the same
 * address replaces the old one. */
static void ictus_timetag_expect(t_ictus_timetag *x, t_symbol *s, int argc, t_atom *argv)
{
    int i;
    (void)s;
    if (argc < 1 || argc > 2 || argv[0].a_type != A_SYMBOL ||
        (argc == 2 && argv[1].a_type != A_SYMBOL)) {
        pd_error(x, "ictus_timetag: expect needs ADDRESS and TAGS, two symbols (e.g. expect "
                    "/ictus/strike iiff; TAGS left out: no arguments); ignored");
        return;
    }
    t_symbol *address = argv[0].a_w.w_symbol, *tags = argc == 2 ? argv[1].a_w.w_symbol : &s_;
    if (address->s_name[0] != '/') {
        pd_error(x, "ictus_timetag: expect: address must start with '/', got '%s'",
                 address->s_name);
        return;
    }
    for (i = 0; i < x->x_expect_count; i++)
        if (x->x_expect_address[i] == address)
            break;
    if (i == ICTUS_TIMETAG_MAX_EXPECT) {
        pd_error(x, "ictus_timetag: expect: at most %d addresses; '%s' ignored",
                 ICTUS_TIMETAG_MAX_EXPECT, address->s_name);
        return;
    }
    x->x_expect_address[i] = address;
    x->x_expect_tags[i] = tags;
    if (i == x->x_expect_count)
        x->x_expect_count++;
}

/* Whether a UDP socket can listen on `name` here, as [netreceive] would: the name
 * resolves (getaddrinfo, passive, as netreceive looks it up) to an address of this
 * machine, which a socket binds (on port 0, any free one: the check never takes the port
 * the patch asks for), or to a multicast group (netreceive joins it). A name looked up in
 * DNS blocks as netreceive's own lookup then does. */
static int ictus_timetag_host_usable(const char *name)
{
    struct addrinfo hints, *list = NULL, *a;
    int usable = 0;
    memset(&hints, 0, sizeof(hints));
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_DGRAM;
    hints.ai_flags = AI_PASSIVE;
    if (getaddrinfo(name, NULL, &hints, &list) != 0)
        return 0;
    for (a = list; a && !usable; a = a->ai_next) {
        if (a->ai_family == AF_INET) {
            const struct sockaddr_in *in = (const struct sockaddr_in *)a->ai_addr;
            if ((ntohl(in->sin_addr.s_addr) >> 28) == 0xE) { /* 224.0.0.0/4 */
                usable = 1;
                break;
            }
        } else if (a->ai_family == AF_INET6) {
            const struct sockaddr_in6 *in6 = (const struct sockaddr_in6 *)a->ai_addr;
            if (IN6_IS_ADDR_MULTICAST(&in6->sin6_addr)) {
                usable = 1;
                break;
            }
        }
        int fd = (int)socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd < 0)
            continue;
        usable = bind(fd, a->ai_addr, (int)a->ai_addrlen) == 0;
        ictus_closesocket(fd);
    }
    freeaddrinfo(list);
    return usable;
}

/* host NAME: `host 1 NAME` when [netreceive] can listen on NAME here, else `host 0 NAME`,
 * on the info outlet. */
static void ictus_timetag_host(t_ictus_timetag *x, t_symbol *s, int argc, t_atom *argv)
{
    t_atom answer[2];
    (void)s;
    if (argc != 1 || argv[0].a_type != A_SYMBOL) {
        pd_error(x, "ictus_timetag: host needs one NAME (an interface's name or address); "
                    "ignored");
        return;
    }
    SETFLOAT(&answer[0], (t_float)ictus_timetag_host_usable(argv[0].a_w.w_symbol->s_name));
    SETSYMBOL(&answer[1], argv[0].a_w.w_symbol);
    outlet_anything(x->x_info_out, gensym("host"), 2, answer);
}

static void ictus_timetag_reset(t_ictus_timetag *x)
{
    x->x_late_count = x->x_malformed_count = x->x_packet_count = 0;
    x->x_have_offset = 0;
    ictus_timetag_schedule(x, 0);
}

static void *ictus_timetag_new(t_symbol *s, int argc, t_atom *argv)
{
    t_ictus_timetag *x = (t_ictus_timetag *)pd_new(ictus_timetag_class);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    x->x_wall_base_s = (double)ts.tv_sec;
    x->x_bytes_out = outlet_new(&x->x_obj, &s_list);
    x->x_delay_out = outlet_new(&x->x_obj, &s_float);
    x->x_info_out = outlet_new(&x->x_obj, 0);
    x->x_buf = NULL;
    x->x_buf_size = 0;
    x->x_atoms = NULL;
    x->x_atoms_size = 0;
    x->x_have_offset = 0;
    x->x_bucket_index = 0;
    x->x_expect_count = 0;
    x->x_late_count = x->x_malformed_count = x->x_packet_count = 0;
    (void)s;
    x->x_latency_ms = 0;
    if (argc > 0)
        ictus_timetag_latency_atom(x, "creation argument", argc, argv);
    x->x_sample_clock = clock_new(x, (t_method)ictus_timetag_tick);
    ictus_timetag_schedule(x, 0);
    return x;
}

static void ictus_timetag_free(t_ictus_timetag *x)
{
    clock_free(x->x_sample_clock);
    if (x->x_buf)
        freebytes(x->x_buf, x->x_buf_size);
    if (x->x_atoms)
        freebytes(x->x_atoms, sizeof(t_atom) * x->x_atoms_size);
}

ICTUS_EXPORT void ictus_timetag_setup(void)
{
    ictus_timetag_class =
        class_new(gensym("ictus_timetag"), (t_newmethod)ictus_timetag_new,
                  (t_method)ictus_timetag_free, sizeof(t_ictus_timetag), CLASS_DEFAULT, A_GIMME, 0);
    class_addlist(ictus_timetag_class, ictus_timetag_list);
    class_addmethod(ictus_timetag_class, (t_method)ictus_timetag_latency, gensym("latency"),
                    A_GIMME, 0);
    class_addmethod(ictus_timetag_class, (t_method)ictus_timetag_status, gensym("status"), 0);
    class_addmethod(ictus_timetag_class, (t_method)ictus_timetag_reset, gensym("reset"), 0);
    class_addmethod(ictus_timetag_class, (t_method)ictus_timetag_expect, gensym("expect"), A_GIMME,
                    0);
    class_addmethod(ictus_timetag_class, (t_method)ictus_timetag_host, gensym("host"), A_GIMME, 0);
}
