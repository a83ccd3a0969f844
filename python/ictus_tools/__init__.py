"""The Python helpers of ictus's tests, benchmarks and scripts, imported by name
(`from ictus_tools import pdrun`) with python/ on PYTHONPATH: CTest sets it for the
Python tests, the shell scripts for what they run (docs/python.md).

- checks: the one assertion helper (check, fail)
- pdrun: the real pd binary in batch mode, patches built in Python, WAV readers
- oscpacket: OSC 1.0 packets built by hand; rtpd: pd in real time, its reports over UDP
- soundrun: the sound models rendered by pd; e2e_util: ictusd's output files, onsets
- uitest: Xvfb, screenshots, a synthetic pose stream; pdlayout: box extents of a patch
- random_score: seeded random scores; render_check: a score through `ictusd render`, checked
- figure5: the stick-tip plot of a render (python3 -m ictus_tools.figure5)
"""
import os

# The repository's root folder (patches/, help/, daemon/ ... are found from here).
ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
