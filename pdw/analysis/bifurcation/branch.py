"""Branches of gaits and their bifurcations: the data a continuation returns (`pdw.analysis.bifurcation.continuation`).

A `Branch` holds one family of period-n gaits followed in one parameter: per-point arrays
(``values``, ``period``, ``step_length``, ``double_support``, ``multipliers``, ``stable``,
``state``, the section coordinates ``z`` and the unit ``tangents`` of the curve) and the list of
located `Bifurcation` s. It writes itself as CSV (`Branch.to_csv`) and JSON (`Branch.to_json`),
plots itself (`Branch.plot`, a bifurcation diagram: stable solid, unstable dashed) and switches
onto the period-2 branch at a period doubling (`Branch.switch`, i.e.
`pdw.analysis.bifurcation.continuation.switch_branch`).
"""
from __future__ import annotations

import csv
import json
import os
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...core.errors import InvalidInputError
from ..gait_types import Gait
from .testfunctions import KINDS, LABELS

__all__ = ["Bifurcation", "Branch", "KINDS", "LABELS"]


@dataclass(eq=False)
class Bifurcation:
    """A located bifurcation (or the end of the family) on a branch.

    Attributes
    ----------
    kind : str
        ``"fold"`` (turning point: the tangent's parameter component through 0, a multiplier
        at +1), ``"period_doubling"`` (a real multiplier through -1), ``"neimark_sacker"`` (a
        complex pair through the unit circle) or ``"end"`` (the family stops existing as
        modelled; ``reason`` says why).
    value : float
        The parameter there, located to ``tolerance`` (parameter units; relative for a log
        continuation).
    gait : Gait or None
        The gait at ``value`` (None for an end found by a failing step map).
    index : int
        The bifurcation lies between branch points ``index`` and ``index + 1``.
    tolerance : float
        Width of the final bracket in the parameter.
    reason : str
        What crossed: the test function, or for an end the physical reason.
    z, mu, tangent, eigenvector, multipliers : ndarray
        Section point, internal parameter coordinate, unit tangent (z, u) of the branch,
        the critical eigenvector (real part, for a period doubling), multipliers.
    located : bool
        True when the final bracket is within ``locate_tol`` and the test function vanishes
        continuously there (`pdw.analysis.bifurcation.continuation_engine.locate`). False: it was only
        *detected* between ``bracket[0]`` and ``bracket[1]``, ``value`` is just the best point
        found, and ``location_note`` says why the location failed.
    bracket : tuple of float
        The final bracket (parameter values, ascending).
    label : str
        AUTO-style label: type (LP, PD, NS, BP, EP, UZ) and running number on its branch,
        e.g. ``"PD1"`` (set by the continuation).
    """

    kind: str
    value: float
    gait: Gait | None
    index: int
    tolerance: float
    reason: str = ""
    z: Any = None
    mu: float = float("nan")
    tangent: Any = None
    eigenvector: Any = None
    multipliers: Any = None
    details: dict = field(default_factory=dict)
    located: bool = True
    bracket: Any = None
    location_note: str = ""
    label: str = ""

    @property
    def type_label(self) -> str:
        """AUTO's two-letter type of this kind (`LABELS`)."""
        return LABELS.get(self.kind, "UZ")

    def describe(self) -> str:
        """One line: label, kind, where (located value +- bracket, or the bracket when only
        detected) and why."""
        head = "%s %s" % (self.label or self.type_label, self.kind)
        if self.located:
            return "%s at %.8g (+-%.2g): %s" % (head, self.value, self.tolerance, self.reason)
        lo, hi = self.bracket if self.bracket is not None else (self.value, self.value)
        return ("%s DETECTED, NOT LOCATED: between %.8g and %.8g (%s); %s"
                % (head, lo, hi, self.location_note, self.reason))

    def __repr__(self):
        return "Bifurcation(%s)" % self.describe()

    def as_dict(self) -> dict:
        """JSON-able fields: kind, label, value, tolerance, located, bracket, location_note,
        index, reason, z (or None), and the multipliers as ``multipliers_re`` and
        ``multipliers_im`` lists."""
        m = np.zeros(0) if self.multipliers is None else np.asarray(self.multipliers)
        return {"kind": self.kind, "label": self.label, "value": self.value,
                "tolerance": self.tolerance, "located": bool(self.located),
                "bracket": None if self.bracket is None else [float(v) for v in self.bracket],
                "location_note": self.location_note,
                "index": self.index, "reason": self.reason,
                "z": None if self.z is None else np.asarray(self.z).tolist(),
                "multipliers_re": [float(np.real(v)) for v in m],
                "multipliers_im": [float(np.imag(v)) for v in m]}


@dataclass(eq=False)
class Branch:
    """A continued family of period-``period_n`` gaits (see the module docstring).

    Per-point arrays have length N (the number of points): ``values`` (parameter), ``period``
    (touch-down to touch-down of the whole n-step cycle [s]), ``step_length`` [m] (mean),
    ``double_support`` [s] (mean; 0 for the hybrid model), ``multipliers`` (N, dim) complex,
    sorted by decreasing modulus, ``stable`` (all moduli < 1), ``state`` (N, 4 hybrid /
    8 continuous, 10 with LuGre: the `Gait.state` of each point), ``z`` (N, dim) section
    coordinates (dim: 3 hybrid; continuous 6, or more with a contact law that has memory,
    ``pdw.analysis.stepmap.section.section_names``),
    ``orbit`` (N, n, dim) the n section points of each period-n gait (``orbit[:, 0] == z``),
    ``tangents`` (N, dim + 1), ``step_size`` (N: the arclength step that reached the point;
    0 for the first), ``newton_iterations`` (N).
    """

    parameter: str
    model: str
    period_n: int
    values: np.ndarray
    period: np.ndarray
    step_length: np.ndarray
    double_support: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    state: np.ndarray
    z: np.ndarray
    orbit: np.ndarray
    tangents: np.ndarray
    step_size: np.ndarray
    newton_iterations: np.ndarray
    bifurcations: list = field(default_factory=list)
    stop_reason: str = ""
    n_maps: int = 0
    wall_time: float = 0.0
    settings: dict = field(default_factory=dict)
    problem: Any = field(default=None, repr=False)
    switcher: Any = field(default=None, repr=False)
    extender: Any = field(default=None, repr=False)
    provenance: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.values)

    def __repr__(self):
        return ("Branch(%s, %s model, period %d, %d points, %s in [%.6g, %.6g], "
                "bifurcations=%r, stop: %s)"
                % (self.parameter, self.model, self.period_n, len(self), self.parameter,
                   np.min(self.values), np.max(self.values), self.bifurcations, self.stop_reason))

    def of_kind(self, kind: str) -> list[Bifurcation]:
        """The bifurcations of one kind (`KINDS`: "fold", "period_doubling", ...)."""
        return [b for b in self.bifurcations if b.kind == kind]

    def switch(self, bifurcation: Bifurcation, amplitude: float = 0.005, **kw: Any) -> Gait:
        """The first gait of the period-2n branch born at a period doubling.

        Parameters
        ----------
        bifurcation : Bifurcation
            A ``period_doubling`` of this branch.
        amplitude : float
            Offset from the bifurcation's fixed point in the section coordinates (halved up to
            ``max_tries`` times when Newton fails or lands back on the period-n branch).
        **kw
            Passed to `pdw.analysis.bifurcation.continuation.switch_branch` (``max_tries``).

        Returns
        -------
        Gait
            A period-2n gait; ``details["value"]`` and ``details["direction"]`` let
            ``pdw.continue_gait(..., period=2n, start=gait)`` follow its branch.
        """
        return self.switcher(self, bifurcation, amplitude=amplitude, **kw)

    def extend(self, stop: float, **kw: Any) -> "Branch":
        """Continue this branch beyond its last point towards ``stop`` (also for a branch read
        back by `pdw.load`): the new branch starts at the last point, in the direction the
        branch was going. ``**kw``: `pdw.continue_gait`'s options (the saved model, variant,
        contact, period and parameter coordinate are reused; a branch continued with
        ``params_of`` needs it again). See `pdw.analysis.bifurcation.continuation.extend_branch`."""
        if self.extender is None:
            raise InvalidInputError("this branch cannot be extended (no problem attached)")
        return self.extender(self, stop, **kw)

    def criticality(self, bifurcation: Bifurcation, **kw: Any) -> dict:
        """Super- or subcritical, for a period doubling of this branch, from the direction of
        the period-2n branch: `pdw.analysis.bifurcation.continuation.criticality`."""
        import importlib
        return importlib.import_module("pdw.analysis.bifurcation.continuation").criticality(
            self, bifurcation, **kw)

    # --- files ------------------------------------------------------------------------------------

    ARRAYS = ("values", "period", "step_length", "double_support", "multipliers", "stable",
              "state", "z", "orbit", "tangents", "step_size", "newton_iterations")

    def save(self, path: str | os.PathLike) -> str | os.PathLike:
        """Write the branch to ``path`` (``.npz``: its arrays, and as JSON its settings,
        bifurcations, the problem (base parameters, model, variant, contact, period, parameter
        coordinate) and provenance: pdw version, input hash, source revision, time). `pdw.load`
        reads it back; the loaded branch can be extended (`extend`) and switched at its period
        doublings (`switch`)."""
        if not str(path).endswith(".npz"):
            raise InvalidInputError("Branch.save: path must end in .npz, got %r" % str(path))
        from ...core.provenance import provenance
        arrays: dict[str, Any] = {k: np.asarray(getattr(self, k)) for k in self.ARRAYS}
        prob = self.problem
        problem = None
        if prob is not None and getattr(prob, "base", None) is not None:
            opts = {k: (v.as_dict() if hasattr(v, "as_dict") else v)
                    for k, v in getattr(prob, "opts", {}).items()}
            problem = {"params": prob.base.as_dict(), "parameter": prob.parameter,
                       "model": prob.model, "period": prob.period, "log": prob.log,
                       "variant": getattr(prob, "variant", "paper"),
                       "fd_step": getattr(prob, "fd_step", 1e-5), "options": opts,
                       "params_of": prob._of is not None}
        bifs = []
        for b in self.bifurcations:
            d = b.as_dict()
            d.update(mu=b.mu, tangent=_list(b.tangent), eigenvector=_list(b.eigenvector),
                     origin=None)
            bifs.append(d)
        meta = {"format": BRANCH_FORMAT, "parameter": self.parameter, "model": self.model,
                "period_n": self.period_n, "stop_reason": self.stop_reason,
                "n_maps": self.n_maps, "wall_time": self.wall_time,
                "settings": self.settings, "bifurcations": bifs, "problem": problem,
                "provenance": {**provenance(), "written": time.strftime(
                    "%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "history": self.provenance}}
        arrays["meta"] = np.array(json.dumps(meta, default=_jsonable))
        np.savez(path, **arrays)
        return path

    # --- output -------------------------------------------------------------------------------

    COLUMNS = ("value", "period_n", "period", "step_length", "double_support", "stable",
               "max_abs_multiplier")

    def rows(self):
        """One dict per point (the CSV's rows): the descriptors, the moduli of the multipliers and z."""
        out = []
        for i in range(len(self)):
            m = self.multipliers[i]
            r = {"value": self.values[i], "period_n": self.period_n, "period": self.period[i],
                 "step_length": self.step_length[i], "double_support": self.double_support[i],
                 "stable": int(self.stable[i]), "max_abs_multiplier": float(np.max(np.abs(m)))}
            for k, v in enumerate(m):
                r["mult%d_re" % k], r["mult%d_im" % k] = float(v.real), float(v.imag)
            for k, v in enumerate(self.z[i]):
                r["z%d" % k] = float(v)
            out.append(r)
        return out

    def to_csv(self, path: str | os.PathLike) -> str | os.PathLike:
        """Write the per-point table (`rows`) to ``path``; returns the path."""
        rows = self.rows()
        with open(path, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else list(self.COLUMNS))
            w.writeheader()
            for r in rows:
                w.writerow({k: ("%.17g" % v if isinstance(v, float) else v) for k, v in r.items()})
        return path

    def summary(self) -> dict:
        """JSON-able summary: settings, counts, stop reason, bifurcations."""
        return {"parameter": self.parameter, "model": self.model, "period_n": self.period_n,
                "points": len(self), "range": [float(np.min(self.values)),
                                               float(np.max(self.values))],
                "stop_reason": self.stop_reason, "map_evaluations": self.n_maps,
                "wall_time_s": self.wall_time, "settings": self.settings,
                "bifurcations": [b.as_dict() for b in self.bifurcations]}

    def to_json(self, path: str | os.PathLike, **extra: Any) -> str | os.PathLike:
        """Write `summary` (plus ``extra``) as JSON to ``path``; returns the path."""
        with open(path, "w") as fh:
            json.dump({**self.summary(), **extra}, fh, indent=2, default=_jsonable)
        return path

    def plot(self, *others: "Branch", ax=None, y="step_length", **kw):
        """Bifurcation diagram of this branch and ``others`` overlaid, one colour each (also
        across calls on the same ``ax``), with units on both axes and ``y`` a named quantity
        (step_length, period, double_support, max_multiplier, speed, z0):
        `pdw.plot_branches`, looked up when called (the analysis layer does not import the
        present layer's plotting code)."""
        import importlib
        plots = importlib.import_module("pdw.present.plots_continuation")
        return plots.plot_branches([self, *others], ax=ax, y=y, **kw)


#: the ``meta["format"]`` of a branch file (`Branch.save`)
BRANCH_FORMAT = "pdw-branch-1"


def _list(a):
    return None if a is None else np.asarray(a, dtype=float).tolist()


def _jsonable(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    return str(o)
