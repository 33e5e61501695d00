"""`pdw.load`: a Result back from a file written by `Result.save` (`pdw.sim.io`)."""
from __future__ import annotations

import numpy as np

from ..core import _layout
from ..core.contact import Contact
from ..core.params import Params
from . import io as _io
from .gait import Steps
from .simulation import Event, Result


def load(path) -> Result:
    """Read a Result written by `Result.save` (``.npz`` or ``.nc``); ``res.provenance`` holds
    the metadata (pdw version, INPUT_HASH, pdw's source revision, settings, scene, time of
    writing)."""
    arrays, meta = _io.read(path)
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
    if s.get("contact"):
        res.contact = Contact(**s["contact"])
    res.provenance = meta
    return res
