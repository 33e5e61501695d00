"""The shapes of `pdw.Ground` (pdw/core/ground.py): number checks, piecewise polynomials, the
natural cubic spline and the monotone cubic of the profile kind, the random ground's modes."""
from __future__ import annotations

import math

import numpy as np

from .errors import InvalidInputError


def _num(name, v, *, lo=None, lo_open=False, unit=""):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise InvalidInputError("%s must be a number, got %r" % (name, v))
    v = float(v)
    if not math.isfinite(v):
        raise InvalidInputError("%s = %r is out of range; allowed: finite%s" % (name, v,
                                (" [%s]" % unit) if unit else ""))
    if lo is not None and (v <= lo if lo_open else v < lo):
        raise InvalidInputError("%s = %r is out of range; allowed: %s %g%s" % (
            name, v, ">" if lo_open else ">=", lo, (" [%s]" % unit) if unit else ""))
    return v


def _array(name, v, n=None):
    try:
        a = np.array(v, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidInputError("%s must be a list of numbers, got %r" % (name, v)) from None
    if n is not None and len(a) != n:
        raise InvalidInputError("%s has %d entries, expected %d" % (name, len(a), n))
    if not np.all(np.isfinite(a)):
        raise InvalidInputError("%s must be finite, got %r" % (name, list(a)))
    return a


def smoothstep(u):
    """The C2 quintic smoothstep 6u^5 - 15u^4 + 10u^3 on [0, 1] (0 below, 1 above) and its first
    two derivatives in u."""
    u = np.clip(u, 0.0, 1.0)
    return (u ** 3 * (10.0 + u * (-15.0 + 6.0 * u)), 30.0 * u ** 2 * (1.0 - u) ** 2,
            60.0 * u * (1.0 - u) * (1.0 - 2.0 * u))


def _natural_spline_second(s, h):
    """Second derivatives at the knots of the natural cubic spline through (s, h) (Thomas)."""
    n = len(s)
    m = np.zeros(n)
    if n < 3:
        return m
    w = np.diff(s)
    a = w[:-1].copy()
    b = 2.0 * (w[:-1] + w[1:])
    c = w[1:].copy()
    d = 6.0 * (np.diff(h[1:]) / w[1:] - np.diff(h[:-1]) / w[:-1])
    for i in range(1, n - 2):
        f = a[i] / b[i - 1]
        b[i] -= f * c[i - 1]
        d[i] -= f * d[i - 1]
    x = np.zeros(n - 2)
    x[-1] = d[-1] / b[-1]
    for i in range(n - 4, -1, -1):
        x[i] = (d[i] - c[i] * x[i + 1]) / b[i]
    m[1:-1] = x
    return m


def _pchip_slopes(s, h):
    """Fritsch-Carlson monotone slopes at the knots (as scipy's PchipInterpolator)."""
    w = np.diff(s)
    delta = np.diff(h) / w
    n = len(s)
    d = np.zeros(n)
    if n == 2:
        return np.full(2, delta[0])
    for k in range(1, n - 1):
        if delta[k - 1] * delta[k] > 0:
            w1, w2 = 2 * w[k] + w[k - 1], w[k] + 2 * w[k - 1]
            d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k])

    def end(h0, h1, m0, m1):
        dd = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
        if np.sign(dd) != np.sign(m0):
            return 0.0
        if np.sign(m0) != np.sign(m1) and abs(dd) > abs(3 * m0):
            return 3 * m0
        return dd
    d[0] = end(w[0], w[1], delta[0], delta[1]) if n > 2 else delta[0]
    d[-1] = end(w[-1], w[-2], delta[-1], delta[-2]) if n > 2 else delta[-1]
    return d


class _Poly:
    """A piecewise polynomial: breakpoints bp (n+1,), coefficients c (n, k) in powers of
    s - org_i (org_i = bp_i unless given); the end pieces extend beyond bp's ends."""

    def __init__(self, bp, c, org=None):
        self.bp = np.asarray(bp, float)
        self.c = np.asarray(c, float)
        self.org = self.bp[:-1] if org is None else np.asarray(org, float)   # origin of each piece

    def piece(self, s):
        return np.clip(np.searchsorted(self.bp, s, side="right") - 1, 0, len(self.bp) - 2)

    def eval(self, s, piece=None):
        s = np.asarray(s, float)
        i = self.piece(s) if piece is None else piece
        x = s - self.org[i]
        c = self.c[i]
        k = self.c.shape[1]
        out = []
        for der in range(3):
            acc = np.zeros_like(x)
            for j in range(k - 1, der - 1, -1):
                f = math.factorial(j) / math.factorial(j - der)
                acc = acc * x + f * c[..., j]
            out.append(acc)
        return out


def _cubic_pieces(s, h, d, m=None):
    """Cubic pieces from values h, slopes d (and, for a spline, second derivatives m)."""
    w = np.diff(s)
    dl = np.diff(h) / w
    if m is not None:
        c = np.stack([h[:-1], dl - w * (2 * m[:-1] + m[1:]) / 6.0, m[:-1] / 2.0,
                      (m[1:] - m[:-1]) / (6.0 * w)], axis=1)
    else:
        c = np.stack([h[:-1], d[:-1], (3 * dl - 2 * d[:-1] - d[1:]) / w,
                      (d[:-1] + d[1:] - 2 * dl) / w ** 2], axis=1)
    return c


def _random_modes(seed, modes, ell):
    """(omega (M,), phi (M,)) from PCG64(seed)'s raw 64-bit output: three uniforms
    (r >> 11) 2^-53 per mode, a normal from the first two by Box-Muller (math.log, math.cos), the
    phase 2 pi u from the third. numpy guarantees PCG64's raw stream; the transformation is ours."""
    raw = np.random.PCG64(seed).random_raw(3 * modes)
    u = [(int(r) >> 11) * 2.0 ** -53 for r in raw]
    omega, phi = [], []
    for m in range(modes):
        u1, u2, u3 = u[3 * m], u[3 * m + 1], u[3 * m + 2]
        omega.append(math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(2.0 * math.pi * u2) / ell)
        phi.append(2.0 * math.pi * u3)
    return np.array(omega), np.array(phi)
