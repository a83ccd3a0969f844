"""Peer of `ictusd track --mode joint`: MuJoCo steps dm_control's CMU humanoid
(suite/humanoid_CMU.xml, 56 hinge DoF) with its root fixed (the free joint
removed, as ictusd anchors the pelvis), a 1 ms step, zero control, for SECONDS
simulated seconds. Runs in the peers' virtual environment (bench/peers/run_peers.sh).

Prints one JSON line: simulated seconds, CPU seconds of the stepping (process
time), wall seconds, and the MuJoCo / dm_control versions.
Usage: peer_mujoco.py [SECONDS]"""
import json
import os
import re
import sys
import time

import importlib.metadata
import importlib.util

import mujoco

seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 20.0
# The model files only: importing dm_control.suite would set up rendering.
suite_dir = os.path.join(os.path.dirname(importlib.util.find_spec("dm_control").origin), "suite")
xml_path = os.path.join(suite_dir, "humanoid_CMU.xml")
with open(xml_path) as f:
    xml = f.read()
# Root fixed: no free joint; 1 ms step.
xml, removed = re.subn(r"<freejoint[^>]*/>", "", xml)
if removed != 1:
    raise SystemExit("peer_mujoco: expected one <freejoint> in %s, found %d" % (xml_path, removed))
assets = {}
common = os.path.join(suite_dir, "common")
for name in os.listdir(common):
    if not name.endswith((".xml", ".png")):
        continue
    with open(os.path.join(common, name), "rb") as f:
        assets["./common/" + name] = f.read()
model = mujoco.MjModel.from_xml_string(xml, assets)
model.opt.timestep = 0.001
data = mujoco.MjData(model)
mujoco.mj_forward(model, data)
steps = int(round(seconds / model.opt.timestep))
mujoco.mj_step(model, data, nstep=100)  # warm up (caches, lazy allocations)
mujoco.mj_resetData(model, data)
t_cpu, t_wall = time.process_time(), time.perf_counter()
mujoco.mj_step(model, data, nstep=steps)
cpu, wall = time.process_time() - t_cpu, time.perf_counter() - t_wall
print(json.dumps({"peer": "mujoco", "dof": int(model.nv), "sim_s": steps * model.opt.timestep,
                  "cpu_s": cpu, "wall_s": wall, "mujoco": mujoco.__version__,
                  "dm_control": importlib.metadata.version("dm_control"),
                  "finite": bool(all(abs(v) < 1e9 for v in data.qpos))}))
