"""The strike's zone from the physics (docs/osc.md, "Zone"): `ictusd render` (the real daemon,
the default grip) plays seeded random spots r/a 0.3 .. 0.95 (the score's range) on the right
hand and the issue's case, `R at 0.93 180`. strikes.csv gives each strike's landing r/a, peak
force and zone; render.json the drum (its radius: the rim's inner radius; the head's
stiffness k).

Asserted:
1. the strike aimed at r/a 0.93 lands on the rim (zone 1): its stick meets the rim;
2. a strike whose bead sphere reaches the rim circle (landing r + r_tip >= R) is rim;
3. a strike that lands at least DELTA_MIN from the rim is head: the shaft, pitched at
   least PITCH_MIN_DEG over the head, clears the rim there unless the bead sinks deeper than
   DELTA_MIN tan(PITCH_MIN_DEG) - which the strike's own peak force over k (the head's
   spring: depth = F / k, a bound: the stretching stiffens it) shows it does not.
PITCH_MIN_DEG is a stated floor for the default grip, not measured here (strikes.csv has no
stick pitch); the depth bound is computed per strike.

Then near the edge of each drum of `--kit standard` (docs/rim.md, "A bead that meets only the
edge"): `L on tom1 at 0.95 90`, whose bead lands outside the disk and meets only the edge, and
16 seeded notes of either hand on any drum at r/a 0.85 .. 0.95 on the side toward the
performer (theta 45 .. 135). Asserted: every note is one primary strike of its hand on its
drum within 5 ms; no strike lands outside its disk (r/a <= 1); the tom1 case's strikes are on
the rim; and rule 2 above with each drum's radius.

Then `on NAME-rim` (docs/score.md): either hand on each drum of `--kit standard` and `--kit
full`, one note a second: every note one primary strike of its hand on its drum within 5 ms,
on the rim (zone 1).
"""
import argparse
import csv
import json
import math
import os
import random
import subprocess

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir

TIP_RADIUS_M = 0.007     # the bead (docs/osc.md)
PITCH_MIN_DEG = 8.0      # the default grip's shaft over the head, a floor
ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
work = make_workdir("ictus-rimzone-")
rng = random.Random(24)
spots = [round(rng.uniform(0.3, 0.95), 3) for _ in range(12)]
score = ["tempo 60", "R at 0.93 180"] + ["R at %.3f 180" % x for x in spots]
path = os.path.join(work, "sweep.score")
with open(path, "w") as f:
    f.write("\n".join(score) + "\n")
out = os.path.join(work, "out")
subprocess.run([os.path.join(args.build, "ictusd"), "render", "--score", path, "--out", out],
               check=True, timeout=600, stdout=subprocess.DEVNULL)
drum = json.load(open(os.path.join(out, "render.json")))["drum"]
R, k = drum["radius_m"], drum["contact_stiffness_n_per_m"]
rows = list(csv.DictReader(open(os.path.join(out, "strikes.csv"))))
prim = [r for r in rows if r["bounce"] == "0"]
check(len(prim) == len(score) - 1, "one strike per note: %d" % len(prim))
print("landing r/a, zone:", [(float(r["r_over_a"]), int(r["zone"])) for r in prim])
check(prim[0]["zone"] == "1", "R at 0.93 lands at r/a %s on the rim" % prim[0]["r_over_a"])
heads = 0
for r in prim:
    ra, zone = float(r["r_over_a"]), int(r["zone"])
    gap = R * (1 - ra)               # bead centre to the rim, in plan
    depth = float(r["peak_force_n"]) / k
    if gap <= TIP_RADIUS_M:
        check(zone == 1, "r/a %.3f: the bead reaches the rim: zone %d" % (ra, zone))
    reach = depth / math.tan(math.radians(PITCH_MIN_DEG))
    if gap > reach + TIP_RADIUS_M:
        heads += 1
        check(zone == 0, "r/a %.3f, %.1f mm from the rim (the shaft reaches %.1f mm at most): "
              "zone %d" % (ra, 1e3 * gap, 1e3 * reach, zone))
check(heads >= 6, "%d strikes far enough from the rim to be head" % heads)

# Near the edges of the standard kit.
rng = random.Random(30)
near = ["L on tom1 at 0.95 90"] * 3 + [
    "%s on %s at %.3f %.1f" % (rng.choice("LR"), rng.choice(["snare", "tom1", "tom2", "floor"]),
                               rng.uniform(0.85, 0.95), rng.uniform(45.0, 135.0))
    for _ in range(16)]
path = os.path.join(work, "edges.score")
with open(path, "w") as f:
    f.write("\n".join(["tempo 60"] + near) + "\n")
out = os.path.join(work, "edges")
subprocess.run([os.path.join(args.build, "ictusd"), "render", "--kit", "standard", "--score", path,
                "--out", out, "--bvh-rate", "0"], check=True, timeout=600,
               stdout=subprocess.DEVNULL)
kit = json.load(open(os.path.join(out, "render.json")))["kit"]["drums"]
strikes = {r["seq"]: r for r in csv.DictReader(open(os.path.join(out, "strikes.csv")))}
notes = list(csv.DictReader(open(os.path.join(out, "notes.csv"))))
check(len(notes) == len(near), "%d notes" % len(notes))
for line, n in zip(near, notes):
    hand, _, name = line.split()[:3]
    s = strikes.get(n["strike_seq"])
    found = (s is not None and s["bounce"] == "0" and kit[int(s["drum"])]["name"] == name
             and int(s["hand"]) == (1 if hand == "R" else 0) and abs(float(n["error_ms"])) <= 5.0)
    check(found, "%s: struck on %s, %s ms" % (line, s and kit[int(s["drum"])]["name"],
                                                n["error_ms"] or "no strike"))
    ra, zone = float(s["r_over_a"]), int(s["zone"])
    check(ra <= 1.0, "%s lands at r/a %.4f, on its disk" % (line, ra))
    if line == near[0]:
        check(zone == 1, "%s: on the rim (r/a %.4f, zone %d)" % (line, ra, zone))
    if kit[int(s["drum"])]["radius_m"] * (1.0 - ra) <= TIP_RADIUS_M:
        check(zone == 1, "%s lands at r/a %.4f: the bead reaches the rim: zone %d"
              % (line, ra, zone))

# A drum's rim by name, each hand on each drum of both kits.
for kit_name in ("standard", "full"):
    rims = ["%s on %s-rim" % (hand, drum) for drum in ("snare", "tom1", "tom2", "floor")
            for hand in "LR"]
    path = os.path.join(work, "rims-%s.score" % kit_name)
    with open(path, "w") as f:
        f.write("\n".join(["tempo 60"] + rims) + "\n")
    out = os.path.join(work, "rims-" + kit_name)
    subprocess.run([os.path.join(args.build, "ictusd"), "render", "--kit", kit_name, "--score",
                    path, "--out", out, "--bvh-rate", "0"], check=True, timeout=600,
                   stdout=subprocess.DEVNULL)
    kit = json.load(open(os.path.join(out, "render.json")))["kit"]["drums"]
    strikes = {r["seq"]: r for r in csv.DictReader(open(os.path.join(out, "strikes.csv")))}
    notes = list(csv.DictReader(open(os.path.join(out, "notes.csv"))))
    check(len(notes) == len(rims), "%s: %d notes" % (kit_name, len(notes)))
    for line, n in zip(rims, notes):
        hand, _, name = line.split()
        s = strikes.get(n["strike_seq"])
        check(s is not None and s["bounce"] == "0" and abs(float(n["error_ms"])) <= 5.0
              and kit[int(s["drum"])]["name"] == name[:-len("-rim")]
              and int(s["hand"]) == (1 if hand == "R" else 0) and s["zone"] == "1",
              "--kit %s, %s: %s" % (kit_name, line, s and "on %s at r/a %s, zone %s, %s ms" % (
                  kit[int(s["drum"])]["name"], s["r_over_a"], s["zone"], n["error_ms"])))
