"""The end-to-end chain for tests and scripts/main.sh: the files `ictusd render`
writes (strikes.csv, events.txt, render.json: docs/osc.md), rendering an events
file with patches/ictus-render.pd in the real pd (batch mode), and an onset
detector that looks at the rendered signal only.

How onsets are measured (docs/main-job.md, "Checking the onsets"):
- The drum in the main render rings for seconds and the two hands strike a few
  ms apart (the CMU clip has pairs 1.6 ms apart), bounces follow their stroke
  within tens of ms: in one mixed signal the onset of a stroke that lands on a
  ringing drum is not a well-defined sample. So the check renders the same
  events file again in a few *passes*: the strikes are dealt into passes so
  that within a pass consecutive strikes are at least MIN_GAP_S apart (greedy,
  in time order), and the drum is given a short decay (render-drum t60 0.01,
  every other line of the events file untouched: same delays, same hit lists;
  a snare's snare side, which rings on its own decay, left out).
  Every strike is then played exactly once, onto a drum at rest.
- The detector sees only the WAV: an onset is the first sample whose magnitude
  (max over the two pickups) exceeds THRESHOLD after at least QUIET_S of
  samples at or below it. It is matched to strikes.csv's time_s: the onset of
  every strike within 1 ms (we measure the error in samples), and exactly as
  many onsets as strikes in the pass (no extra onsets: a second contact made by
  contact~, a click, a strike played twice would each fail).
- The full WAV itself, on the real drum (departure_onsets): Pd is
  deterministic, so the performance and a render of the same events file cut
  just before strike k are bit-identical until strike k starts. Strike k's
  onset in the full WAV is the first sample where the two differ: a detector
  that needs no threshold and works on a ringing drum and for strikes 1 ms
  apart, because whatever sounded before strike k is in both signals.
"""
import json
import math
import os
import struct
import subprocess

import numpy as np

from ictus_tools import ROOT
from ictus_tools.pdrun import PD, PD_BATCH, PD_ENV, read_wav_float

RENDER_PATCH = os.path.join(ROOT, "patches", "ictus-render.pd")
MIN_GAP_S = 0.060   # strikes closer than this go to different passes
MEASURE_T60_S = 0.01  # the drum's decay in the onset passes
THRESHOLD = 1e-7    # |y| above this after silence is an onset
QUIET_S = 0.010     # silence needed before an onset


# strikes.csv's integer columns (docs/osc.md); the others are reals. A column this does not
# know (a newer file) is read as a real.
INTEGER_COLUMNS = ("seq", "hand", "drum", "bounce", "stroke", "stick_tip")


def read_strikes(path):
    """strikes.csv -> list of dicts (numbers converted), in file order."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip()]
    if not lines:
        raise ValueError("%s: empty (no header)" % path)
    header = lines[0].split(",")
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != len(header):
            raise ValueError("%s:%d: %d columns, header has %d" % (path, n, len(cells), len(header)))
        row = {}
        for name, cell in zip(header, cells):
            row[name] = int(cell) if name in INTEGER_COLUMNS else float(cell)
        rows.append(row)
    return rows



def read_kit_render(out):
    """A kit render's outputs: (render.json, the kit's piece names by index, notes.csv's rows,
    strikes.csv's strikes by seq)."""
    import csv
    with open(os.path.join(out, "render.json")) as f:
        rj = json.load(f)
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    strikes = {s["seq"]: s for s in read_strikes(os.path.join(out, "strikes.csv"))}
    return rj, [d["name"] for d in rj["kit"]["drums"]], notes, strikes


def note_found(note, strikes, names, tol_ms=5.0, hand=None):
    """notes.csv's `note` got one primary strike on its piece within tol_ms (and of limb
    `hand`, strikes.csv's number, when given): the whole kit's acceptance (docs/kit.md). The
    error is the strike's time in strikes.csv less the note's in notes.csv, not notes.csv's
    error_ms (the daemon's own)."""
    s = strikes.get(int(note["strike_seq"]))
    return (s is not None and s["bounce"] == 0 and names[s["drum"]] == note["drum"]
            and (hand is None or s["hand"] == hand)
            and abs(1e3 * (float(s["time_s"]) - float(note["time_s"]))) <= tol_ms)

def read_events(path):
    """events.txt -> list of (delay_us, words after the delay) per line, the
    delay in whole microseconds (the file writes ms with 3 decimals)."""
    events = []
    with open(path) as f:
        text = f.read()
    for n, raw in enumerate(text.split(";"), start=1):
        words = raw.split()
        if not words:
            continue
        delay_ms = words[0]
        whole, _, frac = delay_ms.partition(".")
        if not whole.isdigit() or (frac and not frac.isdigit()) or len(frac) > 3:
            raise ValueError("%s: line %d: delay '%s' is not ms with <= 3 decimals" % (path, n, delay_ms))
        events.append((int(whole) * 1000 + int((frac + "000")[:3]), words[1:]))
    return events


def hit_times_us(events):
    """Absolute time (us) of every 'hit' line: the running sum of the delays."""
    t, times = 0, []
    for delay_us, words in events:
        t += delay_us
        if words and words[0] == "hit":
            times.append(t)
    return times


def drum_lines(render_json):
    """The drum of render.json as render-drum lines for ictus-render (membrane~
    parameters: the preset first, when there is one, then the head's numbers; the
    head's stretching k3 and the stick tip to both contact~, when the physics has them)."""
    with open(render_json) as f:
        drum = json.load(f)["drum"]
    preset = ["render-drum preset %s" % drum["preset"]] if drum.get("preset") else []
    tip = drum.get("stick_tip") or ""
    tips = ["render-drum %s tip %s" % (hand, tip) for hand in ("left", "right")] if tip else []
    k3 = drum.get("contact_stretch_n_per_m3") or 0.0
    if k3 > 0.0:
        tips = ["render-drum %s stretch %.9g" % (hand, k3) for hand in ("left", "right")] + tips
    return preset + ["render-drum radius %.6g" % drum["radius_m"],
            "render-drum tension %.6g" % drum["tension_n_per_m"],
            "render-drum density %.6g" % drum["density_kg_per_m2"]] + tips


def write_events(path, header_lines, events, keep=None):
    """An events file: header lines at time 0, then the hit lines whose index
    (among hits) is in `keep` (all when None), with delays recomputed from the
    absolute times so that each kept hit keeps its time to the microsecond."""
    out = ["0 %s;" % h for h in header_lines]
    t, prev, k = 0, 0, 0
    for delay_us, words in events:
        t += delay_us
        if words and words[0] == "hit":
            if keep is None or k in keep:
                d = t - prev
                out.append("%d.%03d %s;" % (d // 1000, d % 1000, " ".join(words)))
                prev = t
            k += 1
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def render_pd(build, events_path, wav_path, seconds, sr=48000, timeout=300, sends=()):
    """patches/ictus-render.pd in pd batch mode -> (samples [n, 2], sr, log).
    `sends`: messages sent to the patch before the events file (as -send, the way
    `ictusd render --wav` sends the drum), before DSP starts."""
    cmd = PD_BATCH + ["-r", str(sr), "-path", os.path.join(build, "ictus"), "-open", RENDER_PATCH]
    for message in sends:
        cmd += ["-send", message]
    cmd += ["-send", "render-file %s" % os.path.abspath(events_path), "-send",
           "render-out %s" % os.path.abspath(wav_path), "-send", "render-seconds %.3f" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=PD_ENV)
    log = proc.stdout + proc.stderr
    if proc.returncode != 0:
        raise RuntimeError("pd exited with %d:\n%s" % (proc.returncode, log))
    x, file_sr = read_wav_float(wav_path)
    return x, file_sr, log


def passes(times_s, min_gap_s=MIN_GAP_S):
    """Deals strike indices into passes, greedily in time order, so that within
    a pass consecutive strikes are >= min_gap_s apart. Returns a list of lists."""
    order = sorted(range(len(times_s)), key=lambda i: times_s[i])
    result, last = [], []
    for i in order:
        for p, members in enumerate(result):
            if times_s[i] - last[p] >= min_gap_s:
                members.append(i)
                last[p] = times_s[i]
                break
        else:
            result.append([i])
            last.append(times_s[i])
    return result


def detect_onsets(x, sr, threshold=THRESHOLD, quiet_s=QUIET_S):
    """Sample indices where the signal (max |y| over channels) first exceeds
    `threshold` after at least quiet_s of samples at or below it (the start of
    the file counts as quiet)."""
    y = np.abs(np.asarray(x, dtype=np.float64))
    if y.ndim == 2:
        y = y.max(axis=1)
    loud = np.flatnonzero(y > threshold)
    if loud.size == 0:
        return []
    quiet = int(round(quiet_s * sr))
    gaps = np.diff(loud)
    starts = [int(loud[0])] + [int(loud[k + 1]) for k in np.flatnonzero(gaps > quiet)]
    return starts


def at_rest_header(header):
    """The drum of the onset passes: `header` with the batter's decay cut to
    MEASURE_T60_S. A snare preset is left out (the head keeps render.json's
    radius, tension and density): its snare head and wires ring on their own
    decay, which the batter's t60 does not shorten, and would hide the next
    strike's onset."""
    kept = [h for h in header if h.split()[:3] != ["render-drum", "preset", "snare"]]
    return kept + ["render-drum t60 %g" % MEASURE_T60_S]


def check_onsets(build, events, strikes, work, sr=48000, header=(), log_errors=None):
    """Renders the strikes in passes (see the module doc) and matches the
    detected onsets to strikes.csv. Returns a dict: errors_ms (per strike, in
    strike order), extra (onsets matched to no strike), missing (strikes
    without an onset), passes, logs. header: extra render-drum lines."""
    times = [s["time_s"] for s in strikes]
    groups = passes(times)
    errors = [None] * len(strikes)
    extra, logs = [], []
    tol = int(round(0.001 * sr))
    for p, members in enumerate(groups):
        ev = os.path.join(work, "pass-%d.txt" % p)
        wav = os.path.join(work, "pass-%d.wav" % p)
        write_events(ev, at_rest_header(header), events, keep=set(members))
        seconds = round(max(times[i] for i in members) + 0.2, 3)
        x, file_sr, log = render_pd(build, ev, wav, seconds, sr)
        logs.append(log)
        if file_sr != sr or not np.all(np.isfinite(x)):
            raise RuntimeError("pass %d: WAV at %d Hz or not finite" % (p, file_sr))
        onsets = detect_onsets(x, sr)
        expected = {i: int(np.floor(times[i] * sr + 0.5)) for i in members}
        used = set()
        for i in sorted(members, key=lambda i: times[i]):
            near = [o for o in onsets if abs(o - expected[i]) <= tol and o not in used]
            if near:
                best = min(near, key=lambda o: abs(o - expected[i]))
                used.add(best)
                errors[i] = (best - expected[i]) * 1000.0 / sr
        extra += [(p, o / sr) for o in onsets if o not in used]
    missing = [i for i, e in enumerate(errors) if e is None]
    return {"errors_ms": errors, "extra": extra, "missing": missing, "passes": groups,
            "logs": logs}


def departure_onsets(build, events, header, full, seconds_after=0.005, sr=48000, work=None,
                     indices=None, header_sent=False):
    """Onset of each strike (indices into the hits, default all) in `full` (the
    WAV samples of the whole events file rendered with `header`): the first
    sample where `full` differs from a render of the hits before it. Returns
    {index: sample or None (no difference)} and the logs. `header_sent`: `full`
    was rendered with the header as -send messages before DSP started (as
    `ictusd render --wav` does), and so are the prefixes. The drum is then set up
    in the same order on the same state, so the prefixes match `full` to the bit
    until the strike even on a chaotic drum (the snare's wires turn a difference
    in the last bit into an audible one within a second)."""
    times = hit_times_us(events)
    result, logs = {}, []
    for k in (range(len(times)) if indices is None else indices):
        ev = os.path.join(work, "prefix-%d.txt" % k)
        wav = os.path.join(work, "prefix-%d.wav" % k)
        write_events(ev, [] if header_sent else header, events, keep=set(range(k)))
        seconds = round(times[k] / 1e6 + seconds_after, 3)
        x, _, log = render_pd(build, ev, wav, seconds, sr, sends=header if header_sent else ())
        logs.append(log)
        n = min(len(x), len(full))
        diff = np.flatnonzero(np.any(x[:n] != full[:n], axis=1))
        result[k] = int(diff[0]) if diff.size else None
    return result, logs


def judge_departures(departures, strikes, sr):
    """Judges departure_onsets on the full WAV. Returns (errors_ms by strike,
    failures [(k, why)], notes [(k, text)]). A strike fails when it changes
    nothing, when the WAV departs before its time (something sounded early),
    or, for a primary stroke, more than 1 ms after it. A bounce may start
    later than 1 ms: contact~ puts the stick on the head where the head is at
    that sample, and a head still moving down from the stroke a few ms before
    runs away from a slow bounce (0.1-0.2 m/s) until it swings back. That is
    the two drum models (the daemon's and membrane~) disagreeing, not timing:
    the same bounce on a drum at rest (the passes) starts on its sample. It is
    reported as a note."""
    errors, failures, notes = {}, [], []
    for k, v in sorted(departures.items()):
        s = strikes[k]
        what = "strike %d (hand %d, %s, %.4f m/s at %.6f s)" % (
            k, s["hand"], "bounce" if s["bounce"] else "stroke", s["normal_velocity_mps"],
            s["time_s"])
        if v is None:
            errors[k] = None
            failures.append((k, what + ": changes nothing in the WAV"))
            continue
        e = (v - int(np.floor(s["time_s"] * sr + 0.5))) * 1000.0 / sr
        errors[k] = e
        if e < 0:
            failures.append((k, what + ": the WAV departs %.4f ms early" % -e))
        elif e > 1.0 and not s["bounce"]:
            failures.append((k, what + ": starts %+.4f ms late" % e))
        elif e > 1.0:
            notes.append((k, what + ": starts %+.4f ms late on a head still moving "
                          "(on a drum at rest: see the passes)" % e))
        elif e != 0:
            notes.append((k, what + ": %+.4f ms" % e))
    return errors, failures, notes


def pd_spawning_env(work):
    """The environment for a program that runs pd itself (ictusd render --wav,
    scripts/main.sh): pd found on PATH; under the ASan build (ICTUS_PD_PRELOAD)
    a wrapper named pd first in PATH preloads the runtime into pd and nothing
    else."""
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    if os.environ.get("ICTUS_PD_PRELOAD"):
        bindir = os.path.join(work, "bin")
        os.makedirs(bindir, exist_ok=True)
        with open(os.path.join(bindir, "pd"), "w") as f:
            f.write("#!/bin/sh\nLD_PRELOAD=%s exec %s \"$@\"\n" % (os.environ["ICTUS_PD_PRELOAD"],
                                                                  PD))
        os.chmod(os.path.join(bindir, "pd"), 0o755)
        env["PATH"] = bindir + os.pathsep + env["PATH"]
    elif os.path.dirname(PD):
        env["PATH"] = os.path.dirname(PD) + os.pathsep + env["PATH"]
    return env


def read_wav_mono(path):
    """A 32-bit float WAV (ictus-render's default) as the mean of its channels."""
    with open(path, "rb") as f:
        data = f.read()
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            fmt = struct.unpack("<HHIIHH", body[:16])
        elif cid == b"data":
            samples = body
        pos += 8 + size + (size & 1)
    tag, channels, rate, _, _, bits = fmt
    if not (bits == 32 and tag in (3, 0xFFFE)):
        raise SystemExit("expected a 32-bit float WAV, got format %d, %d bits" % (tag, bits))
    n = len(samples) // 4
    values = struct.unpack("<%df" % n, samples[:4 * n])
    return rate, [sum(values[i:i + channels]) / channels for i in range(0, n, channels)]


def midi_velocities(v, resolution=1e-4):
    """The MIDI velocities, 1 + 126 ln(v / 0.1) / ln(100) rounded and held to 1..127, that a
    strike of strikes.csv's speed v may be given: the file writes v to `resolution` (m/s), and
    Pd's [expr] works in float32 (a few 1e-5 on the curve near 100). One velocity, or two when v
    lies on a rounding boundary within that precision."""
    def curve(s):
        return 1.0 if not s > 0.1 else 1 + 126 * math.log(s / 0.1) / math.log(100)

    def held(x):
        return int(min(127, max(1, math.floor(x + 0.5))))
    return set(range(held(curve(v - resolution / 2) - 1e-4),
                     held(curve(v + resolution / 2) + 1e-4) + 1))


def require_mido():
    """Debian's python3-mido (an independent MIDI reader and writer for the tests): the module;
    without it the test fails under CI=true, else it is skipped (exit 77)."""
    try:
        import mido
    except ImportError:
        import sys
        from ictus_tools.checks import fail
        if os.environ.get("CI") == "true":
            fail("python3-mido is missing (scripts/deps.sh installs it)")
        print("SKIPPED: python3-mido is missing (scripts/deps.sh installs it)")
        sys.exit(77)
    return mido


def render_kit(ictusd, workdir, name, kit, source_args, timeout=900, wav=True):
    """`ictusd render --kit KIT` of source_args (["--midi", F] or ["--score", F]) into
    workdir/name, with a WAV of the two pickups in 32-bit float there: (out dir, wav path).
    A failed render fails the test (exit 1); pd.log is checked for error lines. wav=False:
    the physics alone (no pd), (out dir, None)."""
    import sys
    from ictus_tools.checks import check
    out = os.path.join(workdir, name)
    wav_path = os.path.join(out, name + ".wav") if wav else None
    env = pd_spawning_env(os.path.abspath(workdir))
    sound = ["--wav", wav_path, "--wav-mix", "pickups", "--wav-bits", "32"] if wav else []
    run = subprocess.run([ictusd, "render", "--kit", kit] + source_args +
                         ["--out", out, "--force"] + sound,
                         capture_output=True, text=True, timeout=timeout, env=env)
    if not check(run.returncode == 0, "ictusd render --kit %s %s: exit %d %s"
                 % (kit, " ".join(source_args), run.returncode, run.stderr[-2000:])):
        sys.exit(1)
    if not wav:
        return out, None
    wav = wav_path
    with open(os.path.join(out, "pd.log")) as f:
        errors = [line for line in f if "error" in line.lower()]
    check(not errors, "%s: pd.log has no error line: %s" % (name, errors[:3]))
    return out, wav


def write_drum_midi(mido, path, events, bpm, tpq):
    """A type-0 Standard MIDI File at `bpm` (ticks_per_beat tpq) of the note-ons `events`
    ((tick, note, velocity), any order) on channel 10, ended by a note-off a beat later."""
    mid = mido.MidiFile(type=0, ticks_per_beat=tpq)
    track = mido.MidiTrack()
    mid.tracks.append(track)
    track.append(mido.MetaMessage("set_tempo", tempo=int(round(60e6 / bpm)), time=0))
    now = 0
    for tick, note, vel in sorted(events):
        track.append(mido.Message("note_on", channel=9, note=note, velocity=vel, time=tick - now))
        now = tick
    track.append(mido.Message("note_off", channel=9, note=42, velocity=0, time=tpq))
    mid.save(path)


def seed_range(text):
    """Seeds "A-B" (or "A") as a range, for a script's --seeds."""
    a, _, b = text.partition("-")
    return range(int(a), int(b or a) + 1)
