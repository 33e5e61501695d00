"""Results out in the forms scientific Python reads: pandas DataFrames (and, through
`pdw.sim.files`, xarray and files with provenance).

- `result_to_dataframe` / `steps_to_dataframe`: pandas (optional dependency, ``pip install
  pandas``), one row per recorded sample / per gait step, units in ``df.attrs["units"]``.
- The file format (``Result.save`` / `pdw.load`, ``.npz`` and ``.nc``) and the xarray Dataset
  of a run are owned by `pdw.sim.files`, writer and reader side by side; ``save``, ``read``,
  ``metadata``, ``result_to_xarray``, ``FORMAT``, ``UNITS`` and ``STEP_UNITS`` here are its
  names, kept as aliases of the old import paths.
"""
from __future__ import annotations

from .files import FORMAT, STEP_UNITS, UNITS, _names, _need, _units, metadata, read, result_to_xarray, save  # noqa: F401
from .gait import steps_to_dataframe  # noqa: F401 (the old import path)


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
