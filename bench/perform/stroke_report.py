#!/usr/bin/env python3
"""Stroke report of an `ictusd render` (score mode, --tips-rate 1000): per nuance the
impact speed planned and measured, the contact time and the restitution (the stick
tip's speed away from the head just after the release over its speed into it), and
the body's limit excursion and trunk amplitude. Prints a markdown table
(docs/perform.md). Usage: stroke_report.py RENDER_DIR [RENDER_DIR ...]"""
import csv
import json
import statistics as st
import sys


def report(d):
    perf = json.load(open(d + "/render.json"))["performance"]
    strikes = {int(r["seq"]): r for r in csv.DictReader(open(d + "/strikes.csv"))}
    tips = list(csv.DictReader(open(d + "/tips.csv")))
    t = [float(r["time_s"]) for r in tips]
    rate = 1.0 / (t[1] - t[0])
    if rate < 900:
        sys.exit("%s: tips.csv at %.0f Hz; render with --tips-rate 1000" % (d, rate))
    rows = {}
    for n in perf["per_note"]:
        if n.get("strike_seq") is None:
            continue
        s = strikes[int(n["strike_seq"])]
        hand = "left" if s["hand"] == "0" else "right"
        release = float(s["time_s"]) + float(s["duration_ms"]) / 1e3
        k = min(range(len(t)), key=lambda i: abs(t[i] - release))
        y = [float(tips[i]["%s_sim_y_m" % hand]) for i in range(k, min(k + 4, len(t)))]
        v_out = max((y[i + 1] - y[i]) * rate for i in range(len(y) - 1))
        v_in = float(s["normal_velocity_mps"])
        rows.setdefault(n["nuance"], []).append(
            (n["planned_impact_speed_mps"], v_in, float(s["duration_ms"]), max(0.0, v_out) / v_in))
    print("| nuance | notes | planned impact (m/s) | measured (m/s) | measured / planned | "
          "contact median (ms) | restitution median |")
    print("|---|---|---|---|---|---|---|")
    for nuance, v in sorted(rows.items(), key=lambda kv: st.mean(x[1] for x in kv[1])):
        print("| %s | %d | %.2f | %.2f | %.2f-%.2f | %.1f | %.2f |" % (
            nuance, len(v), st.mean(x[0] for x in v), st.mean(x[1] for x in v),
            min(x[1] / x[0] for x in v), max(x[1] / x[0] for x in v),
            st.median(x[2] for x in v), st.median(x[3] for x in v)))
    print("\njoint limits: %s; trunk: %s" % (perf.get("joint_limits"), perf.get("trunk")))


if __name__ == "__main__":
    for d in sys.argv[1:]:
        print("\n%s\n" % d)
        report(d)
