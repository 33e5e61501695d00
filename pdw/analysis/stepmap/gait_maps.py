"""Step maps of one parameter, with their Jacobians, for continuation (`pdw.analysis.bifurcation.continuation`).

A *problem* is the period-n step map z -> P^n(z; lambda) on a model's Poincaré section with
the Jacobians the continuation needs: ``M = d P^n / d z`` (the monodromy matrix; its
eigenvalues are the Floquet multipliers) and ``d P^n / d lambda``. Two models:

* `HybridProblem` (`pdw.hybrid`, rigid ground): z = (theta_st, thetad_st, thetad_sw) just after
  heel strike. M is **exact**: the variational equations of the symbolic stance Jacobian
  integrated to the strike (the same Dormand-Prince 5(4) and tolerances as the map) and the
  saltation matrix of the heel-strike event times the derivative of the impact map
  (pdw/core/csrc/pdw_hybrid_var.c, emitted pieces from derive/hybrid.py). It agrees with central
  differences to ~1e-9 at rtol = atol = 1e-12 (tests/analysis/bifurcation/test_continuation.py).
* `ContinuousProblem` (`pdw.limit_cycle`, compliant ground): z at the swing foot's
  touch-down (6 coordinates, or more with a contact law that has memory: ``options["contact"]``,
  `pdw.analysis.stepmap.section.section_names`). M by central differences of the rodas4 map (rtol 1e-10, atol 1e-12, event_tol
  1e-12, step ``fd_step`` = 1e-5): the map is reproducible to ~1e-10, so M is good to ~1e-5
  (multipliers below ~1e-4 in modulus are not resolved). The 12 + 2 evaluations run on an
  executor (threads by default; the compiled loop releases the GIL); 2 dim + 2 with dim = len(z).
  With ``monodromy = "exact"`` (period 1, paper variant, Coulomb friction) P(z), M and the
  step's descriptors come from one variational integration (`variational.step_jacobian`,
  `variational.step_summary`), d P / d lambda from its parameter column (two maps for l, r
  or a change of law).

``d P^n / d lambda`` is a central difference in the (internal) parameter coordinate for both, of
relative step ``lam_rel`` (1e-6 hybrid, 1e-4 continuous) of the continuation's scale.
Every evaluation also returns the gait's descriptors and its *admissibility* functions:
quantities that must stay positive for the gait to exist as modelled (the end of a family when
one crosses zero), see `HybridProblem.ADMISSIBLE` and `ContinuousProblem.ADMISSIBLE`.

Why this module is long (about 570 lines): the two problems share the parameter handling of
`_Problem`, and the continuous one's three ways to its Jacobians (differences, the exact step, the cross-check)
read the same options and descriptors.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ...core import _hybrid  # type: ignore[attr-defined]  # compiled, no stub
from ...core.contact import Contact
from ...core.errors import InvalidInputError
from ...core.interrupt import thread_map
from ...core.model import parameter_vector
from ...core.params import Params
from ..gait_types import Gait
from ..rigid import hybrid as H
from . import poincare as _poincare
from . import section as _section
from . import step_maps as _maps
from .gait_axes import check_parameter, multiplier_gap, parameter_unit  # noqa: F401


class Evaluation:
    """P^n(z), its Jacobians and descriptors at one (z, lambda); ``ok`` False when a step failed
    (``status`` says how)."""

    __slots__ = ("ok", "status", "Pz", "M", "P_lam", "info", "admissible")

    def __init__(self, ok, status, Pz=None, M=None, P_lam=None, info=None, admissible=None):
        self.ok, self.status, self.Pz, self.M, self.P_lam = ok, status, Pz, M, P_lam
        self.info = info or {}
        self.admissible = admissible or {}


class _Problem:
    """Common part: the parameter, its coordinate (linear or log) and ``params_of``.

    The parameter is a `Params` field, or (continuous model) a parameter of the contact law
    ``"contact.<name>"`` (`pdw.Contact.axes`: ``contact.k``, ``contact.d``, ``contact.e``, ...,
    LuGre's ``contact.sigma0``, ...): a point's model is then ``point_at(mu)`` = (the base
    `Params`, the base `Contact` with that field set), and every map of that point runs with
    that contact."""

    dim = 0
    model = ""
    ADMISSIBLE: dict = {}

    #: relative step of the central difference in the parameter coordinate (times
    #: max(|mu_0|, |mu_stop - mu_0|), set by the continuation)
    lam_rel = 1e-6

    #: whether the model has a contact law whose parameters can be continued
    CONTACT_AXES = False

    def __init__(self, params, parameter, params_of=None, period=1, log=False, lam_step=1e-6,
                 contact=None):
        if not isinstance(params, Params):
            raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
        #: the base contact (None: the default laws); a contact axis moves one of its fields
        self.contact = contact
        self.axis = check_parameter(parameter, params_of, contact, self.CONTACT_AXES,
                                    self.model)
        if int(period) < 1:
            raise InvalidInputError("period must be an integer >= 1, got %r" % (period,))
        self.base, self.parameter, self.period = params, parameter, int(period)
        self._of = params_of
        self.log = bool(log)
        self.lam_step = float(lam_step)
        self.n_maps = 0            # step-map evaluations (one step of the walker each)

    # parameter coordinate: mu = log(lambda) or lambda
    def value(self, mu):
        if self.log and not mu < 709.0:
            # a predictor far off on a logarithmic axis: an invalid parameter (the corrector
            # fails and the step is cut), never an OverflowError
            raise InvalidInputError("%s = exp(%r) is out of range" % (self.parameter, mu))
        return float(math.exp(mu)) if self.log else float(mu)

    def coord(self, value):
        if self.log and not value > 0:
            raise InvalidInputError("log continuation needs %s > 0, got %r"
                                    % (self.parameter, value))
        return float(math.log(value)) if self.log else float(value)

    def contact_at(self, mu):
        """The contact at the parameter coordinate ``mu``: the base contact, or with the contact
        axis's field at its value there (`pdw.InvalidInputError` when out of range)."""
        if self.axis is None:
            return self.contact
        v = self.value(mu)
        try:
            return Contact.coerce(self.contact).with_axis(self.axis, v)
        except InvalidInputError as e:
            raise InvalidInputError("%s = %r: %s" % (self.parameter, v, e)) from None

    def point_at(self, mu):
        """(Params, contact) at ``mu``: the model of one point of the branch."""
        return self.params_at(mu), self.contact_at(mu)

    def start_value(self) -> float:
        """The parameter's value in the base model (a Params field, or the contact's)."""
        if self.axis is not None:
            return Contact.coerce(self.contact).axis_value(self.axis, self.base)
        return float(getattr(self.base, self.parameter))

    @property
    def unit(self) -> str:
        """The parameter's unit ("" when unknown, e.g. a ``params_of`` name)."""
        return parameter_unit(self.parameter, self.contact)

    def lam_offsets(self, mu):
        """Offsets (+, -) of the parameter difference: central, or one-sided at the edge of
        the parameter's allowed range (e.g. k_hip -> 0)."""
        h = self.lam_step
        up, down = h, -h
        for s in (h, -h):
            try:
                self.point_at(mu + s)
            except InvalidInputError:
                if s > 0:
                    up = 0.0
                else:
                    down = 0.0
        return up, down

    def images(self, points):
        """P^n(z) for every (z, params) of ``points`` (no Jacobians): a list of (dim,) arrays,
        None where the map fails. The codim-2 problems' second differences use it."""
        raise NotImplementedError

    def params_at(self, mu) -> Params:
        if self.axis is not None:
            return self.base
        v = self.value(mu)
        try:
            return self._of(v) if self._of is not None else self.base.replace(
                **{self.parameter: v})
        except ValueError as e:
            raise InvalidInputError("%s = %r: %s" % (self.parameter, v, e)) from None


class HybridProblem(_Problem):
    """Period-n map of the hybrid walker on z = (theta_st, thetad_st, thetad_sw)."""

    dim = 3
    model = "hybrid"
    #: admissibility functions (> 0 along a valid gait): the new stance foot's smallest normal
    #: force over the stance (no lift-off, it must push), the trailing foot's upward velocity
    #: after the impact (it leaves the ground), the swing foot's downward speed at the strike
    #: (a transversal strike, not a graze)
    ADMISSIBLE = {"Fn_min": "the stance foot would need a pulling ground force (it lifts off)",
                  "v_old_up": "the trailing foot does not leave the ground after heel strike",
                  "strike_speed": "the swing foot grazes the ground (strike velocity -> 0)"}

    def __init__(self, params, parameter, params_of=None, period=1, log=False, options=None,
                 **kw):
        super().__init__(params, parameter, params_of, period, log, **kw)
        self.opts = {**H._TIGHT, **H._options(options or {})}

    def section(self, state):
        s = np.asarray(state, dtype=float).reshape(-1)
        return s[list(H._SECTION)] if s.size == 4 else s.copy()

    def _steps(self, p, z, jac):
        """Compose n steps from z: (y_plus, DP (4x4) or None, step dicts) or a failure string."""
        y = np.ascontiguousarray(H._y_of(z))
        DP = np.eye(4)
        steps = []
        for _ in range(self.period):
            self.n_maps += 1
            if jac:
                res, D = _hybrid.step_jac(p, y, self.opts)
                DP = D @ DP
            else:
                res, _, _ = _hybrid.step(p, y, self.opts)
            if res["status"] != "ok":
                return res["status"]
            steps.append(res)
            y = np.ascontiguousarray(res["y_plus"])
        return y, DP, steps

    def images(self, points):
        out = []
        for z, P in points:
            P = P[0] if isinstance(P, tuple) else P       # (Params, contact): rigid ground
            o = self._steps(parameter_vector(P), np.asarray(z, dtype=float), False)
            out.append(None if isinstance(o, str) else o[0][list(H._SECTION)])
        return out

    def evaluate(self, z, mu, jac=True) -> Evaluation:
        try:
            p = parameter_vector(self.params_at(mu))
        except InvalidInputError as e:
            return Evaluation(False, "invalid parameter: %s" % e)
        out = self._steps(p, z, jac)
        if isinstance(out, str):
            return Evaluation(False, out)
        y, DP, steps = out
        self.last_step_angle = float(min(s["y_minus"][1] - s["y_minus"][0] for s in steps))
        Pz = y[list(H._SECTION)]
        M = P_lam = None
        if jac:
            E = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
            M = DP[list(H._SECTION)] @ E
            up, down = self.lam_offsets(mu)
            if up == down:
                return Evaluation(False, "invalid parameter: no room for a difference")
            vals = []
            for s in (up, down):
                if s == 0.0:
                    vals.append(y[list(H._SECTION)])
                    continue
                o = self._steps(parameter_vector(self.params_at(mu + s)), z, False)
                if isinstance(o, str):
                    return Evaluation(False, "parameter derivative: " + o)
                vals.append(o[0][list(H._SECTION)])
            P_lam = (vals[0] - vals[1]) / (up - down)
        info = {"period": float(sum(s["t_strike"] for s in steps)),
                "step_length": float(np.mean([s["step_length"] for s in steps])),
                "double_support": 0.0, "state": H._y_of(z),
                "orbit": np.array([z] + [s["y_plus"][list(H._SECTION)] for s in steps[:-1]])}
        adm = {"Fn_min": min(s["Fn_min"] for s in steps),
               "v_old_up": min(s["v_old"][1] for s in steps),
               "strike_speed": min(-s["vy_strike"] for s in steps)}
        return Evaluation(True, "ok", Pz, M, P_lam, info, adm)

    def gait(self, z, mu, ev, multipliers) -> Gait:
        return Gait(state=H._y_of(z), period=ev.info["period"], step_length=ev.info["step_length"],
                    double_support=0.0, multipliers=multipliers, model="hybrid",
                    params=self.params_at(mu),
                    details={"z": np.array(z), "period_n": self.period, "jacobian": ev.M,
                             "jacobian_kind": "exact (variational equations + saltation)",
                             "options": dict(self.opts)})


class ContinuousProblem(_Problem):
    """Period-n map of the continuous walker (`pdw.limit_cycle`) on its section: ``dim`` = 6,
    or more with a contact law that has memory (``options["contact"]``, `_section.section_names`)."""

    dim = 6
    model = "continuous"
    CONTACT_AXES = True
    lam_rel = 1e-4          # the map is reproducible to ~1e-10
    #: admissibility: the double support must last (> 0; else the feet are never both down and
    #: the section's event order changes), and the swing phase too
    ADMISSIBLE = {"double_support": "the double support vanishes (flight or swapped events)",
                  "swing_period": "the swing phase vanishes",
                  "event_sequence": "the step's sequence of support events changes (a scuff "
                                    "of the swing foot, an extra lift-off or touch-down)"}

    def __init__(self, params, parameter, params_of=None, period=1, log=False, variant="paper",
                 method="rodas4", options=None, fd_step=1e-5, executor=None, workers=None, **kw):
        opts = {**_poincare.TIGHT, **(options or {})}
        super().__init__(params, parameter, params_of, period, log, contact=opts.get("contact"),
                         **kw)
        self.variant, self.method = variant, method
        self.opts = opts
        self.dim = len(_section.section_names(self.contact))
        self.fd_step = float(fd_step)
        self.executor = executor
        self.workers = max(1, int(workers or os.cpu_count() or 1))
        self.t_hint = None
        self.ref_events = None       # support events per cycle at the branch's first point
        self.monodromy = "differences"   # or "exact" (pdw.analysis.stepmap.variational)

    def section(self, state):
        s = np.asarray(state, dtype=float).reshape(-1)
        if self.contact is None:
            return _section.section_coordinates(s, 2) if s.size == 8 else s.copy()
        return _section._guess_z(s, self.base, self.contact, self.variant)

    def __getstate__(self):
        # the tasks travel to process pools / Dask workers without the executor itself
        return {**self.__dict__, "executor": None}

    def _options(self, contact):
        """The step map's options for a point whose contact is ``contact``."""
        opts = {**self.opts, "t_hint": self.t_hint}
        if contact is not None or "contact" in opts:
            opts["contact"] = contact
        return opts

    def _compose_all(self, zs, models):
        """``[(P^n(z) or None, steps)]`` of every z with its (Params, contact): through
        `step_maps.compose_points` (the ensemble engine where it takes them) when they share
        one contact, else each on its own (a contact axis: its points' laws differ; the
        engine does not run non-default laws anyway); Ctrl-C stops every thread."""
        contacts = [c for _, c in models]
        if self.executor is not None:
            return list(self.executor.map(
                lambda i: _maps._compose(zs[i], self.period, models[i][0], self.variant,
                                         self.method, self._options(contacts[i])),
                range(len(zs))))
        if all(c == contacts[0] for c in contacts):
            return _maps.compose_points(zs, self.period, [P for P, _ in models], self.variant,
                                        self.method, self._options(contacts[0]), self.workers)
        return thread_map(
            lambda i: _maps._compose(zs[i], self.period, models[i][0], self.variant,
                                     self.method, self._options(contacts[i])),
            range(len(zs)), min(self.workers, len(zs)))

    def _run(self, tasks):
        if self.executor is not None:
            return list(self.executor.map(_ContinuousTask(self), tasks))
        # the finite differences through the ensemble engine where it takes them (the same
        # numbers), the rest on threads; Ctrl-C stops every thread
        return self._compose_all([np.asarray(t[0], dtype=float) for t in tasks],
                                 [self.point_at(mu) for _, mu in tasks])

    def images(self, points):
        """P^n(z) of every (z, model), model a `Params` (with the base contact) or a
        (Params, contact) pair (`point_at`)."""
        if not points:
            return []
        zs = [np.asarray(z, dtype=float) for z, _ in points]
        models = [P if isinstance(P, tuple) else (P, self.contact) for _, P in points]
        outs = self._compose_all(zs, models)
        self.n_maps += self.period * len(points)
        return [o[0] for o in outs]

    def evaluate(self, z, mu, jac=True) -> Evaluation:
        z = np.asarray(z, dtype=float)
        try:
            P, contact = self.point_at(mu)
        except InvalidInputError as e:
            return Evaluation(False, "invalid parameter: %s" % e)
        if jac and self.monodromy == "exact":
            got = self._exact(z, mu, P, contact)
        else:
            got = self._differences(z, mu, jac)
        if isinstance(got, Evaluation):
            return got
        Pz, steps, M, P_lam = got
        info = {"period": float(sum(s["period"] for s in steps)),
                "step_length": float(np.mean([s["step_length"] for s in steps])),
                "double_support": float(np.mean([s["double_support"] for s in steps])),
                "state": _section.embed(z, P, contact),
                "n_events": int(sum(s["n_events"] for s in steps)),
                "orbit": np.array([z] + [s["z"] for s in steps[:-1]])}
        if self.ref_events is None:
            self.ref_events = info["n_events"]
        adm = {"double_support": min(s["double_support"] for s in steps),
               "swing_period": min(s["swing_period"] for s in steps),
               "event_sequence": 0.5 - abs(info["n_events"] - self.ref_events)}
        return Evaluation(True, "ok", Pz, M, P_lam, info, adm)

    def _differences(self, z, mu, jac):
        """(P^n(z), its step dicts, M and dP/dlambda by central differences (None without
        ``jac``)) or a failed `Evaluation`: 1 + 2 dim + 2 maps."""
        tasks = [(z, mu)]
        if jac:
            h = self.fd_step
            up, down = self.lam_offsets(mu)
            if up == down:
                return Evaluation(False, "invalid parameter: no room for a difference")
            E = np.eye(self.dim) * h
            tasks += [(z + e, mu) for e in E] + [(z - e, mu) for e in E]
            tasks += [(z, mu + up), (z, mu + down)]
        outs = self._run(tasks)
        self.n_maps += self.period * len(tasks)
        Pz, steps = outs[0]
        if Pz is None:
            return Evaluation(False, steps[-1]["status"] if steps else "failed")
        self.t_hint = steps[0]["period"]
        if not jac:
            return Pz, steps, None, None
        vals = [o[0] for o in outs]
        if any(v is None for v in vals):
            bad = next(o[1][-1]["status"] for o in outs if o[0] is None)
            return Evaluation(False, "finite-difference neighbour: " + bad)
        n = self.dim
        M = np.column_stack([(vals[1 + k] - vals[1 + n + k]) / (2 * h) for k in range(n)])
        return Pz, steps, M, (vals[1 + 2 * n] - vals[2 + 2 * n]) / (up - down)

    #: ``monodromy = "exact"``: df/dmu of the variational step's parameter column is the
    #: difference of f between mu +- this relative step (of the coordinate mu, lambda or log
    #: lambda; 1e-2 of ``lam_step`` at mu = 0; one-sided where `lam_offsets` is): f's
    #: truncation error ~1e-12, its rounding ~1e-10 (relative)
    SENS_REL = 1e-6

    def _exact(self, z, mu, P, contact):
        """(P(z), its step dict, the exact M, dP/dlambda) or a failed `Evaluation`, period 1:
        P(z), M and the step's descriptors from one variational integration
        (`variational.step_jacobian`, `variational.step_summary`: z' equals the map's to
        ~1e-10) and dP/dlambda from the same integration's parameter column
        (`variational.param_column`: a parameter that only f reads; `SENS_REL`), else
        from central differences of the map (2 maps, through the ensemble engine where it
        takes them: l, r, a change of contact law). Where the variational step fails the map at z says why
        (its status: "fell", "no_touch_down", ...)."""
        from . import variational
        up, down = self.lam_offsets(mu)
        if up == down:
            return Evaluation(False, "invalid parameter: no room for a difference")
        h = self.SENS_REL * abs(mu) if mu != 0.0 else 1e-2 * self.lam_step
        ends = []
        for side, off in ((1.0, up), (-1.0, down)):
            try:                    # one-sided at the edge of the parameter's range
                ends.append((mu + side * h, self.point_at(mu + side * h)) if off else
                            (mu, (P, contact)))
            except InvalidInputError:
                ends.append((mu, (P, contact)))
        (hi, plus), (lo, minus) = ends
        models = [plus, minus]
        column = hi != lo and variational.param_column(P, contact, *models)
        try:
            res = variational.step_jacobian(
                z, P, contact=contact, dparam=(*models, hi - lo) if column else None,
                **{k: self.opts[k] for k in ("rtol", "atol") if k in self.opts})
            step = variational.step_summary(res, P)
        except InvalidInputError as e:
            Pz, steps = self._run([(z, mu)])[0]
            self.n_maps += 1
            if Pz is None:
                return Evaluation(False, steps[-1]["status"] if steps else "failed")
            return Evaluation(False, "exact monodromy: %s" % e)
        self.n_maps += 1
        if step["status"] != "ok":
            return Evaluation(False, step["status"])
        self.t_hint = step["period"]
        if column:
            return step["z"], [step], res["M"], res["dz_dparam"]
        models = [self.point_at(mu + up), self.point_at(mu + down)]
        vals = self._images([z, z], models)
        self.n_maps += 2
        for v in vals:
            if isinstance(v, str):
                return Evaluation(False, "finite-difference neighbour: " + v)
        return step["z"], [step], res["M"], (vals[0] - vals[1]) / (up - down)

    def _images(self, zs, models):
        """P(z) of every (z, (Params, contact)), or the failed step's status: through the
        ensemble engine (`step_maps.images`, bitwise `step`'s z') where it takes them all,
        else (and for every point it leaves) as `_compose_all`."""
        contacts = [c for _, c in models]
        opts = self._options(contacts[0])
        out: list = [None] * len(zs)
        if (self.executor is None and all(c == contacts[0] for c in contacts)
                and _maps.batchable(self.method, self.period, opts)):
            out = list(_maps.images(zs, [m[0] for m in models], self.variant, self.method,
                                    opts, threads=1))
        left = [i for i, v in enumerate(out) if v is None]
        if left:
            for i, (v, steps) in zip(left, self._compose_all([zs[i] for i in left],
                                                             [models[i] for i in left])):
                out[i] = v if v is not None else (steps[-1]["status"] if steps else "failed")
        return out

    #: the second difference step of the cross-check, a multiple of ``fd_step``
    CHECK_FACTOR = 10.0
    #: multipliers of the two steps differing by more than this are reported
    CHECK_TOL = 1e-3
    #: multipliers smaller than this in modulus are not compared (`multiplier_gap`)
    CHECK_FLOOR = 0.1

    @property
    def exact_available(self) -> bool:
        """Whether `pdw.analysis.stepmap.variational` gives this problem's exact monodromy:
        the paper variant, period 1 and Coulomb friction (every normal law; not LuGre)."""
        return (self.variant == "paper" and self.period == 1
                and Contact.coerce(self.contact).friction == "coulomb")

    def crosscheck(self, z, mu, multipliers):
        """The multipliers again, exactly (`pdw.analysis.stepmap.variational`: paper variant,
        period 1, every normal law with Coulomb friction, `exact_available`) or else from
        central differences with ``CHECK_FACTOR`` x
        ``fd_step``: (largest difference to ``multipliers``, note or ""). A difference above
        ``CHECK_TOL`` means the step map has a kink within a few difference steps of z (the
        finite-difference multipliers then depend on the step), and the note says so;
        ``last_check`` says which check ran."""
        z = np.asarray(z, dtype=float)
        if self.exact_available and self.monodromy != "exact":
            # the exact monodromy (pdw.analysis.stepmap.variational) where it exists
            from . import variational
            try:
                P, contact = self.point_at(mu)
                Mx = variational.step_jacobian(z, P, contact=contact, **{
                    k: self.opts[k] for k in ("rtol", "atol") if k in self.opts})["M"]
            except InvalidInputError as e:
                return np.inf, "the exact monodromy failed (%s): not checked" % e
            m = np.linalg.eigvals(Mx)
            m = m[np.argsort(-np.abs(m))]
            ref = np.asarray(multipliers)
            diff = multiplier_gap(m, ref, self.CHECK_FLOOR)
            self.last_check = "variational"
            if diff > self.CHECK_TOL:
                return diff, ("the finite-difference multipliers (fd_step %g) differ from the "
                              "exact ones (variational equations) by %.3g (largest %s against "
                              "%s): a kink of the step map within a difference step of this "
                              "point" % (self.fd_step, diff, np.round(ref[0], 4),
                                         np.round(m[0], 4)))
            return diff, ""
        self.last_check = "finite differences x%g" % self.CHECK_FACTOR
        h = self.fd_step * self.CHECK_FACTOR
        E = np.eye(self.dim) * h
        outs = self._run([(z + e, mu) for e in E] + [(z - e, mu) for e in E])
        self.n_maps += self.period * 2 * self.dim
        if any(o[0] is None for o in outs):
            return np.inf, ("the step map fails within %g of the point: the multipliers "
                            "are not checked" % h)
        n = self.dim
        M = np.column_stack([(outs[k][0] - outs[n + k][0]) / (2 * h) for k in range(n)])
        m = np.linalg.eigvals(M)
        m = m[np.argsort(-np.abs(m))]
        ref = np.asarray(multipliers)
        diff = multiplier_gap(m, ref, self.CHECK_FLOOR)
        if diff > self.CHECK_TOL:
            return diff, ("finite-difference multipliers depend on the step: fd_step %g and "
                          "%g differ by %.3g (largest %s against %s): a kink of the step map "
                          "within a few steps of this point, or strong curvature; the "
                          "multipliers are uncertain to that amount" % (self.fd_step, h, diff,
                                                np.round(ref[0], 4), np.round(m[0], 4)))
        return diff, ""

    def gait(self, z, mu, ev, multipliers) -> Gait:
        P, contact = self.point_at(mu)
        return Gait(state=ev.info["state"], period=ev.info["period"],
                    step_length=ev.info["step_length"], double_support=ev.info["double_support"],
                    multipliers=multipliers, model="continuous", params=P,
                    details={"z": np.array(z), "period_n": self.period, "jacobian": ev.M,
                             "jacobian_kind": ("exact (variational equations + saltation)"
                                               if self.monodromy == "exact" else
                                               "central differences, fd_step %g"
                                               % self.fd_step),
                             "variant": self.variant,
                             "options": {**self.opts, **({} if contact is None
                                                         else {"contact": contact})},
                             "section_names": _section.section_names(self.contact)})


class _ContinuousTask:
    """Callable P^n at (z, mu) -> (P^n(z) or None, steps); picklable (for process pools and
    Dask) when ``params_of`` is."""

    def __init__(self, prob):
        self.prob = prob

    def __call__(self, task):
        z, mu = task
        pr = self.prob
        P, contact = pr.point_at(mu)
        return _maps._compose(np.asarray(z), pr.period, P, pr.variant, pr.method,
                              pr._options(contact))
