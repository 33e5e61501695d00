"""Model parameters (paper Tables 1-3, docs/model.md section 1) with validation."""
from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from . import _layout
from .checks import _real
from .errors import InvalidInputError

#: The paper's initial state of the typical gait (Sec. 3.2), flags (swing, support) = (0, 1).
X0_PAPER = (0.0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093)
#: The disturbed start of the paper's Fig. 9.
X0_DISTURBED = (0.0, 0.4840, 0.3285, -0.3285, 0.6875, 0.1375, -1.4206, -1.2684)


def _f(default, unit, doc, lo=None, hi=None, lo_open=True, hi_open=True):
    return field(default=default, metadata=dict(unit=unit, doc=doc, lo=lo, hi=hi,
                                                lo_open=lo_open, hi_open=hi_open))


@dataclass(frozen=True)
class Params:
    """Parameters of the walker and the ground, SI units, named after the paper's symbols.

    The defaults are `Params.paper()` (docs/model.md section 1). Every field is checked on
    construction: a NaN, a non-positive mass or length, ``r >= l``, or ``v_s >= v_d``
    raises `pdw.InvalidInputError` (a `ValueError`) naming the field and its allowed range.

    Use ``dataclasses.replace`` (or `Params.replace`) to change fields.
    """

    l: float = _f(0.5, "m", "leg length, hip to foot", lo=0.0)
    c: float = _f(0.1, "m", "hip to leg centre of mass, along the leg", lo=0.0, lo_open=False)
    w: float = _f(-0.0025, "m", "leg mass offset, perpendicular to the leg")
    r: float = _f(0.2, "m", "radius of the arc foot (0 = point foot); r < l", lo=0.0, lo_open=False)
    J_l: float = _f(0.0398, "kg m^2", "leg moment of inertia about its centre of mass", lo=0.0,
                    lo_open=False)
    m_h: float = _f(2.0, "kg", "hip (torso) mass", lo=0.0)
    m_l: float = _f(1.0, "kg", "mass of each leg", lo=0.0)
    k_hip: float = _f(0.95, "N m/rad", "hip torsional spring stiffness", lo=0.0, lo_open=False)
    d_hip: float = _f(0.018, "N m s/rad", "hip torsional damping", lo=0.0, lo_open=False)
    gamma: float = _f(0.02, "rad", "slope angle", lo=-math.pi / 4, hi=math.pi / 4, lo_open=False,
                      hi_open=False)
    g: float = _f(9.8, "m/s^2", "gravity", lo=0.0, lo_open=False)
    k_n: float = _f(1e5, "N/m^1.5", "normal contact stiffness (Hunt-Crossley)", lo=0.0)
    d_n: float = _f(1e6, "N s/m^2.5", "normal contact damping (Hunt-Crossley)", lo=0.0,
                    lo_open=False)
    k_t: float = _f(90.0, "N/m^1.5", "tangential contact stiffness", lo=0.0, lo_open=False)
    d_t: float = _f(900.0, "N s/m^2.5", "tangential contact damping", lo=0.0, lo_open=False)
    v_s: float = _f(1e-4, "m/s", "stiction velocity of the friction law (Eq. 10); v_s < v_d",
                    lo=0.0)
    v_d: float = _f(1e-3, "m/s", "dynamic-friction velocity of the friction law (Eq. 10)", lo=0.0)
    mu_s: float = _f(0.5, "-", "static friction coefficient", lo=0.0, lo_open=False)
    mu_d: float = _f(0.4, "-", "dynamic friction coefficient", lo=0.0, lo_open=False)

    def __post_init__(self):
        for f, lo, hi, lo_open, hi_open in _bounds():
            v = getattr(self, f.name)
            if type(v) is not float:
                v = _real("Params." + f.name, v)
                object.__setattr__(self, f.name, v)
            if not math.isfinite(v):
                raise InvalidInputError("Params.%s must be finite, got %r (allowed: %s)"
                                 % (f.name, v, _range_text(f)))
            md = f.metadata
            bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
            bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
            if bad_lo or bad_hi:
                raise InvalidInputError("Params.%s = %r is out of range; allowed: %s [%s]"
                                 % (f.name, v, _range_text(f), md["unit"]))
        if self.r >= self.l:
            raise InvalidInputError("Params.r = %r must be smaller than Params.l = %r (0 <= r < l)"
                             % (self.r, self.l))
        if self.J_l == 0.0 and self.c == 0.0 and self.w == 0.0:
            raise InvalidInputError("Params.J_l = 0 with c = w = 0 gives a leg without inertia about the "
                             "hip (singular mass matrix): need J_l > 0 or c**2 + w**2 > 0")
        if self.v_s >= self.v_d:
            raise InvalidInputError("Params.v_s = %r must be smaller than Params.v_d = %r "
                             "(0 < v_s < v_d, Eq. 10)" % (self.v_s, self.v_d))

    # --- presets ---------------------------------------------------------------------------
    @classmethod
    def paper(cls, **overrides: float) -> Params:
        """The paper's Tables 1-3 as read in docs/model.md section 1 (d_hip = 0.018).

        ``overrides``: fields to change (name=value, SI units), validated as in the constructor.
        Without overrides, one shared instance (a Params is immutable): no validation per call.
        """
        if not overrides and cls is Params:
            return _paper()
        return cls(**overrides)

    @classmethod
    def paper_steady(cls, **overrides: float) -> Params:
        """`paper` with d_hip = 0.010: the preset with a stable period-one gait (docs/model.md section 8)."""
        return cls(**{"d_hip": 0.010, **overrides})

    @classmethod
    def preset(cls, name: str, **overrides: float) -> Params:
        """A preset by name.

        Parameters
        ----------
        name : {"paper", "paper_steady"}
            `Params.paper` or `Params.paper_steady`.
        **overrides : float
            Fields to change (SI units), validated.

        Returns
        -------
        Params

        Raises
        ------
        InvalidInputError
            An unknown preset, an unknown field or a value out of its range.
        """
        presets = {"paper": cls.paper, "paper_steady": cls.paper_steady}
        if name not in presets:
            raise InvalidInputError("unknown preset %r; allowed: %s" % (name, ", ".join(presets)))
        return presets[name](**overrides)

    def without(self, features) -> "Params":
        """A copy with the parameters of the force elements *not* in ``features`` set to zero
        (hip_spring: k_hip; hip_damper: d_hip; normal_damping: d_n; tangential: k_t, d_t;
        friction: mu_s, mu_d). The general kernel with these parameters equals a kernel
        specialized for ``features``."""
        zero = {"hip_spring": ("k_hip",), "hip_damper": ("d_hip",), "normal_damping": ("d_n",),
                "tangential": ("k_t", "d_t"), "friction": ("mu_s", "mu_d")}
        unknown = set(features) - set(zero)
        if unknown:
            raise InvalidInputError("unknown feature(s) %s; allowed: %s"
                             % (", ".join(sorted(unknown)), ", ".join(zero)))
        return self.replace(**{n: 0.0 for f, names in zero.items() if f not in features
                               for n in names})

    def replace(self, **changes: float) -> Params:
        """A copy with some fields changed: ``p.replace(k_n=2e5, d_hip=0.01)`` (SI units).

        Raises `pdw.InvalidInputError` for an unknown field (listing the allowed ones) or a
        value out of its range (naming the field and the range).
        """
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise InvalidInputError("unknown Params field(s): %s; allowed: %s"
                             % (", ".join(sorted(unknown)), ", ".join(_layout.PARAMS)))
        return dataclasses.replace(self, **changes)

    def as_array(self) -> np.ndarray:
        """Physical parameters in the C layout (``pdw.core._layout.PARAMS``), shape (NPARAM,)."""
        return np.array([getattr(self, n) for n in _layout.PARAMS], dtype=float)

    def as_dict(self) -> dict[str, float]:
        """Every physical parameter by name (the order of ``pdw.core._layout.PARAMS``), SI units."""
        return {n: getattr(self, n) for n in _layout.PARAMS}

    @property
    def weight(self) -> float:
        """Weight of the walker normal to the slope, (m_h + 2 m_l) g cos(gamma) [N]."""
        return (self.m_h + 2 * self.m_l) * self.g * math.cos(self.gamma)


@functools.lru_cache(maxsize=None)
def _bounds():
    """(field, lo, hi, lo_open, hi_open) of every field, read once from the metadata."""
    return tuple((f, f.metadata["lo"], f.metadata["hi"], f.metadata["lo_open"],
                  f.metadata["hi_open"]) for f in dataclasses.fields(Params))


@functools.lru_cache(maxsize=1)
def _paper():
    """The shared `Params.paper()` without overrides."""
    return Params()


def _range_text(f):
    md = f.metadata
    lo, hi = md["lo"], md["hi"]
    if lo is None and hi is None:
        return "any finite value"
    parts = []
    if lo is not None:
        parts.append("%s %s" % (">" if md["lo_open"] else ">=", lo))
    if hi is not None:
        parts.append("%s %s" % ("<" if md["hi_open"] else "<=", hi))
    return " and ".join(parts)


assert tuple(f.name for f in dataclasses.fields(Params)) == _layout.PARAMS, \
    "Params fields must follow the generated layout"
