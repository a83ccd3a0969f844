"""A drum's modes and the power of one frequency in a signal, for tests that tell drums
apart by ear: the ideal membrane's (m, n) mode, j_mn / (2 pi a) sqrt(T / sigma), with the
air's mass when a head has it, and Goertzel's single-bin power."""
import math

J01 = 2.404825557695773  # first zero of the Bessel function J0


def mode_hz(radius, tension, density, m=0, n=1, airmass=0.0):
    """Mode (m, n) of an ideal circular membrane, Hz (radius m, tension N/m, kg/m^2),
    j_mn / (2 pi a) sqrt(T / sigma), with `airmass` baffled faces' air on it (membrane~'s
    airmass; docs/membrane.md, "The air's mass"): over sqrt(1 + airmass rho_air a / sigma
    g_mn), g_mn from ictus_tools.air."""
    j = J01 if (m, n) == (0, 1) else _zero(m, n)
    ideal = j / (2.0 * math.pi * radius) * math.sqrt(tension / density)
    if airmass <= 0.0:
        return ideal
    from ictus_tools.air import RHO_AIR, air_g
    return ideal / math.sqrt(1.0 + airmass * RHO_AIR * radius / density * air_g(m, n))


def _zero(m, n):
    from scipy.special import jn_zeros
    return float(jn_zeros(m, n)[-1])


def f01(radius, tension, density, airmass=0.0):
    """The (0,1) mode (mode_hz)."""
    return mode_hz(radius, tension, density, 0, 1, airmass)


def goertzel_power(x, rate, freq):
    """The power of x at freq (Hz), sampled at rate, by Goertzel's recurrence."""
    w = 2.0 * math.pi * freq / rate
    c = 2.0 * math.cos(w)
    s1 = s2 = 0.0
    for v in x:
        s1, s2 = v + c * s1 - s2, s1
    return s1 * s1 + s2 * s2 - c * s1 * s2


def lowest_peak_hz(y, rate, onset, t0=0.005, t1=0.065, lo=20.0, hi=400.0, within_db=20.0):
    """A struck drum's fundamental: the lowest spectral peak of y[onset + t0 .. onset + t1]
    (s after the onset sample `onset`) in lo..hi Hz within `within_db` of the strongest there,
    refined by a parabola through the log magnitudes (numpy; Hann window, zero-padded FFT)."""
    import numpy as np
    seg = np.asarray(y[onset + int(t0 * rate):onset + int(t1 * rate)], dtype=np.float64)
    nfft = 1 << 18
    mag = np.abs(np.fft.rfft(seg * np.hanning(len(seg)), nfft))
    f = np.arange(len(mag)) * rate / nfft
    band = (f > lo) & (f < hi)
    floor = np.max(mag[band]) * 10.0 ** (-within_db / 20.0)
    peaks = [j for j in np.nonzero(band)[0][1:-1]
             if mag[j] >= floor and mag[j] > mag[j - 1] and mag[j] >= mag[j + 1]]
    k = int(peaks[0])
    a, b, c = np.log(mag[k - 1:k + 2] + 1e-300)
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) * rate / nfft


def level_db(x, rate, t0_s, t1_s):
    """The mean power of x from t0_s to t1_s (s), in dB."""
    seg = x[int(round(t0_s * rate)):int(round(t1_s * rate))]
    return 10.0 * math.log10(sum(v * v for v in seg) / max(len(seg), 1) + 1e-30)


def decay_t60(x, rate, onset_s, t0=0.100, t1=0.400, window=0.020):
    """T60 (s) from the energy of `window`-long stretches t0..t1 after the onset: the least-
    squares line through their levels (dB) against their centres' times."""
    ts, levels = [], []
    t = t0
    while t + window <= t1 + 1e-9:
        i0 = int(round((onset_s + t) * rate))
        seg = x[i0:i0 + int(round(window * rate))]
        energy = sum(v * v for v in seg) / len(seg)
        ts.append(t + window / 2)
        levels.append(10.0 * math.log10(energy + 1e-30))
        t += window
    n = len(ts)
    mt, ml = sum(ts) / n, sum(levels) / n
    slope = sum((a - mt) * (b - ml) for a, b in zip(ts, levels)) / sum((a - mt) ** 2 for a in ts)
    return -60.0 / slope if slope < 0 else float("inf")
