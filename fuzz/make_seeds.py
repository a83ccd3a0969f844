#!/usr/bin/env python3
"""Writes the generated part of the fuzz seed corpus (fuzz/corpus/): BVH files
of the default body's CMU hierarchy (character/stick_capture.cpp,
default_skeleton), stick-only CSV captures, raw OSC packets and Standard MIDI
Files of drum parts. The
hand-written seeds sit beside them. Deterministic: rerunning rewrites the same
bytes. Usage: python3 fuzz/make_seeds.py
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "corpus")

# The default body (stick_capture.cpp): name, parent, offset in CMU units, end site.
DEFAULT_SKELETON = [
    ("Hips", "", (0, 0, 0), False),
    ("LHipJoint", "Hips", (0, 0, 0), False),
    ("LeftUpLeg", "LHipJoint", (1.8, -1.7, 0.7), False),
    ("LeftLeg", "LeftUpLeg", (2.3, -6.2, 0), False),
    ("LeftFoot", "LeftLeg", (2.6, -7.0, 0), False),
    ("LeftToeBase", "LeftFoot", (0.2, -0.6, 1.7), False),
    ("LeftToeBase_end", "LeftToeBase", (0, 0, 0.9), True),
    ("RHipJoint", "Hips", (0, 0, 0), False),
    ("RightUpLeg", "RHipJoint", (-1.8, -1.7, 0.7), False),
    ("RightLeg", "RightUpLeg", (-2.3, -6.2, 0), False),
    ("RightFoot", "RightLeg", (-2.6, -7.0, 0), False),
    ("RightToeBase", "RightFoot", (-0.2, -0.6, 1.7), False),
    ("RightToeBase_end", "RightToeBase", (0, 0, 0.9), True),
    ("LowerBack", "Hips", (0, 0, 0), False),
    ("Spine", "LowerBack", (0, 1.7, -0.2), False),
    ("Spine1", "Spine", (0, 1.7, 0.2), False),
    ("Neck", "Spine1", (0, 0, 0), False),
    ("Neck1", "Neck", (0, 1.65, 0.1), False),
    ("Head", "Neck1", (0, 1.6, -0.3), False),
    ("Head_end", "Head", (0, 1.7, -0.1), True),
    ("LeftShoulder", "Spine1", (0, 0, 0), False),
    ("LeftArm", "LeftShoulder", (3.1, 1.4, 0.3), False),
    ("LeftForeArm", "LeftArm", (5.1, 0, 0), False),
    ("LeftHand", "LeftForeArm", (3.6, 0, 0), False),
    ("LeftFingerBase", "LeftHand", (0, 0, 0), False),
    ("LeftHandIndex1", "LeftFingerBase", (0.6, 0, 0), False),
    ("LeftHandIndex1_end", "LeftHandIndex1", (0.5, 0, 0), True),
    ("LThumb", "LeftHand", (0, 0, 0), False),
    ("LThumb_end", "LThumb", (0.5, 0, 0.5), True),
    ("RightShoulder", "Spine1", (0, 0, 0), False),
    ("RightArm", "RightShoulder", (-3.1, 1.4, 0.3), False),
    ("RightForeArm", "RightArm", (-5.1, 0, 0), False),
    ("RightHand", "RightForeArm", (-3.6, 0, 0), False),
    ("RightFingerBase", "RightHand", (0, 0, 0), False),
    ("RightHandIndex1", "RightFingerBase", (-0.6, 0, 0), False),
    ("RightHandIndex1_end", "RightHandIndex1", (-0.5, 0, 0), True),
    ("RThumb", "RightHand", (0, 0, 0), False),
    ("RThumb_end", "RThumb", (-0.5, 0, 0.5), True),
]


def write(folder, name, data):
    path = os.path.join(CORPUS, folder, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def fmt(v):
    return ("%.6f" % v).rstrip("0").rstrip(".") if v != int(v) else "%d" % v


def cmu_bvh(frames=3, frame_time="0.008333", offsets=None, hips_y=17.0):
    """The default body as a CMU BVH: Hips with 6 channels (Zrot Yrot Xrot, as
    CMU), every other joint 3 rotations, end sites as End Site."""
    offsets = offsets or {}
    children = {}
    for name, parent, offset, end in DEFAULT_SKELETON:
        children.setdefault(parent, []).append((name, offset, end))
    lines = ["HIERARCHY"]
    order = []  # channelled joints in file order

    def joint(name, offset, depth, root=False):
        pad = "  " * depth
        lines.append(pad + ("ROOT " if root else "JOINT ") + name)
        lines.append(pad + "{")
        o = offsets.get(name, offset)
        lines.append(pad + "  OFFSET " + " ".join(fmt(v) for v in o))
        if root:
            lines.append(pad + "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation")
        else:
            lines.append(pad + "  CHANNELS 3 Zrotation Yrotation Xrotation")
        order.append(name)
        for child, child_offset, end in children.get(name, []):
            if end:
                lines.append(pad + "  End Site")
                lines.append(pad + "  {")
                lines.append(pad + "    OFFSET " + " ".join(fmt(v) for v in child_offset))
                lines.append(pad + "  }")
            else:
                joint(child, child_offset, depth + 1)
        lines.append(pad + "}")

    joint("Hips", (0, 0, 0), 0, root=True)
    lines += ["MOTION", "Frames: %d" % frames, "Frame Time: " + frame_time]
    for f in range(frames):
        values = [0.0, hips_y, 0.0, 0.0, 0.0, 0.0]
        for k, name in enumerate(order[1:]):
            # Small, different angles per joint and frame: a clip that moves.
            a = 10.0 * math.sin(0.7 * f + 0.3 * k)
            values += [round(a, 4), round(0.5 * a, 4), round(-0.25 * a, 4)]
        lines.append(" ".join(fmt(v) for v in values))
    return "\n".join(lines) + "\n"


def stick_csv(frames=120, rate=120.0, time_scale=1.0, names=("stick_l", "stick_r")):
    """Two stick tips striking alternately (y up, m), 4 strokes a second."""
    rows = ["time," + ",".join("%s.x,%s.y,%s.z" % (n, n, n) for n in names)]
    for i in range(frames):
        t = i / rate
        cells = [fmt(round(t * time_scale, 6))]
        for s, x in ((0, 0.15), (1, -0.15)):
            phase = 2 * math.pi * 2.0 * t + s * math.pi
            y = 0.75 + 0.1 * (1 + math.cos(phase))
            cells += [fmt(x), fmt(round(y, 5)), fmt(round(0.45 + 0.02 * math.sin(phase), 5))]
        rows.append(",".join(cells))
    return "\n".join(rows) + "\n"


def osc_string(s):
    b = s.encode() + b"\0"
    return b + b"\0" * (-len(b) % 4)


def osc(address, types="", *args):
    out = osc_string(address) + osc_string("," + types)
    for t, a in zip(types, args):
        if t == "f":
            out += struct.pack(">f", a)
        elif t == "i":
            out += struct.pack(">i", a)
        elif t == "s":
            out += osc_string(a)
    return out


def vlq(v):
    out = [v & 0x7F]
    v >>= 7
    while v:
        out.append(0x80 | (v & 0x7F))
        v >>= 7
    return bytes(reversed(out))


def smf(fmt, tpq, tracks):
    """A Standard MIDI File of tracks of (tick, event bytes), sorted by tick."""
    out = b"MThd" + struct.pack(">IHHH", 6, fmt, len(tracks), tpq)
    for events in tracks:
        data, last = b"", 0
        for tick, msg in sorted(events, key=lambda e: e[0]):
            data += vlq(tick - last) + msg
            last = tick
        data += b"\x00\xff\x2f\x00"
        out += b"MTrk" + struct.pack(">I", len(data)) + data
    return out


def drum_part():
    """A GM drum part: 8ths of snare and hi-hat, kicks, a tom fill, a tempo ramp in steps."""
    notes = [(k * 240, 38 if k % 2 else 40, 60 + k) for k in range(8)]
    notes += [(k * 240, 42, 80) for k in range(8)] + [(0, 36, 100), (960, 36, 100)]
    notes += [(1920 + 120 * k, n, 40 + 5 * k) for k, n in enumerate([50, 48, 47, 45, 43, 41, 43, 38])]
    drums = [(t, bytes([0x99, n, v])) for t, n, v in notes] + \
            [(t + 60, bytes([0x89, n, 0])) for t, n, v in notes]
    tempo = [(0, b"\xff\x58\x04\x03\x02\x18\x08")] + \
            [(480 * k, b"\xff\x51\x03" + round(60e6 / (100 + 10 * k)).to_bytes(3, "big"))
             for k in range(6)]
    return tempo, drums


def main():
    # BVH: the default body, and the known troublemakers on it.
    write("bvh", "cmu_default.bvh", cmu_bvh())
    write("bvh", "cmu_frame_time_60.bvh", cmu_bvh(frames=4, frame_time="60"))
    write("bvh", "cmu_zero_forearm.bvh", cmu_bvh(offsets={"LeftForeArm": (0, 0, 0)}))
    write("bvh", "cmu_zero_upper_leg.bvh", cmu_bvh(offsets={"RightLeg": (0, 0, 0)}))
    write("bvh", "cmu_40_frames.bvh", cmu_bvh(frames=40))
    # Deeper than the reader's limit (500 joints).
    deep = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 1 Xrotation"]
    for d in range(1, 503):
        deep += ["JOINT j%d" % d, "{", "OFFSET 0 1 0"]
    deep += ["}"] * 503 + ["MOTION", "Frames: 1", "Frame Time: 0.01", "0"]
    write("bvh", "too_deep.bvh", "\n".join(deep) + "\n")
    # A finding (docs/fuzzing.md): 1300 end sites under one channel, 14000 frames of one
    # value. 62 KB of text ask for 18 million stored rotations (575 MB in a release build).
    sites = "End Site { OFFSET 0 0 0 }\n" * 1300
    write("bvh", "end_sites_times_frames.bvh",
          "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n" + sites +
          "}\nMOTION\nFrames: 14000\nFrame Time: 0.001\n" + "0\n" * 14000)

    # CSV: stick-only captures.
    write("marker_csv", "sticks.csv", stick_csv())
    write("marker_csv", "sticks_time_in_ms.csv", stick_csv(time_scale=1000.0))
    write("marker_csv", "sticks_left_right_names.csv",
          stick_csv(frames=60, names=("LeftStick", "RightStick")))

    # OSC: one packet per file, every address of docs/osc.md and some faults.
    packets = {
        "ping.osc": osc("/ictus/ping"),
        "status.osc": osc("/ictus/status"),
        "play.osc": osc("/ictus/play"),
        "stop.osc": osc("/ictus/stop"),
        "tempo.osc": osc("/ictus/tempo", "f", 96.0),
        "tempo_out_of_range.osc": osc("/ictus/tempo", "f", 1000.0),
        "tempo_nan.osc": osc("/ictus/tempo", "f", float("nan")),
        "tempo_int.osc": osc("/ictus/tempo", "i", 96),
        "grip.osc": osc("/ictus/grip", "s", "german"),
        "grip_unknown.osc": osc("/ictus/grip", "s", "spanish"),
        "nuance.osc": osc("/ictus/nuance", "s", "vertical_accent"),
        "mode.osc": osc("/ictus/mode", "s", "cartesian"),
        "gains.osc": osc("/ictus/gains", "ff", 1.0, 0.5),
        "drum_radius.osc": osc("/ictus/drum/radius", "f", 0.2),
        "drum_tension.osc": osc("/ictus/drum/tension", "f", 3000.0),
        "drum_density.osc": osc("/ictus/drum/density", "f", 0.26),
        "score.osc": osc("/ictus/score", "s", "R accent 0.8 1/2"),
        "score_repeat.osc": osc("/ictus/score", "s", "repeat 4, R, L, end"),
        "score_nested_repeat_grip.osc": osc(
            "/ictus/score", "s",
            "repeat 1000, repeat 1000, repeat 1000, repeat 1000, grip german, end, end, end, end"),
        "score_control_char.osc": osc("/ictus/score", "s", "R\nL"),
        "score_too_long.osc": osc("/ictus/score", "s", "R " * 200),
        "score_clear.osc": osc("/ictus/score/clear"),
        "unknown_address.osc": osc("/ictus/nothing", "i", 1),
        "bundle.osc": b"#bundle\0" + struct.pack(">Q", 1) + struct.pack(">i", 16) + osc("/ictus/play"),
        "truncated.osc": osc("/ictus/tempo", "f", 96.0)[:-2],
        "no_type_tags.osc": osc_string("/ictus/play"),
        "empty.osc": b"",
    }
    for name, data in packets.items():
        write("osc_server", name, data)

    # MIDI: a drum part in format 1 and the same merged in format 0 with running status.
    tempo, drums = drum_part()
    write("midi", "drum_part_format1.mid", smf(1, 480, [tempo, drums]))
    write("midi", "drum_part_format0.mid", smf(0, 96, [[(t // 5, m) for t, m in tempo + drums]]))
    write("midi", "channel1_only.mid",
          smf(0, 480, [[(k * 120, bytes([0x90, 38, 100])) for k in range(16)]]))


if __name__ == "__main__":
    main()
