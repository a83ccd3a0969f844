#!/usr/bin/env python3
"""Reference numbers for tests/core/test_plate_cascade.cpp, by a second method.

The von Karman coefficients H = integral over the unit disc of chi_a L(W_i, W_j) for a
few triples (an in-plane mode of the clamped biharmonic problem, two free-edge plate
modes), computed independently of externals/core/plate_cascade.c:
  - the roots with scipy's brentq on scipy's jv/iv (the plate's lambda from the bending
    moment and shear conditions, the in-plane zeta from J_m I_m+1 + J_m+1 I_m = 0);
  - the bracket L(w, F) = w_xx F_yy + w_yy F_xx - 2 w_xy F_xy in Cartesian coordinates,
    its second derivatives by central finite differences of the Cartesian fields
    (the code uses the polar form with Bessel recurrences);
  - a polar grid of 160 Gauss-Legendre radii and 96 angles (the code: 96 radii, exact
    angular sums).
Run: /usr/bin/python3 tests/core/plate_cascade_reference.py (needs numpy, scipy).
"""
import numpy as np
from scipy.optimize import brentq
from scipy.special import iv, ivp, jv, jvp

NU = 0.33


def free_det(m, lam):
    """Determinant of the free edge's moment and effective-shear conditions at r = 1."""
    def rows(f, fp, fpp, fppp):
        moment = lam**2 * fpp + NU * (lam * fp - m * m * f)
        # (lap W)' - (1 - nu) m^2 (W' - W) with lap W = W'' + W' - m^2 W (r = 1)
        lap_p = lam**3 * fppp + lam**2 * fpp - lam * fp - m * m * (lam * fp - 2 * f)
        shear = lap_p - (1 - NU) * m * m * (lam * fp - f)
        return moment, shear
    a = rows(jv(m, lam), jvp(m, lam, 1), jvp(m, lam, 2), jvp(m, lam, 3))
    b = rows(iv(m, lam), ivp(m, lam, 1), ivp(m, lam, 2), ivp(m, lam, 3))
    return a[0] * b[1] - a[1] * b[0]


def nth_root(func, s, start=0.5, step=0.01):
    seen, x0, f0 = 0, start, func(start)
    while True:
        x1 = x0 + step
        f1 = func(x1)
        if np.sign(f0) != np.sign(f1):
            if seen == s:
                return brentq(func, x0, x1, xtol=1e-15)
            seen += 1
        x0, f0 = x1, f1


R, WR = np.polynomial.legendre.leggauss(160)
R, WR = 0.5 * (R + 1.0), 0.5 * WR
TH = np.arange(96) * 2 * np.pi / 96
RR, TT = np.meshgrid(R, TH, indexing="ij")
X, Y = RR * np.cos(TT), RR * np.sin(TT)
WEIGHT = (WR * R)[:, None] * (2 * np.pi / 96)


def plate_mode(m, s, sin):
    """Free-edge mode (m, s): s nodal circles (the s-th root for m >= 2, s-1-th for m < 2)."""
    lam = nth_root(lambda x: free_det(m, x), s if m >= 2 else s - 1, start=0.3)
    num = lam**2 * jvp(m, lam, 2) + NU * (lam * jvp(m, lam, 1) - m * m * jv(m, lam))
    den = lam**2 * ivp(m, lam, 2) + NU * (lam * ivp(m, lam, 1) - m * m * iv(m, lam))
    c = -num / den
    return make_field(m, sin, lambda r: jv(m, lam * r) + c * iv(m, lam * r)), lam


def inplane_mode(m, s, sin):
    zeta = nth_root(lambda x: jv(m, x) * iv(m + 1, x) + jv(m + 1, x) * iv(m, x), s)
    c = -jv(m, zeta) / iv(m, zeta)
    return make_field(m, sin, lambda r: jv(m, zeta * r) + c * iv(m, zeta * r)), zeta


def make_field(m, sin, radial):
    ang = (lambda t: np.sin(m * t)) if sin else (lambda t: np.cos(m * t))
    def raw(x, y):
        return radial(np.hypot(x, y)) * ang(np.arctan2(y, x))
    norm = np.sqrt(np.sum(WEIGHT * raw(X, Y) ** 2))
    return lambda x, y: raw(x, y) / norm


def hessian(f, h=2e-4):
    fxx = (f(X + h, Y) - 2 * f(X, Y) + f(X - h, Y)) / h**2
    fyy = (f(X, Y + h) - 2 * f(X, Y) + f(X, Y - h)) / h**2
    fxy = (f(X + h, Y + h) - f(X + h, Y - h) - f(X - h, Y + h) + f(X - h, Y - h)) / (4 * h * h)
    return fxx, fyy, fxy


def h_coefficient(chi, wi, wj):
    a, b = hessian(wi), hessian(wj)
    bracket = a[0] * b[1] + a[1] * b[0] - 2 * a[2] * b[2]
    return np.sum(WEIGHT * chi(X, Y) * bracket)


def main():
    # (in-plane m, s, sin), (plate m, s, sin), (plate m, s, sin)
    triples = [
        ((0, 0, 0), (2, 0, 0), (2, 0, 0)),
        ((0, 0, 0), (2, 0, 1), (2, 0, 1)),
        ((4, 0, 0), (2, 0, 0), (2, 0, 0)),
        ((4, 0, 1), (2, 0, 0), (2, 0, 1)),
        ((1, 0, 0), (2, 0, 0), (3, 0, 0)),
        ((2, 0, 0), (0, 1, 0), (2, 0, 0)),
        ((0, 1, 0), (0, 1, 0), (0, 1, 0)),
        ((5, 0, 1), (2, 0, 1), (3, 0, 0)),
    ]
    for ip, ti, tj in triples:
        chi, zeta = inplane_mode(*ip)
        wi, li = plate_mode(*ti)
        wj, lj = plate_mode(*tj)
        print(f"{{{ip}, {ti}, {tj}, zeta {zeta:.12f}, H {h_coefficient(chi, wi, wj):.9g}}}")
    # the backbone of the (2, 0) cos mode: H^a_00 for the in-plane modes with zeta < 8
    w, lam = plate_mode(2, 0, 0)
    print(f"(2,0) lambda {lam:.12f}")
    for m, s in [(0, 0), (0, 1), (4, 0)]:
        chi, zeta = inplane_mode(m, s, 0)
        print(f"backbone: in-plane ({m},{s}) zeta {zeta:.12f} H {h_coefficient(chi, w, w):.9g}")


if __name__ == "__main__":
    main()
