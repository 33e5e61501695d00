"""What pdw saves, pdw loads: the one file format of everything pdw writes (`pdw.load`).

This module owns the format: the writer and the reader of each kind of object live here, side
by side, so that what one writes the other reads (issue 26.3, 26.10). A file is a NumPy
``.npz`` archive (arrays only, never pickled objects; ``allow_pickle=False`` on reading) with a
JSON ``meta`` entry whose ``format`` tag names its kind; a `Result` may also be written as
NetCDF (``.nc``, through xarray). The kinds are a registry keyed on that tag (`register`):
`Result` (``"pdw-result-1"``) and `BatchResult` (``"pdw-batch-1"``) register here when their
modules are imported; a higher layer registers its own kind the same way (a continuation
`Branch`), and a file suffix may get a reader of its own (`register_suffix`: a sweep's CSV,
`pdw.load_sweep`). `pdw.load(path)` reads any of them and returns the right type.

The rule for numbers: what a run produced is data. A saved result may hold NaN and +-inf
where pdw returns them -- the energies and forces of a diverged or runaway run, the state of a
fell run whose x0 was at -1e308, the NaN double support of a step not yet complete -- and
`load` gives them back bit for bit. What *describes* the run must be valid: times, flags,
counts, statuses, methods, `Params` and `Contact` go through the same checks as a new run's
inputs (NaN parameters are refused as they are everywhere). A file is input like any other:
every array and metadata field is checked before an object is made of it (shapes, dtypes,
ranges, known names); a truncated, damaged, tampered or foreign file is a
`pdw.InvalidInputError` naming the file and the field, never a raw ``zlib.error``,
``BadZipFile`` or ``KeyError``, and never an object that lies.

Why this module is long: it is the one place of the file format (issue 25), so each kind's
writer sits next to its reader and the checks they share; splitting them would put the two
halves of one format in two modules again.
"""
from __future__ import annotations

import datetime
import json
import os
import pathlib
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..core import _layout, checks
from ..core.contact import Contact
from ..core.errors import InvalidInputError, PdwError
from ..core.integrators import METHODS
from ..core.params import Params
from ..core.provenance import provenance
from .dense import DenseOutput
from .gait import STEP_UNITS, Steps
from .options import Outcome

#: The format tag of a saved `Result` (``meta["format"]``).
FORMAT = "pdw-result-1"
#: The format tag of a saved `BatchResult`.
BATCH_FORMAT = "pdw-batch-1"
#: statuses and stop reasons a saved Result can carry: the readings of `Outcome`
STATUSES = tuple(dict.fromkeys(o.status for o in Outcome))
STOP_REASONS = tuple(o.stop_reason for o in Outcome)

UNITS = dict(zip(_layout.STATE, ("m", "m", "rad", "rad", "m/s", "m/s", "rad/s", "rad/s")))
UNITS.update({name: "m" for name in _layout.BRISTLE})      # LuGre's bristle deflections


def _names(res):
    """The column names of res.x (its friction law's state layout)."""
    return tuple(getattr(res, "state_names", _layout.STATE))


def _units(res):
    return {n: UNITS[n] for n in _names(res)}


def _need(name):
    try:
        return __import__(name)
    except ImportError:
        raise ImportError("this export needs %s (pip install %s)" % (name, name)) from None


# --- the registry -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Kind:
    """One kind of file: its ``tag`` (``meta["format"]``), the class it holds, ``to_file(obj)
    -> (arrays, meta)`` and ``from_file(arrays, meta) -> obj`` (raising `BadFile` naming a
    field), and optionally ``to_xarray(obj)`` for ``.nc``."""

    tag: str
    cls: type
    to_file: Callable[[Any], tuple]
    from_file: Callable[[dict, dict], Any]
    to_xarray: Callable[[Any], Any] | None = None


_KINDS: dict[str, Kind] = {}
_SUFFIXES: dict[str, Callable[[pathlib.Path], Any]] = {}


def register(tag: str, cls: type, to_file, from_file, *, to_xarray=None) -> Kind:
    """Register a kind of file: objects of ``cls`` are saved by ``to_file(obj)`` -> (dict of
    arrays, JSON-able metadata dict) under ``meta["format"] = tag``; `load` gives a file of that
    tag to ``from_file(arrays, meta)``, which checks every field (raise `BadFile`). Registering
    a tag again replaces it (a module reloaded)."""
    if not isinstance(tag, str) or not tag:
        raise InvalidInputError("a file kind's tag must be a non-empty string, got %r" % (tag,))
    kind = Kind(tag, cls, to_file, from_file, to_xarray)
    _KINDS[tag] = kind
    return kind


#: readers of whole files by their ``meta["format"]`` tag, for kinds whose reader opens the file
#: itself (registered by the layers above: ``"pdw-branch-1"``,
#: `pdw.analysis.bifurcation.continuation.load_branch`)
LOADERS: dict[str, Callable[[pathlib.Path], Any]] = {}


def register_suffix(suffix: str, reader: Callable[[pathlib.Path], Any]):
    """``load(path)`` of a file ending in ``suffix`` (".csv") calls ``reader(path)``."""
    _SUFFIXES[suffix.lower()] = reader


def kinds() -> dict:
    """{tag: class} of the registered kinds; and the suffixes with readers of their own."""
    return {**{k.tag: k.cls for k in _KINDS.values()},
            **{s: getattr(r, "__name__", "reader") for s, r in _SUFFIXES.items()}}


class BadFile(PdwError):
    """A field of a file is malformed (raised by a kind's reader; `load` names the file)."""


def _kind_of(obj) -> Kind:
    for kind in _KINDS.values():
        if type(obj) is kind.cls:
            return kind
    for kind in _KINDS.values():
        if isinstance(obj, kind.cls):
            return kind
    raise InvalidInputError("pdw saves %s, not %s" % (
        ", ".join(sorted(k.cls.__name__ for k in _KINDS.values())), type(obj).__name__))


# --- writing and reading files ----------------------------------------------------------------

def save(obj, path) -> pathlib.Path:
    """Write ``obj`` (a registered kind: `Result`, `BatchResult`, ...) to ``path`` with its
    provenance: ``.npz``, or ``.nc`` (NetCDF through xarray) for a kind that has it."""
    path = pathlib.Path(path)
    kind = _kind_of(obj)
    if path.suffix == ".nc":
        if kind.to_xarray is None:
            raise InvalidInputError("a %s is saved as .npz only, got %r"
                                    % (kind.cls.__name__, str(path)))
        kind.to_xarray(obj).to_netcdf(path)
    elif path.suffix == ".npz":
        arrays, meta = kind.to_file(obj)
        meta = {"format": kind.tag, **meta}
        np.savez_compressed(path, meta=np.array(json.dumps(meta)), **arrays)
    else:
        raise InvalidInputError("path must end in .npz%s, got %r"
                                % (" or .nc" if kind.to_xarray else "", str(path)))
    return path


def _read_npz(path):
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    if "meta" not in arrays:
        raise BadFile("it has no 'meta' entry (not a file pdw wrote)")
    m = arrays.pop("meta")
    if m.dtype.kind != "U" or m.ndim != 0:
        raise BadFile("its 'meta' entry must be one JSON text, got %s %s" % (m.dtype, m.shape))
    meta = json.loads(str(m))
    return arrays, meta


def _read_nc(path):
    xr = _need("xarray")
    with xr.open_dataset(path) as ds:
        ds.load()
        if "pdw_metadata" not in ds.attrs:
            raise BadFile("it has no 'pdw_metadata' attribute (not a file pdw wrote)")
        meta = json.loads(ds.attrs["pdw_metadata"])
        arrays = {k: ds[k].values for k in ds.data_vars}
        arrays["t"] = ds["time"].values
    if "flags" in arrays:
        arrays["flags"] = arrays["flags"].astype(np.intc)
    return arrays, meta


def read(path) -> tuple[dict, dict]:
    """(arrays, metadata) of a file pdw wrote (``.npz`` or ``.nc``); `load` makes the object
    of them. A file that cannot be read is `pdw.InvalidInputError` naming it."""
    path = pathlib.Path(path)
    if path.suffix not in (".npz", ".nc"):
        raise InvalidInputError("%s: pdw reads .npz or .nc files%s, got suffix %r"
                                % (path, "".join(", " + s for s in sorted(_SUFFIXES)),
                                   path.suffix))
    try:
        arrays, meta = (_read_nc if path.suffix == ".nc" else _read_npz)(path)
    except BadFile as e:
        raise InvalidInputError("%s is not a pdw file: %s" % (path, e)) from None
    except (ImportError, KeyboardInterrupt, MemoryError):
        raise
    except FileNotFoundError:
        raise InvalidInputError("%s: no such file" % path) from None
    except Exception as e:      # noqa: BLE001 - zlib.error, BadZipFile, EOFError, OSError, ...
        raise InvalidInputError("%s is not a readable pdw file (.npz or .nc written by pdw; "
                                "truncated or damaged?): %s: %s"
                                % (path, type(e).__name__, e)) from None
    if not isinstance(meta, dict):
        raise InvalidInputError("%s is not a pdw file: its metadata is not a table" % path)
    return arrays, meta


def load(path: str | os.PathLike):
    """Read any file pdw writes and return its object.

    Parameters
    ----------
    path : str or path-like
        A `Result` (``.npz`` or ``.nc``, `Result.save`), a `BatchResult` (``.npz``,
        ``BatchResult.save``), another registered kind (a continuation `Branch`), or a sweep's
        CSV (``.csv``: `pdw.load_sweep`).

    Returns
    -------
    Result, BatchResult, ...
        The object saved, of the type its ``format`` tag names. A Result's arrays: t (M,)
        [s], x (M, nx), flags (M, 2), Fn, Ft (M, 2) [N], events, gait descriptors, energies,
        settings, dense output; ``res.provenance`` holds the metadata (pdw version,
        INPUT_HASH, pdw's source revision, settings, scene, time of writing).

    Raises
    ------
    pdw.InvalidInputError
        The file is missing, unreadable (truncated, damaged, not a zip/NetCDF file, pickled
        objects), not a pdw file, of an unknown kind, or a field is malformed (the message
        names the file and the field).
    """
    path = pathlib.Path(path)
    reader = _SUFFIXES.get(path.suffix.lower())
    if reader is not None:
        return reader(path)
    arrays, meta = read(path)
    tag = meta.get("format")
    if isinstance(tag, str) and tag in LOADERS:
        return LOADERS[tag](path)
    kind = _KINDS.get(tag) if isinstance(tag, str) else None
    if kind is None:
        raise InvalidInputError("%s is not a pdw result or another file of a kind pdw writes "
                                "(format %r; pdw reads %s)"
                                % (path, tag, ", ".join(sorted(_KINDS))))
    try:
        obj = kind.from_file(arrays, meta)
    except BadFile as e:
        raise InvalidInputError("%s is not a valid pdw file: %s" % (path, e)) from None
    except InvalidInputError as e:       # a Params or Contact field out of range
        raise InvalidInputError("%s is not a valid pdw file: %s" % (path, e)) from None
    if hasattr(obj, "provenance"):
        obj.provenance = meta
    return obj


# --- checks of fields (every reader) ----------------------------------------------------------

def field(meta, key, where="metadata"):
    """meta[key], or `BadFile` naming it."""
    if not isinstance(meta, dict) or key not in meta:
        raise BadFile("%s lacks %r" % (where, key))
    return meta[key]


def number(name, v, **kw):
    """A finite number (`pdw.core.checks.number`), or `BadFile`."""
    try:
        return checks.number(name, v, **kw)
    except InvalidInputError as e:
        raise BadFile(str(e)) from None


def count(name, v):
    try:
        return checks.count(name, v)
    except InvalidInputError as e:
        raise BadFile(str(e)) from None


def array(arrays, name, shape, kind="f", finite=True):
    """arrays[name] with the given shape (-1: any length) and dtype kind (``"f"``: real
    numbers; ``"U"``: text); ``finite``: no NaN or inf (times); False: data, any float."""
    if name not in arrays:
        raise BadFile("the array %r is missing" % name)
    a = np.asarray(arrays[name])
    if a.dtype.kind not in (kind if kind != "f" else "fiu"):
        raise BadFile("array %r must hold %s, got dtype %s"
                      % (name, {"f": "real numbers", "U": "text"}.get(kind, "integers"), a.dtype))
    if a.ndim != len(shape) or any(w not in (-1, g) for w, g in zip(shape, a.shape)):
        raise BadFile("array %r must have shape (%s), got %s"
                      % (name, ", ".join("N" if w == -1 else str(w) for w in shape), a.shape))
    if finite and a.dtype.kind == "f" and not np.isfinite(a).all():
        raise BadFile("array %r must be finite (times and counts hold no NaN or inf)" % name)
    return a


def choice(name, v, allowed):
    if not isinstance(v, str) or v not in allowed:
        raise BadFile("%s must be one of %s, got %r" % (name, ", ".join(allowed), v))
    return v


def settings_of(s):
    """(method, variant, features, params, contact) of a file's ``settings``, checked."""
    method = choice("settings.method", field(s, "method", "settings"), METHODS)
    variant = choice("settings.variant", field(s, "variant", "settings"), _layout.VARIANTS)
    features = field(s, "features", "settings")
    if not isinstance(features, list) or not set(features) <= set(_layout.FEATURES):
        raise BadFile("settings.features must be a list of %s, got %r"
                      % (", ".join(_layout.FEATURES), features))
    params = field(s, "params", "settings")
    if not isinstance(params, dict) or set(params) - set(Params.paper().as_dict()):
        raise BadFile("settings.params must hold Params fields only, got %r" % (params,))
    params = Params(**params)                 # range checks: InvalidInputError naming the field
    contact = s.get("contact")
    if contact is not None and not isinstance(contact, dict):
        raise BadFile("settings.contact must be a table of pdw.Contact fields, got %r"
                      % (contact,))
    return method, variant, tuple(features), params, Contact.coerce(contact)


def _written():
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


# --- Result -----------------------------------------------------------------------------------

def metadata(res) -> dict:
    """JSON-able description of a Result: provenance, settings, status, scene."""
    scene = getattr(res, "scene", None)
    sol = getattr(res, "sol", None)
    meta = {"format": FORMAT, "provenance": dict(provenance()), "written": _written(),
            "settings": {"method": res.method, "variant": res.variant, "dt": res.dt,
                         "t_end": res.t_end, "features": list(res.features),
                         "params": res.params.as_dict(),
                         "contact": (res.contact.as_dict() if getattr(res, "contact", None)
                                     is not None else None)},
            "status": res.status, "stop_reason": res.stop_reason, "failure": None,
            "t_final": res.t_final, "n_steps": int(res.n_steps), "wall_time": res.wall_time,
            "stats": {k: int(v) for k, v in res.stats.items()},
            "n_gait_steps": int(res.n_gait_steps),
            "event_counts": {k: int(v) for k, v in res.event_counts.items()},
            "events_recorded": bool(res.events_recorded),
            "dense_output": None if sol is None else {"order": int(sol.order)},
            "scene": scene.to_toml() if scene is not None and hasattr(scene, "to_toml") else None,
            "units": {"t": "s", "x": _units(res), "Fn": "N", "Ft": "N", "energies": "J"}}
    if res.failure:
        meta["failure"] = {"t": float(res.failure["t"]), "x": list(map(float, res.failure["x"])),
                           "reason": res.failure["reason"], "leg": res.failure["leg"]}
    return meta


def _arrays(res) -> dict:
    ev = np.array([[e.t, e.leg, _layout.EVENT_KIND.index(e.kind), e.x_D, e.y_D]
                   for e in res.events], dtype=float).reshape(-1, 5)
    out = {"t": np.asarray(res.t), "x": np.asarray(res.x), "flags": np.asarray(res.flags),
           "Fn": np.asarray(res.Fn), "Ft": np.asarray(res.Ft), "events": ev,
           "x_final": np.asarray(res.x_final)}
    if res.gait is not None:
        for k, v in res.gait.table.items():
            out["gait_" + k] = np.asarray(v)
    for k, v in (res.energies or {}).items():
        out["energy_" + k] = np.asarray(v)
    sol = getattr(res, "sol", None)
    if sol is not None:         # the interpolant's own steps (t_eval resamples t, x, flags)
        out.update(sol_t=sol.t, sol_x=sol.x, sol_flags=sol.flags)
    return out


def result_to_file(res) -> tuple[dict, dict]:
    meta = metadata(res)
    meta.pop("format")
    return _arrays(res), meta


def result_from_file(arrays, meta, result_cls, event_cls):
    """A Result (``result_cls``, events of ``event_cls``) from a file's arrays and metadata,
    every field checked (`BadFile` naming it)."""
    s = field(meta, "settings")
    method, variant, features, params, contact = settings_of(s)
    nx = contact.nx                           # the state layout of its friction law
    status = choice("status", field(meta, "status"), STATUSES)
    stop = choice("stop_reason", field(meta, "stop_reason"), STOP_REASONS)
    t = array(arrays, "t", (-1,))
    n = len(t)
    x = array(arrays, "x", (n, nx), finite=False)
    flags = array(arrays, "flags", (n, 2), kind="iu")
    if not np.isin(flags, (0, 1)).all():
        raise BadFile("array 'flags' must hold 0 or 1 only")
    fn = array(arrays, "Fn", (-1, 2), finite=False)
    ft = array(arrays, "Ft", (len(fn), 2), finite=False)
    if len(fn) not in (0, n):
        raise BadFile("arrays 'Fn', 'Ft' must have 0 or %d rows (as t), got %d" % (n, len(fn)))
    ev = array(arrays, "events", (-1, len(_layout.EVENT)), finite=False)
    if len(ev) and not (np.isfinite(ev[:, :3]).all() and np.isin(ev[:, 1], (1, 2)).all()
                        and np.isin(ev[:, 2], range(len(_layout.EVENT_KIND))).all()):
        raise BadFile("array 'events' must have finite times, legs 1, 2 and kinds 0 ... %d"
                      % (len(_layout.EVENT_KIND) - 1))
    x_final = array(arrays, "x_final", (nx,), finite=False)
    gait = {k[5:]: array(arrays, k, (-1,), finite=False) for k in arrays if k.startswith("gait_")}
    if gait and (set(gait) != set(_layout.STEP) or len({len(v) for v in gait.values()}) != 1):
        raise BadFile("the gait_* arrays must be the fields %s, all of one length"
                      % ", ".join(_layout.STEP))
    energies = {k[7:]: array(arrays, k, (n,), finite=False)
                for k in arrays if k.startswith("energy_")} or None
    failure = meta.get("failure")
    if failure is not None:
        fx = array({"failure.x": np.asarray(field(failure, "x", "failure"), dtype=float)},
                   "failure.x", (nx,), finite=False)
        leg = field(failure, "leg", "failure")
        if leg not in (None, 0, 1, 2) or not isinstance(field(failure, "reason", "failure"), str):
            raise BadFile("failure.leg must be null, 0, 1 or 2 and failure.reason a text")
        failure = dict(failure, t=number("failure.t", field(failure, "t", "failure")), x=fx)
    stats = field(meta, "stats")
    counts = field(meta, "event_counts")
    if not (isinstance(stats, dict) and isinstance(counts, dict)):
        raise BadFile("stats and event_counts must be tables of counts")
    recorded = field(meta, "events_recorded")
    if not isinstance(recorded, bool):
        raise BadFile("events_recorded must be true or false, got %r" % (recorded,))
    dt = number("settings.dt", field(s, "dt", "settings"), lo=0, lo_open=True)
    res = result_cls(
        t=t, x=x, flags=np.ascontiguousarray(flags, dtype=np.intc), Fn=fn, Ft=ft,
        events=[event_cls(float(e[0]), int(e[1]), _layout.EVENT_KIND[int(e[2])], float(e[3]),
                          float(e[4])) for e in ev],
        status=status, failure=failure, x_final=x_final,
        t_final=number("t_final", field(meta, "t_final")), params=params, variant=variant,
        method=method, dt=dt,
        t_end=number("settings.t_end", field(s, "t_end", "settings"), lo=0, lo_open=True),
        n_steps=count("n_steps", field(meta, "n_steps")),
        wall_time=number("wall_time", field(meta, "wall_time"), lo=0),
        stats={str(k): count("stats." + str(k), v) for k, v in stats.items()},
        gait=Steps(gait) if gait else None,
        n_gait_steps=count("n_gait_steps", field(meta, "n_gait_steps")),
        event_counts={str(k): count("event_counts." + str(k), v) for k, v in counts.items()},
        events_recorded=recorded, stop_reason=stop, energies=energies,
        features=features, contact=contact)
    dense = meta.get("dense_output")
    if dense is not None:
        order = field(dense, "order", "dense_output")
        if order not in (3, 5):
            raise BadFile("dense_output.order must be 3 or 5, got %r" % (order,))
        st = array(arrays, "sol_t", (-1,))
        res.sol = DenseOutput(st, array(arrays, "sol_x", (len(st), nx)),
                              array(arrays, "sol_flags", (len(st), 2), kind="iu"), params,
                              variant, features, order, contact)
    return res


def result_to_xarray(res):
    """``xarray.Dataset``: x (time, state), flags (time, leg), Fn, Ft (time, leg), energies
    (time), events (event, event_field), gait descriptors (step); ``units`` on every variable,
    the provenance and settings in ``ds.attrs`` (``pdw_metadata``: all of it as JSON)."""
    xr = _need("xarray")
    meta = metadata(res)
    a = _arrays(res)
    dv = {"x": (("time", "state"), a["x"], {"units": json.dumps(_units(res))}),
          "flags": (("time", "leg"), a["flags"], {"units": "1", "long_name": "support flag"}),
          "events": (("event", "event_field"), a["events"], {"units": "s, -, -, m, m"}),
          "x_final": (("state",), a["x_final"], {"units": json.dumps(_units(res))})}
    if len(a["Fn"]) == len(a["t"]):
        dv["Fn"] = (("time", "leg"), a["Fn"], {"units": "N", "long_name": "normal contact force"})
        dv["Ft"] = (("time", "leg"), a["Ft"], {"units": "N",
                                               "long_name": "tangential contact force"})
    else:
        dv["Fn"] = (("nf", "leg"), a["Fn"], {"units": "N"})
        dv["Ft"] = (("nf", "leg"), a["Ft"], {"units": "N"})
    for k, v in a.items():
        if k.startswith("energy_"):
            dv[k] = (("time",), v, {"units": "J"})
        elif k.startswith("gait_"):
            dv[k] = (("step",), v, {"units": STEP_UNITS.get(k[5:], "")})
        elif k.startswith("sol_"):
            dv[k] = (("sol_step",) + (("sol_" + ("state" if k == "sol_x" else "leg"),)
                                      if v.ndim == 2 else ()), v, {})
    ds = xr.Dataset(dv, coords={"time": ("time", a["t"], {"units": "s"}),
                                "state": list(_names(res)), "leg": [1, 2],
                                "event_field": list(_layout.EVENT)})
    prov = meta["provenance"]
    ds.attrs.update({"pdw_version": prov["pdw_version"], "input_hash": prov["input_hash"],
                     "source_revision": prov["source_revision"] or "",
                     "method": res.method, "variant": res.variant, "status": res.status,
                     "written": meta["written"], "pdw_metadata": json.dumps(meta)})
    return ds


# --- BatchResult ------------------------------------------------------------------------------

#: BatchResult's per-walker arrays: name -> (dtype kind, trailing shape, finite)
_BATCH_ARRAYS = {
    "status": ("U", (), True), "stop_reason": ("U", (), True),
    "x_final": ("f", (len(_layout.STATE),), False), "t_final": ("f", (), False),
    "n_steps": ("iu", (), True), "flags_final": ("iu", (2,), True),
    "failure_reason": ("U", (), True), "failure_t": ("f", (), False),
    "failure_x": ("f", (len(_layout.STATE),), False), "failure_leg": ("iu", (), True),
    "n_touch_down": ("iu", (), True), "n_lift_off": ("iu", (), True),
    "n_gait_steps": ("iu", (), True),
    "gait_rows": ("f", (_layout.STEP_RING, len(_layout.STEP)), False),
}


def batch_to_file(b) -> tuple[dict, dict]:
    """(arrays, meta) of a `BatchResult`: its per-walker arrays (text as unicode arrays), its
    settings, and each recorded walker's `Result` (arrays ``recorded<i>.<name>``, metadata
    under ``recorded``)."""
    arrays = {}
    for name, (kind, _, _) in _BATCH_ARRAYS.items():
        v = np.asarray(getattr(b, name))
        arrays[name] = v.astype(str) if kind == "U" else v
    rec_meta = {}
    for i, r in b.recorded.items():
        a, m = result_to_file(r)
        arrays.update({"recorded%d.%s" % (int(i), k): v for k, v in a.items()})
        rec_meta[str(int(i))] = m
    meta = {"provenance": dict(provenance()), "written": _written(), "n": len(b),
            "dt": b.dt, "t_end": b.t_end, "method": b.method, "variant": b.variant,
            "engine": b.engine, "recorded": rec_meta}
    return arrays, meta


def batch_from_file(arrays, meta, batch_cls, result_cls, event_cls):
    """A `BatchResult` from a file's arrays and metadata, every field checked."""
    n = count("n", field(meta, "n"))
    out = {}
    for name, (kind, shape, finite) in _BATCH_ARRAYS.items():
        a = array(arrays, name, (n,) + shape, kind=kind, finite=finite)
        out[name] = a.astype(object) if kind == "U" else a
    for name in ("status", "stop_reason"):
        bad = set(out[name]) - set(STATUSES + STOP_REASONS)
        if bad:
            raise BadFile("array %r holds unknown values %s" % (name, sorted(bad)))
    if not np.isin(out["flags_final"], (0, 1)).all():
        raise BadFile("array 'flags_final' must hold 0 or 1 only")
    rec = field(meta, "recorded")
    if not isinstance(rec, dict):
        raise BadFile("recorded must be a table of results, got %r" % (rec,))
    recorded = {}
    for key, m in rec.items():
        try:
            i = int(key)
        except ValueError:
            raise BadFile("recorded: %r is not a walker index" % (key,)) from None
        if not 0 <= i < n:
            raise BadFile("recorded: walker %d is not in [0, %d)" % (i, n))
        pre = "recorded%d." % i
        sub = {k[len(pre):]: v for k, v in arrays.items() if k.startswith(pre)}
        try:
            recorded[i] = result_from_file(sub, m, result_cls, event_cls)
        except BadFile as e:
            raise BadFile("recorded walker %d: %s" % (i, e)) from None
    return batch_cls(
        **out, dt=number("dt", field(meta, "dt"), lo=0, lo_open=True),
        t_end=number("t_end", field(meta, "t_end"), lo=0, lo_open=True),
        method=choice("method", field(meta, "method"), METHODS),
        variant=choice("variant", field(meta, "variant"), _layout.VARIANTS),
        recorded=recorded, engine=choice("engine", field(meta, "engine"), ("batch", "scalar")))
