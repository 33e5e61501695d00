"""Results out in the forms scientific Python reads: pandas, xarray, files with provenance.

- `result_to_dataframe` / `steps_to_dataframe`: pandas (optional dependency, ``pip install
  pandas``), one row per recorded sample / per gait step, units in ``df.attrs["units"]``.
- `result_to_xarray`: an ``xarray.Dataset`` with named dimensions (time, state, leg), units
  per variable and the provenance as attributes (optional dependency ``xarray``).
- `save` / `load`: a Result to one file and back. ``.npz`` (NumPy only): the arrays plus a
  JSON ``meta`` entry; ``.nc`` (NetCDF through xarray). Both keep the provenance: pdw version,
  INPUT_HASH, pdw's own source revision (`pdw.core.provenance`), the run's settings (or its
  scene, as TOML) and the time of writing.
"""
from __future__ import annotations

import datetime
import json
import pathlib

import numpy as np

from ..core import _layout
from ..core.errors import InvalidInputError
from ..core.params import Params
from ..core.provenance import provenance

UNITS = dict(zip(_layout.STATE, ("m", "m", "rad", "rad", "m/s", "m/s", "rad/s", "rad/s")))
FORMAT = "pdw-result-1"


def _need(name):
    try:
        return __import__(name)
    except ImportError:
        raise ImportError("this export needs %s (pip install %s)" % (name, name)) from None


def metadata(res) -> dict:
    """JSON-able description of a Result: provenance, settings, status, scene."""
    scene = getattr(res, "scene", None)
    meta = {"format": FORMAT, "provenance": dict(provenance()),
            "written": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "settings": {"method": res.method, "variant": res.variant, "dt": res.dt,
                         "t_end": res.t_end, "features": list(res.features),
                         "params": res.params.as_dict()},
            "status": res.status, "stop_reason": res.stop_reason, "failure": None,
            "t_final": res.t_final, "n_steps": int(res.n_steps), "wall_time": res.wall_time,
            "stats": {k: int(v) for k, v in res.stats.items()},
            "n_gait_steps": int(res.n_gait_steps),
            "event_counts": {k: int(v) for k, v in res.event_counts.items()},
            "events_recorded": bool(res.events_recorded),
            "scene": scene.to_toml() if scene is not None and hasattr(scene, "to_toml") else None,
            "units": {"t": "s", "x": UNITS, "Fn": "N", "Ft": "N", "energies": "J"}}
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
    return out


def _result_from(arrays: dict, meta: dict):
    from .gait import Steps
    from .simulation import Event, Result
    s = meta["settings"]
    events = [Event(float(e[0]), int(e[1]), _layout.EVENT_KIND[int(e[2])], float(e[3]), float(e[4]))
              for e in arrays["events"]]
    gait = {k[5:]: v for k, v in arrays.items() if k.startswith("gait_")}
    energies = {k[7:]: v for k, v in arrays.items() if k.startswith("energy_")} or None
    failure = meta["failure"]
    if failure:
        failure = dict(failure, x=np.array(failure["x"]))
    res = Result(t=arrays["t"], x=arrays["x"], flags=arrays["flags"], Fn=arrays["Fn"],
                 Ft=arrays["Ft"], events=events, status=meta["status"], failure=failure,
                 x_final=arrays["x_final"], t_final=meta["t_final"], params=Params(**s["params"]),
                 variant=s["variant"], method=s["method"], dt=s["dt"], t_end=s["t_end"],
                 n_steps=meta["n_steps"], wall_time=meta["wall_time"], stats=meta["stats"],
                 gait=Steps(gait) if gait else None, n_gait_steps=meta["n_gait_steps"],
                 event_counts=meta["event_counts"], events_recorded=meta["events_recorded"],
                 stop_reason=meta["stop_reason"], energies=energies,
                 features=tuple(s["features"]))
    res.provenance = meta
    return res


def save(res, path) -> pathlib.Path:
    """Write a Result to ``path`` (``.npz``, or ``.nc`` through xarray) with its provenance."""
    path = pathlib.Path(path)
    if path.suffix == ".nc":
        result_to_xarray(res).to_netcdf(path)
    elif path.suffix == ".npz":
        np.savez_compressed(path, meta=np.array(json.dumps(metadata(res))), **_arrays(res))
    else:
        raise InvalidInputError("path must end in .npz or .nc, got %r" % str(path))
    return path


def load(path):
    """Read a Result written by `save` (``.npz`` or ``.nc``); ``res.provenance`` holds the
    metadata (pdw version, INPUT_HASH, source revision, settings, scene, time of writing)."""
    path = pathlib.Path(path)
    if path.suffix == ".nc":
        xr = _need("xarray")
        with xr.open_dataset(path) as ds:
            ds.load()
            meta = json.loads(ds.attrs["pdw_metadata"])
            arrays = {k: ds[k].values for k in ds.data_vars}
            arrays["t"] = ds["time"].values
        arrays["flags"] = arrays["flags"].astype(np.intc)
    elif path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = json.loads(str(arrays.pop("meta")))
    else:
        raise InvalidInputError("path must end in .npz or .nc, got %r" % str(path))
    if meta.get("format") != FORMAT:
        raise InvalidInputError("%s is not a pdw result file (format %r)" % (path, meta.get("format")))
    return _result_from(arrays, meta)


def result_to_dataframe(res):
    """One row per recorded sample, indexed by t [s]: the state (`pdw.STATE`), the support
    flags ``flag1, flag2``, the contact forces ``Fn1, Fn2, Ft1, Ft2`` [N] (if recorded) and the
    energies [J] (if recorded). Units in ``df.attrs["units"]``."""
    pd = _need("pandas")
    cols = {name: res.x[:, i] for i, name in enumerate(_layout.STATE)}
    units = dict(UNITS)
    cols.update(flag1=res.flags[:, 0], flag2=res.flags[:, 1])
    if len(res.Fn) == len(res.t):
        for i in (0, 1):
            cols["Fn%d" % (i + 1)] = res.Fn[:, i]
            cols["Ft%d" % (i + 1)] = res.Ft[:, i]
            units["Fn%d" % (i + 1)] = units["Ft%d" % (i + 1)] = "N"
    for k, v in (res.energies or {}).items():
        cols[k] = v
        units[k] = "J"
    df = pd.DataFrame(cols, index=pd.Index(res.t, name="t"))
    df.attrs["units"] = units
    df.attrs["provenance"] = metadata(res)["provenance"]
    return df


def steps_to_dataframe(steps):
    """One row per gait step (columns `pdw.core._layout.STEP`); units in ``df.attrs``."""
    pd = _need("pandas")
    from .gait import UNITS as STEP_UNITS
    df = pd.DataFrame({k: np.asarray(v) for k, v in steps.table.items()})
    df.index.name = "step"
    if "leg" in df:
        df["leg"] = df["leg"].astype(int)
    df.attrs["units"] = dict(STEP_UNITS)
    return df


def result_to_xarray(res):
    """``xarray.Dataset``: x (time, state), flags (time, leg), Fn, Ft (time, leg), energies
    (time), events (event, event_field), gait descriptors (step); ``units`` on every variable,
    the provenance and settings in ``ds.attrs`` (``pdw_metadata``: all of it as JSON)."""
    xr = _need("xarray")
    meta = metadata(res)
    a = _arrays(res)
    dv = {"x": (("time", "state"), a["x"], {"units": json.dumps(UNITS)}),
          "flags": (("time", "leg"), a["flags"], {"units": "1", "long_name": "support flag"}),
          "events": (("event", "event_field"), a["events"], {"units": "s, -, -, m, m"}),
          "x_final": (("state",), a["x_final"], {"units": json.dumps(UNITS)})}
    if len(a["Fn"]) == len(a["t"]):
        dv["Fn"] = (("time", "leg"), a["Fn"], {"units": "N", "long_name": "normal contact force"})
        dv["Ft"] = (("time", "leg"), a["Ft"], {"units": "N",
                                               "long_name": "tangential contact force"})
    else:
        dv["Fn"] = (("nf", "leg"), a["Fn"], {"units": "N"})
        dv["Ft"] = (("nf", "leg"), a["Ft"], {"units": "N"})
    from .gait import UNITS as STEP_UNITS
    for k, v in a.items():
        if k.startswith("energy_"):
            dv[k] = (("time",), v, {"units": "J"})
        elif k.startswith("gait_"):
            dv[k] = (("step",), v, {"units": STEP_UNITS.get(k[5:], "")})
    ds = xr.Dataset(dv, coords={"time": ("time", a["t"], {"units": "s"}),
                                "state": list(_layout.STATE), "leg": [1, 2],
                                "event_field": list(_layout.EVENT)})
    prov = meta["provenance"]
    ds.attrs.update({"pdw_version": prov["pdw_version"], "input_hash": prov["input_hash"],
                     "source_revision": prov["source_revision"] or "",
                     "method": res.method, "variant": res.variant, "status": res.status,
                     "written": meta["written"], "pdw_metadata": json.dumps(meta)})
    return ds
