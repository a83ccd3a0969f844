"""Names in any casing in the real pd binary, as ictusd's --drum-preset and OSC take words:
membrane~'s `preset NAME` (and ictus-drum's, which passes it on), `wires on|off`,
contact~'s `tip NAME` and its TIP argument, and the sound panel's `preset NAME`.

Every name of the tables (externals/core/membrane_presets.c, stick_tip.c, read here from
their text) goes in a seeded random casing, never its own:
- after `preset CASED`, membrane~'s `print` gives the radius and density (a drum's tension
  too) of the preset's row (ictus_tools.presets);
- a contact~ given `tip CASED`, or created [contact~ NAME CASED], renders the same samples
  as one given the name as the table spells it, and not those of the default tip;
- `wires CASED-off` after `preset snare` renders what `wires off` does, not the wires' sound;
- the sound panel passes `preset CASED` on to ictus-sound as the table's name;
- no error line but one: a name that is none in any casing (`Bongo`) is still refused."""
import argparse
import os
import random
import re

import numpy as np

from ictus_tools import ROOT
from ictus_tools.checks import check
from ictus_tools.pdrun import Patch, error_lines, make_workdir, read_wav_float, recorder, run_pd
from ictus_tools.presets import preset_head

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--seed", type=int, default=20261203)
args = ap.parse_args()
build = os.path.abspath(args.build)
rng = random.Random(args.seed)


def table_names(path, pattern):
    with open(os.path.join(ROOT, "externals", "core", path)) as f:
        return re.findall(pattern, f.read(), re.M)


presets = table_names("membrane_presets.c", r'^\s*\{"([a-z-]+)", "')
tips = table_names("stick_tip.c", r'^\s*\{"([a-z]+)", [0-9.]+,')
check(len(presets) == 10 and len(tips) == 3, "the tables' names: %s, %s" % (presets, tips))


def cased(name):
    """name in a random casing other than its own."""
    while True:
        out = "".join(c.upper() if rng.random() < 0.5 else c for c in name)
        if out != name:
            return out


sr = 48000
seconds = 0.25
work = make_workdir("ictus-name-casing-")
wav = os.path.join(work, "casing.wav")
p = Patch(declare="-path %s/ictus" % build)
lb = p.obj("loadbang")

# Presets: membrane~ pK prints its head after `preset CASED`; one more through ictus-drum.
sent = {}
for k, name in enumerate(presets):
    sent[name] = cased(name)
    m = p.obj("membrane~ p%d" % k)
    msg = p.msg("preset %s \\, print" % sent[name])
    p.connect(lb, 0, msg, 0)
    p.connect(msg, 0, m, 0)
drum_name = rng.choice([n for n in presets if n != "paper"])
drum_cased = cased(drum_name)
drum = p.obj("ictus-drum")
msg = p.msg("preset %s \\, print \\, preset Bongo" % drum_cased)
p.connect(lb, 0, msg, 0)
p.connect(msg, 0, drum, 0)

# Tips and wires: rendered, each on its own membrane~.
tables, renders = [], {}


def voice(label, contact_args, messages, preset=""):
    m = p.obj("membrane~ %s" % label)
    if contact_args is not None:
        p.obj("contact~ %s %s" % (label, contact_args))
        c = p.count - 1
    else:
        c = m
    tables.append((m, 0, label))
    renders[label] = len(tables) - 1
    return c, messages


voices = []
for name in tips:
    voices.append(voice("ref-" + name, "", "tip %s \\, hit 1 0.3 0" % name))
    voices.append(voice("msg-" + name, "", "tip %s \\, hit 1 0.3 0" % cased(name)))
    voices.append(voice("arg-" + name, cased(name), "hit 1 0.3 0"))
voices.append(voice("default", "", "hit 1 0.3 0"))
voices.append(voice("wires-off", None, "preset snare \\, wires off \\, strike 0.3 0 0.01"))
voices.append(voice("wires-cased", None, "preset snare \\, wires %s \\, strike 0.3 0 0.01"
                    % cased("off")))
voices.append(voice("wires-on", None, "preset snare \\, strike 0.3 0 0.01"))
trig = recorder(p, tables, seconds, sr, wav)
for target, text in voices:
    msg = p.msg(text)
    p.connect(trig, 1, msg, 0)
    p.connect(msg, 0, target, 0)

# The sound panel: its first outlet to [print panel].
panel = p.obj("ictus-sound-panel")
pr = p.obj("print panel")
p.connect(panel, 0, pr, 0)
panel_name = rng.choice(presets[:7])  # the panel's drums, not the cymbals
panel_cased = cased(panel_name)
msg = p.msg("preset %s" % panel_cased)
p.connect(lb, 0, msg, 0)
p.connect(msg, 0, panel, 0)

rc, log = run_pd(p.text(), build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
errors = error_lines(log)
check(len(errors) == 1 and "preset: unknown 'Bongo'" in errors[0],
      "one error, for Bongo alone: %s" % errors)

head_re = re.compile(r"membrane~ (\S+): radius (\S+) m, tension (\S+) N/m, density (\S+) kg/m\^2")
heads = {m.group(1): tuple(float(v) for v in m.group(2, 3, 4)) for m in head_re.finditer(log)}


def same_head(label, name):
    got = heads.get(label)
    radius, tension, density = preset_head(name)
    want = (radius, tension if tension > 0 else None, density)
    ok = got is not None and all(w is None or abs(g - w) <= 1e-5 * w for g, w in zip(got, want))
    check(ok, "%s after preset %s: radius, tension, density %s, the table's %s"
          % (label, sent.get(name, name), got, want))


for k, name in enumerate(presets):
    same_head("p%d" % k, name)
drum_label = [label for label in heads if label.endswith("-drum")]
check(len(drum_label) == 1, "ictus-drum's membrane~ printed its head: %s" % drum_label)
if drum_label:
    sent[drum_name] = drum_cased
    same_head(drum_label[0], drum_name)

x, wsr = read_wav_float(wav)
check(wsr == sr and x.shape[0] == int(round(seconds * sr)), "recorded %d samples" % x.shape[0])


def col(label):
    return x[:, renders[label]]


for name in tips:
    ref = col("ref-" + name)
    check(np.all(np.isfinite(ref)) and np.max(np.abs(ref)) > 0, "tip %s sounds" % name)
    check(np.array_equal(col("msg-" + name), ref),
          "tip in another casing renders tip %s's samples" % name)
    check(np.array_equal(col("arg-" + name), ref),
          "[contact~ NAME TIP] in another casing renders tip %s's samples" % name)
check(sum(np.array_equal(col("ref-" + n), col("default")) for n in tips) <= 1,
      "the default tip is not every table tip: the tips render differently")
check(not np.array_equal(col("ref-felt"), col("ref-wood")), "felt and wood differ")
check(np.max(np.abs(col("wires-off"))) > 0 and np.array_equal(col("wires-cased"),
                                                              col("wires-off")),
      "wires in another casing of off renders wires off's samples")
check(not np.array_equal(col("wires-on"), col("wires-off")), "the wires change the sound")

check(re.search(r"^panel: preset %s$" % re.escape(panel_name), log, re.M) is not None,
      "the panel sends preset %s on for preset %s" % (panel_name, panel_cased))
print("name casing: ok")
