"""A drum's lowest mode and the power of one frequency in a signal, for tests that tell
drums apart by ear: the ideal membrane's (0,1) mode, j01 / (2 pi a) sqrt(T / sigma), and
Goertzel's single-bin power."""
import math

J01 = 2.404825557695773  # first zero of the Bessel function J0


def f01(radius, tension, density):
    """The (0,1) mode of an ideal circular membrane, Hz (radius m, tension N/m, kg/m^2)."""
    return J01 / (2.0 * math.pi * radius) * math.sqrt(tension / density)


def goertzel_power(x, rate, freq):
    """The power of x at freq (Hz), sampled at rate, by Goertzel's recurrence."""
    w = 2.0 * math.pi * freq / rate
    c = 2.0 * math.cos(w)
    s1 = s2 = 0.0
    for v in x:
        s1, s2 = v + c * s1 - s2, s1
    return s1 * s1 + s2 * s2 - c * s1 * s2
