"""The compiled form of a `pdw.Ground` (pdw/core/ground.py) that the C loop reads through
pdw/core/csrc/pdw_ground.h: the piecewise-quintic height table, its arc length, the lookup grid,
the patches and the blend zones."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _layout

_P = {n: i for i, n in enumerate(_layout.PARAMS + _layout.DERIVED + _layout.CONTACT_PARAMS)}
#: the default defined extent [m] of every non-flat ground
DEFAULT_EXTENT = (-2.0, 50.0)


def _hermite5(w, v0, v1):
    """Quintic coefficients in u = (s - s0)/w on [0, 1] from (h, h', h'') at both ends."""
    h0, d0, s0 = v0
    h1, d1, s1 = v1
    a0, a1, a2 = h0, w * d0, 0.5 * w * w * s0
    A = h1 - a0 - a1 - a2
    B = w * d1 - a1 - 2.0 * a2
    C = w * w * s1 - 2.0 * a2
    return np.stack([a0, a1, a2, 10 * A - 4 * B + 0.5 * C, -15 * A + 7 * B - C,
                     6 * A - 3 * B + 0.5 * C], axis=-1)


#: Gauss-Legendre nodes and weights on [0, 1] (8 points) for the arc length of a cell
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_X, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W


@dataclass(frozen=True)
class GroundTable:
    """The compiled ground (`pdw/core/csrc/pdw_ground.h`), NumPy arrays the C loop reads.

    cells : (n, 8) float64: per cell [s_k, 1/w_k, a_0 .. a_5], h = sum a_j d^j, d = s - s_k [m]
        (the quintic in d, not in u = d/w_k: the C evaluator's h' then waits on no scaling)
    arc : (n, 6) float64: the arc length sigma(s) = int_{s_min}^s sqrt(1 + h'^2) ds, same form
    lut : (m,) int64: the cell containing s_min + j / lut_inv (O(1) search)
    patch_fields : (f,) int32: kernel parameter indices (`_layout` PARAMS + CONTACT_PARAMS) patched
    patches : (p, 2 + f) float64: [s_a, s_b, values (NaN: not set)]
    zones : (z,) float64: sorted s where a support foot's blend zone changes (events)
    """

    s_min: float
    s_max: float
    cells: np.ndarray
    arc: np.ndarray
    lut: np.ndarray
    lut_inv: float
    patch_fields: np.ndarray
    patches: np.ndarray
    zones: np.ndarray
    blend: float

    @classmethod
    def build(cls, g) -> "GroundTable":
        """The table of `pdw.Ground` g."""
        lo, hi = g.s_range
        if not (math.isfinite(lo) and math.isfinite(hi)):
            lo, hi = DEFAULT_EXTENT
        knots = g._knots(lo, hi)
        n = len(knots) - 1
        a, b = knots[:-1], knots[1:]
        w = b - a
        mid = 0.5 * (a + b)
        # one-sided values at each cell's ends (the piece of the cell's midpoint)
        va, vb = _knot_values(g, knots, mid)
        # + 0.0: every zero coefficient +0 (a -0 becomes +0, the same polynomial): a flat cell's
        # a_1 .. a_5 are then all bits zero, which the C kernel's level-cell test reads
        # (pdw_ground.h pdw_ground_cell_level)
        coef = _hermite5(w, va, vb) + 0.0
        cells = np.column_stack([a, 1.0 / w, _in_d(coef, w, va)])
        # arc length: exact values at the knots by Gauss-Legendre on the table's own polynomial,
        # Hermite within the cell from sigma' = sqrt(1 + h'^2), sigma'' = h' h'' / sigma'
        u = _GL_X
        dpoly = np.stack([coef[:, 1], 2 * coef[:, 2], 3 * coef[:, 3], 4 * coef[:, 4], 5 * coef[:, 5]], 1)
        upow = np.stack([u ** j for j in range(5)], 0)              # (5, 8)
        dh = (dpoly @ upow) / w[:, None]                             # (n, 8)
        seg = (np.sqrt(1.0 + dh ** 2) @ _GL_W) * w
        sig = np.concatenate([[0.0], np.cumsum(seg)])
        d_a, dd_a = _cell_derivs(coef, w, 0.0)
        d_b, dd_b = _cell_derivs(coef, w, 1.0)
        na, nb = np.sqrt(1 + d_a ** 2), np.sqrt(1 + d_b ** 2)
        arc = _hermite5(w, (sig[:-1], na, d_a * dd_a / na), (sig[1:], nb, d_b * dd_b / nb))
        m = int(min(max(n, math.ceil((hi - lo) / max(w.min(), 1e-12))) + 1, 4 * n + 1_000_000))
        grid = lo + np.arange(m) * ((hi - lo) / m)
        lut = np.clip(np.searchsorted(knots, grid, side="right") - 1, 0, n - 1).astype(np.int64)
        fields = sorted({k for p in g.patches for k, _ in p.values}, key=lambda k: _P[k])
        pf = np.array([_P[k] for k in fields], dtype=np.int32)
        pt = np.full((len(g.patches), 2 + len(fields)), np.nan)
        zones = []
        for i, p in enumerate(g.patches):
            pt[i, 0], pt[i, 1] = p.s_a, p.s_b
            for k, v in p.values:
                pt[i, 2 + fields.index(k)] = v
            zones += [p.s_a - g.blend / 2, p.s_a + g.blend / 2, p.s_b - g.blend / 2, p.s_b + g.blend / 2]
        return cls(s_min=float(lo), s_max=float(hi), cells=np.ascontiguousarray(cells),
                   arc=np.ascontiguousarray(arc), lut=lut, lut_inv=m / (hi - lo),
                   patch_fields=pf, patches=np.ascontiguousarray(pt),
                   zones=np.unique(np.array(zones, float)), blend=g.blend)

    def evaluate(self, s):
        """(h, h', h'') from the table (what the C evaluator computes), for tests and plots."""
        s = np.asarray(s, float)
        k = np.clip(np.searchsorted(self.cells[:, 0], s, side="right") - 1, 0, len(self.cells) - 1)
        c = self.cells[k]
        u = s - c[..., 0]
        a = c[..., 2:]
        h = a[..., 5]
        for j in range(4, -1, -1):
            h = h * u + a[..., j]
        d = 5 * a[..., 5]
        for j in range(4, 0, -1):
            d = d * u + j * a[..., j]
        dd = 20 * a[..., 5]
        for j in range(4, 1, -1):
            dd = dd * u + j * (j - 1) * a[..., j]
        return h, d, dd

    def arc_length(self, s):
        """sigma(s) [m] from the table."""
        s = np.asarray(s, float)
        k = np.clip(np.searchsorted(self.cells[:, 0], s, side="right") - 1, 0, len(self.cells) - 1)
        u = (s - self.cells[k, 0]) * self.cells[k, 1]
        a = self.arc[k]
        out = a[..., 5]
        for j in range(4, -1, -1):
            out = out * u + a[..., j]
        return out


def _in_d(coef, w, va):
    """The quintic in u = d/w (`_hermite5`) as one in d: a_j / w^j, the first three exactly the
    cell's start values h, h', h''/2 (+ 0.0: every zero coefficient +0, as `build` needs)."""
    out = coef / w[:, None] ** np.arange(6)
    out[:, 0], out[:, 1], out[:, 2] = va[0], va[1], 0.5 * va[2]
    return out + 0.0


def _knot_values(g, knots, mid):
    """(h, h', h'') of g at each cell's start and end, one-sided (the piece of the cell's
    midpoint ``mid``); a smooth shape is evaluated once per knot."""
    if g.kind in ("profile", "steps", "plane"):
        return _one_sided(g, knots[:-1], mid), _one_sided(g, knots[1:], mid)
    if g.kind == "sum":
        va = [np.full(len(mid), g.offset), np.zeros(len(mid)), np.zeros(len(mid))]
        vb = [np.full(len(mid), g.offset), np.zeros(len(mid)), np.zeros(len(mid))]
        for p in g.parts:
            pa, pb = _knot_values(p, knots, mid)
            for i in range(3):
                va[i] = va[i] + pa[i]
                vb[i] = vb[i] + pb[i]
        return tuple(va), tuple(vb)
    v = g.evaluate(knots)
    return tuple(x[:-1] for x in v), tuple(x[1:] for x in v)


def _one_sided(g, s, mid):
    """(h, h', h'') of g at s taken on the piece of ``mid`` (one-sided at breakpoints)."""
    if g.kind in ("profile", "steps", "plane"):
        poly = g._poly()
        h, d, dd = poly.eval(s, poly.piece(mid))
        return h + g.offset, d, dd
    if g.kind == "sum":
        out = [np.zeros_like(s) + g.offset, np.zeros_like(s), np.zeros_like(s)]
        for p in g.parts:
            for i, v in enumerate(_one_sided(p, s, mid)):
                out[i] = out[i] + v
        return tuple(out)
    return g.evaluate(s)


def _cell_derivs(coef, w, u):
    d = sum(j * coef[:, j] * u ** (j - 1) for j in range(1, 6)) / w
    dd = sum(j * (j - 1) * coef[:, j] * u ** (j - 2) for j in range(2, 6)) / w ** 2
    return d, dd
