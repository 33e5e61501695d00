"""The ground as data: its shape h(s) and its contact properties along the slope (docs/terrain.md).

s is the distance along the mean slope [m] (the slope frame's X, docs/model.md section 2) and
h(s) the height of the surface above the mean slope plane [m] (along Y). A `Ground` is one
immutable object, read and written as the ``[ground]`` table of scenes, studies, continuation
specs and the command line (`Ground.from_dict`, `Ground.to_dict`).

==========  ====================================================================================
kind        shape
==========  ====================================================================================
flat        h = 0 (the default: today's model, today's kernel, bitwise)
steps       height changes dh_i at edges s_i, each smoothed over ``width`` by the C2 quintic
            smoothstep 6u^5 - 15u^4 + 10u^3 (u from 0 to 1 across [s_i - width/2, s_i + width/2])
profile     points (s_i, h_i): ``order=2`` a natural cubic spline (C2), ``order=1`` the monotone
            piecewise cubic of Fritsch & Carlson (C1)
plane       a tilted plane h = -s tan(slope): the walker on slope gamma + slope
sine        amplitude sin(2 pi s / wavelength + phase)
random      a Gaussian rough ground of RMS height sigma and correlation length ell
            (covariance sigma^2 exp(-ds^2 / (2 ell^2))): the sum of ``modes`` random cosines
            sigma sqrt(2/M) sum cos(omega_m s + phi_m), omega_m ~ N(0, 1/ell^2),
            phi_m ~ U(0, 2 pi), drawn from numpy's PCG64 raw 64-bit output with a fixed
            transformation (the same seed gives the same ground on every machine and numpy)
==========  ====================================================================================

Every kind takes ``offset`` (a constant added to h [m]) and ``patches``; ``a + b`` adds the
heights of two grounds (e.g. steps + random; patches of one of them at most).

**Patches** (`Patch`) make the contact properties piecewise constant along s: between s_a and
s_b a patch sets any of k_n, d_n, k_t, d_t, mu_s, mu_d, v_s, v_d and the contact laws' own
parameters (e_n, v_in_min, sigma0, sigma1, sigma2, lg_mu_s, lg_mu_c, lg_v_s). A foot whose
contact point is within ``blend`` / 2 of a patch edge sees the two values blended by the C2
smoothstep; adaptive methods additionally end a step wherever a support foot's contact point
crosses a blend zone's boundary (an event, located like a flag switch), so no step steps over
an edge unnoticed.

**The compiled table** (`GroundTable`): h on knots s_0 < ... < s_n as a piecewise quintic
(Hermite in h, h', h'' at the knots: exact for the polynomial kinds, sampled finely enough for
sine and random; docs/terrain.md measures the error), a lookup grid for O(1) cell search, the arc
length sigma(s) (for the consistent variant's tangential anchor) and the patches; the C loop reads
it through ``pdw/core/csrc/pdw_ground.h``. The defined extent is [s_min, s_max]; a walker whose
foot leaves it stops with status ``fell`` and reason ``off_ground`` (never an extrapolation).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .errors import InvalidInputError
from .ground_shapes import (
    _array,
    _cubic_pieces,
    _natural_spline_second,
    _num,
    _pchip_slopes,
    _Poly,
    _random_modes,
)
from .ground_table import DEFAULT_EXTENT, GroundTable

KINDS = ("flat", "steps", "profile", "plane", "sine", "random", "sum")
#: the fields a patch may set (names of the kernel parameter vector, layout PARAMS + CONTACT_PARAMS)
PATCH_FIELDS = ("k_n", "d_n", "k_t", "d_t", "mu_s", "mu_d", "v_s", "v_d", "e_n", "v_in_min",
                "sigma0", "sigma1", "sigma2", "lg_mu_s", "lg_mu_c", "lg_v_s")
_POSITIVE = ("k_n", "v_s", "v_d", "sigma0", "lg_v_s", "v_in_min")      # > 0
_NONNEG = ("d_n", "k_t", "d_t", "mu_s", "mu_d", "sigma1", "sigma2", "lg_mu_s", "lg_mu_c")
#: samples per wavelength (sine) and per correlation length (random) of the table
SINE_KNOTS_PER_WAVELENGTH = 64
RANDOM_KNOTS_PER_ELL = 12


@dataclass(frozen=True)
class Patch:
    """Contact properties between s_a and s_b [m] (`PATCH_FIELDS`; unset fields keep the run's)."""

    s_a: float
    s_b: float
    values: tuple = ()          # ((field, value), ...), sorted by field name

    @classmethod
    def make(cls, s_a, s_b, where="patch", **values) -> "Patch":
        s_a = _num(where + ".s_a", s_a, unit="m")
        s_b = _num(where + ".s_b", s_b, unit="m")
        if not s_b > s_a:
            raise InvalidInputError("%s: s_b = %r must be > s_a = %r [m]" % (where, s_b, s_a))
        if not values:
            raise InvalidInputError("%s sets no property; allowed: %s" % (where, ", ".join(PATCH_FIELDS)))
        out = {}
        for k, v in values.items():
            if k not in PATCH_FIELDS:
                raise InvalidInputError("%s.%s is not a patch property; allowed: %s"
                                        % (where, k, ", ".join(PATCH_FIELDS)))
            name = "%s.%s (s in [%g, %g])" % (where, k, s_a, s_b)
            out[k] = _num(name, v, lo=0.0, lo_open=k in _POSITIVE)
        if "e_n" in out and not out["e_n"] <= 1.0:
            raise InvalidInputError("%s.e_n = %r is out of range; allowed: 0 < e_n <= 1" % (where, out["e_n"]))
        if "e_n" in out and not out["e_n"] > 0.0:
            raise InvalidInputError("%s.e_n = %r is out of range; allowed: 0 < e_n <= 1" % (where, out["e_n"]))
        return cls(s_a, s_b, tuple(sorted(out.items())))

    def as_dict(self) -> dict:
        return dict(s_a=self.s_a, s_b=self.s_b, **dict(self.values))


def _check_patches(patches, blend):
    out = []
    for i, p in enumerate(patches):
        if isinstance(p, Patch):
            p = Patch.make(p.s_a, p.s_b, where="ground.patches[%d]" % i, **dict(p.values))
        elif isinstance(p, dict):
            q = dict(p)
            if "s_a" not in q or "s_b" not in q:
                raise InvalidInputError("ground.patches[%d] needs s_a and s_b [m], got %r" % (i, p))
            p = Patch.make(q.pop("s_a"), q.pop("s_b"), where="ground.patches[%d]" % i, **q)
        else:
            raise InvalidInputError("ground.patches[%d] must be a pdw.Patch or a dict, got %s"
                                    % (i, type(p).__name__))
        out.append(p)
    for i in range(1, len(out)):
        a, b = out[i - 1], out[i]
        if b.s_a < a.s_a:
            raise InvalidInputError("ground.patches are not sorted: patch %d starts at s_a = %g < "
                                    "patch %d's s_a = %g" % (i, b.s_a, i - 1, a.s_a))
        if b.s_a < a.s_b:
            raise InvalidInputError("ground.patches overlap: patch %d [%g, %g] and patch %d [%g, %g]"
                                    " (allowed: s_a of each >= s_b of the one before)"
                                    % (i - 1, a.s_a, a.s_b, i, b.s_a, b.s_b))
    for i, p in enumerate(out):
        if p.s_b - p.s_a < blend:
            raise InvalidInputError("ground.patches[%d] [%g, %g] is shorter than ground.blend = %g m"
                                    % (i, p.s_a, p.s_b, blend))
    return tuple(out)


@dataclass(frozen=True)
class Ground:
    """The ground under the walker: shape h(s) [m] and contact patches (module docstring).

    Build one with the class methods (``flat``, `steps`, ``profile``, ``plane``, ``sine``, ``random``) or
    ``from_dict``; ``Ground()`` is flat. Frozen: ``replace``-style changes build a new one.
    """

    kind: str = "flat"
    spec: tuple = ()                # ((name, value), ...) of the kind's parameters
    offset: float = 0.0
    extent: tuple | None = None     # (s_min, s_max) [m]; None: DEFAULT_EXTENT (flat: unbounded)
    patches: tuple = ()
    blend: float = 0.01             # patch-edge blend width [m]
    parts: tuple = ()               # kind "sum": the grounds added
    # derived data (table, polynomial, modes, compiled forms); init=False so that
    # dataclasses.replace builds a new ground with its own cache, never the original's
    _cache: dict = field(default_factory=dict, init=False, compare=False, repr=False, hash=False)

    # ---- construction ------------------------------------------------------------------------
    def __post_init__(self):
        if self.kind not in KINDS:
            raise InvalidInputError("ground.kind must be one of %s, got %r" % (KINDS[:-1], self.kind))
        object.__setattr__(self, "offset", _num("ground.offset", self.offset, unit="m"))
        object.__setattr__(self, "blend", _num("ground.blend", self.blend, lo=0.0, lo_open=True, unit="m"))
        if self.extent is not None:
            e = _array("ground.extent", self.extent, 2)
            if not e[1] > e[0]:
                raise InvalidInputError("ground.extent = %r: s_max must be > s_min [m]" % (list(e),))
            object.__setattr__(self, "extent", (float(e[0]), float(e[1])))
        object.__setattr__(self, "patches", _check_patches(self.patches, self.blend))
        self._validate()

    def _spec(self):
        return dict(self.spec)

    def _validate(self):
        sp = self._spec()
        k = self.kind
        if k == "steps":
            e, dh = sp["edges"], sp["heights"]
            if len(e) != len(dh) or len(e) == 0:
                raise InvalidInputError("ground.edges and ground.heights must have the same length "
                                        ">= 1, got %d and %d" % (len(e), len(dh)))
            w = sp["width"]
            if np.any(np.diff(e) < w):
                raise InvalidInputError("ground.edges must be sorted and at least ground.width = %g m"
                                        " apart, got %r" % (w, list(e)))
        elif k == "profile":
            s = np.asarray(sp["s"])
            if len(s) < 2:
                raise InvalidInputError("ground.s (profile) needs at least 2 points, got %d" % len(s))
            if np.any(np.diff(s) == 0):
                raise InvalidInputError("ground.s (profile) repeats a value: the profile is not a "
                                        "function of s (a vertical or overhanging surface)")
            if np.any(np.diff(s) < 0):
                raise InvalidInputError("ground.s (profile) must be sorted increasing, got %r" % list(s))
        elif k == "sum":
            if sum(1 for p in self.parts if p.patches) + (1 if self.patches else 0) > 1:
                raise InvalidInputError("ground: patches on more than one ground of a sum")

    @classmethod
    def _make(cls, kind, spec, offset, extent, patches, blend):
        return cls(kind=kind, spec=tuple(sorted(spec.items())), offset=offset, extent=extent,
                   patches=tuple(patches or ()), blend=blend)

    @classmethod
    def flat(cls, *, offset=0.0, patches=(), extent=None, blend=0.01) -> "Ground":
        """Flat ground h = offset (the default; with offset 0 and no patches today's model)."""
        return cls._make("flat", {}, offset, extent, patches, blend)

    @classmethod
    def steps(cls, edges, heights, *, width=0.01, offset=0.0, patches=(), extent=None,
              blend=0.01) -> "Ground":
        """Height changes ``heights`` [m] (negative: a step down) at ``edges`` [m] along the slope,
        each smoothed over ``width`` [m] by the C2 quintic smoothstep."""
        e = _array("ground.edges", np.atleast_1d(edges))
        dh = _array("ground.heights", np.atleast_1d(heights))
        w = _num("ground.width", width, lo=0.0, lo_open=True, unit="m")
        return cls._make("steps", {"edges": tuple(e), "heights": tuple(dh), "width": w},
                         offset, extent, patches, blend)

    @classmethod
    def step(cls, at, height, **kw) -> "Ground":
        """One step of ``height`` [m] (negative: down) at s = ``at`` [m] (`steps`)."""
        return cls.steps([at], [height], **kw)

    @classmethod
    def profile(cls, s, h, *, order=2, offset=0.0, patches=(), extent=None, blend=0.01) -> "Ground":
        """Ground through the points (s_i, h_i) [m]: ``order=2`` natural cubic spline (C2),
        ``order=1`` monotone piecewise cubic (C1). s must increase strictly; beyond the points the
        ground continues linearly."""
        s = _array("ground.s", s)
        h = _array("ground.h", h, len(s))
        if order not in (1, 2):
            raise InvalidInputError("ground.order must be 1 (C1) or 2 (C2), got %r" % (order,))
        return cls._make("profile", {"s": tuple(s), "h": tuple(h), "order": int(order)},
                         offset, extent, patches, blend)

    @classmethod
    def plane(cls, slope, *, offset=0.0, patches=(), extent=None, blend=0.01) -> "Ground":
        """A tilted plane h = offset - s tan(slope) [rad]: on slope gamma, the walker on slope
        gamma + slope."""
        d = _num("ground.slope", slope, unit="rad")
        if not abs(d) < 0.5:
            raise InvalidInputError("ground.slope = %r is out of range; allowed: |slope| < 0.5 [rad]" % d)
        return cls._make("plane", {"slope": d}, offset, extent, patches, blend)

    @classmethod
    def sine(cls, amplitude, wavelength, *, phase=0.0, offset=0.0, patches=(), extent=None,
             blend=0.01) -> "Ground":
        """h = amplitude sin(2 pi s / wavelength + phase)."""
        a = _num("ground.amplitude", amplitude, unit="m")
        lam = _num("ground.wavelength", wavelength, lo=0.0, lo_open=True, unit="m")
        ph = _num("ground.phase", phase, unit="rad")
        return cls._make("sine", {"amplitude": a, "wavelength": lam, "phase": ph},
                         offset, extent, patches, blend)

    @classmethod
    def random(cls, sigma, correlation=0.1, *, seed=0, modes=128, offset=0.0, patches=(),
               extent=None, blend=0.01) -> "Ground":
        """Gaussian rough ground: RMS height ``sigma`` [m], correlation length ``correlation``
        [m] (covariance sigma^2 exp(-ds^2/(2 correlation^2))), from ``seed`` (module docstring)."""
        sig = _num("ground.sigma", sigma, lo=0.0, unit="m")
        ell = _num("ground.correlation", correlation, lo=0.0, lo_open=True, unit="m")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise InvalidInputError("ground.seed must be an integer >= 0, got %r" % (seed,))
        if isinstance(modes, bool) or not isinstance(modes, (int, np.integer)) or not 1 <= modes <= 4096:
            raise InvalidInputError("ground.modes must be an integer in [1, 4096], got %r" % (modes,))
        return cls._make("random", {"sigma": sig, "correlation": ell, "seed": int(seed),
                                    "modes": int(modes)}, offset, extent, patches, blend)

    def __add__(self, other):
        if not isinstance(other, Ground):
            return NotImplemented
        parts = tuple(p for g in (self, other) for p in (g.parts if g.kind == "sum" else (g,)))
        ext = [g.extent for g in parts if g.extent is not None]
        extent = (max(e[0] for e in ext), min(e[1] for e in ext)) if ext else None
        patched = [g for g in parts if g.patches]
        if len(patched) > 1:
            raise InvalidInputError("ground: patches on more than one ground of a sum")
        return Ground(kind="sum", parts=tuple(Ground(**{**g._fields(), "patches": (), "extent": None})
                                              for g in parts),
                      extent=extent, patches=patched[0].patches if patched else (),
                      blend=patched[0].blend if patched else 0.01)

    def _fields(self):
        return dict(kind=self.kind, spec=self.spec, offset=self.offset, extent=self.extent,
                    patches=self.patches, blend=self.blend, parts=self.parts)

    def with_patches(self, patches, *, blend=None) -> "Ground":
        """This ground with ``patches`` (a list of `Patch` or dicts with s_a, s_b and properties)."""
        return Ground(**{**self._fields(), "patches": tuple(patches),
                         "blend": self.blend if blend is None else blend})

    @classmethod
    def coerce(cls, ground) -> "Ground":
        """A `Ground` from None (flat), a Ground or a dict (``from_dict``)."""
        if ground is None:
            return cls()
        if isinstance(ground, cls):
            return ground
        if isinstance(ground, dict):
            return cls.from_dict(ground)
        raise InvalidInputError("ground must be a pdw.Ground or a dict ([ground] table), got %s"
                                % type(ground).__name__)

    # ---- properties ------------------------------------------------------------------------------
    @property
    def is_flat(self) -> bool:
        """Flat, at height 0, no patches, unbounded: today's kernel runs it (bitwise today's
        model). A flat ground with an extent runs the shaped kernel (it can be left)."""
        return self.kind == "flat" and self.offset == 0.0 and not self.patches and self.extent is None

    @property
    def s_range(self) -> tuple:
        """The defined extent (s_min, s_max) [m]."""
        if self.extent is not None:
            return self.extent
        return (-math.inf, math.inf) if self.is_flat else DEFAULT_EXTENT

    def patched_params(self, params) -> list:
        """``params`` and, for each patch, ``params`` with the patch's `pdw.Params` fields (for
        the step-size check of fixed-step methods)."""
        names = set(params.as_dict())
        out = [params]
        for p in self.patches:
            ch = {k: v for k, v in p.values if k in names}
            if ch:
                out.append(params.replace(**ch))
        return out

    # ---- evaluation ------------------------------------------------------------------------------
    def evaluate(self, s):
        """(h, h', h'') at s [m] (array-like): the exact shape, in NumPy ([m], [-], [1/m])."""
        s = np.asarray(s, dtype=float)
        h, d, dd = self._shape(s)
        return h + self.offset, d, dd

    def h(self, s):
        """Height h(s) [m]."""
        return self.evaluate(s)[0]

    def dh(self, s):
        """Slope h'(s) [-]."""
        return self.evaluate(s)[1]

    def ddh(self, s):
        """Curvature term h''(s) [1/m]."""
        return self.evaluate(s)[2]

    def _poly(self):
        if "poly" not in self._cache:
            self._cache["poly"] = self._build_poly()
        return self._cache["poly"]

    def _build_poly(self):
        sp = self._spec()
        if self.kind == "profile":
            s, h = np.array(sp["s"]), np.array(sp["h"])
            if sp["order"] == 2:
                c = _cubic_pieces(s, h, None, _natural_spline_second(s, h))
            else:
                c = _cubic_pieces(s, h, _pchip_slopes(s, h))
            # linear continuation beyond the ends (value and slope of the end points)
            d0 = c[0, 1]
            xe = s[-1] - s[-2]
            he = c[-1, 0] + xe * (c[-1, 1] + xe * (c[-1, 2] + xe * c[-1, 3]))
            de = c[-1, 1] + xe * (2 * c[-1, 2] + 3 * xe * c[-1, 3])
            bp = np.concatenate([[-1e12], s, [1e12]])
            org = np.concatenate([[s[0]], s[:-1], [s[-1]]])
            c = np.vstack([[h[0], d0, 0, 0], c, [he, de, 0, 0]])
            return _Poly(bp, c, org)
        if self.kind == "steps":
            e, dh, w = np.array(sp["edges"]), np.array(sp["heights"]), sp["width"]
            bp, org, cs, level = [-1e12], [0.0], [], 0.0
            for ei, hi in zip(e, dh):
                a = ei - 0.5 * w
                cs.append([level, 0, 0, 0, 0, 0])
                bp.append(a)
                org.append(a)
                # level + hi (10 u^3 - 15 u^4 + 6 u^5), u = (s - a) / w
                cs.append([level, 0, 0, 10 * hi / w ** 3, -15 * hi / w ** 4, 6 * hi / w ** 5])
                bp.append(ei + 0.5 * w)
                org.append(ei + 0.5 * w)
                level += hi
            cs.append([level, 0, 0, 0, 0, 0])
            bp.append(1e12)
            return _Poly(np.array(bp), np.array(cs), np.array(org[:len(cs)]))
        if self.kind == "plane":
            return _Poly(np.array([-1e12, 1e12]), np.array([[0.0, -math.tan(sp["slope"])]]), np.array([0.0]))
        return None

    def _shape(self, s):
        sp = self._spec()
        k = self.kind
        if k == "flat":
            z = np.zeros_like(s)
            return z, z.copy(), z.copy()
        if k in ("profile", "steps", "plane"):
            return tuple(self._poly().eval(s))
        if k == "sine":
            a, kk = sp["amplitude"], 2.0 * math.pi / sp["wavelength"]
            arg = kk * s + sp["phase"]
            return a * np.sin(arg), a * kk * np.cos(arg), -a * kk * kk * np.sin(arg)
        if k == "random":
            om, ph = self._modes()
            amp = sp["sigma"] * math.sqrt(2.0 / len(om))
            arg = np.multiply.outer(s, om) + ph
            c, sn = np.cos(arg), np.sin(arg)
            return amp * c.sum(-1), -amp * (sn * om).sum(-1), -amp * (c * om * om).sum(-1)
        out = [np.zeros_like(s) for _ in range(3)]        # sum
        for g in self.parts:
            for i, v in enumerate(g.evaluate(s)):
                out[i] = out[i] + v
        return tuple(out)

    def _modes(self):
        if "modes" not in self._cache:
            sp = self._spec()
            self._cache["modes"] = _random_modes(sp["seed"], sp["modes"], sp["correlation"])
        return self._cache["modes"]

    # ---- the compiled table ----------------------------------------------------------------------
    def _knots(self, lo, hi):
        """Knots the table needs in [lo, hi]: the breakpoints of the polynomial kinds, a uniform
        grid for sine and random."""
        k, sp = self.kind, self._spec()
        if k == "flat":
            return np.array([lo, hi])
        if k in ("profile", "steps", "plane"):
            bp = self._poly().bp
            return np.unique(np.concatenate([[lo, hi], bp[(bp > lo) & (bp < hi)]]))
        if k == "sine":
            dx = sp["wavelength"] / SINE_KNOTS_PER_WAVELENGTH
        elif k == "random":
            dx = sp["correlation"] / RANDOM_KNOTS_PER_ELL
        else:
            return np.unique(np.concatenate([g._knots(lo, hi) for g in self.parts]))
        n = max(1, int(math.ceil((hi - lo) / dx)))
        return np.linspace(lo, hi, n + 1)

    def table(self) -> "GroundTable":
        """The compiled form the C loop reads (cached)."""
        if "table" not in self._cache:
            self._cache["table"] = GroundTable.build(self)
        return self._cache["table"]

    def __getstate__(self):
        """Pickle (executors, processes) without the compiled structs, which hold C pointers;
        the table and the other derived data travel."""
        state = dict(self.__dict__)
        state["_cache"] = {k: v for k, v in self._cache.items()
                           if not (isinstance(k, tuple) and k[0] == "compiled")}
        return state

    def compiled(self, maker):
        """``maker(self.table())``, made once per maker and kept (cached).

        The compiled extension modules' ground structs (``CGround``) check the table and
        bound it over its extent (pdw_ground.h, ``pdw_ground_set_bounds``) in time linear in
        its cells: 4160 cells for a 52 m sine, about 45 us, paid once per Ground instead of
        once per run. The struct only reads the table, which a Ground never changes.
        """
        key = ("compiled", maker)
        if key not in self._cache:
            self._cache[key] = maker(self.table())
        return self._cache[key]

    # ---- TOML -----------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """The ``[ground]`` table (``from_dict`` reads it back to an equal Ground)."""
        d: dict = {"kind": self.kind}
        for k, v in self.spec:
            d[k] = list(v) if isinstance(v, tuple) else v
        if self.offset:
            d["offset"] = self.offset
        if self.extent is not None:
            d["extent"] = list(self.extent)
        if self.patches:
            d["patches"] = [p.as_dict() for p in self.patches]
            d["blend"] = self.blend
        if self.kind == "sum":
            d["parts"] = [g.to_dict() for g in self.parts]
        return d

    @classmethod
    def from_dict(cls, d) -> "Ground":
        """A Ground from its ``[ground]`` table: ``kind`` and the kind's parameters (the class
        methods' arguments), ``offset``, ``extent``, ``patches`` (a list of tables with s_a, s_b
        and properties) and ``blend``."""
        if not isinstance(d, dict):
            raise InvalidInputError("[ground] must be a table, got %s" % type(d).__name__)
        d = dict(d)
        kind = d.pop("kind", "flat")
        common = {k: d.pop(k) for k in ("offset", "extent", "patches", "blend") if k in d}
        if kind == "sum":
            parts = d.pop("parts", None)
            if not isinstance(parts, list) or not parts:
                raise InvalidInputError("[ground] kind = 'sum' needs parts = [ {...}, ... ]")
            _no_more(d, "sum")
            g = cls.from_dict(parts[0])
            for p in parts[1:]:
                g = g + cls.from_dict(p)
            return g.with_patches(common.get("patches", ()), blend=common.get("blend")) \
                if common.get("patches") else g
        makers: dict[str, tuple[Callable[..., Ground], tuple[str, ...]]] = {
            "flat": (cls.flat, ()), "steps": (cls.steps, ("edges", "heights")),
            "profile": (cls.profile, ("s", "h")), "plane": (cls.plane, ("slope",)),
            "sine": (cls.sine, ("amplitude", "wavelength")),
            "random": (cls.random, ("sigma",))}
        optional = {"flat": (), "steps": ("width",), "profile": ("order",), "plane": (),
                    "sine": ("phase",), "random": ("correlation", "seed", "modes")}
        if kind not in makers:
            raise InvalidInputError("ground.kind must be one of %s, got %r" % (KINDS[:-1], kind))
        fn, required = makers[kind]
        missing = [k for k in required if k not in d]
        if missing:
            raise InvalidInputError("[ground] kind = %r needs %s" % (kind, ", ".join(missing)))
        args = [d.pop(k) for k in required]
        kw = {k: d.pop(k) for k in optional[kind] if k in d}
        _no_more(d, kind)
        return fn(*args, **kw, **common)


def _no_more(d, kind):
    if d:
        raise InvalidInputError("unknown [ground] field(s) %s for kind %r" % (", ".join(sorted(d)), kind))
