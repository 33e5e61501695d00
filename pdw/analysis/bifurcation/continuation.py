"""Continuation of gaits in one parameter: branches, stability, bifurcations (docs/continuation.md).

The problem: fixed points of the period-n step map, G(z, u) = P^n(z; lambda(u)) - z = 0, with z
the section coordinates (`pdw.analysis.stepmap.gait_maps`) and u the parameter coordinate, scaled so
that the requested range is one unit: u = (mu - mu_0) / (mu_stop - mu_0), mu = lambda (or
log lambda with ``log=True``). A branch is a curve x(s) = (z, u)(s) of solutions. The engine
itself is `pdw.analysis.bifurcation.continuation_engine`.

Pseudo-arclength (default): from a point x_i with unit tangent t_i (the null vector of
DG = [M - I, dP/du], oriented by t_{i-1}), predict x_i + ds t_i and correct by Newton's method on
[G(x); t_i . (x - x_i - ds t_i)] = 0 (the bordered Jacobian [DG; t_i^T]). Natural continuation
(``method="natural"``) replaces the arclength row by u = u_i + ds (it cannot pass a fold). The
step ds adapts: x 1.5 after a correction in <= 2 iterations, x 0.7 after >= 5, halved and retried
when the corrector fails, down to ``step_min`` (then the family ends). Newton converges when
max|G| < ``tol``.

Test functions, evaluated at every point, a sign change between points i and i+1 marking a
bifurcation there: fold: the tangent's u component (natural: det(M - I)); period doubling:
det(M + I); Neimark-Sacker: prod_{j<k} (mu_j mu_k - 1) (a complex pair with |mu| = 1 makes a
factor vanish; a real pair with mu_j mu_k = 1, a neutral saddle, is rejected after location);
the end of the family: an admissibility function of the model through 0
(`pdw.analysis.stepmap.gait_maps.HybridProblem.ADMISSIBLE`, ...), or the step map failing (the walker
falls, no heel strike, ...) where the corrector cannot go on. Each crossing is located by the Illinois
(regula falsi) method on the arclength s along the predictor from x_i, every trial point
corrected onto the branch, until the bracket in the parameter is narrower than ``locate_tol``.

Branch switching at a period doubling (`switch_branch`): the period-2n fixed point near the
bifurcation x* = (z*, u*) is found by Newton's method on P^{2n} in the hyperplane
w . (x - x*) = a, w the critical eigenvector (v, 0) made orthogonal to the period-n tangent,
which the period-n branch does not cross (it stays near w . (x - x*) = 0) and the period-2n
branch, tangent to (v, 0), does.

Why this module is long (about 560 lines): the driver (`continue_gait`, `run_continuation`),
branch switching and criticality (`switch_branch`, `criticality`, `follow_cascade`) and the
branch files (`load_branch`, `extend_branch`) all rebuild problems with `_problem` and hand
themselves to `Branch` as its switch/extend hooks; split into sibling modules they would
import each other (an import cycle, which the architecture forbids).
"""
from __future__ import annotations

import copy
import json
import os
import time
from concurrent.futures import Executor
from typing import Callable, Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...core.contact import AXIS_PREFIX, Contact
from ...core.errors import InvalidInputError
from ...core.params import Params
from ...core.progress import Progress, progress_bar
from ...sim import files as _files
from ..gait_types import Gait, GaitNotFoundError
from ..rigid import hybrid as H
from ..stepmap import limit_cycle as LC
from ..stepmap.gait_maps import ContinuousProblem, HybridProblem
from . import extension as X
from . import testfunctions as TF
from .branch import BRANCH_FORMAT, Bifurcation, Branch
from .continuation_engine import (
    METHODS,
    Engine,
    Point,
    _check_options,
    _explain,
    check_crossings,
    label_points,
    tests,
)

MODELS = ("continuous", "hybrid")


# --- the driver -------------------------------------------------------------------------------

def _problem(params, parameter, model, variant, period, params_of, log, options, executor,
             workers, fd_step):
    if model == "hybrid":
        return HybridProblem(params, parameter, params_of, period, log, options)
    if model == "continuous":
        return ContinuousProblem(params, parameter, params_of, period, log, variant=variant,
                                 options=options, executor=executor, workers=workers,
                                 fd_step=fd_step)
    raise InvalidInputError("model must be one of %s, got %r" % (", ".join(MODELS), model))


def _start_z(prob, params, start, variant, period, mu=None):
    if isinstance(start, Gait):
        z = start.details.get("z") if start.details else None
        return prob.section(start.state) if z is None else prob.section(z)
    if start is not None:
        return prob.section(start)
    if prob.model == "hybrid":
        g = H.find_gait(params)
        if period > 1:
            raise InvalidInputError("a hybrid period-%d start needs start= (Branch.switch)"
                                    % period)
        return prob.section(g.state)
    contact = prob.opts.get("contact")
    if mu is not None and prob.axis is not None:     # a contact axis: the contact at the start
        params, contact = prob.point_at(mu)
    g = LC.find_gait(params, variant, period=period,
                     **({} if contact is None else dict(contact=contact)))
    return np.asarray(g.details["z"], dtype=float)


def continue_gait(params: Params, parameter: str, stop: float, *,
                  model: Literal["continuous", "hybrid"] = "continuous", variant: str = "paper",
                  period: int = 1, step: float | None = None, start: Gait | ArrayLike | None = None,
                  value: float | None = None,
                  method: Literal["pseudo_arclength", "natural"] = "pseudo_arclength",
                  max_points: int = 200, step_min: float | None = None,
                  step_max: float | None = None, tol: float | None = None,
                  locate_tol: float | None = None,
                  params_of: Callable[[float], Params] | None = None, log: bool = False,
                  detect: Sequence[str] = TF.DEFAULT_DETECT,
                  max_newton: int = 8, executor: Executor | None = None,
                  workers: int | None = None, fd_step: float = 1e-5,
                  options: dict | None = None, at: Sequence[float] = (),
                  progress: bool | Progress = False,
                  events: Sequence[TF.TestFunction] = (), stall_points: int = 8,
                  stall_length: float = 1e-3,
                  monodromy: Literal["differences", "exact"] = "differences") -> Branch:
    """Follow the period-``period`` gait of ``params`` as ``parameter`` moves towards ``stop``.

    Parameters
    ----------
    params : Params
        The walker at the start (``parameter`` at its value there, or ``value``).
    parameter : str
        A `Params` field; with the continuous model also a parameter of the contact law,
        ``"contact.<name>"`` (``pdw.Contact.axes()``: ``contact.k``, ``contact.d`` (hunt_crossley,
        kelvin_voigt), ``contact.e``, ``contact.v_in_min`` (lankarani_nikravesh, flores),
        LuGre's ``contact.sigma0`` ... ``contact.v_s``), applied to ``options["contact"]``
        (default the paper's law: its k, d start at ``Params.k_n``, ``d_n``); or any name when
        ``params_of`` is given. Another name is a `pdw.InvalidInputError` listing the allowed
        ones.
    stop : float
        Continue until the parameter reaches ``stop`` (or the family ends, or ``max_points``).
    model : {"continuous", "hybrid"}
        The compliant-ground walker (`pdw.find_gait`'s map) or the rigid-ground one
        (``pdw.hybrid``).
    variant : str
        Contact variant of the continuous model.
    period : int
        Period n of the gait (steps per cycle).
    step : float
        First step, in parameter units (log: in log(parameter)); default 1/50 of the range.
    start : Gait or array_like, optional
        The first gait (a `Gait`, e.g. from ``Branch.switch``, or a section point / state);
        default: the model's ``find_gait`` at ``params``.
    value : float, optional
        The parameter's value at the start (default: ``getattr(params, parameter)``, or the
        start gait's).
    method : {"pseudo_arclength", "natural"}
        Pseudo-arclength (follows folds) or natural continuation (steps in the parameter).
    max_points : int
        Most points on the branch.
    step_min, step_max : float
        Bounds of the arclength step in the scaled coordinates (the range is 1 unit; default
        1e-6 and 0.1).
    tol : float
        Newton tolerance on max|P^n(z) - z| (default 1e-10 hybrid, 1e-8 continuous).
    locate_tol : float
        Bifurcations are located to this width in the parameter coordinate (default 1e-6 of
        the range).
    params_of : callable, optional
        value -> Params, for a parameter that moves others with it (e.g. d_n with k_n).
    log : bool
        Continue in log(parameter) (for parameters spanning decades, e.g. k_n).
    detect : tuple of str
        Which built-in test functions to watch (``pdw.analysis.bifurcation.testfunctions.BUILTIN``: "fold",
        "period_doubling", "neimark_sacker", "end", "branch_point").
    max_newton : int
        Newton iterations of the corrector per point (>= 1).
    executor, workers : concurrent.futures.Executor, int
        Where the continuous model's finite-difference evaluations run (default: threads).
    fd_step : float
        Central-difference step of the continuous model's Jacobian.
    options : dict
        Step-map options (hybrid: ``pdw.hybrid.DEFAULT_OPTIONS``; continuous: rtol, atol,
        event_tol, t_max, dt, contact: with a contact law that has memory (LuGre friction,
        lankarani_nikravesh, flores) the section and z have its extra coordinates,
        ``pdw.analysis.stepmap.section.section_names``).
    at : sequence of float
        Parameter values at which the branch gets a point of its own (a natural correction
        there, when the branch passes the value), e.g. to compare with a table.
    progress : bool or pdw.Progress
        A bar over the branch's points (up to ``max_points``) on stderr when it is a terminal
        (``pdw.core.progress``).
    events : sequence of TestFunction
        User test functions, e.g. ``pdw.analysis.bifurcation.testfunctions.Event("step_length", 0.4)``
        (step length = 0.4 m): located like bifurcations and reported with them (kind
        ``"event"``, label UZ).
    monodromy : {"differences", "exact"}
        The continuous model's M: central differences (default), or exact from the variational
        equations with saltation matrices (``pdw.analysis.stepmap.variational``; every normal
        law with Coulomb friction (``options["contact"]``), paper variant, period 1; 25-40x
        the CPU time per point).
    stall_points, stall_length : int, float
        The continuation stops as *stalled* when the last ``stall_points`` steps together
        advanced less than ``stall_length`` in arclength (scaled coordinates: the requested
        range is 1), i.e. the corrector only converges for ever smaller steps.

    Every option is range-checked (`pdw.InvalidInputError` naming it).

    Returns
    -------
    Branch
    """
    t0 = time.perf_counter()
    _check_options(dict(method=method, step=step, step_min=step_min, step_max=step_max,
                        tol=tol, locate_tol=locate_tol, max_points=max_points,
                        max_newton=max_newton, period=period, workers=workers,
                        fd_step=fd_step, stop=stop, value=value, at=at,
                        stall_points=stall_points, stall_length=stall_length))
    TF.select(detect, events)
    prob = _problem(params, parameter, model, variant, period, params_of, log, options,
                    executor, workers, fd_step)
    _check_read(prob, parameter, params_of)
    if monodromy not in ("differences", "exact"):
        raise InvalidInputError("monodromy must be 'differences' or 'exact', got %r"
                                % (monodromy,))
    if monodromy == "exact" and model == "continuous":
        if not prob.exact_available:
            raise InvalidInputError("monodromy='exact' of the continuous model needs Coulomb "
                                    "friction (any normal law), variant 'paper' and period 1 "
                                    "(pdw.analysis.stepmap.variational)")
        prob.monodromy = "exact"
    if value is None:
        if isinstance(start, Gait) and start.details and "value" in start.details:
            value = start.details["value"]
        elif params_of is None:
            value = prob.start_value()
        else:
            raise InvalidInputError("value= (the start's %s) is needed with params_of"
                                    % parameter)
    if prob.coord(float(stop)) == prob.coord(float(value)):
        raise InvalidInputError("stop must differ from the start value %r, got %r"
                                % (value, stop))
    z0 = _start_z(prob, params, start, variant, period, prob.coord(float(value)))
    details = start.details if isinstance(start, Gait) and start.details else {}
    tol = tol if tol is not None else (1e-10 if model == "hybrid" else 1e-8)
    return run_continuation(prob, z0, value, stop, method=method, max_points=max_points,
                            step=step, step_min=step_min, step_max=step_max, tol=tol,
                            locate_tol=locate_tol, detect=detect, max_newton=max_newton,
                            direction=details.get("direction"), origin=details.get("origin"),
                            settings=dict(log=log, variant=variant, fd_step=fd_step,
                                          monodromy=monodromy), t0=t0,
                            at=at, progress=progress, events=events,
                            stall_points=stall_points, stall_length=stall_length)


def _check_read(prob, parameter, params_of):
    """Refuse k_n / d_n where the contact law never reads them (the branch would vary
    nothing): a Contact with its own k or d (kelvin_voigt always: other units), hertz's d
    (none); point at the contact axis instead."""
    c = getattr(prob, "contact", None)
    if c is None or params_of is not None or parameter not in ("k_n", "d_n"):
        return
    name = parameter[0]
    c = Contact.coerce(c)
    if getattr(c, name) is None and not (name == "d" and c.normal == "hertz"):
        return
    hint = ("continue in %r (%s)" % (AXIS_PREFIX + name, c.axis_unit(AXIS_PREFIX + name))
            if AXIS_PREFIX + name in c.axes() else "the law has no damping")
    raise InvalidInputError("parameter %r is not read by the %s law (its %s is the "
                            "Contact's, never Params.%s): %s" % (
                                parameter, c.normal,
                                "stiffness" if name == "k" else "damping", parameter, hint))


def run_continuation(prob, z0, value, stop, *, method="pseudo_arclength", max_points=200,
                     step=None, step_min=None, step_max=None, tol=1e-10, locate_tol=None,
                     detect=TF.DEFAULT_DETECT, max_newton=8,
                     direction=None, origin=None, settings=None, t0=None, at=(),
                     progress=False, events=(), stall_points=8, stall_length=1e-3,
                     step_control=None) -> Branch:
    """The continuation proper, on any problem object (`pdw.analysis.stepmap.gait_maps`: ``dim``, ``evaluate``,
    ``coord``/``value``, ``gait``, ``ADMISSIBLE``, ...), from the fixed point z0 at ``value``
    towards ``stop``; the arguments as in `continue_gait` (``direction``: (dz, dmu) to orient
    the first tangent; ``origin``: where a switched branch was born, for plots; ``at``:
    parameter values where a point is also computed, by a natural correction, whenever the
    branch passes them; ``method``: "pseudo_arclength", "natural" or a predictor object,
    ``step_control``: a `pdw.analysis.bifurcation.extension.StepControl`, both extension points)."""
    t0 = time.perf_counter() if t0 is None else t0
    o = _check_options(dict(method=method, step=step, step_min=step_min, step_max=step_max,
                            tol=tol, locate_tol=locate_tol, max_points=max_points,
                            max_newton=max_newton, stop=stop, value=value, at=at,
                            stall_points=stall_points, stall_length=stall_length))
    max_points, max_newton = o["max_points"], o["max_newton"]
    functions = TF.select(detect, events)
    mu0, mu_stop = prob.coord(float(value)), prob.coord(float(stop))
    if not np.isfinite(mu_stop) or mu_stop == mu0:
        raise InvalidInputError("stop must differ from the start value %r, got %r"
                                % (value, stop))
    scale = mu_stop - mu0          # signed: u runs from 0 to 1
    if hasattr(prob, "lam_rel"):
        prob.lam_step = prob.lam_rel * max(abs(mu0), abs(scale))
    predictor = X.PREDICTORS[method]() if isinstance(method, str) else method
    eng = Engine(prob, mu0, scale, tol, max_newton, False, functions, predictor)
    step_min = 1e-6 if step_min is None else step_min
    step_max = 0.1 if step_max is None else step_max
    if step_control is None:
        step_control = X.StepControl(abs(step / scale) if step else 0.02, step_min, step_max)
    ctl = step_control
    step_min, step_max = ctl.step_min, ctl.step_max
    ds = ctl.first
    locate_tol = 1e-6 * abs(scale) if locate_tol is None else locate_tol
    x0 = np.append(np.asarray(z0, dtype=float), 0.0)
    e = np.zeros(prob.dim + 1)
    e[-1] = 1.0
    first, why, _ = eng.correct(x0, e)
    if first is None:
        raise GaitNotFoundError("the start is not a period-%d gait of the %s model at %s = %r: "
                                "%s" % (prob.period, prob.model, prob.parameter, value, why))
    ev = why
    ref = e.copy()
    if direction is not None:
        dz, dmu = direction
        ref = np.append(np.asarray(dz, dtype=float), dmu / scale)
    pts = [Point(first, ev, eng.tangent(ev, ref), 0, 0.0)]
    pts[0].tests = tests(eng, pts[0])
    accept = getattr(prob, "accept", None)          # a problem's hook on accepted points
    if accept is not None:
        accept(pts[0])
    bifs: list = []
    advances: list = []            # the arclength of every accepted step
    last_failure = "none: Newton needed >= 5 iterations"
    stop_reason = "max_points (%d) reached" % max_points
    bar, seen = progress_bar(progress, int(max_points), "continuation %s" % prob.parameter), 0
    while len(pts) < max_points:
        bar.update(len(pts) - seen)
        seen = len(pts)
        a = pts[-1]
        b, why, its = eng.step_from(a, ds)
        if b is None and str(why).startswith("invalid parameter") and a.tangent[-1] > 0:
            # the predictor left the parameter's allowed range: land on stop if it is there
            c, evc, _ = eng.correct(a.x + (1.0 - a.x[-1]) / a.tangent[-1] * a.tangent, e)
            if c is not None:
                b = Point(c, evc, eng.tangent(evc, a.tangent), 0,
                          (1.0 - a.x[-1]) / a.tangent[-1])
                b.tests = tests(eng, b)
                bifs += check_crossings(eng, a, b, len(pts) - 1, locate_tol)
                pts.append(b)
                stop_reason = "reached stop = %.10g" % float(stop)
                break
        if b is None:
            last_failure = str(why)
            nds = ctl.failed(ds)
            if nds is None:
                ds *= 0.5
                beyond = eng.value(a.x + 2 * ds * a.tangent)
                bifs.append(Bifurcation(
                    kind="end", value=eng.value(a.x), gait=None, index=len(pts) - 1,
                    tolerance=abs(ds * 2 * scale), reason="the corrector fails beyond the "
                    "last point: %s" % _explain(prob, why), z=a.x[:-1].copy(), mu=eng.mu(a.x),
                    tangent=a.tangent.copy(), multipliers=a.mult.copy(), located=False,
                    bracket=tuple(sorted((eng.value(a.x), beyond))),
                    location_note="the last converged point; the corrector fails at every "
                    "step down to step_min = %g" % step_min))
                stop_reason = "end of the family: %s" % _explain(prob, why)
                break
            ds = nds
            continue
        b.tests = tests(eng, b)
        found = check_crossings(eng, a, b, len(pts) - 1, locate_tol)
        ends = [f for f in found if f.kind == "end"]
        bifs += found
        u = b.x[-1]
        if ends:
            stop_reason = "end of the family: " + ends[0].reason
            break
        if u >= 1.0:
            # land on stop exactly
            c, why2, _ = eng.correct(a.x + (b.x - a.x) * (1.0 - a.x[-1]) / (u - a.x[-1]), e)
            if c is not None:
                last = Point(c, why2, eng.tangent(why2, a.tangent), 0, ds)
                last.tests = tests(eng, last)
                pts.append(last)
            else:
                pts.append(b)
            stop_reason = "reached stop = %.10g" % float(stop)
            bifs = [f for f in bifs if (f.mu - mu0) / scale <= 1.0 + 1e-12]
            break
        for ua in sorted((prob.coord(float(v)) - mu0) / scale for v in at):
            if min(a.x[-1], u) < ua < max(a.x[-1], u):
                c, evc, _ = eng.correct(a.x + (b.x - a.x) * (ua - a.x[-1]) / (u - a.x[-1]), e)
                if c is not None:
                    extra = Point(c, evc, eng.tangent(evc, a.tangent), 0, 0.0)
                    extra.tests = tests(eng, extra)
                    pts.append(extra)
        pts.append(b)
        if accept is not None:
            accept(b)
        if u < -1e-9 and not eng.natural:
            folds = [f for f in bifs if f.kind == "fold"]
            stop_reason = ("the branch returned past the start value (after the fold at "
                           "%.8g)" % folds[-1].value if folds else
                           "the branch went back past the start value")
            break
        advances.append(b.ds)
        recent = advances[-stall_points:]
        if len(advances) >= stall_points and sum(recent) < stall_length:
            stop_reason = ("stalled: the last %d steps advanced %.3g in arclength together "
                           "(stall_length %.3g; the range is 1): the corrector converges only "
                           "for ever smaller steps (last failure: %s)"
                           % (stall_points, sum(recent), stall_length, last_failure))
            break
        ds = ctl.accepted(ds, its)
    bar.update(len(pts) - seen)
    bar.close()
    label_points(bifs)
    return _branch(eng, pts, bifs, stop_reason, prob, time.perf_counter() - t0,
                   dict(method=method if isinstance(method, str) else type(method).__name__,
                        tol=tol, locate_tol=locate_tol, step_min=step_min,
                        step_max=step_max, start_value=float(value), stop=float(stop),
                        options=dict(getattr(prob, "opts", {})), origin=origin,
                        **(settings or {})))


def _branch(eng, pts, bifs, stop_reason, prob, wall, settings) -> Branch:
    mult = np.array([p.mult for p in pts])
    return Branch(
        parameter=prob.parameter, model=prob.model, period_n=prob.period,
        values=np.array([eng.value(p.x) for p in pts]),
        period=np.array([p.ev.info["period"] for p in pts]),
        step_length=np.array([p.ev.info["step_length"] for p in pts]),
        double_support=np.array([p.ev.info["double_support"] for p in pts]),
        multipliers=mult, stable=np.all(np.abs(mult) < 1.0, axis=1),
        state=np.array([p.ev.info["state"] for p in pts]),
        z=np.array([p.x[:-1] for p in pts]), orbit=np.array([p.ev.info["orbit"] for p in pts]),
        tangents=np.array([p.tangent for p in pts]),
        step_size=np.array([p.ds for p in pts]),
        newton_iterations=np.array([p.iters for p in pts]),
        bifurcations=bifs, stop_reason=stop_reason, n_maps=prob.n_maps, wall_time=wall,
        settings={**settings, "scale": eng.scale, "mu0": eng.mu0,
                  "unit": getattr(prob, "unit", "")}, problem=prob,
        switcher=switch_branch, extender=extend_branch)


# --- branches as files ------------------------------------------------------------------------

def load_branch(path: str | os.PathLike) -> Branch:
    """Read a branch written by `Branch.save` (also reached through `pdw.load`). The problem is
    rebuilt from the saved base parameters, model, variant, contact and period, so the branch
    can be extended (`Branch.extend`) and switched (``Branch.switch``); a branch continued with
    ``params_of`` is read without it (extend it with ``params_of=`` again)."""
    try:
        with np.load(path, allow_pickle=False) as f:
            arrays = {k: f[k] for k in f.files}
        meta = json.loads(str(arrays.pop("meta")))
    except (OSError, ValueError, KeyError, EOFError) as e:
        raise InvalidInputError("%s is not a readable pdw branch file (.npz written by "
                                "Branch.save): %s: %s" % (path, type(e).__name__, e)) from None
    if meta.get("format") != BRANCH_FORMAT:
        raise InvalidInputError("%s is not a pdw branch file (format %r)"
                                % (path, meta.get("format")))
    missing = [k for k in Branch.ARRAYS if k not in arrays]
    if missing:
        raise InvalidInputError("%s: branch file lacks %s" % (path, ", ".join(missing)))
    prob = None
    pr = meta.get("problem")
    if pr is not None and not pr.get("params_of"):
        opts = dict(pr["options"])
        if isinstance(opts.get("contact"), dict):
            opts["contact"] = Contact(**opts["contact"])
        opts.pop("t_hint", None)
        prob = _problem(Params(**pr["params"]), pr["parameter"], pr["model"], pr["variant"],
                        pr["period"], None, pr["log"], opts, None, None, pr["fd_step"])
        st = meta["settings"]
        if hasattr(prob, "lam_rel"):
            prob.lam_step = prob.lam_rel * max(abs(st["mu0"]), abs(st["scale"]))
    bifs = []
    for d in meta["bifurcations"]:
        m = np.array(d["multipliers_re"]) + 1j * np.array(d["multipliers_im"])
        bifs.append(Bifurcation(
            kind=d["kind"], value=d["value"], gait=None, index=d["index"],
            tolerance=d["tolerance"], reason=d["reason"],
            z=None if d["z"] is None else np.array(d["z"]), mu=d["mu"],
            tangent=None if d["tangent"] is None else np.array(d["tangent"]),
            eigenvector=None if d["eigenvector"] is None else np.array(d["eigenvector"]),
            multipliers=m, located=d["located"],
            bracket=None if d["bracket"] is None else tuple(d["bracket"]),
            location_note=d["location_note"], label=d["label"],
            details={} if prob is None else {"problem": prob}))
    settings = meta["settings"]
    if isinstance(settings.get("origin"), list):
        settings["origin"] = (settings["origin"][0], np.array(settings["origin"][1]))
    return Branch(parameter=meta["parameter"], model=meta["model"], period_n=meta["period_n"],
                  **{k: arrays[k] for k in Branch.ARRAYS}, bifurcations=bifs,
                  stop_reason=meta["stop_reason"], n_maps=meta["n_maps"],
                  wall_time=meta["wall_time"], settings=settings, problem=prob,
                  switcher=switch_branch, extender=extend_branch,
                  provenance=meta["provenance"])


_files.LOADERS[BRANCH_FORMAT] = load_branch


def extend_branch(branch: Branch, stop: float, **kw) -> Branch:
    """Continue ``branch`` from its last point towards ``stop`` (`Branch.extend`)."""
    prob = branch.problem
    if prob is None:
        raise InvalidInputError("this branch has no problem to continue (it was continued "
                                "with params_of or by run_continuation on a custom problem)")
    v = float(branch.values[-1])
    t = np.asarray(branch.tangents[-1], dtype=float)
    scale = float(branch.settings["scale"])
    mult = branch.multipliers[-1]
    g = Gait(state=branch.state[-1], period=float(branch.period[-1]),
             step_length=float(branch.step_length[-1]),
             double_support=float(branch.double_support[-1]), multipliers=mult,
             model=branch.model, params=prob.params_at(prob.coord(v)),
             details={"z": np.array(branch.z[-1]), "value": v,
                      "direction": (t[:-1], t[-1] * scale)})
    opts = dict(model=branch.model, period=prob.period, log=prob.log,
                options={k: val for k, val in prob.opts.items() if k != "t_hint"})
    if branch.model == "continuous":
        opts.update(variant=prob.variant, fd_step=prob.fd_step)
    for k in ("tol", "locate_tol", "method"):
        if branch.settings.get(k) is not None:
            opts[k] = branch.settings[k]
    if opts.get("method") not in METHODS:       # a custom predictor is not saved
        opts.pop("method", None)
    opts.update(kw)
    return continue_gait(prob.base, branch.parameter, stop, start=g, **opts)


# --- branch switching -------------------------------------------------------------------------

def switch_branch(branch, bifurcation, amplitude=0.005, max_tries=6) -> Gait:
    """The first gait of the period-2n branch born at a period doubling of ``branch``.

    Newton's method on P^{2n} in the hyperplane w . (x - x*) = a (module docstring), a =
    ``amplitude`` (in the section coordinates; halved up to ``max_tries`` times when Newton
    fails or lands back on the period-n branch). The returned `Gait` carries
    ``details["value"]`` (its parameter) and ``details["direction"]`` (the branch's direction
    away from the bifurcation), so ``continue_gait(..., period=2n, start=gait)`` follows it.
    """
    if bifurcation.kind == "branch_point":
        return _switch_at_branch_point(branch, bifurcation, amplitude)
    if bifurcation.kind != "period_doubling":
        raise InvalidInputError("switch needs a period_doubling or branch_point bifurcation, "
                                "got %r" % bifurcation.kind)
    p1 = branch.problem
    s = branch.settings
    prob = copy.copy(p1)
    prob.period = 2 * p1.period
    prob.n_maps = 0
    if hasattr(prob, "ref_events"):
        prob.ref_events = None
    eng = Engine(prob, s["mu0"], s["scale"], s["tol"], 12, False)
    eng1 = Engine(p1, s["mu0"], s["scale"], s["tol"], 12, False)
    x_star = np.append(bifurcation.z, (bifurcation.mu - s["mu0"]) / s["scale"])
    t1 = np.asarray(bifurcation.tangent, dtype=float)
    w = np.append(bifurcation.eigenvector, 0.0)
    w = w - (w @ t1) * t1
    w /= np.linalg.norm(w)
    a = float(amplitude)
    why = "not tried"
    for _ in range(max_tries):
        x, ev, _ = eng.correct(x_star + a * w, w)
        if x is not None:
            one = eng1.evaluate(x, jac=False)
            gap = np.max(np.abs(one.Pz - x[:-1])) if one.ok else np.inf
            if gap > 100 * s["tol"]:
                m = np.linalg.eigvals(ev.M)
                gait = prob.gait(x[:-1], eng.mu(x), ev, m[np.argsort(-np.abs(m))])
                d = x - x_star
                gait.details.update(value=eng.value(x), direction=(d[:-1], d[-1] * s["scale"]),
                                    switched_from=bifurcation.as_dict(),
                                    origin=(bifurcation.value, np.asarray(
                                        bifurcation.details.get("orbit", [bifurcation.z]))),
                                    distance_to_period_n=float(gap))
                return gait
            why = "landed on the period-%d branch" % p1.period
        else:
            why = ev
        a *= 0.5
    raise GaitNotFoundError("no period-%d gait found next to the period doubling at %s = %.8g: "
                            "%s" % (prob.period, p1.parameter, bifurcation.value, why))


def _switch_at_branch_point(branch, bif, amplitude) -> Gait:
    """The first point of the other branch through a simple branch point x*: DG there has a
    two-dimensional null space; its direction t2 orthogonal to this branch's tangent is the
    other branch's tangent. Newton from x* + a t2 bordered by t2 (a halved on failure)."""
    s = branch.settings
    prob = branch.problem
    eng = Engine(prob, s["mu0"], s["scale"], s["tol"], 12, False)
    x_star = np.append(bif.z, (bif.mu - s["mu0"]) / s["scale"])
    ev = eng.evaluate(x_star)
    if not ev.ok:
        raise GaitNotFoundError("the branch point does not evaluate: %s" % ev.status)
    _, _, Vt = np.linalg.svd(eng.dG(ev))
    t1 = np.asarray(bif.tangent, dtype=float)
    N = Vt[-2:]                                # the two smallest right singular vectors
    p = N @ t1                                 # t1 in that basis; t2 is the orthogonal one
    t2 = N.T @ np.array([-p[1], p[0]])
    t2 = t2 - (t2 @ t1) * t1
    t2 /= np.linalg.norm(t2)
    a, why = float(amplitude), "not tried"
    for _ in range(8):
        x, ev2, _ = eng.correct(x_star + a * t2, t2)
        if x is not None:
            m = np.linalg.eigvals(ev2.M)
            gait = prob.gait(x[:-1], eng.mu(x), ev2, m[np.argsort(-np.abs(m))])
            d = x - x_star
            gait.details.update(value=eng.value(x), direction=(d[:-1], d[-1] * s["scale"]),
                                switched_from=bif.as_dict())
            return gait
        why = ev2
        a *= 0.5
    raise GaitNotFoundError("no point of the crossing branch next to the branch point at "
                            "%s = %.8g: %s" % (prob.parameter, bif.value, why))


def criticality(branch, bifurcation, amplitude=0.005) -> dict:
    """Super- or subcritical, for a period doubling of ``branch``, from the direction of the
    period-2n branch born there (`switch_branch`): it lies on the side where the period-n
    gait is unstable (supercritical: a small period-2n gait takes over) or on the stable side
    (subcritical: the period-2n gait coexists with the stable period-n one, unstable, and
    there is no small gait beyond).

    Returns
    -------
    dict
        ``criticality`` ("supercritical" or "subcritical"), ``value`` (the period-2n gait's
        parameter), ``offset`` (its distance from the doubling, signed towards the unstable
        side of the period-n branch), ``stable`` (of the period-2n gait) and ``gait``.
    """
    if bifurcation.kind != "period_doubling":
        raise InvalidInputError("criticality needs a period_doubling, got %r" % bifurcation.kind)
    i = bifurcation.index
    va, vb = branch.values[i], branch.values[min(i + 1, len(branch) - 1)]
    # the side of the doubling on which the period-n gait's flip multiplier is outside
    ma = np.min(np.real(branch.multipliers[i]))
    unstable_dir = np.sign(vb - va) if ma > -1.0 else -np.sign(vb - va)
    g = switch_branch(branch, bifurcation, amplitude=amplitude)
    off = (g.details["value"] - bifurcation.value) * unstable_dir
    return {"criticality": "supercritical" if off > 0 else "subcritical",
            "value": g.details["value"], "offset": float(off), "stable": bool(g.stable),
            "gait": g}


def follow_cascade(params, parameter, stop, depth=2, **kw) -> list:
    """Continue the period-n gait to ``stop``, switch at its first period doubling, continue
    the period-2n branch, and so on ``depth`` times: the list of branches."""
    branches = [continue_gait(params, parameter, stop, **kw)]
    period = kw.pop("period", 1)
    kw.pop("start", None)
    kw.pop("value", None)
    for _ in range(depth):
        pds = branches[-1].of_kind("period_doubling")
        if not pds:
            break
        period *= 2
        g = branches[-1].switch(pds[0])
        branches.append(continue_gait(g.params, parameter, stop, period=period, start=g, **kw))
    return branches
