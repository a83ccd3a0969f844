"""One corpus item: render it into a temporary folder beside its final one, write labels.json,
checksum every file, and move the folder into place whole (docs/corpus.md, "Resume")."""
import csv
import hashlib
import json
import os
import shutil
import subprocess

SAMPLE_RATE = 48000
WAV_BITS = 24
LABELS = "labels.json"
CHECKSUMS = "checksums.json"   # written last, inside the temporary folder
BASE_FILES = ["score.txt", "performance.wav", "performance.mid", "strikes.csv", "notes.csv",
              "events.txt", "render.json", LABELS]
HANDS = {0: "left", 1: "right"}
ZONES = {0: "head", 1: "rim"}


def item_name(index):
    return "item-%06d" % index


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def expected_files(bvh):
    return BASE_FILES + (["performance.bvh"] if bvh else [])


def is_done(folder, bvh):
    """Done: the final folder holds checksums.json and every file it names, each matching."""
    try:
        with open(os.path.join(folder, CHECKSUMS)) as f:
            sums = json.load(f)
    except (OSError, ValueError):
        return None
    if not set(expected_files(bvh)) <= set(sums):
        return None
    for name, digest in sums.items():
        p = os.path.join(folder, name)
        if not os.path.isfile(p) or sha256(p) != digest:
            return None
    return sums


def _read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _num(v):
    try:
        x = float(v)
    except (TypeError, ValueError):
        return v
    return int(x) if x.is_integer() and "." not in str(v) else x


def labels(params, folder):
    """labels.json: the item's parameters and, per strike (strikes.csv joined with notes.csv by
    the strike's seq), its sample, time, hand, drum, zone, nuance, dynamics, impact speed,
    force, contact time, position and whether it is a bounce."""
    strikes = _read_csv(os.path.join(folder, "strikes.csv"))
    notes = _read_csv(os.path.join(folder, "notes.csv"))
    by_seq = {}
    for n in notes:
        seq = n.get("strike_seq", n.get("seq", ""))
        if seq not in ("", "-1", None):
            by_seq[str(int(float(seq)))] = n
    onsets = []
    for s in strikes:
        t = float(s["time_s"])
        n = by_seq.get(str(int(s["seq"])))
        onsets.append({
            "seq": int(s["seq"]),
            "sample": int(t * SAMPLE_RATE + 0.5),
            "time_s": t,
            "hand": HANDS.get(int(s["hand"]), s["hand"]),
            "drum": int(s["drum"]),
            "zone": ZONES.get(int(s.get("zone", 0) or 0), s.get("zone")),
            "bounce": bool(int(s["bounce"])),
            "nuance": n.get("nuance") if n else None,
            "dynamics": _num(n.get("dynamics")) if n else None,
            "impact_speed_mps": float(s["normal_velocity_mps"]),
            "tangential_speed_mps": float(s["tangential_velocity_mps"]),
            "peak_force_n": float(s["peak_force_n"]),
            "impulse_n_s": float(s["impulse_n_s"]),
            "contact_time_ms": float(s["duration_ms"]),
            "r_over_a": float(s["r_over_a"]),
            "theta_deg": float(s["theta_deg"]),
        })
    onsets.sort(key=lambda o: (o["time_s"], o["seq"]))
    return {"item": params, "sample_rate": SAMPLE_RATE, "wav_bits": WAV_BITS, "onsets": onsets}


def command(ictusd, params, score_path, tmp, bvh):
    cmd = [ictusd, "render", "--out", tmp, "--force", "--wav", os.path.join(tmp, "performance.wav"),
           "--wav-bits", str(WAV_BITS), "--wav-rate", str(SAMPLE_RATE), "--wav-mix", "stereo",
           "--drum-preset", params["drum_preset"],
           "--drum-tension", "%g" % params["tension_n_per_m"],
           "--stick-tip", params["stick_tip"], "--grip", params["grip"],
           "--humanize", "%g" % params["humanize"], "--seed", str(params["render_seed"]),
           "--tips-rate", "0", "--progress-every", "0"]
    cmd += ["--bvh-rate", "250" if bvh else "0"]
    # relative to the render's folder (its cwd): render.json names the score, and an item's
    # bytes must not depend on where it was rendered
    score_path = os.path.basename(score_path)
    if score_path.lower().endswith((".mid", ".midi")):
        cmd += ["--midi", score_path]
    else:
        cmd += ["--score", score_path]
    return cmd


def render_item(ictusd, out, params, score_text, source=None, bvh=False, timeout_s=900):
    """Renders the item (unless done) and returns its manifest row: params, files, sha256,
    status (done | skipped | failed), error, seconds."""
    import time
    t0 = time.time()
    final = os.path.join(out, item_name(params["index"]))
    row = dict(params)
    sums = is_done(final, bvh)
    if sums is not None:
        row.update(status="skipped", error="", files=sorted(sums), sha256=json.dumps(sums, sort_keys=True),
                   render_s=0.0, host=os.uname().nodename)
        return row
    tmp = os.path.join(out, ".tmp", "%s.%s.%d" % (item_name(params["index"]), os.uname().nodename,
                                                  os.getpid()))
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    try:
        score_path = os.path.join(tmp, "score.txt")
        if source is not None and source.lower().endswith((".mid", ".midi")):
            shutil.copyfile(source, os.path.join(tmp, "score.mid"))
            score_path = os.path.join(tmp, "score.mid")
            with open(os.path.join(tmp, "score.txt"), "w") as f:
                f.write("# MIDI drum part: score.mid (%s)\n" % os.path.basename(source))
        elif source is not None:
            shutil.copyfile(source, score_path)
        else:
            with open(score_path, "w") as f:
                f.write(score_text)
        cmd = command(ictusd, params, score_path, tmp, bvh)
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=timeout_s, cwd=tmp)
        if p.returncode != 0:
            tail = " | ".join(p.stdout.strip().splitlines()[-3:])
            raise RuntimeError("ictusd render exit %d: %s" % (p.returncode, tail))
        with open(os.path.join(tmp, LABELS), "w") as f:
            json.dump(labels(params, tmp), f, indent=1, sort_keys=True)
            f.write("\n")
        for extra in ("tips.csv", "pd.log"):
            if os.path.exists(os.path.join(tmp, extra)):
                os.remove(os.path.join(tmp, extra))
        names = expected_files(bvh) + (["score.mid"] if os.path.exists(
            os.path.join(tmp, "score.mid")) else [])
        sums = {n: sha256(os.path.join(tmp, n)) for n in names}
        with open(os.path.join(tmp, CHECKSUMS), "w") as f:
            json.dump(sums, f, indent=1, sort_keys=True)
        shutil.rmtree(final, ignore_errors=True)   # an unfinished one (no or wrong checksums)
        os.rename(tmp, final)
        row.update(status="done", error="", files=sorted(sums),
                   sha256=json.dumps(sums, sort_keys=True))
    except Exception as e:  # recorded in the manifest; the run goes on
        shutil.rmtree(tmp, ignore_errors=True)
        row.update(status="failed", error="%s: %s" % (type(e).__name__, e), files=[], sha256="")
    row.update(render_s=round(time.time() - t0, 3), host=os.uname().nodename)
    return row
