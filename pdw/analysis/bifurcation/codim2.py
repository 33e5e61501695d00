"""Two-parameter continuation of folds, period doublings and ends of gaits (docs/continuation.md).

A fold (a multiplier at +1) or a period doubling (a multiplier at -1) of the period-n map P is
one equation more than a gait: it is followed in a second parameter lambda2 as the solution
curve of the *minimally augmented* system (Govaerts 2000; BifurcationKit's codim-2
continuation), with unknowns x = (z, mu1) and the continuation parameter mu2:

    F(z, mu1; mu2) = ( P(z; mu1, mu2) - z ,  sigma(z, mu1, mu2) ) = 0,

where A = M + s I (s = +1 period doubling, -1 fold; M = dP/dz) and sigma is the last component
of the solution of the bordered system

    [ A    a ] [ v     ]   [ 0 ]
    [ b^T  0 ] [ sigma ] = [ 1 ],

a and b being approximate null vectors of A^T and A (refreshed after every accepted point, so
the bordered matrix stays regular). sigma vanishes exactly where A is singular. Its
derivatives are d sigma / dx_k = -w^T (dA/dx_k) v, with w from the transposed system, and
dA/dx_k = dM/dx_k is a central difference of the model's exact (hybrid) or finite-difference
(continuous) M.

An ``end`` (an admissibility function g of the problem through 0, the edge of the family as
modelled) is followed the same way with sigma replaced by g(z, mu1, mu2) itself (its
derivatives by central differences of maps, no monodromy). The second parameter may be a
derived one (``params_of``), e.g. Goswami's b/a or m_H/m.

A Neimark-Sacker point uses A = C2(M) - I instead (`compound2`, the second compound matrix,
singular where mu mu-bar = 1). dsigma/dx comes from differences of M (``second="monodromy"``,
the hybrid model's default) or, without extra monodromies, from central differences of
w^T M v = w^T (P(z + e v) - P(z - e v)) / 2e (``"directional"``, the continuous model's).

`AugmentedProblem` presents F as a step map, P~(x) = x + F(x), with M~ = I + dF/dx and
dP~/dmu2 = dF/dmu2, so the *unchanged* one-parameter engine (`run_continuation`) follows it.
`continue_bifurcation` returns a `BifurcationCurve` whose ``values`` are (N, 2): the first
(the bifurcation's own) and the second parameter.

(Why this module is long: the augmented problem's three residuals (bordered sigma with monodromy or
directional derivatives, and the admissibility function of an end) share its border vectors,
parameter handling and batch of maps, so they stay in one class.)
"""
from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...core.contact import Contact
from ...core.errors import InvalidInputError
from ...core.params import Params
from ..stepmap.gait_maps import Evaluation, check_parameter, parameter_unit
from .branch import Bifurcation

#: the bifurcation kinds a curve can follow, and the sign s of A = M + s I ("end": the
#: admissibility function g(z, mu1, mu2) = 0 itself is the extra equation, no A)
SIGNS = {"period_doubling": 1.0, "fold": -1.0, "end": 0.0, "neimark_sacker": 0.0}


def compound2(M):
    """The second compound matrix C2(M) (m x m, m = n (n - 1) / 2; its entries are M's 2 x 2
    minors, rows and columns the index pairs p > q): its eigenvalues are the products
    mu_i mu_j (i < j) of M's, so C2(M) - I is singular at a Neimark-Sacker point
    (mu mu-bar = 1), and at a neutral saddle (real mu_i mu_j = 1) too."""
    M = np.asarray(M, dtype=float)
    n = len(M)
    pairs = [(p, q) for p in range(1, n) for q in range(p)]
    C = np.empty((len(pairs), len(pairs)))
    for i, (p, q) in enumerate(pairs):
        for j, (r, s) in enumerate(pairs):
            C[i, j] = M[p, r] * M[q, s] - M[p, s] * M[q, r]
    return C


def _null_vectors(A):
    U, _, Vt = np.linalg.svd(A)
    return U[:, -1].copy(), Vt[-1].copy()


class _Fail(Exception):
    """A failed evaluation inside the augmented problem (becomes a not-ok Evaluation)."""


class AugmentedProblem:
    """The minimally augmented system of a fold / period doubling of ``prob`` (a one-parameter
    problem of `pdw.analysis.stepmap.gait_maps`, whose parameter is the bifurcation's) in the second
    parameter ``parameter2``, as a problem of the continuation engine (module docstring)."""

    ADMISSIBLE: dict = {}
    lam_rel = 1e-6

    def __init__(self, prob, kind, parameter2, z, mu1, h=1e-6, params_of=None, value=None,
                 admissible=None, second="auto"):
        if kind not in SIGNS:
            raise InvalidInputError("continue_bifurcation follows %s, got a %r"
                                    % (", ".join(SIGNS), kind))
        if kind == "end" and admissible not in getattr(prob, "ADMISSIBLE", {}):
            raise InvalidInputError("an end is followed through its admissibility function "
                                    "(one of %s), got %r"
                                    % (", ".join(getattr(prob, "ADMISSIBLE", {})), admissible))
        self.admissible = admissible
        if second not in ("auto", "monodromy", "directional"):
            raise InvalidInputError("second must be 'auto', 'monodromy' or 'directional', got "
                                    "%r" % (second,))
        #: how d sigma / dx is differenced: "monodromy" (central differences of M, 2 (n + 1)
        #: + 2 monodromies: the hybrid model's exact M is cheap) or "directional" (of
        #: w^T M v = w^T (P(z + e v) - P(z - e v)) / 2e, 4 (n + 1) + 6 maps in one batch)
        self.second = (("monodromy" if prob.model == "hybrid" else "directional")
                       if second == "auto" else second)
        self.lam_rel = getattr(prob, "lam_rel", 1e-6)
        #: weight of sigma in the residual (`continue_bifurcation`'s ``sigma_tol``): Newton's
        #: max |F| < tol then means |sigma| < sigma_tol
        self.kappa = 1.0
        #: the second parameter's contact axis ("contact.<name>") or None (a Params field)
        self.axis2 = check_parameter(parameter2, params_of, getattr(prob, "contact", None),
                                     getattr(prob, "CONTACT_AXES", False), prob.model)
        if params_of is not None and not callable(params_of):
            raise InvalidInputError("params_of must be a callable (params, value) -> Params, "
                                    "got %s" % type(params_of).__name__)
        if params_of is not None and value is None:
            raise InvalidInputError("value= (the start's %s) is needed with params_of"
                                    % parameter2)
        if parameter2 == prob.parameter:
            raise InvalidInputError("parameter must differ from the bifurcation's own "
                                    "parameter %r" % parameter2)
        if getattr(prob, "_of", None) is not None:
            raise InvalidInputError("continue_bifurcation: a branch continued with params_of "
                                    "is not supported")
        self.p1 = copy.copy(prob)
        self.p2 = copy.copy(prob)
        self.p2.parameter, self.p2.log = parameter2, False
        self.base = prob.base
        self.contact = getattr(prob, "contact", None)      # the base contact
        self.unit = parameter_unit(parameter2, self.contact)
        self.kind, self.s = kind, SIGNS[kind]
        self.parameter, self.parameter1 = parameter2, prob.parameter
        self.model = prob.model
        self.period = prob.period
        self.dim = prob.dim + 1
        self.h = float(h)
        self.ADMISSIBLE = dict(getattr(prob, "ADMISSIBLE", {}))
        self.n_maps = 0
        self.lam_step = 1e-6
        self.opts = dict(getattr(prob, "opts", {}))
        self._of = params_of
        if value is not None:
            self.start2 = float(value)
        elif self.axis2 is not None:
            self.start2 = Contact.coerce(self.contact).axis_value(self.axis2, self.base)
        else:
            self.start2 = float(getattr(prob.base, parameter2))
        ev = self._base_eval(np.asarray(z, dtype=float), mu1, self.start2)
        if not ev.ok:
            raise InvalidInputError("the bifurcation's gait does not evaluate: %s" % ev.status)
        if kind == "neimark_sacker":
            self.second = "monodromy"          # C2(M) is quadratic in M: no directional form
        self.a, self.b = _null_vectors(self._A(ev.M))

    def _g(self, z, mu1, mu2):
        """The followed admissibility function at (z, mu1, mu2) (an "end" curve)."""
        ev = self._base_eval(z, mu1, mu2, False)
        if not ev.ok:
            return None, ev.status
        return float(ev.admissible[self.admissible]), "ok"

    def _evaluate_end(self, x, mu2, jac) -> Evaluation:
        """F = (P^n(z) - z, g(z, mu1, mu2)) with dg/dx, dg/dmu2 by central differences of g
        (maps only, no monodromy)."""
        z, mu1 = np.asarray(x[:-1], dtype=float), float(x[-1])
        ev = self._base_eval(z, mu1, mu2, jac)
        if not ev.ok:
            return Evaluation(False, ev.status)
        n = len(z)
        g = float(ev.admissible[self.admissible])
        F = np.concatenate([ev.Pz - z, [g]])
        Mt = Pt = None
        if jac:
            up, down = self._mu2_offsets(mu2)
            h2 = 0.5 * (up - down)
            e_hi = self._base_eval(z, mu1, mu2 + up, False) if up else ev
            e_lo = self._base_eval(z, mu1, mu2 + down, False) if down else ev
            if not (e_hi.ok and e_lo.ok):
                return Evaluation(False, "parameter derivative: %s"
                                  % (e_hi.status if not e_hi.ok else e_lo.status))
            dg = np.zeros(n + 1)
            for k in range(n + 1):
                d = np.zeros(n + 1)
                d[k] = self.h
                hi, st_hi = self._g(z + d[:n], mu1 + d[n], mu2)
                lo, st_lo = self._g(z - d[:n], mu1 - d[n], mu2)
                if hi is None or lo is None:
                    return Evaluation(False, "admissibility derivative: %s"
                                      % (st_hi if hi is None else st_lo))
                dg[k] = (hi - lo) / (2 * self.h)
            J = np.zeros((n + 1, n + 1))
            J[:n, :n] = ev.M - np.eye(n)
            J[:n, n] = ev.P_lam
            J[n, :] = dg
            Mt = np.eye(n + 1) + J
            Pt = np.concatenate([(e_hi.Pz - e_lo.Pz) / (2 * h2),
                                 [(e_hi.admissible[self.admissible]
                                   - e_lo.admissible[self.admissible]) / (2 * h2)]])
        m = np.linalg.eigvals(ev.M)
        info = dict(ev.info, base_multipliers=m[np.argsort(-np.abs(m))], sigma=g,
                    value1=self.p1.value(mu1), M=ev.M)
        adm = {k: v for k, v in ev.admissible.items() if k != self.admissible}
        return Evaluation(True, "ok", x + F, Mt, Pt, info, adm)

    # the parameter coordinate of lambda2 (linear)
    def value(self, mu):
        return float(mu)

    def coord(self, value):
        return float(value)

    def _with2(self, mu2):
        """The base (Params, contact) at ``mu2`` of the second parameter (a field, a contact
        parameter, or ``params_of``)."""
        if self.axis2 is not None:
            try:
                return self.base, Contact.coerce(self.contact).with_axis(self.axis2, float(mu2))
            except InvalidInputError as e:
                raise InvalidInputError("%s = %r: %s" % (self.parameter, mu2, e)) from None
        if self._of is None:
            return self.base.replace(**{self.parameter: float(mu2)}), self.contact
        P = self._of(self.base, float(mu2))
        if not isinstance(P, Params):
            raise InvalidInputError("params_of must return a pdw.Params, got %s"
                                    % type(P).__name__)
        return P, self.contact

    def _set2(self, mu2):
        """Move the base problem's model to ``mu2`` of the second parameter."""
        self.p1.base, self.p1.contact = self._with2(mu2)

    def _mu2_offsets(self, mu2):
        """(up, down) of the difference in mu2: central, or one-sided at the edge of its
        allowed range (e.g. k_hip -> 0)."""
        h, out = self.lam_step, []
        for s in (h, -h):
            try:
                self._with2(mu2 + s)
                out.append(s)
            except (ValueError, InvalidInputError):
                out.append(0.0)
        return out[0], out[1]

    def params_at(self, mu2, mu1):
        self._set2(mu2)
        return self.p1.params_at(mu1)

    def _base_eval(self, z, mu1, mu2, jac=True) -> Evaluation:
        try:
            self._set2(mu2)
        except (ValueError, InvalidInputError) as e:
            return Evaluation(False, "invalid parameter: %s = %r: %s" % (self.parameter, mu2, e))
        n0 = self.p1.n_maps
        ev = self.p1.evaluate(z, mu1, jac)
        self.n_maps += self.p1.n_maps - n0
        return ev

    def _A(self, M):
        """The matrix singular at the bifurcation: M + s I, or C2(M) - I (Neimark-Sacker)."""
        if self.kind == "neimark_sacker":
            C = compound2(M)
            return C - np.eye(len(C))
        return M + self.s * np.eye(len(M))

    def _sigma(self, M):
        A = self._A(M)
        n = len(A)
        K = np.zeros((n + 1, n + 1))
        K[:n, :n], K[:n, n], K[n, :n] = A, self.a, self.b
        rhs = np.zeros(n + 1)
        rhs[-1] = 1.0
        vs = np.linalg.solve(K, rhs)
        ws = np.linalg.solve(K.T, rhs)
        return vs[-1], vs[:n], ws[:n]

    def _at(self, mu1, mu2):
        """The (Params, contact) of the base problem at (mu1, mu2) (`images`' models)."""
        self._set2(mu2)
        return self.p1.point_at(mu1)

    def _directional(self, z, mu1, mu2, v, w, ev=None):
        """d sigma / d(z, mu1) (n + 1,), d sigma / d mu2 and dP / d mu2 from central
        differences of S(x) = w^T (P(z + e v^) - P(z - e v^)) / 2e |v| = w^T M v, all maps of
        one batch (`images`): no monodromy but the base point's (``ev``, unused here)."""
        n = len(z)
        nv = float(np.linalg.norm(v))
        vh, e = v / nv, self.h
        h1 = self.p1.lam_step if self.p1.lam_step > 0 else self.h
        steps = [self.h] * n + [h1]
        up, down = self._mu2_offsets(mu2)
        pts = []
        for k in range(n + 1):
            for sgn in (1.0, -1.0):
                d = np.zeros(n + 1)
                d[k] = sgn * steps[k]
                try:
                    P = self._at(mu1 + d[n], mu2)
                except (ValueError, InvalidInputError) as err:
                    raise _Fail("second derivative: %s" % err) from None
                zk = z + d[:n]
                pts += [(zk + e * vh, P), (zk - e * vh, P)]
        for off in (up, down):
            P = self._at(mu1, mu2 + off)
            pts += [(z + e * vh, P), (z - e * vh, P), (z, P)]
        self._set2(mu2)
        ims = self.p1.images(pts)
        self.n_maps += len(pts) * self.period
        if any(im is None for im in ims):
            raise _Fail("second derivative: the step map fails within %g of the point" % e)

        def S(i):
            return float(w @ (ims[i] - ims[i + 1])) / (2 * e) * nv

        ds = np.array([-(S(4 * k) - S(4 * k + 2)) / (2 * steps[k]) for k in range(n + 1)])
        b0 = 4 * (n + 1)
        h2 = up - down
        dsig2 = -(S(b0) - S(b0 + 3)) / h2
        P_mu2 = (ims[b0 + 2] - ims[b0 + 5]) / h2
        return ds, dsig2, P_mu2

    def _bordered(self, z, mu1, mu2):
        """The base map at (z, mu1, mu2) and its bordered (sigma, v, w), or a failed Evaluation."""
        ev = self._base_eval(z, mu1, mu2, True)
        if not ev.ok:
            return ev, Evaluation(False, ev.status)
        try:
            return ev, self._sigma(ev.M)
        except np.linalg.LinAlgError:
            return ev, Evaluation(False, "singular bordered matrix")

    def evaluate(self, x, mu2, jac=True) -> Evaluation:
        if self.kind == "end":
            return self._evaluate_end(x, mu2, jac)
        z, mu1 = np.asarray(x[:-1], dtype=float), float(x[-1])
        ev, bordered = self._bordered(z, mu1, mu2)
        if isinstance(bordered, Evaluation):
            return bordered
        sigma, v, w = bordered
        n = len(z)
        F = np.concatenate([ev.Pz - z, [self.kappa * sigma]])
        Mt = Pt = None
        if jac:
            second = self._directional if self.second == "directional" else self._by_monodromy
            try:
                ds, dsig2, P_mu2 = second(z, mu1, mu2, v, w, ev)
            except _Fail as err:
                return Evaluation(False, str(err))
            J = np.zeros((n + 1, n + 1))
            J[:n, :n] = ev.M - np.eye(n)
            J[:n, n] = ev.P_lam
            J[n, :] = self.kappa * ds
            Mt = np.eye(n + 1) + J
            Pt = np.concatenate([P_mu2, [self.kappa * dsig2]])
        m = np.linalg.eigvals(ev.M)
        info = dict(ev.info, base_multipliers=m[np.argsort(-np.abs(m))], sigma=sigma,
                    value1=self.p1.value(mu1), M=ev.M)
        return Evaluation(True, "ok", x + F, Mt, Pt, info, dict(ev.admissible))

    def _by_monodromy(self, z, mu1, mu2, v, w, ev):
        """(d sigma/d(z, mu1), d sigma/d mu2, dP/d mu2) from central differences of M (the
        monodromies of 2 (n + 2) more maps)."""
        n = len(z)
        # P_mu2 by a central difference in lambda2
        up, down = self._mu2_offsets(mu2)
        h2 = up - down
        e_hi = self._base_eval(z, mu1, mu2 + up, True) if up else ev
        e_lo = self._base_eval(z, mu1, mu2 + down, True) if down else ev
        if not (e_hi.ok and e_lo.ok):
            raise _Fail("parameter derivative: %s" % (e_hi.status if not e_hi.ok else e_lo.status))
        P_mu2 = (e_hi.Pz - e_lo.Pz) / h2
        dA_mu2 = (self._A(e_hi.M) - self._A(e_lo.M)) / h2
        # d sigma / dz_k and d sigma / d mu1 from central differences of M
        ds = np.zeros(n + 1)
        for k in range(n + 1):
            d = np.zeros(n + 1)
            d[k] = self.h
            lo = self._base_eval(z - d[:n], mu1 - d[n], mu2, True)
            hi = self._base_eval(z + d[:n], mu1 + d[n], mu2, True)
            if not (lo.ok and hi.ok):
                raise _Fail("second derivative: %s" % (hi.status if not hi.ok else lo.status))
            ds[k] = -w @ ((self._A(hi.M) - self._A(lo.M)) / (2 * self.h)) @ v
        return ds, -(w @ dA_mu2 @ v), P_mu2

    def accept(self, pt) -> None:
        """Refresh the border vectors a, b at an accepted point (BifurcationKit's
        ``update_minaug_every_step``), called by the engine."""
        M = pt.ev.info.get("M")
        if M is not None and self.kind != "end":
            self.a, self.b = _null_vectors(self._A(M))

    def gait(self, x, mu2, ev, multipliers):
        g = self.p1.gait(np.asarray(x[:-1]), float(x[-1]), ev,
                         ev.info.get("base_multipliers", multipliers))
        return g


@dataclass(eq=False)
class BifurcationCurve:
    """A fold, period-doubling or end curve in two parameters (`continue_bifurcation`).

    Attributes
    ----------
    kind : str
        "fold", "period_doubling" or "end".
    parameters : tuple of str
        (the bifurcation's own parameter, the second parameter).
    values : ndarray (N, 2)
        The two parameters along the curve.
    z : ndarray (N, dim)
        The gait's section coordinates at each point.
    multipliers : ndarray (N, dim)
        The gait's Floquet multipliers (one at -1 / +1 along the curve), by modulus.
    step_length, period : ndarray (N,)
        [m], [s] of the gait along the curve.
    branch : Branch
        The engine's branch of the augmented problem (its ``z`` is (z, mu1)).
    stop_reason : str
    """

    kind: str
    parameters: tuple
    values: np.ndarray
    z: np.ndarray
    multipliers: np.ndarray
    step_length: np.ndarray
    period: np.ndarray
    stop_reason: str
    branch: Any = field(repr=False)
    wall_time: float = 0.0
    n_maps: int = 0
    #: the units of the two parameters ("" when unknown, e.g. a ``params_of`` name)
    units: tuple = ("", "")

    def __len__(self):
        return len(self.values)

    def __repr__(self):
        return ("BifurcationCurve(%s in (%s, %s), %d points, %s in [%.6g, %.6g], %s in "
                "[%.6g, %.6g], stop: %s)" % (
                    self.kind, *self.parameters, len(self), self.parameters[0],
                    self.values[:, 0].min(), self.values[:, 0].max(), self.parameters[1],
                    self.values[:, 1].min(), self.values[:, 1].max(), self.stop_reason))

    def at(self, value2: float) -> float:
        """The first parameter on the curve at ``value2`` of the second (linear interpolation
        between the two nearest points; the curve must pass ``value2``)."""
        v = self.values
        for i in range(len(v) - 1):
            lo, hi = v[i, 1], v[i + 1, 1]
            if min(lo, hi) <= value2 <= max(lo, hi) and hi != lo:
                w = (value2 - lo) / (hi - lo)
                return float(v[i, 0] + w * (v[i + 1, 0] - v[i, 0]))
        raise InvalidInputError("the curve does not pass %s = %r" % (self.parameters[1], value2))


def continue_bifurcation(bifurcation: Bifurcation, parameter: str, stop: float, *,
                         step: float | None = None, max_points: int = 200,
                         tol: float = 1e-9, max_newton: int = 10, fd_step: float = 1e-6,
                         params_of: Any = None, value: float | None = None,
                         second: str = "auto", sigma_tol: float | None = None,
                         skip: Any = (), **kw: Any) -> BifurcationCurve:
    """Follow a located fold, period doubling or end of a branch in a second parameter.

    Parameters
    ----------
    bifurcation : Bifurcation
        A located ``fold``, ``period_doubling`` or ``end`` of a `pdw.continue_gait` branch (it
        carries its problem: model, period, options). An end is followed as the curve where
        its admissibility function is 0 (the edge of the gait's existence as modelled).
    parameter : str
        The second parameter (a `pdw.Params` field other than the branch's, a parameter of
        the continuous model's contact law ``"contact.<name>"`` (`pdw.Contact.axes`), or any
        name with ``params_of``); either parameter may be a contact one.
    stop : float
        Continue until ``parameter`` reaches ``stop`` (or ``max_points``, or the curve ends).
    step : float, optional
        First step in ``parameter`` (default 1/50 of the range).
    tol : float
        Newton tolerance on max |(P^n(z) - z, sigma)| (default 1e-9).
    fd_step : float
        Difference step of the second derivatives dM/dx (default 1e-6: M is exact for the
        hybrid model; use about 1e-4 with the continuous model's finite-difference M).
    second : {"auto", "monodromy", "directional"}
        How the fold / doubling condition's derivatives are differenced: of the monodromy M
        (2 (n + 1) + 2 extra monodromies per Newton iteration; "auto" for the hybrid model,
        whose M is exact and cheap) or of w^T M v along the null vector (4 (n + 1) + 6 maps in
        one parallel batch; "auto" for the continuous model, whose M costs 2n + 3 maps).
    sigma_tol : float, optional
        Newton's tolerance on the fold / doubling condition sigma (default ``tol`` for the
        hybrid model, whose M is exact; 3e-6 for the continuous model: sigma from its
        finite-difference M moves by ~4e-6 between difference steps 1e-6 and 1e-4, so
        ``tol`` = 1e-9 cannot be met and Newton stalls). The curve is then located to about
        sigma_tol / |d sigma / d parameter| in the first parameter.
    params_of : callable (Params, float) -> Params, optional
        A derived second parameter: the branch's base parameters at ``parameter`` = value,
        e.g. Goswami's b/a, ``lambda P, r: P.replace(c=r / (1 + r))``. The bifurcation's own
        parameter is applied on top of it.
    value : float, optional
        The start's ``parameter`` (needed with ``params_of``; default: the base's field).
    skip : sequence of str, optional
        Admissibility functions of the problem that do not end the curve (e.g.
        ``("event_sequence",)``: a change of the continuous model's sequence of support
        events, where its step map is continuous, is then reported as a UZ point of
        ``curve.branch`` instead, `testfunctions.SequenceChange`).
    **kw
        `run_continuation`'s other options (``max_newton``, ``step_max``, ``at``, ...).

    Returns
    -------
    BifurcationCurve
        ``values`` (N, 2): the bifurcation's parameter and ``parameter``.
    """
    from .continuation import run_continuation
    t0 = time.perf_counter()
    if not isinstance(bifurcation, Bifurcation):
        raise InvalidInputError("bifurcation must be a pdw.Bifurcation, got %s"
                                % type(bifurcation).__name__)
    prob = bifurcation.details.get("problem")
    if prob is None:
        raise InvalidInputError("the bifurcation carries no problem (a bifurcation of a "
                                "continue_gait branch is needed)")
    if not bifurcation.located:
        raise InvalidInputError("the %s was only detected, not located (%s): locate it "
                                "first" % (bifurcation.kind, bifurcation.location_note))
    adm = None
    if bifurcation.kind == "end":
        adm = str(bifurcation.details.get("test", ""))[len("end:"):]
    aug = AugmentedProblem(prob, bifurcation.kind, parameter, bifurcation.z, bifurcation.mu,
                           h=fd_step, params_of=params_of, value=value, admissible=adm,
                           second=second)
    if sigma_tol is None:
        sigma_tol = tol if prob.model == "hybrid" else max(tol, 3e-6)
    if not (isinstance(sigma_tol, (int, float)) and 0 < sigma_tol < 1):
        raise InvalidInputError("sigma_tol must be in (0, 1), got %r" % (sigma_tol,))
    aug.kappa = float(tol) / float(sigma_tol)
    x0 = np.append(np.asarray(bifurcation.z, dtype=float), bifurcation.mu)
    detect: tuple = ("end",)
    if isinstance(skip, str) or any(k not in getattr(prob, "ADMISSIBLE", {}) for k in skip):
        raise InvalidInputError("skip must be a sequence of the problem's admissibility "
                                "functions (%s), got %r"
                                % (", ".join(getattr(prob, "ADMISSIBLE", {})), skip))
    if skip:
        from . import testfunctions as TF
        events: list = [TF.AdmissibleEnd(skip=skip)]
        if "event_sequence" in skip:
            events.append(TF.SequenceChange())
        kw["events"] = events + list(kw.get("events", ()))
        detect = ()
    b = run_continuation(aug, x0, aug.start2, stop, step=step,
                         max_points=max_points, tol=tol, max_newton=max_newton,
                         detect=detect, **kw)
    vals = np.column_stack([[prob.value(m) for m in b.z[:, -1]], b.values])
    mult = []
    for x, mu2 in zip(b.z, b.values):
        ev = aug._base_eval(x[:-1], x[-1], mu2, True)
        m = np.linalg.eigvals(ev.M) if ev.ok else np.full(prob.dim, np.nan)
        mult.append(m[np.argsort(-np.abs(m))])
    return BifurcationCurve(kind=bifurcation.kind, parameters=(prob.parameter, parameter),
                            values=vals, z=b.z[:, :-1].copy(), multipliers=np.array(mult),
                            step_length=b.step_length, period=b.period,
                            stop_reason=b.stop_reason, branch=b,
                            wall_time=time.perf_counter() - t0, n_maps=aug.n_maps,
                            units=(getattr(prob, "unit", ""),
                                   parameter_unit(parameter, aug.contact)))
