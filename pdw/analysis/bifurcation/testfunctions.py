"""Test functions of a continuation as objects: what is watched along a branch (docs/continuation.md).

A test function maps a branch point to one or more named scalars; a sign change between two
points marks a point to locate there (`pdw.analysis.bifurcation.continuation_engine.check_crossings`). The
built-in ones are the bifurcations of a fixed point of a map, the admissible ends of a gait
family, and user events:

=================  =====  ==========================================================
class              label  scalar(s) (zero at the special point)
=================  =====  ==========================================================
`Fold`             LP     the tangent's parameter component (natural: det(M - I))
`PeriodDoubling`   PD     det(M + I) (a real multiplier through -1)
`NeimarkSacker`    NS     prod_{j<k} (mu_j mu_k - 1) (a complex pair through |mu| = 1)
`BranchPoint`      BP     det of the bordered Jacobian [DG; t_prev^T] (a simple branch point)
`AdmissibleEnd`    EP     each admissibility function of the problem (> 0 on a valid gait)
`Event`            UZ     quantity - level (e.g. ``Event("step_length", 0.4)``)
`SequenceChange`   UZ     0.5 - |n_events - n_events at the start| (a step function: bracketed)
=================  =====  ==========================================================

The list of kinds (`KINDS`) and labels (`LABELS`) derives from these classes. A user's own test
function subclasses `TestFunction` (``kind``, ``label``, ``values``, optionally ``crossed`` and
``describe``) and is given in ``continue_gait(..., events=[...])``.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ...core.errors import InvalidInputError


class TestFunction:
    """Base class: ``values(engine, pt) -> {name: float}``; a sign change of one of them between
    two consecutive points is a crossing, located by `continuation_engine.locate`.

    Attributes
    ----------
    kind : str
        The bifurcation kind it reports (the ``kind`` of a `pdw.Bifurcation`).
    label : str
        AUTO's two-letter type (LP, PD, NS, BP, EP, UZ).
    """

    __test__ = False           # not a pytest class
    kind = "user"
    label = "UZ"

    def values(self, engine: Any, pt: Any) -> dict[str, float]:
        raise NotImplementedError

    def crossed(self, name: str, fa: float, fb: float) -> bool:
        """Whether the scalar ``name`` changed sign from fa to fb."""
        return bool(np.sign(fa) != np.sign(fb) and fa != 0.0)

    def describe(self, engine: Any, pt: Any, name: str) -> tuple[str, Any] | None:
        """(reason, eigenvector or None) at the located point; None rejects the crossing."""
        return "%s through 0" % name, None

    #: the largest natural residual (`residual`) of a located point
    tol = 1e-3

    def residual(self, engine: Any, pt: Any, name: str) -> float | None:
        """The distance from the special point in the test's natural measure (e.g. |mu + 1|
        of the critical multiplier), accepted up to `tol` where the test function itself is
        at its noise floor (finite-difference multipliers); None: no such measure."""
        return None


class Fold(TestFunction):
    """A turning point (saddle-node): the branch reverses in the parameter; a multiplier at +1."""

    kind, label = "fold", "LP"

    def values(self, engine, pt):
        if engine.natural:
            return {"fold": float(np.real(np.prod(pt.mult - 1.0)))}
        return {"fold": float(pt.tangent[-1])}

    def describe(self, engine, pt, name):
        return ("turning point: the branch reverses in %s" % engine.prob.parameter, None)


class PeriodDoubling(TestFunction):
    """A real multiplier through -1 (flip)."""

    kind, label = "period_doubling", "PD"

    def values(self, engine, pt):
        return {"period_doubling": float(np.real(np.prod(pt.mult + 1.0)))}

    def residual(self, engine, pt, name):
        return float(np.min(np.abs(pt.mult + 1.0)))

    def describe(self, engine, pt, name):
        m = pt.mult
        j = int(np.argmin(np.abs(m + 1.0)))
        w, V = np.linalg.eig(pt.ev.M)
        v = np.real(V[:, int(np.argmin(np.abs(w - m[j])))])
        return "a multiplier through -1 (%.6g)" % np.real(m[j]), v / np.linalg.norm(v)


class NeimarkSacker(TestFunction):
    """A complex pair of multipliers through the unit circle (a neutral saddle is rejected)."""

    kind, label = "neimark_sacker", "NS"

    def residual(self, engine, pt, name):
        cx = [v for v in pt.mult if abs(v.imag) > 1e-8]
        return float(min(abs(abs(v) - 1.0) for v in cx)) if cx else None

    def values(self, engine, pt):
        m = pt.mult
        n = len(m)
        ns = np.prod([m[j] * m[k] - 1.0 for j in range(n) for k in range(j + 1, n)])
        return {"neimark_sacker": float(np.real(ns))}

    def describe(self, engine, pt, name):
        # a neutral saddle (a real mu_i mu_j = 1) is rejected; a complex pair that is not on
        # the circle at the returned point is still reported (its location failed, and
        # `continuation_engine.locate` says so), never dropped
        cx = [v for v in pt.mult if abs(v.imag) > 1e-8]
        re = [float(v.real) for v in pt.mult if abs(v.imag) <= 1e-8]
        saddle = min([abs(a * b - 1.0) for i, a in enumerate(re) for b in re[i + 1:]],
                     default=np.inf)
        if not cx:
            return None
        c = min(cx, key=lambda v: abs(abs(v) - 1.0))
        if saddle < abs(abs(c) - 1.0):
            return None
        return ("a complex pair through the unit circle (|mu| = %.6g, arg %.4g rad)"
                % (abs(c), abs(np.angle(c))), None)


class BranchPoint(TestFunction):
    """A simple branch point of G(z, u) = 0: the bordered Jacobian [DG; t^T] (t the branch's
    continuously oriented tangent) is singular there and its determinant changes sign (at a
    fold it does not). Off by default (``detect``)."""

    kind, label = "branch_point", "BP"

    def values(self, engine, pt):
        A = np.vstack([engine.dG(pt.ev), pt.tangent[None, :]])
        return {"branch_point": float(np.linalg.det(A))}

    def describe(self, engine, pt, name):
        return "the bordered Jacobian is singular (two branches cross)", None


class AdmissibleEnd(TestFunction):
    """The end of the family as modelled: an admissibility function of the problem
    (``prob.ADMISSIBLE``) through 0 from above.

    Parameters
    ----------
    skip : sequence of str, optional
        Admissibility functions not watched (e.g. ``("event_sequence",)``, with
        `SequenceChange` reporting the changes instead of ending the branch there). The
        built-in instance watches all; give ``AdmissibleEnd(skip=...)`` in ``events=`` and
        leave "end" out of ``detect``.
    """

    kind, label = "end", "EP"

    def __init__(self, skip: Any = ()):
        if isinstance(skip, str) or not all(isinstance(k, str) for k in skip):
            raise InvalidInputError("AdmissibleEnd: skip must be a sequence of admissibility "
                                    "names, got %r" % (skip,))
        self.skip = tuple(skip)

    def values(self, engine, pt):
        return {"end:" + k: float(v) for k, v in pt.ev.admissible.items()
                if k not in self.skip}

    def crossed(self, name, fa, fb):
        return bool(fa > 0.0 >= fb)

    def describe(self, engine, pt, name):
        adm = name[4:]
        return "%s -> 0: %s" % (adm, engine.prob.ADMISSIBLE.get(adm, adm)), None


class SequenceChange(TestFunction):
    """A change of the step's sequence of support events (the continuous model: the count of
    lift-offs and touch-downs per period, ``info["n_events"]``) reported as a point of the
    branch (kind ``"event"``, label UZ) instead of its end.

    Where the extra events are a lift-off and a re-touch-down of a foot that carries no force
    in between (paper_steady's stance foot rising 3 mm above the ground early in single
    support, docs/continuation.md), the step map is continuous across the change, so the
    family goes on; whether it does is checked by the corrector converging beyond it and by
    long walks. The scalar, 0.5 - |n - n_0| with n_0 the count at the first point this
    instance sees, is a step function: its crossings are bracketed to ``locate_tol`` and
    reported as detected, not located (`continuation_engine.locate`). A return to n_0 is a
    crossing too; a change between two counts both different from n_0 is not seen.
    """

    kind, label = "event", "UZ"

    def __init__(self):
        self.ref: int | None = None

    def values(self, engine, pt):
        n = pt.ev.info.get("n_events")
        if n is None:
            return {}
        if self.ref is None:
            self.ref = int(n)
        return {"event_sequence": 0.5 - abs(int(n) - self.ref)}

    def describe(self, engine, pt, name):
        return ("the step's sequence of support events changes (%d events per period at the "
                "start): a foot lifts off and touches down again within the step, or stops "
                "doing so" % self.ref, None)


#: the gait descriptors an `Event` can name (a problem evaluation's ``info``)
EVENT_QUANTITIES = {"step_length": "m", "period": "s", "double_support": "s", "speed": "m/s"}


class Event(TestFunction):
    """A user's point along a branch: ``quantity`` (a gait descriptor, `EVENT_QUANTITIES`, or a
    callable of the evaluation's ``info`` dict) equal to ``level``, located like a bifurcation
    and reported with them (kind ``"event"``, label UZ).

    Example: ``Event("step_length", 0.4)`` (step length = 0.4 m).
    """

    kind, label = "event", "UZ"

    def __init__(self, quantity: str | Callable[[dict], float], level: float = 0.0,
                 name: str | None = None):
        if not callable(quantity) and quantity not in EVENT_QUANTITIES:
            raise InvalidInputError("events: quantity must be one of %s or a callable, got %r"
                                    % (", ".join(EVENT_QUANTITIES), quantity))
        lv = float(level)
        if not np.isfinite(lv):
            raise InvalidInputError("events: level must be finite, got %r" % (level,))
        self.quantity, self.level = quantity, lv
        q = quantity if isinstance(quantity, str) else getattr(quantity, "__name__", "user")
        self.name = name or "%s = %g" % (q, lv)

    def _q(self, info):
        if callable(self.quantity):
            return float(self.quantity(info))
        if self.quantity == "speed":
            n = info.get("period_n", 1)
            return float(info["step_length"] * n / info["period"])
        return float(info[self.quantity])

    def values(self, engine, pt):
        info = dict(pt.ev.info, period_n=engine.prob.period)
        return {"event:" + self.name: self._q(info) - self.level}

    def describe(self, engine, pt, name):
        return self.name, None


#: the built-in test functions, by kind (the order of `KINDS`)
BUILTIN = (Fold(), PeriodDoubling(), NeimarkSacker(), AdmissibleEnd(), BranchPoint())
KINDS = tuple(t.kind for t in BUILTIN) + (Event.kind,)
LABELS = {**{t.kind: t.label for t in BUILTIN}, Event.kind: Event.label}
#: detected by default (a branch point test costs a determinant only, but is off by default:
#: generic one-parameter families have none)
DEFAULT_DETECT = ("fold", "period_doubling", "neimark_sacker", "end")


def select(detect: Any, events: Any = ()) -> list[TestFunction]:
    """The test functions of the kinds in ``detect`` plus the user's ``events`` (`Event` or any
    `TestFunction`)."""
    if isinstance(detect, str):
        detect = (detect,)
    detect = tuple(detect)
    bad = set(detect) - {t.kind for t in BUILTIN}
    if bad:
        raise InvalidInputError("detect: unknown kind(s) %s; allowed: %s"
                                % (sorted(bad), ", ".join(t.kind for t in BUILTIN)))
    out: list[TestFunction] = [t for t in BUILTIN if t.kind in detect]
    for e in events or ():
        if not isinstance(e, TestFunction):
            raise InvalidInputError("events: each must be a pdw.analysis.bifurcation.testfunctions.Event "
                                    "or TestFunction, got %r" % (e,))
        out.append(e)
    return out
