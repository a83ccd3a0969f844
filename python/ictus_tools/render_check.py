"""Render a random score with the real `ictusd render` and check what came out against the notes
the generator (ictus_tools.random_score) says the score holds -- times from its own tempo map,
not from the daemon. Shared by tests/perform/test_random_scores.py and bench/random_scores.py.

The acceptance ("Any valid score plays right", docs/perform.md):
- the render is accepted (exit 0): the generator only writes valid scores;
- notes.csv lists exactly the generator's notes (hand, nuance, grip; time within 10 us);
- every note gets exactly one primary (bounce = 0) strike of its hand within +-TOLERANCE_MS of its
  beat, and there is no other primary strike;
- no NaN or infinity in strikes.csv, notes.csv, render.json;
- bounce rows are tagged consistently: a bounce starts within the bounce window of the previous
  release of its hand and keeps that stroke's number, a primary strike takes the next number; and
  (from tips.csv, independent of the detector) the tip stayed low between a bounce and the
  release before it, and rose between a primary strike and a release less than a window before it;
- if render.json reports joint limits (performance.joint_limits.max_excursion_deg), <= 2 deg.

For the statistics every note is also given its nearest primary strike of its hand (within
ASSIGN_MS and closer to it than to the hand's neighbouring notes): its timing error, contact and
impact speed; primary strikes given to no note are "extra".
"""
import csv
import io
import json
import math
import os
import shutil
import subprocess
import tempfile

from ictus_tools.random_score import LEAD_IN_S, LIMB_ORDER, RandomScore

TOLERANCE_MS = 5.0            # the acceptance bound, never loosened
FOOT_TOLERANCE_MS = 0.5       # a kick's: the pedal's planning tolerance (docs/pedal.md)
LIMB_OF_HAND = {0: "left", 1: "right", 2: "right-foot", 3: "left-foot"}  # strikes.csv's hand
FEET = ("right-foot", "left-foot")
ASSIGN_MS = 50.0              # a strike further than this from a note is not its strike
PLAN_TIME_TOL_S = 1e-5        # notes.csv has 6 decimals
MAX_LIMIT_EXCURSION_DEG = 2.0
BOUNCE_WINDOW_S = 0.15        # ictusd's --bounce-window default (docs/osc.md)
BOUNCE_HEIGHT_M = 0.01        # --bounce-height default
DRIVEN_SPEED_MPS = 0.1        # the detector's driven_speed_mps (docs/osc.md)
DRIVE_WINDOW_S = 0.02         # and its drive_window_s
DRIVEN_SLOP_MPS = 0.3         # tips.csv's 4 ms samples against the detector's 1 ms step
# Tip (the stick's end point) above the membrane when the bead touches it: r_tip (1 + d_y),
# 5.2 mm for a 7 mm bead on a stick 15 deg down (docs/perform.md), 3.5..7 mm over 0..30 deg.
TIP_OVER_BEAD_M = 0.0052
TIP_SLOP_M = 0.003


def _floats(text, where):
    """Every cell of a CSV that should be a number, checked finite."""
    bad = []
    rows = list(csv.DictReader(io.StringIO(text)))
    for n, row in enumerate(rows, start=2):
        for k, v in row.items():
            if v is None or v == "":
                continue
            try:
                x = float(v)
            except ValueError:
                continue
            if not math.isfinite(x):
                bad.append("%s:%d: %s = %s" % (where, n, k, v))
    return rows, bad


def _json_nonfinite(obj, path, out):
    if isinstance(obj, dict):
        for k, v in obj.items():
            _json_nonfinite(v, path + "." + k, out)
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            _json_nonfinite(v, "%s[%d]" % (path, i), out)
    elif isinstance(obj, float) and not math.isfinite(obj):
        out.append("render.json%s = %r" % (path, obj))


def _find_keys(obj, pred, path=""):
    """(path, value) of every key in a JSON tree for which pred(key) holds."""
    found = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            p = path + "." + k
            if pred(k):
                found.append((p, v))
            found.extend(_find_keys(v, pred, p))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            found.extend(_find_keys(v, pred, "%s[%d]" % (path, i)))
    return found


class Result:
    """What one render gave: `ok`, `problems` (strings), per-note records, strike records."""

    def __init__(self, score):
        self.seed = score.seed
        self.score = score
        self.problems = []
        self.notes = []        # one dict per expected note: the note, its strike, its status
        self.extra = []        # primary strikes given to no note
        self.strikes = []
        self.bounces = 0
        self.refused = None    # the daemon's message if it refused the score
        self.crashed = None
        self.joint_limits_deg = None
        self.trunk = []
        self.render_s = 0.0
        self.simulated_s = 0.0

    @property
    def ok(self):
        return not self.problems

    def failing_notes(self):
        return [n for n in self.notes if n["status"] != "ok"]

    def report(self, ictusd="ictusd"):
        """Everything needed to reproduce and see a failure."""
        out = ["seed %d: %s" % (self.seed, "; ".join(self.problems[:6]) +
                                (" ..." if len(self.problems) > 6 else ""))]
        kit = " --kit " + self.score.kit if getattr(self.score, "kit", None) else ""
        out.append("  reproduce: PYTHONPATH=python python3 -m ictus_tools.random_score --seed %d --ictusd %s%s "
                   "> s.txt && %s render%s --score s.txt --out out-%d"
                   % (self.seed, ictusd, kit, ictusd, kit, self.seed))
        out.append("  score:")
        out.extend("    | " + line for line in self.score.text.rstrip("\n").split("\n"))
        for n in self.failing_notes():
            out.append("  note %d (line %d) %s%s %s %s dyn %.2f beats %.4f tempo %.1f at plan t=%.6f s:"
                       " %s" % (n["index"], n["line"], n["hand"],
                                " on " + n["drum"] if "drum" in n else "", n["nuance"], n["grip"],
                                n["dynamics"], n["beats"], n["tempo_bpm"], n["plan_time_s"],
                                n["why"]))
        for s in self.extra:
            out.append("  extra primary strike seq %d hand %s at %.6f s (%.1f ms from its hand's "
                       "nearest note), %.2f m/s, contact %.1f ms"
                       % (s["seq"], s["hand"], s["time_s"], s["nearest_ms"],
                          s["normal_velocity_mps"], s["duration_ms"]))
        return "\n".join(out)


def render(ictusd, score, workdir, timeout_s=600, extra_args=()):
    """Render `score` (a RandomScore) in workdir/seed-N and check it. Returns a Result."""
    import time
    res = Result(score)
    d = os.path.join(workdir, "seed-%d" % score.seed)
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, "score.txt")
    score.write(path)
    out = os.path.join(d, "out")
    if os.path.exists(out):
        shutil.rmtree(out)
    cmd = [ictusd, "render", "--score", path, "--out", out, "--bvh-rate", "0"] + list(extra_args)
    if getattr(score, "kit", None):
        cmd += ["--kit", score.kit]
    t0 = time.monotonic()
    try:
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=timeout_s)
    except subprocess.TimeoutExpired:
        res.crashed = "timed out after %g s" % timeout_s
        res.problems.append("ictusd render " + res.crashed)
        return res
    res.render_s = time.monotonic() - t0
    if proc.stderr.strip():  # a sanitizer's report, a warning: kept beside the render
        with open(os.path.join(d, "stderr.txt"), "w") as f:
            f.write(proc.stderr)
    if proc.returncode != 0:
        msg = (proc.stderr.strip() or proc.stdout.strip()).split("\n")
        if proc.returncode == 1 and any(path + ":" in l for l in msg):
            res.refused = msg[-1]
            res.problems.append("ictusd refused the score: " + msg[-1])
        else:
            res.crashed = "exit %d: %s" % (proc.returncode, "\n".join(msg[-20:]))
            res.problems.append("ictusd render failed, " + res.crashed)
        return res
    judge(res, out)
    return res


def judge(res, out):
    """Judges the render in `out` against res.score (the acceptance above): fills res.notes,
    res.extra and res.problems."""
    score = res.score
    with open(os.path.join(out, "render.json")) as f:
        text = f.read()
    nonfinite = []
    j = json.loads(text, parse_constant=lambda c: float(c))
    _json_nonfinite(j, "", nonfinite)
    res.problems.extend(nonfinite)
    perf = j.get("performance", {})
    res.simulated_s = j.get("duration_s", 0.0)
    lead_in = perf.get("plan", {}).get("lead_in_s", LEAD_IN_S)
    origin = perf.get("plan", {}).get("origin_s", 0.0)
    per_note_json = perf.get("per_note", [])
    # Each piece's striking plane (its head; a cymbal's top face): tip heights are taken
    # over the plane of the strike's piece.
    drums = j.get("kit", {}).get("drums") or [j["drum"]]
    names = [d.get("name", "drum") for d in drums]
    planes = [d["center_m"][1] + (d.get("shell_depth_m", 0.0) / 2 if d.get("bending_n_m") else 0.0)
              for d in drums]

    for p, v in _find_keys(j, lambda k: k == "max_excursion_deg"):
        res.joint_limits_deg = v if res.joint_limits_deg is None else max(res.joint_limits_deg, v)
        if isinstance(v, (int, float)) and v > MAX_LIMIT_EXCURSION_DEG:
            res.problems.append("joint limit excursion %s = %.2f deg > %.1f" % (p, v, MAX_LIMIT_EXCURSION_DEG))
    res.trunk = []  # numbers under any key naming the trunk: (path, value)
    for p, v in _find_keys(j, lambda k: "trunk" in k.lower()):
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            res.trunk.append((p, v))
        elif isinstance(v, dict):
            res.trunk.extend((p + q, w) for q, w in _find_keys(v, lambda k: True)
                             if isinstance(w, (int, float)) and not isinstance(w, bool))

    with open(os.path.join(out, "notes.csv")) as f:
        note_rows, bad = _floats(f.read(), "notes.csv")
    res.problems.extend(bad)
    with open(os.path.join(out, "strikes.csv")) as f:
        strike_rows, bad = _floats(f.read(), "strikes.csv")
    res.problems.extend(bad)
    tips = None
    tips_path = os.path.join(out, "tips.csv")
    if os.path.exists(tips_path):
        with open(tips_path) as f:
            tip_rows, bad = _floats(f.read(), "tips.csv")
        res.problems.extend(bad)
        if tip_rows:
            tips = {"t": [float(r["time_s"]) for r in tip_rows],
                    "left": [float(r["left_sim_y_m"]) for r in tip_rows],
                    "right": [float(r["right_sim_y_m"]) for r in tip_rows]}
            # Where the hand held the stick (the sticks on their fulcrum): the bounce rule
            # also counts a re-contact the hand did not lift the stick 1 cm for (docs/osc.md).
            if "left_held_y_m" in tip_rows[0]:
                tips["held"] = {h: [float(r[h + "_held_y_m"]) for r in tip_rows]
                                for h in ("left", "right")}

    # The plan holds the generator's notes.
    expected = score.notes
    rows = sorted(note_rows, key=lambda r: (float(r["time_s"]), LIMB_ORDER.get(r["hand"], 4)))
    if len(rows) != len(expected):
        res.problems.append("notes.csv has %d notes, the score %d" % (len(rows), len(expected)))
    for e, r in zip(expected, rows):
        t = origin + lead_in + e["time_s"]
        if (r["hand"] != e["hand"] or r["nuance"] != e["nuance"] or r["grip"] != e["grip"]
                or r.get("drum") != e.get("drum", r.get("drum"))
                or abs(float(r["time_s"]) - t) > PLAN_TIME_TOL_S):
            res.problems.append("notes.csv row %s (%s %s %s %s at %s s) is not the score's note "
                                "(%s %s %s %s at %.6f s)" % (
                                    r["index"], r["hand"], r["nuance"], r["grip"],
                                    r.get("drum", ""), r["time_s"], e["hand"], e["nuance"],
                                    e["grip"], e.get("drum", ""), t))
            break
    per_note_by_index = {i: pn for i, pn in enumerate(per_note_json)}
    rows_by_hand = {}
    for r in note_rows:
        rows_by_hand.setdefault(r["hand"], []).append((float(r["time_s"]), int(r["index"])))

    def row_index(hand, t):
        near = [i for tt, i in rows_by_hand.get(hand, []) if abs(tt - t) <= PLAN_TIME_TOL_S]
        return near[0] if near else -1

    # Strikes.
    strikes = []
    for r in strike_rows:
        s = {"seq": int(r["seq"]), "hand": LIMB_OF_HAND[int(r["hand"])],
             "drum": names[int(r.get("drum") or 0)], "plane_y": planes[int(r.get("drum") or 0)],
             "bounce": int(r["bounce"]), "stroke": int(r["stroke"]), "time_s": float(r["time_s"]),
             "duration_ms": float(r["duration_ms"]),
             "normal_velocity_mps": float(r["normal_velocity_mps"]),
             "peak_force_n": float(r["peak_force_n"])}
        strikes.append(s)
    res.strikes = strikes
    res.bounces = sum(s["bounce"] for s in strikes)
    check_bounce_tags(res, strikes, tips)
    if getattr(score, "kit", None):
        late = [(a, b) for a, b in zip(strikes, strikes[1:]) if b["time_s"] < a["time_s"]]
        if late:
            res.problems.append("strikes.csv is not in onset order: seq %d at %.6f s after seq "
                                "%d at %.6f s" % (late[0][1]["seq"], late[0][1]["time_s"],
                                                  late[0][0]["seq"], late[0][0]["time_s"]))

    # Notes and their strikes, per limb (on a kit, the strikes on the note's piece).
    for hand in ("right", "left") + FEET:
        notes = [n for n in expected if n["hand"] == hand]
        tolerance_ms = FOOT_TOLERANCE_MS if hand in FEET else TOLERANCE_MS
        prim = [s for s in strikes if s["hand"] == hand and s["bounce"] == 0]
        taken = set()
        for k, n in enumerate(notes):
            t = origin + lead_in + n["time_s"]
            lo = t - ASSIGN_MS / 1000.0
            hi = t + ASSIGN_MS / 1000.0
            if k > 0:
                lo = max(lo, (t + origin + lead_in + notes[k - 1]["time_s"]) / 2)
            if k + 1 < len(notes):
                hi = min(hi, (t + origin + lead_in + notes[k + 1]["time_s"]) / 2)
            mine = [s for s in prim if s["drum"] == n.get("drum", s["drum"])]
            near = [s for s in mine if lo <= s["time_s"] < hi]
            within = [s for s in mine if abs(s["time_s"] - t) <= tolerance_ms / 1000.0]
            rec = dict(n)
            rec["plan_time_s"] = t
            rec["index"] = row_index(hand, t)
            pn = per_note_by_index.get(rec["index"], {})
            rec["planned_impact_speed_mps"] = pn.get("planned_impact_speed_mps")
            best = min(near, key=lambda s: abs(s["time_s"] - t)) if near else None
            rec["strike"] = best
            rec["error_ms"] = (best["time_s"] - t) * 1000.0 if best else None
            if best:
                taken.add(best["seq"])
            if len(within) == 1:
                rec["status"], rec["why"] = "ok", ""
            elif len(within) > 1:
                rec["status"] = "double"
                rec["why"] = "%d primary strikes within %g ms (%s ms)" % (
                    len(within), tolerance_ms,
                    ", ".join("%+.2f" % ((s["time_s"] - t) * 1000) for s in within))
            elif best:
                rec["status"] = "off-time"
                rec["why"] = "nearest primary strike on it %+.2f ms from the beat (%.2f m/s, contact %.1f ms)" % (
                    rec["error_ms"], best["normal_velocity_mps"], best["duration_ms"])
            else:
                rec["status"] = "missed"
                rec["why"] = "no primary strike of its limb%s within %g ms" % (
                    " on " + n["drum"] if "drum" in n else "", ASSIGN_MS)
            res.notes.append(rec)
        for s in prim:
            if s["seq"] in taken:
                continue
            d = [abs(s["time_s"] - (origin + lead_in + n["time_s"])) * 1000 for n in notes]
            s = dict(s, nearest_ms=min(d) if d else float("inf"))
            if notes:
                s["nearest_note"] = notes[d.index(min(d))]
            res.extra.append(s)
        # A strike assigned (nearest) but off-time is also an extra primary for the acceptance.
    res.notes.sort(key=lambda n: (n["plan_time_s"], n["hand"] != "right"))
    bad_notes = res.failing_notes()
    if bad_notes:
        kinds = {}
        for n in bad_notes:
            kinds[n["status"]] = kinds.get(n["status"], 0) + 1
        res.problems.append("%d of %d notes not played right (%s)" % (
            len(bad_notes), len(res.notes), ", ".join("%d %s" % (v, k) for k, v in sorted(kinds.items()))))
    if res.extra:
        res.problems.append("%d extra primary strike(s)" % len(res.extra))


def _held_max(tips, hand, t0, t1):
    """Highest held-tip height (tips.csv *_held_y_m) over (t0, t1), or None."""
    if not tips or "held" not in tips:
        return None
    return _tip_max({"t": tips["t"], hand: tips["held"][hand]}, hand, t0, t1)


def _held_down_speeds(tips, hand, t, above_m):
    """The held tip's speeds toward the membrane (m/s) over the tips.csv sample intervals
    that overlap the drive window before t (tips.csv *_held_y_m) and start with the held tip
    higher than above_m over the membrane (the held bead above it: a stick pressed into the
    head is not driven), or None when there is no held tip; 0 when no interval counts."""
    if not tips or "held" not in tips:
        return None
    ts, ys = tips["t"], tips["held"][hand]
    out = [-(ys[k] - ys[k - 1]) / (ts[k] - ts[k - 1]) for k in range(1, len(ts))
           if ts[k] > t - DRIVE_WINDOW_S and ts[k - 1] <= t and ys[k - 1] > above_m]
    return out or [0.0]


def _tip_max(tips, hand, t0, t1):
    """Highest sampled tip (above the membrane) strictly between t0 and t1, or None."""
    ts = tips["t"]
    vals = [tips[hand][i] for i in range(len(ts)) if t0 < ts[i] < t1]
    return max(vals) if vals else None


def _over_plane(tips, hand, plane_y):
    """A hand's tips (and held tips) as heights over a piece's plane; None for a foot's."""
    if not tips or hand not in tips:
        return None
    out = {"t": tips["t"], hand: [y - plane_y for y in tips[hand]]}
    if "held" in tips:
        out["held"] = {hand: [y - plane_y for y in tips["held"][hand]]}
    return out


def check_bounce_tags(res, strikes, all_tips):
    last = {}   # hand -> previous strike of that hand
    for s in strikes:
        prev = last.get(s["hand"])
        tips = _over_plane(all_tips, s["hand"], s["plane_y"])
        if s["bounce"]:
            if prev is None:
                res.problems.append("strike seq %d is tagged a bounce but is its hand's first" % s["seq"])
            else:
                release = prev["time_s"] + prev["duration_ms"] / 1000.0
                if s["time_s"] - release > BOUNCE_WINDOW_S + 1e-6:
                    res.problems.append("bounce seq %d starts %.1f ms after its hand's release "
                                        "(window %g ms)" % (s["seq"], (s["time_s"] - release) * 1000,
                                                            BOUNCE_WINDOW_S * 1000))
                if s["stroke"] != prev["stroke"]:
                    res.problems.append("bounce seq %d has stroke %d, its stroke is %d"
                                        % (s["seq"], s["stroke"], prev["stroke"]))
                if tips:
                    high = _tip_max(tips, s["hand"], release, s["time_s"])
                    limit = BOUNCE_HEIGHT_M + TIP_OVER_BEAD_M + TIP_SLOP_M
                    held = _held_max(tips, s["hand"], release, s["time_s"])
                    if held is not None and held <= limit:
                        high = None  # the hand kept the stick down: a bounce either way
                    drive = _held_down_speeds(tips, s["hand"], s["time_s"],
                                              TIP_OVER_BEAD_M + TIP_SLOP_M)
                    if drive is not None and max(drive) < DRIVEN_SPEED_MPS + DRIVEN_SLOP_MPS:
                        high = None  # the hand was not driving it down: the stick fell back
                    if high is not None and high > limit:
                        res.problems.append("bounce seq %d: the tip rose %.1f mm above the head "
                                            "since the release (a bounce rises < %.0f mm)"
                                            % (s["seq"], high * 1000, BOUNCE_HEIGHT_M * 1000))
        else:
            want = prev["stroke"] + 1 if prev else 0
            if s["stroke"] != want:
                res.problems.append("primary seq %d has stroke %d, expected %d"
                                    % (s["seq"], s["stroke"], want))
            if prev is not None and tips:
                release = prev["time_s"] + prev["duration_ms"] / 1000.0
                if s["time_s"] - release < BOUNCE_WINDOW_S - 1e-3:
                    high = _tip_max(tips, s["hand"], release, s["time_s"])
                    limit = BOUNCE_HEIGHT_M + TIP_OVER_BEAD_M - TIP_SLOP_M
                    held = _held_max(tips, s["hand"], release, s["time_s"])
                    if held is not None and high is not None:
                        high = min(high, held)  # a primary: the tip and the hand both rose
                    drive = _held_down_speeds(tips, s["hand"], s["time_s"],
                                              TIP_OVER_BEAD_M - TIP_SLOP_M)
                    if drive is not None and max(drive) < DRIVEN_SPEED_MPS - DRIVEN_SLOP_MPS:
                        res.problems.append("primary seq %d: the hand was not driving the stick "
                                            "down (held tip %.2f m/s toward the head) %.1f ms "
                                            "after the release: an untagged bounce"
                                            % (s["seq"], max(drive),
                                               (s["time_s"] - release) * 1000))
                    if high is not None and high < limit:
                        res.problems.append("primary seq %d: the tip rose only %.1f mm above the "
                                            "head since the release %.1f ms before: an untagged "
                                            "bounce" % (s["seq"], high * 1000,
                                                        (s["time_s"] - release) * 1000))
        last[s["hand"]] = s


def seed_arguments(ap, count, seeds_note):
    """The random-score tests' common options: --ictusd, the seeds (--first, --count or
    --seeds; `seeds_note` says what --seeds skips), --jobs, --workdir, --keep."""
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--first", type=int, default=1, help="first seed (default 1)")
    ap.add_argument("--count", type=int, default=count, help="number of seeds (default %d)" % count)
    ap.add_argument("--seeds", help="these seeds (comma-separated) instead of --first/--count; "
                    + seeds_note)
    ap.add_argument("--jobs", type=int, default=0, help="parallel renders (default: the cores)")
    ap.add_argument("--workdir", help="folder for the renders (emptied first)")
    ap.add_argument("--keep", action="store_true", help="keep every render, not only failures")


def seeds_of(args):
    if args.seeds:
        return [int(x) for x in args.seeds.split(",") if x.strip()]
    return list(range(args.first, args.first + args.count))


def empty_workdir(path, prefix):
    """`path` (else a new temporary folder) emptied and made."""
    workdir = path or tempfile.mkdtemp(prefix=prefix)
    if os.path.isdir(workdir):
        shutil.rmtree(workdir)
    os.makedirs(workdir)
    return workdir


def progress_printer(t0):
    """One line per score as it comes (a timeout still shows the rest): run_many's progress."""
    import time

    def progress(i, n, r):
        print("[%d/%d %.0f s] seed %d: %s" % (i, n, time.monotonic() - t0, r.seed,
                                                "ok" if r.ok else "; ".join(r.problems)), flush=True)
    return progress


def run_many(ictusd, seeds, workdir=None, jobs=None, nuances=None, keep=False, extra_args=(),
             progress=None, kit=None):
    """Render every seed in parallel (threads, each waiting on its own ictusd); results in
    seed order. `kit`: scores over that kit (random_score's kit mode)."""
    from concurrent.futures import ThreadPoolExecutor
    jobs = jobs or os.cpu_count() or 2
    own = workdir is None
    workdir = workdir or tempfile.mkdtemp(prefix="ictus-random-scores-")
    scores = [RandomScore(s, nuances, kit=kit) for s in seeds]
    results = []
    try:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            for i, r in enumerate(pool.map(lambda sc: _render_clean(ictusd, sc, workdir, keep,
                                                                      extra_args), scores)):
                results.append(r)
                if progress:
                    progress(i + 1, len(scores), r)
    finally:
        if own and not keep:
            shutil.rmtree(workdir, ignore_errors=True)
    return results, workdir


def _render_clean(ictusd, score, workdir, keep, extra_args):
    r = render(ictusd, score, workdir, extra_args=extra_args)
    if not keep and r.ok:
        shutil.rmtree(os.path.join(workdir, "seed-%d" % score.seed), ignore_errors=True)
    return r


def planted_faults(score, out):
    """Plant one fault at a time in copies of a render that passed (`out`) and check that
    `check` finds each (a problem naming it): returns [(fault, found, problems)]. So the test
    shows it can fail."""
    with open(os.path.join(out, "strikes.csv")) as f:
        lines = f.read().rstrip("\n").split("\n")
    header = lines[0].split(",")
    col = {name: i for i, name in enumerate(header)}
    rows = [l.split(",") for l in lines[1:]]
    primaries = [i for i, r in enumerate(rows) if r[col["bounce"]] == "0"]
    if len(primaries) < 2:
        raise ValueError("planted_faults needs a render with two primary strikes")
    first = primaries[0]
    # The second primary strike of the first one's hand (its stroke number is then wrong).
    hand = rows[first][col["hand"]]
    second = next(i for i in primaries[1:] if rows[i][col["hand"]] == hand)

    def moved(r, dt):
        r = list(r)
        r[col["time_s"]] = "%.6f" % (float(r[col["time_s"]]) + dt)
        return r

    last_same = max(i for i in primaries if rows[i][col["hand"]] == hand)
    extra = moved(rows[last_same], 0.4)
    extra[col["stroke"]] = str(int(rows[last_same][col["stroke"]]) + 1)
    extra[col["seq"]] = str(len(rows))
    faults = [
        ("a note's strike removed", "missed", [r for i, r in enumerate(rows) if i != first]),
        ("a strike 6 ms late", "off-time", [moved(r, 0.006) if i == first else r for i, r in enumerate(rows)]),
        ("a NaN velocity", "= nan", [r[:col["normal_velocity_mps"]] + ["nan"] + r[col["normal_velocity_mps"] + 1:]
                            if i == first else r for i, r in enumerate(rows)]),
        ("a primary strike tagged a bounce", "bounce seq", [r[:col["bounce"]] + ["1"] + r[col["bounce"] + 1:]
                                              if i == second else r for i, r in enumerate(rows)]),
        ("an extra primary strike 0.4 s after the hand's last", "extra primary", rows + [extra]),
    ]
    found = []
    for k, (name, sign, mutated) in enumerate(faults):
        d = out + "-planted-%d" % k
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(out, d)
        with open(os.path.join(d, "strikes.csv"), "w") as f:
            f.write("\n".join([lines[0]] + [",".join(r) for r in mutated]) + "\n")
        res = Result(score)
        judge(res, d)
        found.append((name, any(sign in p for p in res.problems), res.problems))
        shutil.rmtree(d, ignore_errors=True)
    # A joint beyond its limit, as render.json reports it.
    d = out + "-planted-limits"
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(out, d)
    with open(os.path.join(d, "render.json")) as f:
        j = json.load(f)
    j.setdefault("performance", {})["joint_limits"] = {"max_excursion_deg": 2.5}
    with open(os.path.join(d, "render.json"), "w") as f:
        json.dump(j, f)
    res = Result(score)
    judge(res, d)
    found.append(("a joint 2.5 deg beyond its limit", any("joint limit" in p for p in res.problems),
                  res.problems))
    shutil.rmtree(d, ignore_errors=True)
    return found
