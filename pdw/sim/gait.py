"""Gait descriptors per step (docs/model.md section 8, paper Sec. 4.1) from a simulation's events.

A *step* ends at a touch-down of the swing leg j (time t_td, contact point x_td):

- step length L: x_td minus the other foot's contact point at that foot's own previous
  touch-down (footprint spacing; the paper's L of about 0.40 m);
- travel: x_td minus leg j's contact point at its previous lift-off (the swing foot's own
  travel, about 0.6 m);
- period P: t_td minus leg j's previous lift-off (the swing time);
- velocity v = L / P;
- cycle: t_td minus the previous touch-down (of the other leg);
- double support: from t_td to the other leg's next lift-off (both flags 1), and its
  fraction of the step's cycle; NaN when the run ends before that lift-off, or when
  the other leg does not lift off before the next touch-down.

The compiled loops compute the same descriptors online, as the events happen (pdw/core/csrc/
pdw_discrete.c, layout `pdw.core._layout.STEP`), keeping the last ``pdw.core._layout.STEP_RING`` steps:
`Result.gait`. `steps` recomputes every step from a run's events; for a run that did not keep
its events (``record_events=False``) it returns `Result.gait`.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..core import _layout, checks
from ..core.errors import InvalidInputError

if TYPE_CHECKING:                 # annotations only (simulation imports this module)
    import pandas

    from .simulation import Event, Result

FIELDS = _layout.STEP
UNITS = {"leg": "", "t_lift_off": "s", "t_touch_down": "s", "L": "m", "travel": "m", "P": "s",
         "v": "m/s", "cycle": "s", "double_support": "s", "ds_fraction": ""}


@dataclass
class Steps:
    """Per-step gait descriptors (docs/model.md section 8), one entry per complete step.

    Attributes
    ----------
    table : dict
        Column name -> ndarray (n_steps,): ``leg`` (the swing leg, 1 or 2), ``t_lift_off``
        and ``t_touch_down`` [s], step length
        ``L`` and hip ``travel`` [m], step period ``P`` [s], speed ``v`` [m/s], ``cycle`` [s],
        ``double_support`` [s] and its share of the step, ``ds_fraction`` [-].
        ``steps["L"]`` is ``steps.table["L"]``; ``len(steps)`` the number of steps.
    """

    table: dict[str, np.ndarray]

    def __len__(self):
        return len(self.table["leg"])

    def __getitem__(self, name):
        return self.table[name]

    def steady(self, last: int = 4, *, rtol: float = 1e-3) -> dict[str, float | int | bool]:
        """The steady gait: the mean of the last ``last`` complete steps, and whether they
        have converged.

        Parameters
        ----------
        last : int
            Steps to average (>= 1; fewer when the run has fewer; NaN entries are skipped;
            ``converged`` needs at least 2).
        rtol : float
            ``converged`` needs every consecutive pair of the averaged steps to agree in L,
            travel, P and cycle within rtol relative to the mean (the tolerance of a scene's
            periodic stop, `pdw.Scene`); > 0.

        Returns
        -------
        dict
            ``n_steps`` (all steps), ``last`` (steps averaged), ``converged`` (bool: ``last``
            full steps were averaged and they agree within ``rtol``; False for a run with
            fewer steps, e.g. one that fell after one step, or one still in its transient),
            the means of ``L``, ``travel`` [m], ``P``, ``cycle``, ``double_support`` [s],
            ``v`` [m/s], ``ds_fraction`` [-], and for each ``spread_<name>``: the largest
            absolute difference between consecutive averaged steps (how far from steady they
            still are; NaN for one step). The means are those of the steps there are, steady
            or not: read them as a steady gait only when ``converged`` is True. ``converged``
            says nothing about how the run ended (`Result.status`).
        """
        last = checks.count("last", last, lo=1)
        rtol = checks.positive("rtol", rtol)
        out: dict[str, float | int | bool] = {"n_steps": len(self), "last": min(last, len(self)),
                                              "converged": False}
        agree = last >= 2
        for name in ("L", "travel", "P", "v", "cycle", "double_support", "ds_fraction"):
            a = self.table[name]
            a = a[np.isfinite(a)][-last:]
            out[name] = float(np.mean(a)) if len(a) else float("nan")
            spread = float(np.max(np.abs(np.diff(a)))) if len(a) > 1 else float("nan")
            out["spread_" + name] = spread
            if name in ("L", "travel", "P", "cycle"):
                agree = agree and len(a) == last and spread <= rtol * abs(out[name])
        out["converged"] = bool(agree)
        return out

    def to_dataframe(self) -> pandas.DataFrame:
        """One row per step as a pandas DataFrame (``steps_to_dataframe``; needs
        pandas): the columns of `table`, units in ``df.attrs["units"]``."""
        return steps_to_dataframe(self)

    def describe_step(self, k: int = -1) -> str:
        """One step in words: ``"leg 2, L 0.3685 m, P 0.5644 s, v 0.653 m/s, double support
        16.5 ms (2.84 %)"`` (the last complete step by default)."""
        t = self.table
        return ("leg %d, L %.4f m, P %.4f s, v %.4f m/s, double support %.1f ms (%.2f %%)"
                % (t["leg"][k], t["L"][k], t["P"][k], t["v"][k], 1e3 * t["double_support"][k],
                   100 * t["ds_fraction"][k]))

    def __repr__(self):
        if not len(self):
            return "<pdw.Steps: no complete step>"
        t = self.table
        return ("<pdw.Steps: %d steps, touch-downs %.4f .. %.4f s\n  last: %s>"
                % (len(self), t["t_touch_down"][0], t["t_touch_down"][-1], self.describe_step()))

    def to_text(self) -> str:
        """The table as aligned text (times in s, lengths in m, double support in ms)."""
        head = "%4s %3s %9s %9s %8s %8s %7s %7s %7s %8s %7s" % (
            "step", "leg", "lift-off", "touch", "L [m]", "travel", "P [s]", "v [m/s]",
            "cycle", "DS [ms]", "DS [%]")
        rows = [head]
        t = self.table
        for k in range(len(self)):
            rows.append("%4d %3d %9.4f %9.4f %8.4f %8.4f %7.4f %7.4f %7.4f %8.1f %7.2f" % (
                k + 1, t["leg"][k], t["t_lift_off"][k], t["t_touch_down"][k], t["L"][k],
                t["travel"][k], t["P"][k], t["v"][k], t["cycle"][k],
                1e3 * t["double_support"][k], 100 * t["ds_fraction"][k]))
        return "\n".join(rows)


def steps_from_rows(rows, capacity: int = _layout.STEP_RING) -> Steps:
    """Steps from rows of the compiled online analysis (layout `pdw.core._layout.STEP`, legs 0/1).

    The columns are views of arrays of ``capacity`` (at least len(rows)) entries, so that the
    memory of a result does not depend on how many steps its ring holds."""
    rows = np.asarray(rows, dtype=float).reshape(-1, len(FIELDS))
    n = len(rows)
    cols = np.full((len(FIELDS), max(capacity, n)), np.nan)
    cols[:, :n] = rows.T
    legs = np.zeros(cols.shape[1], dtype=int)
    legs[:n] = cols[FIELDS.index("leg"), :n]
    legs[:n] += 1
    table = {f: (legs[:n] if f == "leg" else cols[i, :n]) for i, f in enumerate(FIELDS)}
    return Steps(table)


def steps(result_or_events: Result | Sequence[Event]) -> Steps:
    """Gait descriptors of every complete step of a run.

    Parameters
    ----------
    result_or_events : Result or sequence of Event
        A `pdw.simulate` result, or its ``events`` (time-ordered touch-downs and lift-offs,
        legs numbered 1 and 2). For a result that did not keep its events
        (``record_events=False``): its online descriptors, `Result.gait` (the last
        ``pdw.core._layout.STEP_RING`` steps).

    Returns
    -------
    Steps
        Steps whose swing leg has a known lift-off and whose other foot has a known
        touch-down (the first, partial step of a run is skipped).
    """
    src: Any = result_or_events       # duck-typed: a Result, or a sequence of events
    if getattr(src, "events_recorded", True) is False:
        return src.gait
    if not hasattr(src, "events") and callable(getattr(src, "steps", None)):
        raise InvalidInputError("pdw.steps takes one run (a Result or its events); for the "
                                "walkers of a %s b use b.steps(i) (walker i)"
                                % type(src).__name__)
    events = getattr(src, "events", src)
    if isinstance(events, (str, bytes)) or not isinstance(events, Iterable):
        raise InvalidInputError("pdw.steps takes a Result or a sequence of its Events, got %s"
                                % type(src).__name__)
    events = list(events)
    if any(not all(hasattr(e, a) for a in ("t", "kind", "leg")) for e in events):
        raise InvalidInputError("pdw.steps takes a Result or a sequence of its Events, got %s"
                                % type(src).__name__)
    events = sorted(events, key=lambda e: e.t)
    last_td: dict[int, Any] = {1: None, 2: None}     # (t, x_D) of each leg's latest touch-down
    last_lo: dict[int, Any] = {1: None, 2: None}     # (t, x_D) of each leg's latest lift-off
    prev_td_t = None
    rows = []
    for k, e in enumerate(events):
        if e.kind == "lift_off":
            last_lo[e.leg] = (e.t, e.x_D)
            continue
        j, i = e.leg, 3 - e.leg
        if last_lo[j] is not None and last_td[i] is not None and prev_td_t is not None:
            L = e.x_D - last_td[i][1]
            P = e.t - last_lo[j][0]
            ds, nxt_td = float("nan"), None
            for f in events[k + 1:]:
                if f.kind == "lift_off" and f.leg == i and np.isnan(ds):
                    ds = f.t - e.t
                if f.kind == "touch_down":
                    nxt_td = f.t
                    break
            if nxt_td is not None and not np.isnan(ds) and ds > nxt_td - e.t:
                ds = float("nan")
            rows.append(dict(leg=j, t_lift_off=last_lo[j][0], t_touch_down=e.t, L=L,
                             travel=e.x_D - last_lo[j][1], P=P, v=L / P if P > 0 else float("nan"),
                             cycle=e.t - prev_td_t, double_support=ds,
                             ds_fraction=ds / (e.t - prev_td_t)))
        last_td[j] = (e.t, e.x_D)
        prev_td_t = e.t
    table = {f: np.array([r[f] for r in rows], dtype=int if f == "leg" else float) for f in FIELDS}
    return Steps(table)


#: Units of the step descriptors (`pdw.core._layout.STEP`).
STEP_UNITS = {"leg": "", "t_lift_off": "s", "t_touch_down": "s", "L": "m", "travel": "m",
              "P": "s", "v": "m/s", "cycle": "s", "double_support": "s", "ds_fraction": ""}


def steps_to_dataframe(steps):
    """One row per gait step (columns `pdw.core._layout.STEP`); units in ``df.attrs``. Needs
    pandas."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError("this export needs pandas (pip install pandas)") from None
    df = pd.DataFrame({k: np.asarray(v) for k, v in steps.table.items()})
    df.index.name = "step"
    if "leg" in df:
        df["leg"] = df["leg"].astype(int)
    df.attrs["units"] = dict(STEP_UNITS)
    return df
