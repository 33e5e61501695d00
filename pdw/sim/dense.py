"""Dense output of `pdw.simulate`: a piecewise Hermite interpolant between accepted steps.

Every method records its state at every accepted step (``record_every=1``), and the flags
recorded at step n are the ones in force on [t_n, t_{n+1}] (the loops update the discrete
state at a step's start, and adaptive ones end a step at each located flag switch). On that
interval the solution of x' = f(x; flags_n, anchors_n) (Eq. A.4) is interpolated from the
recorded end points and their derivatives under the interval's discrete state:

- methods of order >= 4 (``rk4``, ``dopri5``, ``rodas4``): quintic Hermite from x, f(x) and
  x'' = (df/dx) f at both ends, interpolation error O(h^6) per step, above the methods' order;
- methods of order <= 2 (``cdm``, ``verlet``): cubic Hermite from x and f(x), O(h^4).

The state is the run's, nx entries (8; 10 with LuGre's bristle states z1, z2, whose f is the
LuGre kernel's). x'' comes from the symbolic Jacobian where the kernel has one (the Coulomb
law's kernels); with LuGre's kernels (a finite-difference Jacobian, 21 right-hand sides) x'' is
a fourth-order difference of f along f with a step proportional to h (`DenseOutput._along`,
4 right-hand sides, independent of a Jacobian's step across |v|'s kink): still O(h^6). The loops reset a foot's z to 0 at its
touch-down before recording that step, so the recorded sample starts the next interval; the
interval before it ends at the swing value of z (`_left_limits`).

The interpolant passes through the recorded states exactly, is C^1 inside each smooth stretch,
and its error between steps converges with the method's order (tests/sim/test_dense_output.py,
tests/sim/test_lugre_dense.py).
The anchors (docs/model.md section 6, ``pdw.core._layout.ANCHORS``) are not recorded; they are
rebuilt from the touch-downs as the loops set them: the rolling coordinate s_i and the approach
speed max(-v_y, 0) of foot i at the step where flag i became 1 (or at the start, for a foot
that starts in support). The approach speeds are the discrete values of the Lankarani-Nikravesh
and Flores laws (docs/contact_laws.md): the interpolant's f(x) uses the values of the run.
"""
from __future__ import annotations

import numpy as np

from ..core import _core, _layout, checks
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.model import contact_forces, kernel_index, parameter_vector


def _anchors(x, flags, params, variant):
    """Anchors in force at each recorded step, shape (N, 4): s0_1, s0_2 [m], v_in1, v_in2 [m/s]
    (``pdw.core._layout.ANCHORS``)."""
    # s and v_y use no anchors and no bristle states
    cs = contact_forces(x[:, :_core.NX], params, flags=(0, 0), variant=variant)
    s, vin = np.atleast_2d(cs.s), np.maximum(-np.atleast_2d(cs.v_y), 0.0)
    a = np.zeros((len(x), len(_layout.ANCHORS)))
    for i in range(2):
        f = flags[:, i]
        down = f.astype(bool) & np.r_[True, f[:-1] == 0]          # touch-downs (and start)
        last = np.maximum.accumulate(np.where(down, np.arange(len(x)), -1))
        ok = last >= 0
        a[ok, _layout.ANCHORS.index("s0_%d" % (i + 1))] = s[last[ok], i]
        a[ok, _layout.ANCHORS.index("v_in%d" % (i + 1))] = vin[last[ok], i]
    return a


#: Steps of the finite difference for x'' per interval length (`DenseOutput._along`).
EPS_PER_STEP = 8.0


def _left_limits(x, flags):
    """The states at the right ends of the intervals, x(t_{n+1}^-), shape (N - 1, nx): the
    recorded x_{n+1}, except a bristle state reset at a touch-down. The loops reset z_i to 0 at
    foot i's touch-down before recording the step, so the recorded x_{n+1} starts the next
    interval; on [t_n, t_{n+1}] foot i was in swing (flag 0), where dz_i/dt = 0 exactly, so its
    z_i there is x_n's."""
    x1 = x[1:].copy()
    for i in range(x.shape[1] - _core.NX):
        down = (flags[:-1, i] == 0) & (flags[1:, i] == 1)
        x1[down, _core.NX + i] = x[:-1][down, _core.NX + i]
    return x1


class DenseOutput:
    """Piecewise Hermite interpolant of a recorded run; ``sol(t)`` -> (nx,) or (len(t), nx).

    Attributes ``t`` (N,), ``x`` (N, nx), ``flags`` (N, 2), ``anchors`` (N, 4) (layout
    ``pdw.core._layout.ANCHORS``) are the recorded steps; ``nx`` the width of the run's state
    (8, or 10 with LuGre's bristle states: `pdw.Contact.nx`); ``order`` is 3 (cubic) or 5
    (quintic); ``contact`` the run's `pdw.Contact` (its normal and friction laws' f is
    interpolated).
    """

    _x1 = None          # the right ends' states where they differ from x[1:] (`_left_limits`)

    def __init__(self, t, x, flags, params, variant, features, order, contact=None):
        self.t = np.ascontiguousarray(t, dtype=float)
        self.x = np.ascontiguousarray(x, dtype=float)
        self.flags = np.ascontiguousarray(flags, dtype=np.intc)
        if len(self.t) < 2:
            raise InvalidInputError("dense output needs at least two recorded steps")
        self.order = order
        self.anchors = _anchors(self.x, self.flags, params, variant)
        self.contact = Contact.coerce(contact)
        k = kernel_index(variant, features, self.contact.normal, self.contact.friction)
        p = self.contact.vector(parameter_vector(params), features, params)
        nx = self.nx = _core.kernel_nx(k)
        if self.x.ndim != 2 or self.x.shape[1] != nx:
            raise InvalidInputError("dense output of the %s friction law needs states of %d "
                                    "entries, got shape %s" % (self.contact.friction, nx,
                                                               self.x.shape))
        fl = np.ascontiguousarray(self.flags[:-1])
        an = np.ascontiguousarray(self.anchors[:-1])
        n = len(self.t) - 1
        self._fl, self._an, self._k, self._p = fl, an, k, p
        if nx > _core.NX:
            self._x1 = _left_limits(self.x, self.flags)
        ends = []
        for xs in (np.ascontiguousarray(self.x[:-1]),
                   np.ascontiguousarray(self.x[1:] if self._x1 is None else self._x1)):
            f = np.empty((n, nx))
            _core.rhs_batch(k, xs, p, fl, an, f, np.empty((n, _core.NWORK)))
            a = None
            if order == 5 and nx == _core.NX:       # the symbolic Jacobian
                J = np.empty((n, nx * nx))
                _core.jacobian_batch(k, xs, p, fl, an, J, np.empty((n, _core.NWORK)))
                a = np.einsum("nij,nj->ni", J.reshape(n, nx, nx), f)
            elif order == 5:                        # a finite-difference Jacobian: see _along
                a = self._along(xs, f)
            ends.append((f, a))
        (self.f0, self.a0), (self.f1, self.a1) = ends

    def _along(self, xs, f):
        """x'' = (df/dx) f at the states xs (n, nx) with f = f(xs), as the fourth-order central
        difference of f along f, step e = h_n / EPS_PER_STEP on interval n:
        [8 (f(x + e f) - f(x - e f)) - (f(x + 2e f) - f(x - 2e f))] / (12 e).
        Its error, O(e^4) + O(eps |f| / e), enters the quintic times h^2: O(h^6) + O(h eps),
        so the interpolant stays sixth order. The kernels without a symbolic Jacobian (LuGre's)
        have a central difference with a fixed step, cbrt(eps) max(1, |x_j|): that step is
        larger than a creeping foot's slip velocity, whose |v| has a kink at 0, and a Jacobian
        error that does not fall with h makes the quintic second order (tests/sim/test_lugre_dense.py
        measures both). Four right-hand sides per state instead of that Jacobian's 21."""
        h = np.diff(self.t)
        e = np.where(h > 0, h, 1.0)[:, None] / EPS_PER_STEP
        n = len(xs)
        work = np.empty((n, _core.NWORK))

        def f_at(y):
            out = np.empty_like(y)
            _core.rhs_batch(self._k, np.ascontiguousarray(y), self._p, self._fl, self._an, out,
                            work)
            return out

        a = (8.0 * (f_at(xs + e * f) - f_at(xs - e * f))
             - (f_at(xs + 2.0 * e * f) - f_at(xs - 2.0 * e * f))) / (12.0 * e)
        a[h <= 0] = 0.0                     # a step of length 0 is never interpolated
        return a

    def interval(self, tq):
        """Index n of the step [t_n, t_{n+1}] holding each time (right-continuous)."""
        i = np.searchsorted(self.t, tq, side="right") - 1
        return np.clip(i, 0, len(self.t) - 2)

    def _times(self, tq):
        """tq as a 0-d or 1-d float array of real times (no strings, complex, booleans)."""
        return checks.real_array("t", tq, [(), (-1,)])

    def __call__(self, tq):
        """The interpolated state at time(s) tq [s] (scalar or 1-D, within the span): (nx,) or
        (len(tq), nx)."""
        tq = self._times(tq)
        scalar = tq.ndim == 0
        tq = np.atleast_1d(tq)
        if np.any(tq < self.t[0]) or np.any(tq > self.t[-1]) or not np.isfinite(tq).all():
            raise InvalidInputError("t must lie in the recorded span [%g, %g] s"
                                    % (self.t[0], self.t[-1]))
        i = self.interval(tq)
        h = self.t[i + 1] - self.t[i]
        safe = np.where(h > 0, h, 1.0)
        th = np.where(h > 0, (tq - self.t[i]) / safe, 0.0)[:, None]
        hh = h[:, None]
        y0, y1 = self.x[i], self.x[i + 1] if self._x1 is None else self._x1[i]
        if self.order == 3:
            out = ((2 * th**3 - 3 * th**2 + 1) * y0 + (th**3 - 2 * th**2 + th) * hh * self.f0[i]
                   + (-2 * th**3 + 3 * th**2) * y1 + (th**3 - th**2) * hh * self.f1[i])
        else:
            t2, t3, t4, t5 = th**2, th**3, th**4, th**5
            out = ((1 - 10 * t3 + 15 * t4 - 6 * t5) * y0
                   + (th - 6 * t3 + 8 * t4 - 3 * t5) * hh * self.f0[i]
                   + 0.5 * (t2 - 3 * t3 + 3 * t4 - t5) * hh**2 * self.a0[i]
                   + 0.5 * (t3 - 2 * t4 + t5) * hh**2 * self.a1[i]
                   + (-4 * t3 + 7 * t4 - 3 * t5) * hh * self.f1[i]
                   + (10 * t3 - 15 * t4 + 6 * t5) * y1)
        out[th[:, 0] == 0.0] = y0[th[:, 0] == 0.0]          # exactly the recorded steps
        return out[0] if scalar else out

    def flags_at(self, tq):
        """Support flags in force at each time, shape (len(t), 2)."""
        return self.flags[self.interval(np.atleast_1d(self._times(tq)))]

    def anchors_at(self, tq):
        return self.anchors[self.interval(np.atleast_1d(self._times(tq)))]


def check_t_eval(t_eval, t_end):
    """t_eval as a sorted 1-D array in [0, t_end] [s], or InvalidInputError."""
    if isinstance(t_eval, (str, bytes)):
        raise InvalidInputError("t_eval must be a non-empty 1-D array of times [s], got shape ()")
    try:
        te = np.asarray(t_eval)
    except (TypeError, ValueError):
        raise InvalidInputError("t_eval must be a 1-D array of times [s], got %r"
                                % (t_eval,)) from None
    if te.dtype.kind not in "iuf":
        raise InvalidInputError("t_eval must hold real times [s] (not %s)" % te.dtype)
    te = te.astype(float)
    if te.ndim != 1 or len(te) == 0:
        raise InvalidInputError("t_eval must be a non-empty 1-D array of times [s], got shape %s"
                                % (te.shape,))
    if not np.isfinite(te).all() or te[0] < 0 or te[-1] > t_end or np.any(np.diff(te) < 0):
        raise InvalidInputError("t_eval must be finite, non-decreasing and within [0, t_end = %g] s"
                                % t_end)
    return te


def resample(res, sol, t_eval, params, variant):
    """Replace the Result's records (t, x, flags, Fn, Ft) by their values at t_eval (those up to
    the run's last recorded time); the steps stay in ``res.sol``."""
    te = t_eval[t_eval <= sol.t[-1]]
    x = sol(te) if len(te) else np.zeros((0, sol.nx))
    fl = sol.flags_at(te) if len(te) else np.zeros((0, 2), dtype=np.intc)
    res.t, res.x, res.flags = te, x, fl
    if len(res.Fn):
        Fn = np.zeros((len(te), 2))
        Ft = np.zeros((len(te), 2))
        an = sol.anchors_at(te) if len(te) else np.zeros((0, len(_layout.ANCHORS)))
        for f in np.unique(fl, axis=0):
            m = np.all(fl == f, axis=1)
            for a in np.unique(an[m], axis=0):
                mm = m & np.all(an == a, axis=1)
                c = contact_forces(x[mm], params, flags=tuple(int(v) for v in f),
                                   anchors=tuple(a), variant=variant, features=None,
                                   contact=sol.contact)
                Fn[mm], Ft[mm] = np.atleast_2d(c.F_n), np.atleast_2d(c.F_t)
        res.Fn, res.Ft = Fn, Ft
    return res


def attach(res, t_eval, dense_output, params, variant, features, order, record_energies,
           contact=None):
    """Give a Result its dense output (``res.sol``) and, with t_eval, its samples there."""
    sol = DenseOutput(res.t, res.x, res.flags, params, variant, features,
                      3 if order <= 3 else 5, contact)
    if t_eval is not None:
        resample(res, sol, t_eval, params, variant)
        if record_energies:
            from ..core.model import energies
            e = energies(res.x[:, :_core.NX], params) if len(res.x) else {}   # q, qd only
            res.energies = {k: np.atleast_1d(v) for k, v in e.items()}
    if dense_output:
        res.sol = sol
    return res
