"""How near the performer's limbs come to the kit, from a render's own outputs.

Reads performance.bvh (the simulated bodies, world metres, y up) and render.json's kit,
computes each frame's joint positions by forward kinematics (an independent reading of the
BVH: offsets, then the channels' Euler angles in their written order), and measures the
clearance of each limb, a volume about its bones (LIMBS), to each piece: a drum a solid
cylinder below its head (the kick's lies along +z from its batter), a cymbal a 1 cm disc on
its stand, a 2.5 cm rod from the floor to its centre (the hi-hat's rod goes on 10 cm above
its plates, to the clutch). The sticks are measured against the stands alone (the scene
keeps them out of the pieces). A negative clearance is a limb's volume in a piece; a
negative clearance of its core (its bones' axes, the palm's midplane, the grip's or the
stick's axis) is a limb through a piece, and the exit status is then 1.

    PYTHONPATH=python python3 -m ictus_tools.limb_clearance RENDER_DIR
"""
import argparse
import collections
import json
import os
import sys

import numpy as np

# The sticks (the score's default, character.hpp's StickParams: 0.406 m, a 14.5 mm shaft),
# from the butt to the tip, are measured against the stands only: the scene's collisions
# keep them out of the drums and cymbals (render.json's shell_passes).
STICK_LENGTH_M = 0.406
STICK_RADIUS_M = 0.00725

# The limbs, each a set of points along or over its bones with a radius about each point:
# (name, kind, joints, radii). Radii from adult men's girths over 2 pi and breadths, rounded
# (ANSUR II, 2012: biceps 31-33 cm, forearm below the elbow 29 cm, wrist 17.5 cm, thigh
# above the knee 38 cm, calf 38 cm at its widest and 31 cm below, hand breadth 8.9 cm,
# thickness 3.3 cm): an arm bone a cone rounded at both ends; the palm a slab 3.3 cm thick
# and 8.9 cm wide along the skeleton's hand (the wrist to the index's end, 6.2 cm on CMU's
# skeleton; the stick is gripped 2.7 cm from the wrist), the thumb's side across it; the
# fingers closed round the stick a capsule of 1.7 cm about the stick's axis, 4 cm to
# either side of the grip.
LIMBS = [
    ("left upper arm", "bone", ("LeftArm", "LeftForeArm"), (0.050, 0.045)),
    ("left forearm", "bone", ("LeftForeArm", "LeftHand"), (0.045, 0.028)),
    ("left palm", "palm", ("LeftHand", "LeftHandIndex1_End", "LThumb_End"), (0.0165,)),
    ("left fingers", "grip", ("LeftHandStick", "LeftHandStick_End"), (0.017,)),
    ("right upper arm", "bone", ("RightArm", "RightForeArm"), (0.050, 0.045)),
    ("right forearm", "bone", ("RightForeArm", "RightHand"), (0.045, 0.028)),
    ("right palm", "palm", ("RightHand", "RightHandIndex1_End", "RThumb_End"), (0.0165,)),
    ("right fingers", "grip", ("RightHandStick", "RightHandStick_End"), (0.017,)),
    ("left stick", "stick", ("LeftHandStick", "LeftHandStick_End"), (STICK_RADIUS_M,)),
    ("right stick", "stick", ("RightHandStick", "RightHandStick_End"), (STICK_RADIUS_M,)),
    ("left thigh", "bone", ("LeftUpLeg", "LeftLeg"), (0.06, 0.06)),
    ("left shank", "bone", ("LeftLeg", "LeftFoot"), (0.05, 0.05)),
    ("right thigh", "bone", ("RightUpLeg", "RightLeg"), (0.06, 0.06)),
    ("right shank", "bone", ("RightLeg", "RightFoot"), (0.05, 0.05)),
]
PALM_BREADTH_M = 0.089
FINGERS_HALF_WIDTH_M = 0.04
STAND_RADIUS_M = 0.0125
HIHAT_ROD_ABOVE_M = 0.10
SAMPLES = 41  # points along each bone (1 cm apart or less: a cymbal is 1 cm thick)


class Bvh:
    """A BVH file's hierarchy and frames."""

    def __init__(self, path):
        with open(path) as f:
            tokens = f.read().split()
        self.names, self.parent, self.offset, self.channels = [], [], [], []
        i, stack = 0, []
        while tokens[i] != "MOTION":
            t = tokens[i]
            if t in ("ROOT", "JOINT") or (t == "End" and tokens[i + 1] == "Site"):
                name = tokens[i + 1] if t != "End" else self.names[stack[-1]] + "_End"
                self.names.append(name)
                self.parent.append(stack[-1] if stack else -1)
                self.offset.append(np.zeros(3))
                self.channels.append([])
                i += 2
            elif t == "{":
                stack.append(len(self.names) - 1)
                i += 1
            elif t == "}":
                stack.pop()
                i += 1
            elif t == "OFFSET":
                self.offset[stack[-1]] = np.array([float(x) for x in tokens[i + 1:i + 4]])
                i += 4
            elif t == "CHANNELS":
                n = int(tokens[i + 1])
                self.channels[stack[-1]] = tokens[i + 2:i + 2 + n]
                i += 2 + n
            else:
                i += 1
        frames = int(tokens[i + 2])
        self.frame_time_s = float(tokens[i + 5])
        values = np.array([float(x) for x in tokens[i + 6:]])
        width = sum(len(c) for c in self.channels)
        if values.size != frames * width:
            raise ValueError("%s: %d values for %d frames of %d channels" %
                             (path, values.size, frames, width))
        self.motion = values.reshape(frames, width)

    def positions(self):
        """Every joint's world position in every frame: (frames, joints, 3)."""
        frames, n = self.motion.shape[0], len(self.names)
        pos = np.zeros((frames, n, 3))
        rot = np.zeros((frames, n, 3, 3))
        col = 0
        for j in range(n):
            local_r = np.broadcast_to(np.eye(3), (frames, 3, 3)).copy()
            local_t = np.broadcast_to(self.offset[j], (frames, 3)).copy()
            for ch in self.channels[j]:
                v = self.motion[:, col]
                col += 1
                if ch.endswith("position"):
                    local_t[:, "XYZ".index(ch[0])] += v
                else:
                    local_r = local_r @ _axis_rotation(ch[0], np.radians(v))
            p = self.parent[j]
            if p < 0:
                pos[:, j], rot[:, j] = local_t, local_r
            else:
                pos[:, j] = pos[:, p] + np.einsum("fij,fj->fi", rot[:, p], local_t)
                rot[:, j] = rot[:, p] @ local_r
        return pos


def _axis_rotation(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    r = np.zeros(angle.shape + (3, 3))
    i = "XYZ".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    r[:, i, i] = 1.0
    r[:, j, j], r[:, j, k], r[:, k, j], r[:, k, k] = c, -s, s, c
    return r


def cylinder_distance(p, top, axis, depth, radius):
    """Signed distance of points p (..., 3) to a solid cylinder whose one face is centred on
    top and which runs depth along the unit axis from it."""
    d = p - top
    along = d @ axis
    radial = np.linalg.norm(d - along[..., None] * axis, axis=-1)
    qx = radial - radius
    qy = np.abs(along - 0.5 * depth) - 0.5 * depth
    outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
    return outside + np.minimum(np.maximum(qx, qy), 0.0)


def pieces(render_json):
    """The kit's solids as (name, kind, top, axis, depth, radius) from render.json."""
    out = []
    for d in render_json["kit"]["drums"]:
        top = np.array(d["center_m"], dtype=float)
        plate = d.get("bending_n_m", 0.0) > 0.0
        if "pedal" in d:
            axis = np.array([0.0, 0.0, 1.0])
        else:
            axis = np.array([0.0, -1.0, 0.0])
        out.append((d["name"], "piece", top, axis, d["shell_depth_m"], d["radius_m"]))
        if plate:
            rod_top = top + np.array([0.0, HIHAT_ROD_ABOVE_M if d["name"] == "hihat" else 0.0,
                                      0.0])
            out.append((d["name"] + " stand", "stand", rod_top, np.array([0.0, -1.0, 0.0]),
                        rod_top[1], STAND_RADIUS_M))
    return out


Clearance = collections.namedtuple("Clearance", "volume_m time_s frames_inside core_m")


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def limb_points(pos, index, kind, joints, radii):
    """A limb's points in every frame (frames, n, 3) and their radii (n,)."""
    p = [pos[:, index[j]] for j in joints]
    if kind == "bone":
        t = np.linspace(0.0, 1.0, SAMPLES)
        pts = p[0][:, None, :] + (p[1] - p[0])[:, None, :] * t[None, :, None]
        return pts, radii[0] + (radii[1] - radii[0]) * t
    if kind == "palm":
        length = p[1] - p[0]
        along = _unit(length)
        thumb = p[2] - p[0]
        across = _unit(thumb - np.sum(thumb * along, axis=-1, keepdims=True) * along)
        half = 0.5 * PALM_BREADTH_M - radii[0]
        a, c = np.meshgrid(np.linspace(0.0, 1.0, 11), np.linspace(-half, half, 7))
        a, c = a.ravel(), c.ravel()
        pts = (p[0][:, None, :] + a[None, :, None] * length[:, None, :] +
               c[None, :, None] * across[:, None, :])
        return pts, np.full(a.size, radii[0])
    along = _unit(p[1] - p[0])
    if kind == "stick":
        to_butt = STICK_LENGTH_M - np.linalg.norm(p[1] - p[0], axis=-1)
        s = np.linspace(0.0, 1.0, 41)
        butt = p[0] - to_butt[:, None] * along
        pts = butt[:, None, :] + (p[1] - butt)[:, None, :] * s[None, :, None]
        return pts, np.full(s.size, radii[0])
    s = np.linspace(-FINGERS_HALF_WIDTH_M, FINGERS_HALF_WIDTH_M, 9)
    pts = p[0][:, None, :] + s[None, :, None] * along[:, None, :]
    return pts, np.full(s.size, radii[0])


def clearances(render_dir, bvh=None, pos=None):
    """{(limb, piece): Clearance}: the limb's volume's least clearance to the piece (m), its
    time (s), the frames with the volume inside the piece, and the least clearance of the
    limb's core (its points' own radius left out: its bones, the palm's midplane, the grip's
    axis), negative when the limb is through the piece. bvh and pos: performance.bvh already
    read, and its positions."""
    with open(os.path.join(render_dir, "render.json")) as f:
        rj = json.load(f)
    if bvh is None:
        bvh = Bvh(os.path.join(render_dir, "performance.bvh"))
    if pos is None:
        pos = bvh.positions()
    index = {n: i for i, n in enumerate(bvh.names)}
    out = {}
    for limb, kind, joints, radii in LIMBS:
        pts, r = limb_points(pos, index, kind, joints, radii)
        for name, what, top, axis, depth, radius in pieces(rj):
            if kind == "stick" and what != "stand":
                continue
            core = cylinder_distance(pts, top, axis, depth, radius)
            d = (core - r[None, :]).min(axis=1)
            f = int(np.argmin(d))
            out[(limb, name)] = Clearance(float(d[f]), f * bvh.frame_time_s,
                                          int((d < 0.0).sum()), float(core.min()))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("render_dir")
    ap.add_argument("--all", action="store_true", help="every limb and piece, not only the "
                    "nearest piece of each limb")
    args = ap.parse_args(argv)
    c = clearances(args.render_dir)
    through = 0
    for limb, *_ in LIMBS:
        rows = sorted(((v, k[1]) for k, v in c.items() if k[0] == limb))
        for v, piece in (rows if args.all else rows[:1]):
            print("%-16s %-12s least clearance %7.1f mm at %7.3f s (frames inside %d), "
                  "its core %7.1f mm" % (limb, piece, 1e3 * v.volume_m, v.time_s,
                                         v.frames_inside, 1e3 * v.core_m))
        through += min(v.core_m for v, _ in rows) < 0.0
    return 1 if through else 0


if __name__ == "__main__":
    sys.exit(main())
