"""Peer of membrane~ + contact~: the Sound Design Toolkit's impact interactor
between an inertial mass and a modal resonator (SDT's C library through the
pysdt bindings from PyPI: SDT's Pd externals impact~ / inertial / modal are not
packaged for Debian 12 nor on PyPI). Runs in the peers' virtual environment.

The scene mirrors bench_peers.py's Pd case: a 10 kg hammer hits at 0.5 m/s every
100 ms and stays pressed in (stiffness 1e6, shape 1.5, dissipation 0.5), N modes
(100 + 5 k Hz, decay 0.01 s), two pickups (the contact point and a listening
point), 48 kHz. The per-sample Python call costs the same at any N, so the cost
per mode is the difference between N modes and BASE modes:
    ns per mode-sample = (cpu(N) - cpu(BASE)) / ((N - BASE) * samples)
Prints one JSON line. Usage: peer_sdt.py N [SECONDS] [BASE]"""
import json
import sys
import time

import importlib.metadata

import pysdt

SR = 48000


def run(n, samples):
    pysdt.common.set_samplerate(SR)
    res = pysdt.resonators.Resonator
    hammer = res(1, 1)
    hammer.set_frequency(0, 0.0)
    hammer.set_decay(0, 0.0)
    hammer.set_weight(0, 10.0)
    hammer.set_gain(0, 0, 1.0)
    hammer.active_modes = 1
    hammer.fragment_size = 1.0
    hammer.update()
    drum = res(n, 2)
    for k in range(n):
        drum.set_frequency(k, 100.0 + 5.0 * k)
        drum.set_decay(k, 0.01)
        drum.set_weight(k, 0.01)
        drum.set_gain(0, k, 1.0)
        drum.set_gain(1, k, 0.5 if k % 2 else -0.5)
    drum.active_modes = n
    drum.fragment_size = 1.0
    drum.update()
    imp = pysdt.interactors.Impact()
    imp.stiffness = 1.0e6
    imp.dissipation = 0.5
    imp.shape = 1.5
    imp.first_resonator = hammer
    imp.second_resonator = drum
    imp.first_point = 0
    imp.second_point = 0
    period = SR // 10
    touching = 0
    out = 0.0
    t0 = time.process_time()
    for i in range(samples):
        if i % period == 0:
            hammer.set_position(0, drum.get_position(0) + 1.0e-6)
            hammer.set_velocity(0, -0.5)
        imp.dsp(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        out += drum.get_velocity(1)
        if i % 64 == 0:
            touching += hammer.get_position(0) < drum.get_position(0)
    cpu = time.process_time() - t0
    return cpu, touching / ((samples + 63) // 64), out


n = int(sys.argv[1])
seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 0.5
base = int(sys.argv[3]) if len(sys.argv) > 3 else 16
samples = int(seconds * SR)
cpu_base, _, _ = run(base, samples)
cpu_n, touching, out = run(n, samples)
print(json.dumps({"peer": "sdt", "modes": n, "base_modes": base, "samples": samples,
                  "cpu_s": cpu_n, "cpu_base_s": cpu_base,
                  "ns_per_mode_sample": (cpu_n - cpu_base) * 1e9 / ((n - base) * samples),
                  "touching": touching, "finite": out == out,
                  "pysdt": importlib.metadata.version("pysdt"), "sdt": pysdt.common.SDT_VERSION}))
