"""How a rendered sound decays and where its energy lies (numpy): the broadband T60 from
the energy decay curve (M. R. Schroeder, "New method of measuring reverberation time",
JASA 37, 1965) and the spectral centroid of a stretch."""
import numpy as np


def schroeder_t60(y, rate, top_db=5.0, bottom_db=25.0):
    """T60 (s) of y: the backward-integrated energy in dB, a least-squares line from
    -top_db to -bottom_db, extrapolated to -60 dB (T20 x 3 by default). None when the
    curve does not fall to -bottom_db."""
    e = np.cumsum((np.asarray(y, dtype=np.float64) ** 2)[::-1])[::-1]
    if not e[0] > 0.0:
        return None
    db = 10.0 * np.log10(e / e[0] + 1e-300)
    i0, i1 = np.searchsorted(-db, top_db), np.searchsorted(-db, bottom_db)
    if i1 >= len(db) or i1 - i0 < 2:
        return None
    t = np.arange(len(db)) / float(rate)
    slope = np.polyfit(t[i0:i1], db[i0:i1], 1)[0]
    return -60.0 / slope if slope < 0.0 else None


def centroid(y, rate, t0, t1):
    """The spectral centroid (Hz) of y between t0 and t1 (s), Hann window."""
    seg = np.asarray(y[int(t0 * rate):int(t1 * rate)], dtype=np.float64)
    power = np.abs(np.fft.rfft(seg * np.hanning(len(seg)))) ** 2
    f = np.fft.rfftfreq(len(seg), 1.0 / rate)
    return float(np.sum(f * power) / np.sum(power))
