#!/usr/bin/env python3
"""Writes the hoop of patches/ictus-drum.pd (the subpatch [pd rim], docs/rim.md).

The hoop of a 14 in drum is a thin steel ring. Its in-plane flexural modes (Fletcher &
Rossing, The Physics of Musical Instruments, 2nd ed. 1998, section 2.18):

    f_n = (1 / 2 pi) (k / R^2) sqrt(E / rho) n (n^2 - 1) / sqrt(n^2 + 1),   n = 2 .. 10

Each mode moves the ring's surface radially as cos(n phi): it radiates as a cylinder of
circumferential order n, whose radiation efficiency is (the pressure of a cylinder vibrating
as cos(n phi), M. C. Junger & D. Feit, Sound, Structures and Their Interaction, 2nd ed.
1986, ch. 6; the real part of the modal impedance by the Wronskian of J_n and Y_n):

    sigma_n = 2 / (pi k_a |H_n^(1)'(k_a)|^2),   k_a = 2 pi f_n R / c

A mode's radiated pressure goes with sqrt(sigma_n) times its velocity: the patch weights each
mode by it, so that the low ring modes (a quadrupole at ka 0.65 for n = 2) are faint and the
click is bright. Usage: python3 scripts/rim_hoop.py [--write] (prints the table; --write
replaces the [pd rim] subpatch of patches/ictus-drum.pd).
"""
import argparse
import math
import os
import re

import mpmath

# The hoop (docs/rim.md): steel, its ring radius, the radius of gyration of its section
# about the drum's axis direction, its mass, the loss factor, air.
E, RHO, R_RING, K_GYR = 200e9, 7850.0, 0.183, 0.003
MASS, ETA, C_AIR = 0.75, 0.02, 343.0
ORDERS = range(2, 11)
# The hoop's side (25 mm deep) over the head's area: its velocity to the head's pickups.
AREA_RATIO = 0.025 * 2 * math.pi * R_RING / (math.pi * 0.178 ** 2)


def ring_mode_hz(n):
    return (K_GYR / R_RING ** 2) * math.sqrt(E / RHO) * n * (n * n - 1) / math.sqrt(n * n + 1) / (
        2 * math.pi)


def radiation_efficiency(n, ka):
    dh = (mpmath.hankel1(n - 1, ka) - mpmath.hankel1(n + 1, ka)) / 2
    return float(2 / (mpmath.pi * ka * abs(dh) ** 2))


def table():
    rows = []
    for n in ORDERS:
        f = ring_mode_hz(n)
        ka = 2 * math.pi * f * R_RING / C_AIR
        s = radiation_efficiency(n, ka)
        rows.append((n, f, ka, s, math.sqrt(s), 2.2 / (ETA * f)))
    return rows


def subpatch(rows):
    """The [pd rim] canvas: a Hertz pulse (wood on steel) into one biquad~ per mode."""
    m = MASS / 2  # modal mass of a ring mode struck at an antinode
    lines = [
        "#N canvas 100 100 1360 %d 12;" % (200 + 100 * len(rows)),
        "#X obj 20 20 inlet;",
        "#X obj 20 50 list append 0 0 0 0 0;",
        "#X obj 20 80 unpack f f f f f;",
        "#X obj 20 110 pack f f;",
        "#X obj 20 140 expr 2870*pow(pow(if($f2>0 \\, $f2 \\, 0.05) \\, 2)/(0.007*2.25e+18*"
        "max($f1 \\, 0.01)) \\, 0.2) \\; 4/3*1.5e+09*sqrt(0.007)*pow(15*if($f2>0 \\, $f2 \\, "
        "0.05)*$f1*$f1/(16*1.5e+09*sqrt(0.007)) \\, 0.6), f 60;",
        "#X msg 20 230 0 \\, 1 \\$1 \\$2;",
        "#X obj 20 260 vline~;",
        "#X obj 20 290 expr~ if($v1 > 0 && $v1 < 1 \\, sin(3.14159265*$v1)*$f2 \\, 0), f 46;",
        "#X obj 500 20 loadbang;",
        "#X obj 500 50 samplerate~;",
        "#X obj 20 %d *~ %.4f;" % (120 + 100 * len(rows), AREA_RATIO),
        "#X obj 20 %d outlet~;" % (150 + 100 * len(rows)),
        "#X text 20 %d The hoop: a Hertz pulse (wood on steel) rings %d in-plane ring modes "
        "(biquad~: velocity per force \\, modal mass %.3f kg \\, each weighted by the square "
        "root of its radiation efficiency) \\, scaled by the hoop's side area over the head's. "
        "'t60 S' caps each mode's T60 at S (the drum's t60 reaches here). "
        "Written by scripts/rim_hoop.py \\; docs/rim.md., f 64;"
        % (190 + 100 * len(rows), len(rows), m),
    ]
    # After the modes: [route t60 list] (the drum's 't60 S' reaches the hoop and caps every
    # mode's T60 at S, 0.005 s at least as membrane~'s t60; a list is a hit), [t b f] and
    # [pack f 60] (the sample rate and the cap, to each mode's coefficients).
    top = 13 + 3 * len(rows)
    route, tbf, srcap = top, top + 1, top + 2
    conns = ["0 0 %d 0" % route, "%d 1 1 0" % route, "%d 0 %d 0" % (route, tbf),
             "%d 1 %d 1" % (tbf, srcap), "%d 0 9 0" % tbf, "9 0 %d 0" % srcap,
             "1 0 2 0", "2 4 3 1", "2 1 3 0", "3 0 4 0", "4 1 7 1", "4 0 %d 0" % (top + 3),
             "%d 0 5 0" % (top + 3), "9 0 %d 0" % (top + 4), "%d 0 %d 1" % (top + 4, top + 3),
             "5 0 6 0", "6 0 7 0", "8 0 9 0", "10 0 11 0"]
    for i, (n, f, _ka, _s, w, t60) in enumerate(rows):
        y = 90 + 100 * i
        g = w / m
        t = "min(%.5f \\, max($f2 \\, 0.005))" % t60
        lines.append(
            "#X obj 500 %d expr 2*exp(-6.9078/(%s*$f1))*cos(6.28319*%.2f/$f1) \\; "
            "-exp(-13.8155/(%s*$f1)) \\; %.6f/$f1 \\; "
            "-exp(-6.9078/(%s*$f1))*cos(6.28319*%.2f/$f1)*%.6f/$f1 \\; 0, f 90;"
            % (y, t, f, t, g, t, f, g))
        lines.append("#X obj 1220 %d pack f f f f f;" % y)
        lines.append("#X obj %d %d biquad~;" % (20 + 80 * (i % 6), 60 + 100 * len(rows)
                                               - 40 * (i // 6)))
        e, p, b = 13 + 3 * i, 14 + 3 * i, 15 + 3 * i
        conns += ["%d 0 %d 0" % (srcap, e)] + ["%d %d %d %d" % (e, k, p, k) for k in range(5)]
        conns += ["%d 0 %d 0" % (p, b), "7 0 %d 0" % b, "%d 0 10 0" % b]
    # [pack f f] and [expr 500/$f1]: the pulse starts half a sample after the hit's logical
    # time (vline~ sounds from the sample whose span holds its start), on the hit's sample,
    # round(t sr), as contact~'s stroke.
    lines += ["#X obj 160 20 route t60 list;", "#X obj 660 20 t b f;", "#X obj 660 50 pack f 60;",
              "#X obj 200 230 pack f f;", "#X obj 300 230 expr 500/$f1;"]
    lines += ["#X connect %s;" % c for c in conns]
    lines.append("#X restore 480 372 pd rim;")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", action="store_true", help="rewrite patches/ictus-drum.pd")
    args = ap.parse_args()
    rows = table()
    print(" n   f_n Hz    ka   sigma_n  sqrt  T60 s")
    for n, f, ka, s, w, t60 in rows:
        print("%2d %8.1f %6.2f %7.4f %5.3f %6.3f" % (n, f, ka, s, w, t60))
    if args.write:
        path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "patches",
                            "ictus-drum.pd")
        text = open(path).read()
        pat = re.compile(r"#N canvas 100 100 1[13]60 \d+ 12;\n.*?#X restore 480 372 pd rim;\n", re.S)
        if not pat.search(text):
            raise SystemExit("rim_hoop.py: no [pd rim] subpatch in %s" % path)
        text = pat.sub(lambda _m: subpatch(rows), text, count=1)
        with open(path, "w") as f:
            f.write(text)
        print("wrote", os.path.normpath(path))


if __name__ == "__main__":
    main()
