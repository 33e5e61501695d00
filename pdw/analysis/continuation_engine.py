"""The predictor-corrector engine and the test functions of `pdw.analysis.continuation`.

`Engine` works in the scaled coordinates x = (z, u) of one problem (`pdw.analysis.gait_maps`):
Newton correction on the step map bordered by the arclength (or natural) condition, unit
tangents, and one continuation step. `tests` evaluates the test functions at a point,
`check_crossings` finds their sign changes between two points and locates each by the
Illinois method (`locate`); the method is described in `pdw.analysis.continuation`.
"""
from __future__ import annotations

import numpy as np

from .branch import Bifurcation
from .gait_maps import Evaluation


class Point:
    __slots__ = ("x", "ev", "tangent", "mult", "tests", "iters", "ds")

    def __init__(self, x, ev, tangent, iters, ds):
        self.x, self.ev, self.tangent, self.iters, self.ds = x, ev, tangent, iters, ds
        m = np.linalg.eigvals(ev.M)
        self.mult = m[np.argsort(-np.abs(m))]
        self.tests = {}


class Engine:
    """Predictor-corrector machinery on one problem, in the scaled coordinates x = (z, u)."""

    def __init__(self, prob, mu0, scale, tol, max_newton, natural):
        self.prob, self.mu0, self.scale = prob, mu0, scale
        self.tol, self.max_newton, self.natural = tol, max_newton, natural
        self.n = prob.dim

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
        """The next point at arclength ds from pt (natural: ds in u)."""
        if self.natural:
            e = np.zeros(self.n + 1)
            e[-1] = 1.0
            d = pt.tangent / pt.tangent[-1] if abs(pt.tangent[-1]) > 1e-12 else e
            x_pred = pt.x + ds * d
            c = e
        else:
            x_pred = pt.x + ds * pt.tangent
            c = pt.tangent
        x, ev, its = self.correct(x_pred, c)
        if x is None:
            return None, ev, its
        ref = c if self.natural else pt.tangent
        return Point(x, ev, self.tangent(ev, ref), its, ds), None, its


# --- test functions ---------------------------------------------------------------------------

def tests(engine, pt):
    m = pt.mult
    n = len(m)
    ns = np.prod([m[j] * m[k] - 1.0 for j in range(n) for k in range(j + 1, n)])
    t = {"period_doubling": float(np.real(np.prod(m + 1.0))),
         "neimark_sacker": float(np.real(ns))}
    if engine.natural:
        t["fold"] = float(np.real(np.prod(m - 1.0)))
    else:
        t["fold"] = float(pt.tangent[-1])
    for k, v in pt.ev.admissible.items():
        t["end:" + k] = float(v)
    return t


def locate(engine, a, b, name, locate_tol, max_iter=40):
    """Illinois on s in (0, b.ds) along a's predictor for the test ``name``: (the point there,
    the width of the final bracket in the parameter coordinate mu)."""
    lo, hi = 0.0, b.ds
    flo, fhi = a.tests[name], b.tests[name]
    p_lo, p_hi = a, b
    side = 0
    for _ in range(max_iter):
        if abs(engine.mu(p_lo.x) - engine.mu(p_hi.x)) < locate_tol:
            break
        s = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
        if not (lo < s < hi):
            s = 0.5 * (lo + hi)
        pt, _, _ = engine.step_from(a, s)
        if pt is None:
            s = 0.5 * (lo + hi)
            pt, _, _ = engine.step_from(a, s)
            if pt is None:
                break
        pt.tests = tests(engine, pt)
        f = pt.tests[name]
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
    best = p_lo if abs(p_lo.tests[name]) < abs(p_hi.tests[name]) else p_hi
    return best, abs(engine.mu(p_lo.x) - engine.mu(p_hi.x))


def _bifurcation(engine, kind, pt, index, width, reason, eigvec=None):
    prob = engine.prob
    gait = prob.gait(pt.x[:-1], engine.mu(pt.x), pt.ev, pt.mult)
    return Bifurcation(kind=kind, value=engine.value(pt.x), gait=gait, index=index,
                       tolerance=width, reason=reason, z=pt.x[:-1].copy(),
                       mu=engine.mu(pt.x), tangent=pt.tangent.copy(), eigenvector=eigvec,
                       multipliers=pt.mult.copy(), details={"orbit": pt.ev.info["orbit"]})


def check_crossings(engine, a, b, index, locate_tol, detect):
    out = []
    for name in a.tests:
        kind = "end" if name.startswith("end:") else name
        if kind not in detect:
            continue
        fa = a.tests[name]
        fb = b.tests.get(name, fa)
        if kind == "end":
            crossed = fa > 0.0 >= fb
        else:
            crossed = np.sign(fa) != np.sign(fb) and fa != 0.0
        if not crossed:
            continue
        pt, width = locate(engine, a, b, name, locate_tol)
        if kind == "end":
            adm = name[4:]
            out.append(_bifurcation(engine, "end", pt, index, width,
                                    "%s -> 0: %s" % (adm, engine.prob.ADMISSIBLE.get(adm, adm))))
            continue
        m = pt.mult
        if kind == "period_doubling":
            j = int(np.argmin(np.abs(m + 1.0)))
            w, V = np.linalg.eig(pt.ev.M)
            v = np.real(V[:, int(np.argmin(np.abs(w - m[j])))])
            out.append(_bifurcation(engine, kind, pt, index, width,
                                    "a multiplier through -1 (%.6g)" % np.real(m[j]),
                                    v / np.linalg.norm(v)))
        elif kind == "neimark_sacker":
            cx = [v for v in m if abs(v.imag) > 1e-8 and abs(abs(v) - 1.0) < 1e-3]
            if cx:
                out.append(_bifurcation(engine, kind, pt, index, width,
                                        "a complex pair through the unit circle (|mu| = %.6g, "
                                        "arg %.4g rad)" % (abs(cx[0]), abs(np.angle(cx[0])))))
        else:
            out.append(_bifurcation(engine, "fold", pt, index, width,
                                    "turning point: the branch reverses in %s" % (
                                        engine.prob.parameter)))
    return out
