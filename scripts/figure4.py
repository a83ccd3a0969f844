#!/usr/bin/python3
"""Plots the paper's Figure 4 from two `ictusd track` runs (joint, cartesian).

usage: figure4.py OUT_DIR   (OUT_DIR/joint and OUT_DIR/cartesian hold track.csv
and summary.json). Top: right elbow flexion (the angle between upper arm and
forearm), raw capture vs the IK targets Theta^T of the Cartesian mode. Bottom:
right stick-tip height, raw capture vs joint-space vs Cartesian tracking (the
cleaned capture, which both modes track, dotted). Writes OUT_DIR/figure4.png,
.svg and figure4.md (with the options of both runs).
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    header = rows[0]
    data = np.array(rows[1:], dtype=float)
    return {name: data[:, i] for i, name in enumerate(header)}


def tip_error_mm(run, side):
    return 1e3 * np.sqrt(sum((run[f"tip_{side}_ref_{a}_m"] - run[f"tip_{side}_sim_{a}_m"]) ** 2
                             for a in "xyz"))


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    joint, cart = load(f"{out}/joint/track.csv"), load(f"{out}/cartesian/track.csv")
    sj = json.load(open(f"{out}/joint/summary.json"))
    sc = json.load(open(f"{out}/cartesian/summary.json"))
    t = cart["time_s"]

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    top.plot(t, cart["r_elbow_flexion_raw_deg"], "k", lw=1.2, label="motion capture (raw)")
    top.plot(t, cart["r_elbow_flexion_target_deg"], "r", lw=0.9, label="IK (Θ^T)")
    top.set_ylabel("right elbow flexion (deg)")
    top.legend(loc="upper right")
    top.set_title("Figure 4: joint-space (ID) vs Cartesian (IK + ID) tracking, same PD gains")
    bottom.plot(t, cart["tip_right_raw_y_m"], "k", lw=1.2, label="motion capture (raw)")
    bottom.plot(t, cart["tip_right_ref_y_m"], "k:", lw=0.8, label="cleaned capture")
    bottom.plot(joint["time_s"], joint["tip_right_sim_y_m"], "b", lw=0.9,
                label="joint space (ID)")
    bottom.plot(t, cart["tip_right_sim_y_m"], "r", lw=0.9, label="Cartesian (IK + ID)")
    bottom.set_ylabel("right stick tip height (m)")
    bottom.set_xlabel("time (s)")
    bottom.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(f"{out}/figure4.png", dpi=120)
    fig.savefig(f"{out}/figure4.svg")

    ramp = 0.25  # errors are counted after the start-up blend, as in the summaries
    mj, mc = joint["time_s"] >= ramp, t >= ramp
    lines = ["| quantity | joint space (ID) | Cartesian (IK + ID) |", "|---|---|---|"]
    for side in ("left", "right"):
        for key, what in (("tip_rms_mm", "vs cleaned capture"), ("tip_rms_raw_mm", "vs raw capture"),
                          ("tip_rms_free_mm", "vs cleaned, free flight"),
                          ("tip_rms_contact_mm", "vs cleaned, contact windows"),
                          ("tip_rms_raw_free_mm", "vs raw, free flight"),
                          ("tip_rms_raw_contact_mm", "vs raw, contact windows")):
            lines.append(f"| {side} tip RMS {what} (mm) | {sj[key][side]:.2f} "
                         f"| {sc[key][side]:.2f} |")
        lines.append(f"| {side} tip max error (mm) | {sj['tip_max_mm'][side]:.1f} "
                     f"| {sc['tip_max_mm'][side]:.1f} |")
    ey = {name: rms(1e3 * (run["tip_right_ref_y_m"] - run["tip_right_sim_y_m"])[m])
          for name, run, m in (("joint", joint, mj), ("cart", cart, mc))}
    lines.append(f"| right tip height RMS (mm) | {ey['joint']:.2f} | {ey['cart']:.2f} |")
    for side, s in (("left", "l"), ("right", "r")):
        ikraw = rms((cart[f"{s}_elbow_flexion_target_deg"]
                     - cart[f"{s}_elbow_flexion_raw_deg"])[mc])
        lines.append(f"| {side} elbow flexion RMS, IK target vs raw capture (deg) | – "
                     f"| {ikraw:.2f} |")
        ik = rms((cart[f"{s}_elbow_flexion_target_deg"] - cart[f"{s}_elbow_flexion_ref_deg"])[mc])
        simj = rms((joint[f"{s}_elbow_flexion_sim_deg"] - joint[f"{s}_elbow_flexion_ref_deg"])[mj])
        simc = rms((cart[f"{s}_elbow_flexion_sim_deg"] - cart[f"{s}_elbow_flexion_ref_deg"])[mc])
        lines.append(f"| {side} elbow flexion RMS, IK target vs cleaned capture (deg) | – "
                     f"| {ik:.2f} |")
        lines.append(f"| {side} elbow flexion RMS, simulated vs cleaned capture (deg) | {simj:.2f} "
                     f"| {simc:.2f} |")
    lines.append(f"| all joints RMS (deg) | {sj['joint_rms_deg_all']:.2f} "
                 f"| {sc['joint_rms_deg_all']:.2f} |")
    lines.append(f"| real-time factor | {sj['realtime_factor']:.1f} "
                 f"| {sc['realtime_factor']:.1f} |")
    lines.append(f"| IK µs per step (both arms) | – | {sc['ik']['us_per_step']:.1f} |")
    lines.append(f"| IK iterations per solve, mean / max | – | "
                 f"{sc['ik']['mean_iterations']:.2f} / {sc['ik']['max_iterations']} |")
    table = "\n".join(lines) + "\n"
    with open(f"{out}/figure4.md", "w") as f:
        ik = sc["ik"]
        f.write(f"Motion: {sc['mocap']}. Options of both runs: "
                f"{os.environ.get('FIGURE4_OPTS') or 'the defaults'}. Gains {sc['gain_hz']} Hz, "
                f"damping ratio {sc['damping_ratio']} (both modes); limits {sc['limits']} "
                f"(k = {sc['limit_k']}); reference de-spiked at {sc['despike_deg']:.1f} deg and "
                f"low-passed at {sc['smooth_hz']} Hz ({sc.get('smooth_kernel', 'gaussian')}), tips at "
                f"{sc['tip_smooth_hz']} Hz; drum "
                f"{'auto (' + sc.get('drum_rule', 'turnarounds') + ')' if sc['drum_auto'] else 'given'} at "
                f"{', '.join(f'{x:.3f}' for x in sc['drum_center_m'])} m. Cartesian: eq. 2 gain "
                f"{ik['gain']}, velocity term {ik['velocity_gain_s']} s, correction limit "
                f"{ik['correction_limit_m']} m, IK start {ik['start']}, posture weight "
                f"{ik['posture_weight']}. Contact windows: ±30 ms about each captured impact "
                f"(stroke turnaround), {sc['captured_impacts']['left']} left and "
                f"{sc['captured_impacts']['right']} right.\n\n")
        f.write(table)
    print(table, end="")
    print(f"wrote {out}/figure4.png, {out}/figure4.svg, {out}/figure4.md")


if __name__ == "__main__":
    main()
