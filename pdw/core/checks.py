"""One validation path for every public input: numbers, counts, flags and states.

Every check returns the value in its canonical type or raises `pdw.InvalidInputError` naming the
field and the allowed range. Nothing malformed is coerced into something else: a string is not a
sequence of flags, 0.9 is not the flag 0, a (2, 4) array is not a state, a complex number is not
a real one, ``True`` is not the number 1, a masked array's masked entries are not numbers (it is
refused), and NaN is never in range.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import InvalidInputError

#: The largest count any loop accepts (steps, samples): beyond it no run could finish.
MAX_COUNT = 2 ** 40


def unmasked(name, value):
    """``value`` itself, or a masked array's data when no entry is masked; a masked array with
    a masked entry is refused (pdw would otherwise run on the hidden values: numpy's
    ``asarray`` drops the mask)."""
    if isinstance(value, np.ma.MaskedArray):
        mask = np.ma.getmaskarray(value)
        if mask.any():
            where = [int(i) for i in np.argwhere(mask)[0]]
            raise InvalidInputError("%s is a masked array with %d masked entr%s (the first at "
                                    "%s): pdw does not fill them; pass a plain array (e.g. "
                                    "x.filled(value))" % (name, int(mask.sum()),
                                                          "y" if mask.sum() == 1 else "ies",
                                                          where))
        return np.ma.getdata(value)
    return value


def _real(name, value):
    """A real scalar as float (no bool, str, complex, None, 0-d arrays of those)."""
    t = type(value)
    if t is float:                      # the common cases first: no ABC checks (issue 23)
        return value
    if t is int:
        return float(value)
    value = unmasked(name, value)
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidInputError("%s must be a real number, got %r" % (name, value))
    return float(value)


def number(name, value, lo=None, hi=None, lo_open=False, hi_open=False):
    """A finite real number in the given range (bounds optional, closed unless ``*_open``)."""
    v = _real(name, value)
    if not math.isfinite(v):
        raise InvalidInputError("%s must be finite (%s), got %r"
                                % (name, _range_text(lo, hi, lo_open, hi_open), value))
    if (lo is not None and (v <= lo if lo_open else v < lo)) or \
            (hi is not None and (v >= hi if hi_open else v > hi)):
        raise InvalidInputError("%s = %r is out of range; allowed: %s"
                                % (name, value, _range_text(lo, hi, lo_open, hi_open)))
    return v


def positive(name, value, hi=None):
    """A finite number > 0 (and <= hi)."""
    return number(name, value, lo=0.0, lo_open=True, hi=hi)


def count(name, value, lo=0, hi=MAX_COUNT):
    """An integer in [lo, hi] (no bool, no string; an integral float such as 2.0 is accepted,
    1.5 is not)."""
    if type(value) is int and lo <= value <= hi:        # the common case first
        return value
    value = unmasked(name, value)
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)):
        raise InvalidInputError("%s must be an integer in [%d, %d], got %r" % (name, lo, hi, value))
    if isinstance(value, numbers.Integral):
        v = int(value)
    elif isinstance(value, numbers.Real) and math.isfinite(value) and float(value).is_integer():
        v = int(value)
    else:
        raise InvalidInputError("%s must be an integer in [%d, %d], got %r" % (name, lo, hi, value))
    if not lo <= v <= hi:
        raise InvalidInputError("%s = %r is out of range; allowed: integers in [%d, %d]"
                                % (name, value, lo, hi))
    return v


def leg_or_off(name, value):
    """0 (off), or a leg number in the paper's numbering: 1 or 2."""
    return count(name, value, lo=0, hi=2)


def choice(name, value, allowed):
    """One of ``allowed`` (compared as is: no case folding, no stripping)."""
    if not isinstance(value, str) or value not in allowed:
        raise InvalidInputError("%s must be one of %s, got %r"
                                % (name, ", ".join(map(repr, allowed)), value))
    return value


def flags(name, value, n=None):
    """Support flags: a pair (2,) of 0/1 integers, or with ``n`` also an array (n, 2). Returns a
    tuple (pair) or an int array (n, 2). Strings, non-integers, other lengths are refused."""
    if type(value) is tuple and len(value) == 2:        # the common case first: (0, 1)
        a, b = value
        if type(a) is int and type(b) is int and a in (0, 1) and b in (0, 1):
            return a, b
    if isinstance(value, (str, bytes)):
        raise InvalidInputError("%s must be two integers in {0, 1}, got the string %r" % (name, value))
    value = unmasked(name, value)
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        raise InvalidInputError("%s must be two integers in {0, 1}, got %r" % (name, value)) from None
    if arr.dtype.kind not in "iub":
        raise InvalidInputError("%s must be integers in {0, 1} (not %s), got %r"
                                % (name, arr.dtype, value))
    ok_shape = arr.shape == (2,) or (n is not None and arr.shape == (n, 2))
    if not ok_shape:
        want = "(2,)" if n is None else "(2,) or (%d, 2)" % n
        raise InvalidInputError("%s must have shape %s, got %s" % (name, want, arr.shape))
    if not np.isin(arr, (0, 1)).all():
        raise InvalidInputError("%s must be 0 (swing) or 1 (support), got %r" % (name, value))
    if arr.ndim == 1:
        return int(arr[0]), int(arr[1])
    return np.ascontiguousarray(arr, dtype=np.intc)


def real_array(name, value, shapes, labels=None, lo=None):
    """A finite float array whose shape is one of ``shapes`` (tuples; -1 matches any length).
    Refuses strings, complex, object and boolean arrays. ``labels``: names of the last axis's
    components (for the message); ``lo``: the smallest allowed value."""
    if isinstance(value, (str, bytes)):
        raise InvalidInputError("%s must be an array of numbers, got the string %r" % (name, value))
    value = unmasked(name, value)
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        raise InvalidInputError("%s must be an array of numbers, got %r" % (name, value)) from None
    if arr.dtype.kind not in "iuf":
        raise InvalidInputError("%s must hold real numbers (not %s), got %r"
                                % (name, arr.dtype, value))
    if not any(len(s) == arr.ndim and all(w in (-1, g) for w, g in zip(s, arr.shape))
               for s in shapes):
        raise InvalidInputError("%s must have shape %s, got %s"
                                % (name, " or ".join(_shape_text(s) for s in shapes), arr.shape))
    arr = np.array(arr, dtype=float, order="C")
    if not np.isfinite(arr).all():
        bad = ~np.isfinite(arr)
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        label = " (%s)" % labels[where[-1]] if labels and len(labels) == arr.shape[-1] else ""
        raise InvalidInputError("%s%s%s must be finite, got %r"
                                % (name, list(where), label, float(arr[where])))
    if lo is not None and (arr < lo).any():
        where = tuple(int(i) for i in np.argwhere(arr < lo)[0])
        raise InvalidInputError("%s%s must be >= %g, got %r" % (name, list(where), lo,
                                                               float(arr[where])))
    return arr


def features(value, allowed):
    """A collection of force-element names (None: all of ``allowed``), in ``allowed``'s order."""
    if value is None:
        return tuple(allowed)
    if isinstance(value, str):
        raise InvalidInputError("features must be a collection of names, got the string %r"
                                % value)
    try:
        unknown = set(value) - set(allowed)
    except TypeError:
        raise InvalidInputError("features must be a collection of names from %s, got %r"
                                % (", ".join(allowed), value)) from None
    if unknown:
        raise InvalidInputError("unknown feature(s) %s; allowed: %s"
                                % (", ".join(sorted(map(str, unknown))), ", ".join(allowed)))
    return tuple(f for f in allowed if f in set(value))


def _shape_text(s):
    return "(" + ", ".join("N" if w == -1 else str(w) for w in s) + ("," if len(s) == 1 else "") + ")"


def _range_text(lo, hi, lo_open, hi_open):
    parts = []
    if lo is not None:
        parts.append("%s %r" % (">" if lo_open else ">=", lo))
    if hi is not None:
        parts.append("%s %r" % ("<" if hi_open else "<=", hi))
    return " and ".join(parts) if parts else "any finite value"
