"""The air's mass on a circular head's modes (docs/membrane.md, "The air's mass"), computed
for the tests by a route of its own: the mode's Hankel transform by quadrature over the head,
then the low-frequency radiation reactance of a baffled head (Morse & Ingard, Theoretical
Acoustics, sec. 7.4), M_air = rho_air a^3 (2 pi or pi) int_0^inf H(k)^2 dk, over the mode's
own mass sigma a^2 (2 pi or pi) J_m'(j)^2 / 2. membrane~ integrates the transform's closed
Lommel form instead (mode_table_air_g); the two agree to 1e-4."""
import functools
import math

import numpy as np
from scipy.integrate import quad
from scipy.special import jn_zeros, jv

RHO_AIR = 1.2  # kg/m^3, as membrane.h


@functools.lru_cache(maxsize=None)
def air_g(m, n):
    """The air's mass on mode (m, n) over the mode's own, per unit of rho_air a / sigma."""
    j = jn_zeros(m, n)[-1]

    def hankel(k):
        return quad(lambda r: jv(m, j * r) * jv(m, k * r) * r, 0.0, 1.0, limit=200)[0]

    # int_0^inf H^2 dk on the unit disc, by panels of pi/2 to 3 j + 60; the tail with
    # J_m(k)^2 ~ 1 / (pi k) and (k^2 - j^2)^2 ~ k^4 (the transform's asymptote)
    edges = np.arange(0.0, 3.0 * j + 60.0 + 1e-9, 0.5 * math.pi)
    total = sum(quad(lambda k: hankel(k) ** 2, a, b, limit=50)[0]
                for a, b in zip(edges[:-1], edges[1:]))
    total += (j * jv(m + 1, j)) ** 2 / (4.0 * math.pi * edges[-1] ** 4)
    return total / (0.5 * jv(m + 1, j) ** 2)
