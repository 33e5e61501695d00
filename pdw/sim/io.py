"""Results out in the forms scientific Python reads: pandas, xarray, files with provenance.

- `result_to_dataframe` / `steps_to_dataframe`: pandas (optional dependency, ``pip install
  pandas``), one row per recorded sample / per gait step, units in ``df.attrs["units"]``.
- `result_to_xarray`: an ``xarray.Dataset`` with named dimensions (time, state, leg), units
  per variable and the provenance as attributes (optional dependency ``xarray``).
- `save` / `read` (`pdw.load`): a Result to one file and back. ``.npz`` (NumPy only): the arrays plus a
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
from ..core.provenance import provenance

STEP_UNITS = {"leg": "", "t_lift_off": "s", "t_touch_down": "s", "L": "m", "travel": "m",
              "P": "s", "v": "m/s", "cycle": "s", "double_support": "s", "ds_fraction": ""}
UNITS = dict(zip(_layout.STATE, ("m", "m", "rad", "rad", "m/s", "m/s", "rad/s", "rad/s")))
UNITS.update({name: "m" for name in _layout.BRISTLE})      # LuGre's bristle deflections


def _names(res):
    """The column names of res.x (its friction law's state layout)."""
    return tuple(getattr(res, "state_names", _layout.STATE))


def _units(res):
    return {n: UNITS[n] for n in _names(res)}
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
                         "params": res.params.as_dict(),
                         "contact": (res.contact.as_dict() if getattr(res, "contact", None)
                                     is not None else None)},
            "status": res.status, "stop_reason": res.stop_reason, "failure": None,
            "t_final": res.t_final, "n_steps": int(res.n_steps), "wall_time": res.wall_time,
            "stats": {k: int(v) for k, v in res.stats.items()},
            "n_gait_steps": int(res.n_gait_steps),
            "event_counts": {k: int(v) for k, v in res.event_counts.items()},
            "events_recorded": bool(res.events_recorded),
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
    return out


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


def read(path):
    """(arrays, metadata) of a file written by `save` (``.npz`` or ``.nc``); `pdw.load`
    makes a Result of them."""
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
    return arrays, meta


def result_to_dataframe(res):
    """One row per recorded sample, indexed by t [s]: the state (`Result.state_names`), the support
    flags ``flag1, flag2``, the contact forces ``Fn1, Fn2, Ft1, Ft2`` [N] (if recorded) and the
    energies [J] (if recorded). Units in ``df.attrs["units"]``."""
    pd = _need("pandas")
    cols = {name: res.x[:, i] for i, name in enumerate(_names(res))}
    units = _units(res)
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
    ds = xr.Dataset(dv, coords={"time": ("time", a["t"], {"units": "s"}),
                                "state": list(_names(res)), "leg": [1, 2],
                                "event_field": list(_layout.EVENT)})
    prov = meta["provenance"]
    ds.attrs.update({"pdw_version": prov["pdw_version"], "input_hash": prov["input_hash"],
                     "source_revision": prov["source_revision"] or "",
                     "method": res.method, "variant": res.variant, "status": res.status,
                     "written": meta["written"], "pdw_metadata": json.dumps(meta)})
    return ds
