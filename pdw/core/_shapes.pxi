# Shape checks of the compiled boundary, shared by _core.pyx and _hybrid.pyx (``include``d):
# every entry point checks its arrays once per call, before it takes a pointer.

cdef int _len(str name, Py_ssize_t got, Py_ssize_t want) except -1:
    if got != want:
        raise ValueError("%s must have shape (%d,), got (%d,)" % (name, want, got))
    return 0


#: The largest count (steps, samples, events) a compiled entry point takes: beyond it no run
#: could finish and no buffer could be allocated (`pdw.core.checks.MAX_COUNT`).
MAX_COUNT = 1 << 40
cdef long _MAX_COUNT = 1 << 40


cdef int _count(str name, long v, long lo) except -1:
    """A count argument in [lo, MAX_COUNT], checked before any size is computed from it."""
    if v < lo or v > _MAX_COUNT:
        raise _InvalidInputError("%s = %d is out of range; allowed: integers in [%d, %d]"
                                 % (name, v, lo, _MAX_COUNT))
    return 0


cdef object _zeros(str what, object shape, object dtype=float):
    """np.zeros(shape, dtype), or a MemoryError saying what it was for and how large it was."""
    try:
        return _np.zeros(shape, dtype=dtype)
    except (MemoryError, ValueError):
        n = 1
        for w in (shape if isinstance(shape, tuple) else (shape,)):
            n *= w
        raise MemoryError("%s needs %.3g GB (%d entries of %d bytes), more than can be "
                          "allocated" % (what, n * _np.dtype(dtype).itemsize / 1e9, n,
                                         _np.dtype(dtype).itemsize)) from None


cdef int _rows(str name, Py_ssize_t r, Py_ssize_t c, Py_ssize_t want_r, Py_ssize_t want_c) except -1:
    if r != want_r or c != want_c:
        raise ValueError("%s must have shape (%d, %d), got (%d, %d)" % (name, want_r, want_c, r, c))
    return 0


# Cython converts a typed-memoryview argument before the function body runs, and its errors
# ("Buffer dtype mismatch, expected 'const double' but got 'long'", "ndarray is not
# C-contiguous", ...) do not say which argument. `_named_buffers` wraps an entry point: on such
# an error it finds the argument at fault from the typed signature Cython embeds in __doc__
# (directive embedsignature) and raises the same exception type naming it, the expected array
# and the given one. A call that succeeds pays one Python-level call (~0.1 us), nothing else.

import functools as _functools
import re as _re

import numpy as _np

from pdw.core.errors import InvalidInputError as _InvalidInputError

_BUFFER_ERRORS = ("Buffer dtype mismatch", "C-contiguous", "C contiguous",
                  "wrong number of dimensions", "bytes-like object", "buffer interface",
                  "read-only", "Buffer has wrong")
_C_DTYPES = {"double": _np.dtype(_np.float64), "int": _np.dtype(_np.intc),
             "long": _np.dtype(_np.int_)}
_INT_ARG = _re.compile(r"\b(int|long)\s+(\w+)")
_C_INT_RANGE = {"int": (-2 ** 31, 2 ** 31 - 1), "long": (-2 ** 63, 2 ** 63 - 1)}
_VIEW_ARG = _re.compile(r"(const\s+)?(double|int|long)\[([:, 0-9]*)\]\s+(\w+)")


def _buffer_specs(fn):
    """({argument name: (const, C type, ndim)} of fn's typed-memoryview arguments, [names of
    all its arguments in order]), from the signature Cython embeds as the docstring's first
    line."""
    # (no negative indices here: this module is compiled with wraparound=False)
    head = (fn.__doc__ or "").split("\n", 1)[0]
    lo, hi = head.find("("), head.rfind(")")
    sig = head[lo + 1:hi] if 0 <= lo < hi else ""
    specs = {m.group(4): (bool(m.group(1)), m.group(2), m.group(3).count(",") + 1)
             for m in _VIEW_ARG.finditer(sig)}
    names = []
    for part in _re.split(r",(?![^\[]*\])", sig):
        words = part.split("=")[0].split()
        if words:
            names.append(words[len(words) - 1])
    return specs, names


def _fault(name, value, spec):
    """Why ``value`` cannot be argument ``name`` of spec (const, C type, ndim), or None."""
    const, ctype, ndim = spec
    want = "a C-contiguous %d-D %s array (%s)" % (ndim, _C_DTYPES[ctype].name, ctype)
    if not isinstance(value, _np.ndarray):
        return "%s must be %s, got %s" % (name, want, type(value).__name__)
    if value.ndim != ndim:
        return "%s must be %s, got a %d-D array of shape %s" % (name, want, value.ndim,
                                                                 value.shape)
    if value.dtype != _C_DTYPES[ctype]:
        return "%s must be %s, got dtype %s" % (name, want, value.dtype)
    if not value.flags.c_contiguous:
        return "%s must be %s, got a non-contiguous array (strides %s)" % (name, want,
                                                                            value.strides)
    if not const and not value.flags.writeable:
        return "%s must be %s and writeable (an output), got a read-only array" % (name, want)
    return None


def _named_buffers(fn):
    """Wrap a compiled entry point so that a typed-memoryview conversion error names the
    argument (see above)."""
    specs, names = _buffer_specs(fn)
    head = (fn.__doc__ or "").split("\n", 1)[0]
    ints = {m.group(2): m.group(1) for m in _INT_ARG.finditer(head)}

    @_functools.wraps(fn)
    def entry(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except OverflowError:
            # a Python int too large for its C int/long argument: name it and its range
            given = dict(zip(names, args))
            given.update(kwargs)
            for name, ctype in ints.items():
                v = given.get(name)
                lo, hi = _C_INT_RANGE[ctype]
                if isinstance(v, int) and not lo <= v <= hi:
                    raise _InvalidInputError("%s = %d is out of range; allowed: integers in "
                                             "[%d, %d] (a C %s)" % (name, v, lo, hi, ctype)) \
                        from None
            raise
        except (ValueError, TypeError) as e:
            if not any(s in str(e) for s in _BUFFER_ERRORS):
                raise
            given = dict(zip(names, args))
            given.update(kwargs)
            for name, spec in specs.items():
                if name in given and given[name] is not None:
                    why = _fault(name, given[name], spec)
                    if why is not None:
                        raise type(e)(why) from None
            raise
    return entry
