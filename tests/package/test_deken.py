"""The deken package as a user gets it: `cmake --build <build> --target deken`
makes ictus[vVERSION](Linux-amd64-32).dek (deken's naming, the version from the
top CMakeLists.txt); it is unpacked into an empty folder and used from there
alone (pd -noprefs -nostdpath -path <that folder>/ictus; Gem's own folder is
added for the Gem view, which needs Gem): the main patch and every help patch
open without an error line, the packaged ictus-render.pd renders one strike to
a WAV that sounds at the strike's sample, the packaged ictusd starts, prints
its version and renders a score to a WAV from an empty folder with no flag
naming the library, and the references the patches point at are in docs/
beside them, as Markdown and HTML. No binary's RUNPATH points outside its own folder, in the
package or in a `cmake --install` tree, which holds the same files (README.md,
"Installing")."""
import argparse
import atexit
import glob
import hashlib
import os
import platform
import re
import shutil
import stat
import subprocess
import tempfile
import zipfile

import numpy as np  # Debian's, as pdrun

from ictus_tools import ROOT as REPO
from ictus_tools import e2e_util, pdrun
from ictus_tools.checks import check
from ictus_tools.pdrun import PD, PD_ENV, error_lines, make_workdir, read_wav_float

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--cmake", default="cmake", help="the cmake that configured the build")
args = ap.parse_args()
build = os.path.abspath(args.build)

# The name deken expects, computed here from the sources and the machine.
top_cmake = open(os.path.join(REPO, "CMakeLists.txt")).read()
version = re.search(r"project\(ictus VERSION ([0-9.]+)", top_cmake).group(1)
cpu = {"x86_64": "amd64", "amd64": "amd64", "aarch64": "arm64", "arm64": "arm64"}.get(
    platform.machine().lower(), platform.machine().lower())
dek = os.path.join(build, "ictus[v%s](Linux-%s-32).dek" % (version, cpu))

proc = subprocess.run([args.cmake, "--build", build, "--target", "deken"], capture_output=True,
                      text=True, timeout=900)
check(proc.returncode == 0, "cmake --build --target deken succeeds%s"
      % ("" if proc.returncode == 0 else ":\n" + proc.stdout[-2000:] + proc.stderr[-2000:]))
check(os.path.isfile(dek), "the package is named by deken's convention: %s" % os.path.basename(dek))
data = open(dek, "rb").read()
sha = open(dek + ".sha256").read().split()
check(sha == [hashlib.sha256(data).hexdigest(), os.path.basename(dek)], "the .sha256 beside it matches")

# What the package must hold, listed from the source tree (not from the build rules).
expected = {"ictus/" + os.path.basename(p) for p in glob.glob(os.path.join(REPO, "help", "*.pd"))
            + glob.glob(os.path.join(REPO, "help", "*.mid"))}  # the help patches' examples
for pattern in ("patches/*.pd", "patches/sound/*.pd", "patches/ui/*.pd"):
    for p in glob.glob(os.path.join(REPO, pattern)):
        if os.path.basename(p) != "ictus-sound-render-clips.pd":  # a build step's patch
            expected.add("ictus/" + os.path.basename(p))
expected |= {"ictus/examples/scores/" + os.path.basename(p)
             for p in glob.glob(os.path.join(REPO, "examples", "scores", "*.txt"))}
expected |= {"ictus/%s.pd_linux" % n for n in ("membrane~", "contact~", "ictus_timetag", "ictus_error",
                                                "ictus")}
expected |= {"ictus/libictus_pd.so", "ictus/clips/ictus-clips.wav", "ictus/README.md",
             "ictus/LICENSE", "ictus/ictusd"}
# The references beside the help patches: every page of docs/ as Markdown and HTML,
# and its figures.
doc_pages = [os.path.basename(p)[:-3] for p in glob.glob(os.path.join(REPO, "docs", "*.md"))]
expected |= {"ictus/docs/%s.%s" % (n, ext) for n in doc_pages for ext in ("md", "html")}
expected |= {"ictus/docs/img/" + os.path.basename(p)
             for p in glob.glob(os.path.join(REPO, "docs", "img", "*.png"))}
with zipfile.ZipFile(dek) as z:
    infos = z.infolist()
    names = {i.filename for i in infos if not i.is_dir()}
    check(all(i.filename.startswith("ictus/") for i in infos),
          "every entry is inside the folder ictus/")
    missing, extra = sorted(expected - names), sorted(names - expected)
    check(not missing, "the package holds the library, patches, scores, README, LICENSE and "
          "ictusd (%d files); missing: %s" % (len(expected), missing))
    check(not extra, "and nothing else (a stray file would be shipped): %s" % extra)
    ictusd_info = z.getinfo("ictus/ictusd")
    check((ictusd_info.external_attr >> 16) & stat.S_IXUSR, "ictusd is executable in the archive")
    check(z.read("ictus/LICENSE") == open(os.path.join(REPO, "LICENSE"), "rb").read()
          and b"BSD 3-Clause" in z.read("ictus/LICENSE"), "LICENSE is the repository's, BSD 3-Clause")
    # Unpacked into an empty folder, file modes as stored (as unzip does).
    root = make_workdir("ictus-deken-")
    for i in infos:
        z.extract(i, root)
        mode = (i.external_attr >> 16) & 0o777
        if mode:
            os.chmod(os.path.join(root, i.filename), mode)
lib = os.path.join(root, "ictus")


def runpaths(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library r(?:un)?path: \[(.*)\]", out)


def check_relocatable(folder, what):
    binaries = [p for p in glob.glob(os.path.join(folder, "*"))
                if p.endswith((".pd_linux", ".so")) or os.path.basename(p) == "ictusd"]
    check(len(binaries) >= 5, "%s: %d binaries to check" % (what, len(binaries)))
    for b in binaries:
        for rp in runpaths(b):
            check(all(e == "$ORIGIN" for e in rp.split(":")),
                  "%s: %s's RUNPATH is $ORIGIN only, got %s" % (what, os.path.basename(b), rp))


check_relocatable(lib, "package")

# The packaged ictusd starts and says its version.
proc = subprocess.run([os.path.join(lib, "ictusd"), "--version"], capture_output=True, text=True,
                      timeout=60)
check(proc.returncode == 0 and proc.stdout == "ictusd %s\n" % version,
      "the packaged ictusd --version prints 'ictusd %s': %r" % (version, proc.stdout + proc.stderr))

# The references the patches point at ("docs/NAME.md", relative to the patch's
# folder) are there, as Markdown and as HTML whose links stay in the package.
pointed = set()
for p in glob.glob(os.path.join(lib, "*.pd")):
    pointed |= set(re.findall(r"docs/([a-z0-9_-]+)\.md", open(p).read()))
check({"score", "osc", "midi", "ui", "pd-osc", "sound"} <= pointed,
      "the patches point at the score, OSC, MIDI, main patch (ui), pd-osc and sound references: "
      "%s" % sorted(pointed))
for n in sorted(pointed):
    check(all(os.path.isfile(os.path.join(lib, "docs", "%s.%s" % (n, e))) for e in ("md", "html")),
          "docs/%s.md and docs/%s.html are beside the help patches" % (n, n))
score_html = open(os.path.join(lib, "docs", "score.html")).read()
check("<h1" in score_html and "<code>tempo" in score_html and "score.md" in score_html,
      "docs/score.html is the score language's reference as HTML, naming its Markdown")
for page in glob.glob(os.path.join(lib, "docs", "*.html")):
    for target in re.findall(r'(?:href|src)="([^"#:]+)(?:#[^"]*)?"', open(page).read()):
        check(os.path.isfile(os.path.join(lib, "docs", target)),
              "%s links to %s, which is in the package" % (os.path.basename(page), target))

# The packaged ictusd renders a WAV from an empty folder with no flag naming the
# library: it finds the folder it is in (and Pd on PATH).
def render_wav(ictusd, what):
    folder = make_workdir("ictus-deken-score-")
    with open(os.path.join(folder, "s.txt"), "w") as f:
        f.write("tempo 120\nbeats 1/2\ndynamics mf\nR, L, R, L\n")
    # pd from PATH (under the sanitizer build a wrapper, outside the folder, preloads its
    # runtime into pd); no ICTUS_ variable names the library
    spawn = e2e_util.pd_spawning_env(make_workdir("ictus-deken-pd-"))
    env = {k: v for k, v in spawn.items() if not k.startswith("ICTUS_")}
    proc = subprocess.run([ictusd, "render", "--score", "s.txt", "--out", "o", "--wav", "o/p.wav"],
                          cwd=folder, capture_output=True, text=True, timeout=300, env=env)
    wav = os.path.join(folder, "o", "p.wav")
    check(proc.returncode == 0 and os.path.isfile(wav),
          "%s: ictusd render --score S --out O --wav O/p.wav, with no library flag, writes the "
          "WAV: %s" % (what, (proc.stdout + proc.stderr)[-1500:]))
    if not os.path.isfile(wav):
        return
    first = min(float(row.split(",")[5]) for row in
                open(os.path.join(folder, "o", "strikes.csv")).read().splitlines()[1:])
    sound, rate = read_wav_float(wav)
    level = np.abs(sound).max(axis=1)
    onset = int(np.argmax(level > 1e-3 * level.max())) / rate
    check(np.all(np.isfinite(sound)) and level.max() > 1e-3 and abs(onset - first) < 0.002,
          "%s: the WAV sounds from the first strike (%.4f s): peak %.3g, first sample over "
          "-60 dB at %.4f s" % (what, first, level.max(), onset))
    shutil.rmtree(folder, ignore_errors=True)


render_wav(os.path.join(lib, "ictusd"), "package")

# Pd with this folder only: no preferences, no standard path; Gem's folder for
# the Gem view (it needs Gem, a library of its own).
pd_path = ["-noprefs", "-nostdpath", "-path", lib]
gem = "/usr/lib/pd/extra/Gem"
if os.path.isdir(gem):
    pd_path += ["-path", gem]
# and cyclone (Debian's pd-cyclone, a dependency: [ictus-midifile] plays a file with
# [cyclone/seq]), alone in a folder of its own, reached as cyclone/NAME.
cyclone = "/usr/lib/pd/extra/cyclone"
check(os.path.isdir(cyclone), "cyclone is installed (pd-cyclone, scripts/deps.sh)")
cyclone_parent = tempfile.mkdtemp(prefix="ictus-deken-cyclone-")
atexit.register(shutil.rmtree, cyclone_parent, True)
os.symlink(cyclone, os.path.join(cyclone_parent, "cyclone"))
pd_path += ["-path", cyclone_parent]


def open_patch(path, name):
    status, bad = pdrun.open_patch(path, pd_path)
    check(status == 0 and not bad,
          "%s opens from the package without error lines%s"
          % (name, "" if not bad else ":\n" + "\n".join(bad)))


# The main patch listens on UDP 9000; a copy beside it on a free port, so that
# the test does not depend on that port being free.
main_text = open(os.path.join(lib, "ictus.pd")).read()
check("ictus-receive 9000" in main_text, "the packaged main patch listens on UDP 9000")
copy = os.path.join(lib, "ictus-test-port0.pd")
with open(copy, "w") as f:
    f.write(main_text.replace("ictus-receive 9000", "ictus-receive 0"))
open_patch(copy, "ictus.pd (the main patch)")
os.remove(copy)
helps = sorted(glob.glob(os.path.join(lib, "*-help.pd")))
check(len(helps) == len(glob.glob(os.path.join(REPO, "help", "*-help.pd"))),
      "every help patch is in the package (%d)" % len(helps))
for h in helps:
    open_patch(h, os.path.basename(h))

# One strike through the packaged objects: ictus-render.pd plays an events
# file on [ictus-drum] (membrane~ + contact~) and writes a 2-channel WAV.
sr, strike_ms = 48000, 50.0
work = make_workdir("ictus-deken-render-")
events = os.path.join(work, "events.txt")
with open(events, "w") as f:
    # <delay_ms> hit <hand> <drum> <bounce> <v m/s> <r/a> <theta> <force N> <impulse> <ms> <vt> <t s>
    f.write("%.3f hit 0 0 0 3 0.3 45 150 0.01 1.2 0.1 %.6f;\n" % (strike_ms, strike_ms / 1000))
wav = os.path.join(work, "strike.wav")
cmd = [PD, "-nogui", "-nosound", "-batch", "-nrt", "-stderr", "-r", str(sr)] + pd_path + [
    "-open", os.path.join(lib, "ictus-render.pd"), "-send", "render-file %s" % events,
    "-send", "render-out %s" % wav, "-send", "render-seconds 0.5"]
proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=PD_ENV)
log = proc.stdout + proc.stderr
check(proc.returncode == 0 and not error_lines(log) and os.path.isfile(wav),
      "the packaged ictus-render.pd renders a strike: %s" % error_lines(log))
samples, wav_sr = read_wav_float(wav)
check(wav_sr == sr and samples.shape == (int(0.5 * sr), 2),
      "the WAV is 0.5 s of 2 channels at %d Hz: %s at %d" % (sr, samples.shape, wav_sr))
mono = np.abs(samples).max(axis=1)
peak = float(mono.max())
check(np.all(np.isfinite(samples)) and peak > 1e-3, "the WAV has sound (peak %.4g)" % peak)
onset = int(np.argmax(mono > 1e-3 * peak))
strike_sample = round(strike_ms * sr / 1000)
check(abs(onset - strike_sample) <= 2,
      "the sound starts on the strike's sample %d (first sample over -60 dB: %d)"
      % (strike_sample, onset))

# `cmake --install`: the same library folder (ictusd goes to bin/ instead), relocatable.
prefix = make_workdir("ictus-install-")
proc = subprocess.run([args.cmake, "--install", build, "--prefix", prefix], capture_output=True,
                      text=True, timeout=300)
check(proc.returncode == 0, "cmake --install succeeds: %s" % proc.stderr[-2000:])
installed_lib = os.path.join(prefix, "lib", "pd-externals", "ictus")
installed = {os.path.relpath(os.path.join(d, f), os.path.dirname(installed_lib))
             for d, _, fs in os.walk(installed_lib) for f in fs}
check(installed == names - {"ictus/ictusd"},
      "cmake --install puts the package's files in lib/pd-externals/ictus: missing %s, extra %s"
      % (sorted(names - {"ictus/ictusd"} - installed), sorted(installed - names)))
check(os.access(os.path.join(prefix, "bin", "ictusd"), os.X_OK), "and ictusd in bin/")
check_relocatable(installed_lib, "install")
check(not runpaths(os.path.join(prefix, "bin", "ictusd")), "the installed ictusd has no RUNPATH")
render_wav(os.path.join(prefix, "bin", "ictusd"), "install")
shutil.rmtree(prefix, ignore_errors=True)
print("ok: all")
