"""`pdw.load`: a Result back from a file written by `Result.save` (`pdw.sim.io`).

A file is input like any other: every array and metadata field is checked before a `Result` is
made of it (shapes, dtypes, finiteness, ranges, known names), so a truncated, tampered or
foreign file is a `pdw.InvalidInputError` naming the field, never a Result that lies.
"""
from __future__ import annotations

import json
import os
import zipfile

import numpy as np

from ..core import _layout, checks
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.integrators import METHODS
from ..core.params import Params
from . import io as _io
from .gait import Steps
from .options import Outcome
from .simulation import Event, Result

#: statuses and stop reasons a saved Result can carry: the readings of `Outcome`
STATUSES = tuple(dict.fromkeys(o.status for o in Outcome))
STOP_REASONS = tuple(o.stop_reason for o in Outcome)


class _Bad(Exception):
    pass


def _field(meta, key, where="metadata"):
    if not isinstance(meta, dict) or key not in meta:
        raise _Bad("%s lacks %r" % (where, key))
    return meta[key]


def _num(name, v, **kw):
    try:
        return checks.number(name, v, **kw)
    except InvalidInputError as e:
        raise _Bad(str(e)) from None


def _count(name, v):
    try:
        return checks.count(name, v)
    except InvalidInputError as e:
        raise _Bad(str(e)) from None


def _array(arrays, name, shape, kind="f", finite=True):
    """arrays[name] with the given shape (-1: any length) and dtype kind."""
    if name not in arrays:
        raise _Bad("the array %r is missing" % name)
    a = np.asarray(arrays[name])
    if a.dtype.kind not in (kind if kind != "f" else "fiu"):
        raise _Bad("array %r must hold %s, got dtype %s"
                   % (name, "integers" if "i" in kind else "real numbers", a.dtype))
    if a.ndim != len(shape) or any(w not in (-1, g) for w, g in zip(shape, a.shape)):
        raise _Bad("array %r must have shape (%s), got %s"
                   % (name, ", ".join("N" if w == -1 else str(w) for w in shape), a.shape))
    if finite and a.dtype.kind == "f" and not np.isfinite(a).all():
        raise _Bad("array %r must be finite (a saved result holds no NaN or inf)" % name)
    return a


def _check(arrays, meta):
    """The Result's constructor arguments from a file's arrays and metadata, checked."""
    s = _field(meta, "settings")
    method, variant = _field(s, "method", "settings"), _field(s, "variant", "settings")
    if method not in METHODS:
        raise _Bad("settings.method must be one of %s, got %r" % (", ".join(METHODS), method))
    if variant not in ("paper", "consistent"):
        raise _Bad("settings.variant must be 'paper' or 'consistent', got %r" % (variant,))
    features = _field(s, "features", "settings")
    if not isinstance(features, list) or not set(features) <= set(_layout.FEATURES):
        raise _Bad("settings.features must be a list of %s, got %r"
                   % (", ".join(_layout.FEATURES), features))
    params = _field(s, "params", "settings")
    if not isinstance(params, dict) or set(params) - set(Params.paper().as_dict()):
        raise _Bad("settings.params must hold Params fields only, got %r" % (params,))
    params = Params(**params)                 # range checks: InvalidInputError naming the field
    contact = s.get("contact")
    if contact is not None and not isinstance(contact, dict):
        raise _Bad("settings.contact must be a table of pdw.Contact fields, got %r" % (contact,))
    contact = Contact.coerce(contact)         # InvalidInputError naming the field
    nx = contact.nx                           # the state layout of its friction law
    status = _field(meta, "status")
    if status not in STATUSES:
        raise _Bad("status must be one of %s, got %r" % (", ".join(STATUSES), status))
    stop = _field(meta, "stop_reason")
    if stop not in STOP_REASONS:
        raise _Bad("stop_reason must be one of %s, got %r" % (", ".join(STOP_REASONS), stop))
    t = _array(arrays, "t", (-1,))
    n = len(t)
    x = _array(arrays, "x", (n, nx))
    flags = _array(arrays, "flags", (n, 2), kind="iu")
    if not np.isin(flags, (0, 1)).all():
        raise _Bad("array 'flags' must hold 0 or 1 only")
    fn = _array(arrays, "Fn", (-1, 2))
    ft = _array(arrays, "Ft", (len(fn), 2))
    if len(fn) not in (0, n):
        raise _Bad("arrays 'Fn', 'Ft' must have 0 or %d rows (as t), got %d" % (n, len(fn)))
    ev = _array(arrays, "events", (-1, len(_layout.EVENT)))
    if len(ev) and not (np.isin(ev[:, 1], (1, 2)).all()
                        and np.isin(ev[:, 2], range(len(_layout.EVENT_KIND))).all()):
        raise _Bad("array 'events' must have legs 1, 2 and kinds 0 ... %d"
                   % (len(_layout.EVENT_KIND) - 1))
    x_final = _array(arrays, "x_final", (nx,))
    gait = {k[5:]: _array(arrays, k, (-1,), finite=False) for k in arrays if k.startswith("gait_")}
    if gait and (set(gait) != set(_layout.STEP) or len({len(v) for v in gait.values()}) != 1):
        raise _Bad("the gait_* arrays must be the fields %s, all of one length"
                   % ", ".join(_layout.STEP))
    energies = {k[7:]: _array(arrays, k, (n,)) for k in arrays if k.startswith("energy_")} or None
    failure = meta.get("failure")
    if failure is not None:
        fx = _array({"failure.x": np.asarray(_field(failure, "x", "failure"))}, "failure.x",
                    (nx,))
        leg = _field(failure, "leg", "failure")
        if leg not in (None, 1, 2) or not isinstance(_field(failure, "reason", "failure"), str):
            raise _Bad("failure.leg must be null, 1 or 2 and failure.reason a text")
        failure = dict(failure, t=_num("failure.t", _field(failure, "t", "failure")), x=fx)
    stats = _field(meta, "stats")
    counts = _field(meta, "event_counts")
    if not (isinstance(stats, dict) and isinstance(counts, dict)):
        raise _Bad("stats and event_counts must be tables of counts")
    recorded = _field(meta, "events_recorded")
    if not isinstance(recorded, bool):
        raise _Bad("events_recorded must be true or false, got %r" % (recorded,))
    return dict(
        t=t, x=x, flags=np.ascontiguousarray(flags, dtype=np.intc), Fn=fn, Ft=ft,
        events=[Event(float(e[0]), int(e[1]), _layout.EVENT_KIND[int(e[2])], float(e[3]),
                      float(e[4])) for e in ev],
        status=status, failure=failure, x_final=x_final,
        t_final=_num("t_final", _field(meta, "t_final")), params=params, variant=variant,
        method=method, dt=_num("settings.dt", _field(s, "dt", "settings"), lo=0, lo_open=True),
        t_end=_num("settings.t_end", _field(s, "t_end", "settings"), lo=0, lo_open=True),
        n_steps=_count("n_steps", _field(meta, "n_steps")),
        wall_time=_num("wall_time", _field(meta, "wall_time"), lo=0),
        stats={str(k): _count("stats." + str(k), v) for k, v in stats.items()},
        gait=Steps(gait) if gait else None,
        n_gait_steps=_count("n_gait_steps", _field(meta, "n_gait_steps")),
        event_counts={str(k): _count("event_counts." + str(k), v) for k, v in counts.items()},
        events_recorded=recorded, stop_reason=stop, energies=energies,
        features=tuple(features), contact=contact)


def load(path: str | os.PathLike) -> Result:
    """Read a Result written by `Result.save`.

    Parameters
    ----------
    path : str or path-like
        An ``.npz`` file, or ``.nc`` (NetCDF, needs xarray).

    Returns
    -------
    Result
        The run's recorded arrays (t (M,) [s], x (M, nx), flags (M, 2), Fn, Ft (M, 2) [N]),
        events, gait descriptors and settings; ``res.provenance`` holds the metadata (pdw
        version, INPUT_HASH, pdw's source revision, settings, scene, time of writing).

    Raises
    ------
    pdw.InvalidInputError
        The file is missing, unreadable (truncated, not a zip/NetCDF file, pickled objects),
        not a pdw result, or a field is malformed (the message names it).
    """
    try:
        arrays, meta = _io.read(path)
    except InvalidInputError:
        raise
    except (OSError, EOFError, ValueError, KeyError, TypeError, zipfile.BadZipFile,
            json.JSONDecodeError) as e:
        raise InvalidInputError("%s is not a readable pdw result file (.npz or .nc written by "
                                "Result.save): %s: %s" % (path, type(e).__name__, e)) from None
    try:
        res = Result(**_check(arrays, meta))
    except _Bad as e:
        raise InvalidInputError("%s is not a valid pdw result file: %s" % (path, e)) from None
    res.provenance = meta
    return res
