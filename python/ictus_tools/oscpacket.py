"""OSC 1.0 packets built by hand (struct + UDP), independent of the project's
daemon code and of liblo, for the tests and the latency benchmark.

Strikes follow docs/osc.md: a bundle whose timetag is the strike time plus a
lookahead, holding /ictus/strike ,iiiiffffffffffffffi."""
import struct
import time

NTP_UNIX_OFFSET = 2208988800  # seconds from 1900 (NTP) to 1970 (Unix)
STRIKE_TAGS = "iiiiffffffffffffffi"
STRIKE_FIELDS = ["seq", "hand", "drum", "bounce", "time_s", "x_m", "y_m", "r_over_a", "theta_deg",
                 "normal_velocity_mps", "tangential_velocity_mps", "peak_force_n", "impulse_ns",
                 "duration_ms", "force_dir_x", "force_dir_y", "force_dir_z", "stick_mass_kg",
                 "stick_tip"]


def osc_string(s):
    b = s.encode() + b"\0"
    return b + b"\0" * (-len(b) % 4)


def message(address, tags, *args):
    out = osc_string(address) + osc_string("," + tags)
    for t, a in zip(tags, args):
        if t == "i":
            out += struct.pack(">i", int(a))
        elif t == "f":
            out += struct.pack(">f", float(a))
        elif t == "s":
            out += osc_string(a)
        else:
            raise ValueError("type tag %r not supported here" % t)
    return out


def timetag(unix_seconds):
    """NTP timetag (64-bit fixed point) for a Unix time in seconds (float)."""
    whole = int(unix_seconds // 1)
    frac = int(round((unix_seconds - whole) * 2 ** 32))
    if frac >= 2 ** 32:
        whole, frac = whole + 1, frac - 2 ** 32
    return struct.pack(">II", whole + NTP_UNIX_OFFSET, frac)


def bundle(tag_bytes, *elements):
    out = b"#bundle\0" + tag_bytes
    for e in elements:
        out += struct.pack(">i", len(e)) + e
    return out


def strike(seq, hand, velocity=2.0, r_over_a=0.3, theta_deg=0.0, bounce=0, time_s=0.0,
           peak_force_n=50.0, stick_mass_kg=0.03, stick_tip=1):
    """A /ictus/strike message with plausible values for the fields not given."""
    return message("/ictus/strike", STRIKE_TAGS, seq, hand, 0, bounce, time_s, 0.05, 0.0,
                   r_over_a, theta_deg, velocity, 0.1, peak_force_n, 0.01, 1.0, 0.0, 0.0, -1.0,
                   stick_mass_kg, stick_tip)


def now():
    """Wall-clock time (CLOCK_REALTIME, as Pd's [ictus_timetag] reads it)."""
    return time.clock_gettime(time.CLOCK_REALTIME)

IMMEDIATE = struct.pack(">II", 0, 1)  # the OSC timetag "immediately"
