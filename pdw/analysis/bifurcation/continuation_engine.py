"""The predictor-corrector engine and the test functions of `pdw.analysis.bifurcation.continuation`.

`Engine` works in the scaled coordinates x = (z, u) of one problem (`pdw.analysis.stepmap.gait_maps`):
Newton correction on the step map bordered by the arclength (or natural) condition, unit
tangents, and one continuation step. `tests` evaluates the test functions at a point,
`check_crossings` finds their sign changes between two points and locates each by the
Illinois method (`locate`); the method is described in `pdw.analysis.bifurcation.continuation`.
"""
from __future__ import annotations

import warnings

import numpy as np

from ...core import checks
from ...core.errors import InvalidInputError
from ..stepmap.gait_maps import Evaluation
from . import extension as X
from . import testfunctions as TF
from .branch import Bifurcation


class Point:
    __slots__ = ("x", "ev", "tangent", "mult", "tests", "iters", "ds")

    def __init__(self, x, ev, tangent, iters, ds):
        self.x, self.ev, self.tangent, self.iters, self.ds = x, ev, tangent, iters, ds
        m = np.linalg.eigvals(ev.M)
        self.mult = m[np.argsort(-np.abs(m))]
        self.tests = {}


class Engine:
    """Predictor-corrector machinery on one problem, in the scaled coordinates x = (z, u)."""

    def __init__(self, prob, mu0, scale, tol, max_newton, natural, functions=None,
                 predictor=None):
        self.prob, self.mu0, self.scale = prob, mu0, scale
        self.tol, self.max_newton = tol, max_newton
        if predictor is None:
            predictor = (X.NaturalPredictor if natural else X.TangentPredictor)()
        self.predictor = predictor
        self.natural = bool(getattr(predictor, "natural", False))
        self.n = prob.dim
        self.functions = list(TF.select(TF.DEFAULT_DETECT) if functions is None else functions)
        self.owner: dict = {}         # test-function name -> its TestFunction

    def mu(self, x):
        return self.mu0 + x[-1] * self.scale

    def value(self, x):
        return self.prob.value(self.mu(x))

    def evaluate(self, x, jac=True) -> Evaluation:
        return self.prob.evaluate(x[:-1], self.mu(x), jac)

    def dG(self, ev):
        return np.hstack([ev.M - np.eye(self.n), (ev.P_lam * self.scale)[:, None]])

    def tangent(self, ev, ref):
        """Unit null vector of DG with ref . t > 0."""
        A = np.vstack([self.dG(ev), ref[None, :]])
        b = np.zeros(self.n + 1)
        b[-1] = 1.0
        try:
            t = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            t = np.linalg.lstsq(A, b, rcond=None)[0]
        return t / np.linalg.norm(t)

    def correct(self, x_pred, c):
        """Newton on [G; c . (x - x_pred)] = 0: (x, ev, iterations) or (None, reason, its)."""
        x = x_pred.copy()
        last = "no convergence"
        for it in range(self.max_newton + 1):
            ev = self.evaluate(x)
            if not ev.ok:
                return None, ev.status, it
            G = ev.Pz - x[:-1]
            if np.max(np.abs(G)) < self.tol and it > 0:
                return x, ev, it
            if it == self.max_newton:
                last = "no convergence in %d Newton iterations (residual %.2g)" % (
                    it, np.max(np.abs(G)))
                break
            J = np.vstack([self.dG(ev), c[None, :]])
            r = np.concatenate([G, [c @ (x - x_pred)]])
            try:
                dx = np.linalg.solve(J, -r)
            except np.linalg.LinAlgError:
                return None, "singular corrector matrix", it
            if not np.isfinite(dx).all():
                return None, "non-finite Newton step", it
            x = x + dx
            if np.max(np.abs(G)) < self.tol:      # converged at the predictor already
                continue
        return None, last, self.max_newton

    def step_from(self, pt, ds):
        """The next point at step ds from pt, predicted by ``self.predictor``
        (`pdw.analysis.bifurcation.extension`)."""
        x_pred, c = self.predictor.predict(self, pt, ds)
        x, ev, its = self.correct(x_pred, c)
        if x is None:
            return None, ev, its
        ref = c if self.natural else pt.tangent
        return Point(x, ev, self.tangent(ev, ref), its, ds), None, its


# --- test functions ---------------------------------------------------------------------------

def tests(engine, pt, functions=None):
    """The values of every test function (`pdw.analysis.bifurcation.testfunctions`) at ``pt``: {name: f}."""
    out = {}
    for tf in (engine.functions if functions is None else functions):
        for name, v in tf.values(engine, pt).items():
            out[name] = v
            engine.owner[name] = tf
    return out


#: a located point's test function must be within this factor of what its secant slope over
#: the detection step predicts for the final bracket (a jump of the test function, e.g. at a
#: kink of the step map, fails this however narrow the bracket)
SLOPE_FACTOR = 10.0


class Location:
    """The result of `locate`: the best point, the final bracket, whether it is located."""

    __slots__ = ("point", "width", "bracket", "located", "why", "residual")

    def __init__(self, point, width, bracket, located, why, residual):
        self.point, self.width, self.bracket = point, width, bracket
        self.located, self.why, self.residual = located, why, residual


def locate(engine, a, b, name, locate_tol, max_iter=40) -> Location:
    """Illinois on s in (0, b.ds) along a's predictor for the test ``name``.

    The crossing is *located* when (i) the final bracket is narrower than ``locate_tol`` in
    the parameter coordinate mu and (ii) the test function at the returned point is at most
    `SLOPE_FACTOR` times its secant slope over the detection step times the final bracket in
    arclength (it vanishes continuously there), or, where the test function is at its noise
    floor (finite-difference multipliers), its natural residual (`TestFunction.residual`, e.g.
    |mu + 1| of the critical multiplier) is within the test's ``tol`` (1e-3). Otherwise (the corrector failed inside the
    bracket, the iterations ran out, or the function jumps) it is only *detected*, between
    ``bracket`` (parameter values), and ``why`` says which."""
    lo, hi = 0.0, b.ds
    fa0, fb0 = a.tests[name], b.tests[name]
    flo, fhi = fa0, fb0
    p_lo, p_hi = a, b
    side = 0
    why = ""
    for _ in range(max_iter):
        if abs(engine.mu(p_lo.x) - engine.mu(p_hi.x)) < locate_tol:
            break
        s = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
        if not (lo < s < hi):
            s = 0.5 * (lo + hi)
        pt, err, _ = engine.step_from(a, s)
        if pt is None:
            s = 0.5 * (lo + hi)
            pt, err, _ = engine.step_from(a, s)
            if pt is None:
                why = "the corrector fails inside the bracket (%s)" % err
                break
        pt.tests = tests(engine, pt)
        f = pt.tests.get(name, np.nan)
        if not np.isfinite(f):
            why = "the test function is not finite inside the bracket"
            break
        if np.sign(f) == np.sign(flo):
            lo, flo, p_lo = s, f, pt
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi, p_hi = s, f, pt
            if side == 1:
                flo *= 0.5
            side = 1
    else:
        why = "no bracket below locate_tol in %d iterations" % max_iter
    f_lo, f_hi = p_lo.tests[name], p_hi.tests[name]
    best = p_lo if abs(f_lo) < abs(f_hi) else p_hi
    width = abs(engine.mu(p_lo.x) - engine.mu(p_hi.x))
    bracket = tuple(sorted((engine.value(p_lo.x), engine.value(p_hi.x))))
    slope = abs(fb0 - fa0) / b.ds if b.ds > 0 else np.inf
    allowed = SLOPE_FACTOR * slope * (hi - lo)
    f_best = abs(best.tests[name])
    residual = f_best / allowed if allowed > 0 else (0.0 if f_best == 0 else np.inf)
    if not why and width >= locate_tol:
        why = "the bracket is %.3g wide (locate_tol %.3g)" % (width, locate_tol)
    natural = None
    tf = engine.owner.get(name)
    if tf is not None and residual > 1.0:
        natural = tf.residual(engine, best, name)
    if not why and residual > 1.0 and not (natural is not None and natural <= tf.tol):
        why = ("the test function jumps across the bracket (|f| = %.3g at the best point, "
               "%.3g x what its slope allows): a kink or discontinuity, not a crossing"
               % (f_best, residual))
    return Location(best, width, bracket, not why, why, residual)


def _bifurcation(engine, kind, loc, index, reason, eigvec=None):
    prob = engine.prob
    pt = loc.point
    gait = prob.gait(pt.x[:-1], engine.mu(pt.x), pt.ev, pt.mult)
    return Bifurcation(kind=kind, value=engine.value(pt.x), gait=gait, index=index,
                       tolerance=loc.width, reason=reason, z=pt.x[:-1].copy(),
                       mu=engine.mu(pt.x), tangent=pt.tangent.copy(), eigenvector=eigvec,
                       multipliers=pt.mult.copy(),
                       details={"orbit": pt.ev.info["orbit"], "problem": prob},
                       located=loc.located, bracket=loc.bracket,
                       location_note=loc.why)


def check_crossings(engine, a, b, index, locate_tol, detect=None):
    """The special points between branch points a and b (index, index + 1): every sign change of
    a test function of ``engine.functions`` (or of those whose kind is in ``detect``), each
    located (`locate`) and described by its test function."""
    out = []
    for name, fa in a.tests.items():
        tf = engine.owner.get(name)
        if tf is None or (detect is not None and tf.kind not in detect):
            continue
        fb = b.tests.get(name, fa)
        if not tf.crossed(name, fa, fb):
            continue
        loc = locate(engine, a, b, name, locate_tol)
        d = tf.describe(engine, loc.point, name)
        if d is None:
            continue
        reason, eigvec = d
        bif = _bifurcation(engine, tf.kind, loc, index, reason, eigvec)
        bif.details["test"] = name
        check = getattr(engine.prob, "crosscheck", None)
        if check is not None and tf.kind in ("fold", "period_doubling", "neimark_sacker"):
            diff, note = check(loc.point.x[:-1], engine.mu(loc.point.x), loc.point.mult)
            bif.details["fd_check"] = diff
            bif.details["fd_check_kind"] = getattr(engine.prob, "last_check", "")
            if note:
                warnings.warn("%s at %s = %.8g: %s" % (tf.kind, engine.prob.parameter,
                                                      bif.value, note), stacklevel=3)
                bif.details["fd_check_note"] = note
        out.append(bif)
    out.sort(key=lambda f: (f.mu - engine.mu(a.x)) * np.sign(engine.mu(b.x) - engine.mu(a.x)))
    return out


# --- options, labels, reasons -----------------------------------------------------------------

METHODS = ("pseudo_arclength", "natural")


def _check_options(o: dict) -> dict:
    """Range-check the continuation's options (those present in ``o``; None = the default),
    each error naming its option and allowed range; returns them normalised."""
    out = dict(o)
    if "method" in o and isinstance(o["method"], str) and o["method"] not in METHODS:
        raise InvalidInputError("method must be 'pseudo_arclength' or 'natural', got %r"
                                % (o["method"],))
    for k in ("step", "step_min", "step_max", "tol", "locate_tol", "stall_length"):
        if o.get(k) is not None:
            out[k] = checks.positive(k, o[k])
    if o.get("fd_step") is not None:
        out["fd_step"] = checks.number("fd_step", o["fd_step"], lo=0.0, lo_open=True, hi=0.1)
    if o.get("step_min") is not None and o.get("step_max") is not None \
            and out["step_min"] > out["step_max"]:
        raise InvalidInputError("step_min (%r) must not exceed step_max (%r)"
                                % (o["step_min"], o["step_max"]))
    for k, lo in (("max_points", 2), ("max_newton", 1), ("period", 1), ("stall_points", 2)):
        if o.get(k) is not None:
            out[k] = checks.count(k, o[k], lo=lo, hi=10 ** 7)
    if o.get("workers") is not None:
        out["workers"] = checks.count("workers", o["workers"], lo=1, hi=4096)
    for k in ("stop", "value"):
        if o.get(k) is not None:
            out[k] = checks.number(k, o[k])
    if o.get("at") is not None:
        out["at"] = [checks.number("at[%d]" % i, v) for i, v in enumerate(o["at"])]
    return out


def label_points(bifs) -> None:
    """AUTO-style labels: the type (LP, PD, NS, BP, EP, UZ) and a running number along the
    branch, in branch order (``Bifurcation.label``, e.g. "PD1", "LP2")."""
    for k, f in enumerate(sorted(bifs, key=lambda f: f.index), start=1):
        f.label = "%s%d" % (f.type_label, k)


def _explain(prob, why) -> str:
    """A step-map failure, with the option that caused it where known (the hybrid map's
    ``min_step_angle``: a strike is only armed at a step angle at least that large)."""
    why = str(why)
    if getattr(prob, "model", "") == "hybrid" and ("no_strike" in why or "fell" in why):
        ang = getattr(prob, "last_step_angle", None)
        lim = prob.opts.get("min_step_angle", 0.0)
        if ang is not None and ang < 1.1 * lim:
            return ("%s: the step angle at heel strike (%.4g rad at the last gait) reaches the "
                    "option min_step_angle = %g rad, below which a strike is not armed"
                    % (why, ang, lim))
    return why
