# cython: language_level=3
"""Thin Cython layer over the hybrid walker (generated/pdw_hybrid.c, pdw/core/csrc/pdw_hybrid_sim.c).

Private: the public API is `pdw.hybrid`. Parameter vectors are the full model's ``p``
(`pdw.core.model.parameter_vector`); reduced states are y = [theta_st, theta_sw, thetad_st,
thetad_sw]. The stance-phase integration, heel-strike location and impact run in C with the
GIL released.
"""
import numpy as np

from cpython.exc cimport PyErr_CheckSignals
from libc.string cimport memset

from pdw.core import interrupt as _interrupt


cdef extern from "pdw_hybrid.h":
    enum:
        PDW_NX, PDW_NP, PDW_NHY, PDW_NHYFOOT, PDW_NENERGY
    void pdw_hybrid_stance(const double *y, const double *p, double *Mr, double *fr) noexcept nogil
    int pdw_hybrid_rhs(const double *y, const double *p, double *ydot) noexcept nogil
    void pdw_hybrid_ground_force(const double *y, const double *ydd, const double *p,
                                 double *F) noexcept nogil
    void pdw_hybrid_swing_foot(const double *y, const double *p, double *foot) noexcept nogil
    void pdw_hybrid_energies(const double *y, const double *p, double *e) noexcept nogil
    void pdw_hybrid_full_state(const double *y, const double *p, double *x) noexcept nogil
    void pdw_hybrid_impact_terms(const double *q, const double *p, double *MJ) noexcept nogil


cdef extern from "pdw_hybrid_sim.h":
    ctypedef struct pdw_hybrid_opts:
        double rtol, atol, h0, h_max, t_max, event_tol, min_step_angle, fall_angle
        long max_steps
        double dt_out
        int (*poll)(void *ctx) noexcept nogil
        void *poll_ctx
        double dh
        int (*ground)(const void *ctx, double s, double *h, double *slope) noexcept nogil
        const void *ground_ctx
        double max_slope
    ctypedef struct pdw_hybrid_result:
        int status
        double t0, s0
        double y0[4]
        double t_strike
        double y_minus[4]
        double y_plus[4]
        double qd_minus[4]
        double qd_plus[4]
        double impulse[2]
        double v_old[2]
        int old_foot_down
        double vy_strike, T_minus, T_plus, x_touch, step_length, s0_next, E0, dE_max
        double Fn_min, ratio_max
        long n_steps, n_rejected, n_rhs, n_rec
        int rec_full
        double h_st, h_touch
    void pdw_hybrid_default_opts(pdw_hybrid_opts *o) noexcept nogil
    int pdw_hybrid_impact(const double *p, const double *y_minus, pdw_hybrid_result *r) noexcept nogil
    int pdw_hybrid_step(const double *p, const double *y0, double t0, double s0,
                        const pdw_hybrid_opts *o, pdw_hybrid_result *r,
                        double *rec_t, double *rec_y, long rec_cap) noexcept nogil
    long pdw_hybrid_walk(const double *p, const double *y0, double s0, long n_steps,
                         const pdw_hybrid_opts *o, pdw_hybrid_result *results,
                         double *rec_t, double *rec_y, long *rec_step, long rec_cap) noexcept nogil
    int pdw_hybrid_solve(int n, double *A, double *b, double *x) noexcept nogil
    int pdw_hybrid_rhs_jac(const double *y, const double *p, double *ydot, double *A) noexcept nogil
    int pdw_hybrid_impact_jac(const double *p, const double *ym, double *D) noexcept nogil
    int pdw_hybrid_step_jac(const double *p, const double *y0, const pdw_hybrid_opts *o,
                            pdw_hybrid_result *r, double *DP) noexcept nogil
    void pdw_hybrid_swing_foot_grad(const double *y, const double *p, double *g) noexcept nogil
    int pdw_hybrid_step_sens(const double *p, const double *y0, const pdw_hybrid_opts *o,
                             pdw_hybrid_result *r, double *DP, double *dym_dy0, double *dym_ddh,
                             double *dT_dy0, double *dT_ddh) noexcept nogil
    long pdw_hybrid_walk_dh(const double *p, const double *y0, long n_steps,
                            const double *dh_seq, const pdw_hybrid_opts *o, double *y_out,
                            double *t_out, int *status) noexcept nogil


cdef extern from "pdw_ground.h":
    ctypedef struct pdw_ground:
        double s_min, s_max
        long n_cells
        const double *cells
        const double *arc
        long n_lut
        double lut_inv
        const long *lut
        int n_patches, n_fields
        const int *fields
        const double *patches
        double blend
        int n_zones
        const double *zones
    void pdw_ground_eval(const pdw_ground *g, double s, double *out) noexcept nogil
    int pdw_ground_inside(const pdw_ground *g, double s) noexcept nogil


cdef int _ground_h(const void *ctx, double s, double *h, double *slope) noexcept nogil:
    """The hybrid loop's ground hook over a compiled pdw.Ground (pdw_ground.h)."""
    cdef double out[3]
    cdef const pdw_ground *g = <const pdw_ground *> ctx
    pdw_ground_eval(g, s, out)
    h[0] = out[0]
    if slope != NULL:
        slope[0] = out[1]
    return 0 if pdw_ground_inside(g, s) else 1


cdef class GroundRef:
    """A `pdw.core.ground_table.GroundTable`'s height cells as the C struct the hybrid loop
    reads (its arrays kept alive here; patches are not used: the hybrid ground is rigid)."""
    cdef pdw_ground g
    cdef object keep

    def __cinit__(self, table):
        cells = np.ascontiguousarray(table.cells, dtype=np.float64)
        lut = np.ascontiguousarray(table.lut, dtype=np.int_)
        if cells.ndim != 2 or cells.shape[0] < 1 or lut.shape[0] < 1:
            raise ValueError("a ground table needs at least one cell and one lookup bin")
        self.keep = (cells, lut)
        cdef double[:, ::1] vc = cells
        cdef long[::1] vl = lut
        memset(&self.g, 0, sizeof(self.g))
        self.g.s_min = table.s_min
        self.g.s_max = table.s_max
        self.g.n_cells = cells.shape[0]
        self.g.cells = &vc[0, 0]
        self.g.n_lut = lut.shape[0]
        self.g.lut_inv = table.lut_inv
        self.g.lut = &vl[0]

    def h(self, double s):
        """(h, dh/ds, inside) at s, through the hook the loop calls."""
        cdef double hh = 0.0, sl = 0.0
        cdef int off = _ground_h(&self.g, s, &hh, &sl)
        return hh, sl, not off


NY = PDW_NHY
NFOOT = PDW_NHYFOOT
STATUS = ("ok", "no_strike", "fell", "singular", "nonfinite", "max_steps", "step_tiny",
          "interrupted", "tripped", "off_ground")
cdef int _INTERRUPTED = 7


include "_shapes.pxi"


cdef int _py(const double[::1] p, const double[::1] y, str yname="y") except -1:
    _len("p", p.shape[0], PDW_NP)
    _len(yname, y.shape[0], PDW_NHY)
    return 0


OPTION_NAMES = ("rtol", "atol", "h0", "h_max", "t_max", "event_tol", "min_step_angle",
                "fall_angle", "max_steps", "dt_out", "dh", "max_slope")


def default_options():
    """The C defaults of the step map's options, as a dict."""
    cdef pdw_hybrid_opts o
    pdw_hybrid_default_opts(&o)
    return _opts_dict(&o)


cdef dict _opts_dict(pdw_hybrid_opts *o):
    return {"rtol": o.rtol, "atol": o.atol, "h0": o.h0, "h_max": o.h_max, "t_max": o.t_max,
            "event_tol": o.event_tol, "min_step_angle": o.min_step_angle,
            "fall_angle": o.fall_angle, "max_steps": o.max_steps, "dt_out": o.dt_out,
            "dh": o.dh, "max_slope": o.max_slope}


include "_poll.pxi"


cdef object _raised(list pending, partial=None):
    """Re-raise what a poll caught, with the partial result as ``.partial``."""
    if pending:
        exc = pending[0]
        exc.partial = partial
        raise exc


cdef void _fill_opts(pdw_hybrid_opts *o, dict opts, list pending, GroundRef ground=None) except *:
    pdw_hybrid_default_opts(o)
    o.poll = _poll
    o.poll_ctx = <void *> pending
    if ground is not None:
        o.ground = _ground_h
        o.ground_ctx = <const void *> &ground.g
    for k, v in opts.items():
        if k == "rtol": o.rtol = v
        elif k == "atol": o.atol = v
        elif k == "h0": o.h0 = v
        elif k == "h_max": o.h_max = v
        elif k == "t_max": o.t_max = v
        elif k == "event_tol": o.event_tol = v
        elif k == "min_step_angle": o.min_step_angle = v
        elif k == "fall_angle": o.fall_angle = v
        elif k == "max_steps": o.max_steps = v
        elif k == "dt_out": o.dt_out = v
        elif k == "dh": o.dh = v
        elif k == "max_slope": o.max_slope = v
        else:
            raise ValueError("unknown hybrid option %r; allowed: %s" % (k, ", ".join(OPTION_NAMES)))


cdef dict _result_dict(pdw_hybrid_result *r):
    return {
        "status": STATUS[r.status] if 0 <= r.status < len(STATUS) else str(r.status),
        "t0": r.t0, "s0": r.s0, "y0": np.array(<double[:4]> r.y0),
        "t_strike": r.t_strike,
        "y_minus": np.array(<double[:4]> r.y_minus), "y_plus": np.array(<double[:4]> r.y_plus),
        "qd_minus": np.array(<double[:4]> r.qd_minus), "qd_plus": np.array(<double[:4]> r.qd_plus),
        "impulse": np.array(<double[:2]> r.impulse), "v_old": np.array(<double[:2]> r.v_old),
        "old_foot_down": bool(r.old_foot_down), "vy_strike": r.vy_strike,
        "T_minus": r.T_minus, "T_plus": r.T_plus, "x_touch": r.x_touch,
        "step_length": r.step_length, "s0_next": r.s0_next, "E0": r.E0, "dE_max": r.dE_max,
        "Fn_min": r.Fn_min, "ratio_max": r.ratio_max,
        "n_steps": r.n_steps, "n_rejected": r.n_rejected, "n_rhs": r.n_rhs, "n_rec": r.n_rec,
        "rec_full": bool(r.rec_full), "h_st": r.h_st, "h_touch": r.h_touch,
    }


@_named_buffers
def rhs(const double[::1] p, const double[::1] y):
    """dy/dt of the stance phase; raises on a singular reduced mass matrix."""
    _py(p, y)
    out = np.empty(PDW_NHY)
    cdef double[::1] v = out
    if pdw_hybrid_rhs(&y[0], &p[0], &v[0]):
        raise ArithmeticError("singular reduced mass matrix at y = %r" % (np.asarray(y),))
    return out


@_named_buffers
def stance_terms(const double[::1] p, const double[::1] y):
    """(M_r (2, 2), f_r (2,)) of M_r phidd = f_r."""
    _py(p, y)
    Mr = np.empty(4)
    fr = np.empty(2)
    cdef double[::1] vm = Mr, vf = fr
    pdw_hybrid_stance(&y[0], &p[0], &vm[0], &vf[0])
    return Mr.reshape(2, 2), fr


@_named_buffers
def ground_force(const double[::1] p, const double[::1] y, const double[::1] ydd):
    """Ground reaction (F_x, F_y) on the stance foot for accelerations ydd (2,)."""
    _py(p, y)
    _len("ydd", ydd.shape[0], 2)
    F = np.empty(2)
    cdef double[::1] v = F
    pdw_hybrid_ground_force(&y[0], &ydd[0], &p[0], &v[0])
    return F


@_named_buffers
def swing_foot(const double[::1] p, const double[::1] y):
    """[y_sw, vy_sw, x_sw, x_st] (stance rolling coordinate 0)."""
    _py(p, y)
    out = np.empty(PDW_NHYFOOT)
    cdef double[::1] v = out
    pdw_hybrid_swing_foot(&y[0], &p[0], &v[0])
    return out


@_named_buffers
def energies(const double[::1] p, const double[::1] y):
    """[T, V_gravity, V_hip] of the stance phase (stance rolling coordinate 0)."""
    _py(p, y)
    out = np.empty(PDW_NENERGY)
    cdef double[::1] v = out
    pdw_hybrid_energies(&y[0], &p[0], &v[0])
    return out


@_named_buffers
def full_state_batch(const double[::1] p, const double[:, ::1] y, double[:, ::1] x):
    """Full-model states x (N, 8) of reduced states y (N, 4): stance leg = leg 1, s0 = 0."""
    cdef Py_ssize_t i, n = y.shape[0]
    _len("p", p.shape[0], PDW_NP)
    _rows("y", n, y.shape[1], n, PDW_NHY)
    _rows("x", x.shape[0], x.shape[1], n, PDW_NX)
    with nogil:
        for i in range(n):
            pdw_hybrid_full_state(&y[i, 0], &p[0], &x[i, 0])


@_named_buffers
def impact_terms(const double[::1] p, const double[::1] q):
    """M(q) (4, 4) and the material-point Jacobians J (2 feet, 2, 4)."""
    _len("p", p.shape[0], PDW_NP)
    if q.shape[0] != 4 and q.shape[0] != PDW_NX:
        raise ValueError("q must have shape (4,) or (%d,), got (%d,)" % (PDW_NX, q.shape[0]))
    out = np.empty(32)
    cdef double[::1] v = out
    pdw_hybrid_impact_terms(&q[0], &p[0], &v[0])
    return out[:16].reshape(4, 4), out[16:].reshape(2, 2, 4)


@_named_buffers
def impact(const double[::1] p, const double[::1] y_minus):
    """The impact map at a pre-impact state; a dict (see pdw_hybrid_result)."""
    _py(p, y_minus, "y_minus")
    cdef pdw_hybrid_result r
    memset(&r, 0, sizeof(r))
    r.status = pdw_hybrid_impact(&p[0], &y_minus[0], &r)
    return _result_dict(&r)


@_named_buffers
def solve(double[:, ::1] A, double[::1] b):
    """x of A x = b by the C Gaussian elimination (A, b overwritten); for tests."""
    if not 1 <= A.shape[0] <= 8:
        raise ValueError("A must have 1 to 8 rows, got %d" % A.shape[0])
    cdef int n = A.shape[0]
    _rows("A", A.shape[0], A.shape[1], n, n)
    _len("b", b.shape[0], n)
    x = np.empty(n)
    cdef double[::1] vx = x
    if pdw_hybrid_solve(n, &A[0, 0], &b[0], &vx[0]):
        raise ArithmeticError("singular matrix")
    return x


@_named_buffers
def step(const double[::1] p, const double[::1] y0, dict opts, double t0=0.0, double s0=0.0,
         long rec_cap=0, GroundRef ground=None):
    """One step of the hybrid map (on ``ground`` if given). Returns (result dict, rec_t,
    rec_y)."""
    cdef pdw_hybrid_opts o
    cdef pdw_hybrid_result r
    _py(p, y0, "y0")
    _count("rec_cap", rec_cap, 0)
    cdef list pending = []
    _fill_opts(&o, opts, pending, ground)
    rec_t = _zeros("the record (rec_cap)", max(rec_cap, 1))
    rec_y = _zeros("the record (rec_cap)", (max(rec_cap, 1), PDW_NHY))
    cdef double[::1] vt = rec_t
    cdef double[:, ::1] vy = rec_y
    with nogil:
        pdw_hybrid_step(&p[0], &y0[0], t0, s0, &o, &r, &vt[0], &vy[0, 0], rec_cap)
    d = _result_dict(&r)
    _raised(pending, (d, rec_t[:r.n_rec], rec_y[:r.n_rec]))
    return d, rec_t[:r.n_rec], rec_y[:r.n_rec]


@_named_buffers
def step_batch(const double[::1] p, const double[:, ::1] y0, dict opts, double[:, ::1] y_plus,
               int[::1] status):
    """The step map of each row of y0 (N, 4) into y_plus (N, 4); status (N,) per row."""
    cdef pdw_hybrid_opts o
    cdef pdw_hybrid_result r
    cdef Py_ssize_t i, j, n = y0.shape[0]
    _len("p", p.shape[0], PDW_NP)
    _rows("y0", n, y0.shape[1], n, PDW_NHY)
    _rows("y_plus", y_plus.shape[0], y_plus.shape[1], n, PDW_NHY)
    _len("status", status.shape[0], n)
    cdef list pending = []
    _fill_opts(&o, opts, pending)
    with nogil:
        for i in range(n):
            pdw_hybrid_step(&p[0], &y0[i, 0], 0.0, 0.0, &o, &r, NULL, NULL, 0)
            status[i] = r.status
            for j in range(PDW_NHY):
                y_plus[i, j] = r.y_plus[j]
            if r.status == _INTERRUPTED:
                break
    _raised(pending)


@_named_buffers
def walk(const double[::1] p, const double[::1] y0, double s0, long n_steps, dict opts,
         long rec_cap, GroundRef ground=None):
    """n_steps steps (on ``ground`` if given); returns (list of result dicts, rec_t, rec_y,
    rec_step)."""
    cdef pdw_hybrid_opts o
    _py(p, y0, "y0")
    # both counts checked before a size is computed from them: n_steps * sizeof(...) cannot
    # wrap (MAX_COUNT * sizeof < 2**63), and an allocation that cannot be made is a MemoryError
    _count("n_steps", n_steps, 1)
    _count("rec_cap", rec_cap, 0)
    cdef list pending = []
    _fill_opts(&o, opts, pending, ground)
    results = _zeros("the step results of %d steps (n_steps)" % n_steps,
                     n_steps * <long>sizeof(pdw_hybrid_result), np.uint8)
    cdef unsigned char[::1] vr = results
    cdef pdw_hybrid_result *res = <pdw_hybrid_result *> &vr[0]
    rec_t = _zeros("the record (rec_cap)", max(rec_cap, 1))
    rec_y = _zeros("the record (rec_cap)", (max(rec_cap, 1), PDW_NHY))
    rec_step = _zeros("the record (rec_cap)", max(rec_cap, 1), np.int_)
    cdef double[::1] vt = rec_t
    cdef double[:, ::1] vy = rec_y
    cdef long[::1] vs = rec_step
    cdef long done, k, n_rec = 0
    with nogil:
        done = pdw_hybrid_walk(&p[0], &y0[0], s0, n_steps, &o, res, &vt[0], &vy[0, 0],
                               &vs[0], rec_cap)
    out = []
    for k in range(min(done + 1, n_steps)):
        out.append(_result_dict(&res[k]))
        n_rec += res[k].n_rec
    _raised(pending, (out, rec_t[:n_rec], rec_y[:n_rec], rec_step[:n_rec]))
    return out, rec_t[:n_rec], rec_y[:n_rec], rec_step[:n_rec]


@_named_buffers
def rhs_jac(const double[::1] p, const double[::1] y):
    """(ydot (4,), A = d ydot / d y (4, 4)) of the stance phase (symbolic Jacobian)."""
    _py(p, y)
    yd = np.empty(PDW_NHY)
    A = np.empty((PDW_NHY, PDW_NHY))
    cdef double[::1] vy = yd
    cdef double[:, ::1] vA = A
    if pdw_hybrid_rhs_jac(&y[0], &p[0], &vy[0], &vA[0, 0]):
        raise ArithmeticError("singular reduced mass matrix at y = %r" % (np.asarray(y),))
    return yd, A


@_named_buffers
def swing_foot_grad(const double[::1] p, const double[::1] y):
    """d y_sw / d y (4,)."""
    _py(p, y)
    g = np.empty(PDW_NHY)
    cdef double[::1] v = g
    pdw_hybrid_swing_foot_grad(&y[0], &p[0], &v[0])
    return g


@_named_buffers
def impact_jac(const double[::1] p, const double[::1] y_minus):
    """d y+ / d y- (4, 4) of the impact-and-relabel map."""
    _py(p, y_minus, "y_minus")
    D = np.empty((PDW_NHY, PDW_NHY))
    cdef double[:, ::1] v = D
    if pdw_hybrid_impact_jac(&p[0], &y_minus[0], &v[0, 0]):
        raise ArithmeticError("singular impact system at y- = %r" % (np.asarray(y_minus),))
    return D


@_named_buffers
def step_jac_batch(const double[::1] p, const double[:, ::1] y0, dict opts,
                   double[:, ::1] y_plus, double[:, :, ::1] DP, int[::1] status):
    """The step map of each row of y0 (N, 4) and its exact Jacobian DP (N, 4, 4)."""
    cdef pdw_hybrid_opts o
    cdef pdw_hybrid_result r
    cdef Py_ssize_t i, j, n = y0.shape[0]
    _len("p", p.shape[0], PDW_NP)
    _rows("y0", n, y0.shape[1], n, PDW_NHY)
    _rows("y_plus", y_plus.shape[0], y_plus.shape[1], n, PDW_NHY)
    _len("status", status.shape[0], n)
    if DP.shape[0] != n or DP.shape[1] != PDW_NHY or DP.shape[2] != PDW_NHY:
        raise ValueError("DP must have shape (%d, %d, %d), got (%d, %d, %d)"
                         % (n, PDW_NHY, PDW_NHY, DP.shape[0], DP.shape[1], DP.shape[2]))
    cdef list pending = []
    _fill_opts(&o, opts, pending)
    with nogil:
        for i in range(n):
            status[i] = pdw_hybrid_step_jac(&p[0], &y0[i, 0], &o, &r, &DP[i, 0, 0])
            for j in range(PDW_NHY):
                y_plus[i, j] = r.y_plus[j]
            if status[i] == _INTERRUPTED:
                break
    _raised(pending)


@_named_buffers
def step_jac(const double[::1] p, const double[::1] y0, dict opts):
    """One step and its exact Jacobian: (result dict, DP (4, 4)); DP is NaN unless ok."""
    cdef pdw_hybrid_opts o
    cdef pdw_hybrid_result r
    cdef int st
    _py(p, y0, "y0")
    cdef list pending = []
    _fill_opts(&o, opts, pending)
    DP = np.full((PDW_NHY, PDW_NHY), np.nan)
    cdef double[:, ::1] v = DP
    with nogil:
        st = pdw_hybrid_step_jac(&p[0], &y0[0], &o, &r, &v[0, 0])
    _raised(pending)
    d = _result_dict(&r)
    if st != 0:
        d["status"] = STATUS[st] if 0 <= st < len(STATUS) else str(st)
        DP[:] = np.nan
    return d, DP


@_named_buffers
def step_sens(const double[::1] p, const double[::1] y0, dict opts):
    """One step, its Jacobian and its sensitivities to the floor offset ``dh``: (result dict,
    DP (4, 4), dym_dy0 (4, 4), dym_ddh (4,), dT_dy0 (4,), dT_ddh); NaN unless ok."""
    cdef pdw_hybrid_opts o
    cdef pdw_hybrid_result r
    cdef int st
    cdef double tdh = np.nan
    _py(p, y0, "y0")
    cdef list pending = []
    _fill_opts(&o, opts, pending)
    DP = np.full((PDW_NHY, PDW_NHY), np.nan)
    Ym = np.full((PDW_NHY, PDW_NHY), np.nan)
    ydh = np.full(PDW_NHY, np.nan)
    Tg = np.full(PDW_NHY, np.nan)
    cdef double[:, ::1] v = DP, vm = Ym
    cdef double[::1] vd = ydh, vt = Tg
    with nogil:
        st = pdw_hybrid_step_sens(&p[0], &y0[0], &o, &r, &v[0, 0], &vm[0, 0], &vd[0], &vt[0],
                                  &tdh)
    _raised(pending)
    d = _result_dict(&r)
    if st != 0:
        d["status"] = STATUS[st] if 0 <= st < len(STATUS) else str(st)
        for a in (DP, Ym, ydh, Tg):
            a[...] = np.nan
        tdh = np.nan
    return d, DP, Ym, ydh, Tg, tdh


@_named_buffers
def walk_dh_batch(const double[::1] p, const double[:, ::1] y0, const double[:, ::1] dh,
                  dict opts, long[::1] n_done, int[::1] status, double[:, ::1] y_last,
                  double[::1] t_sum, list grounds=None):
    """Walker i walks from y0[i] with the floor offsets dh[i, :] (one per step) until a step
    fails or the row ends: n_done[i] completed steps, status[i] (0: none failed), y_last[i]
    the state after its last completed step (y0[i] if none), t_sum[i] their duration [s]."""
    cdef pdw_hybrid_opts o
    cdef Py_ssize_t i, j, n = y0.shape[0], K = dh.shape[1]
    _len("p", p.shape[0], PDW_NP)
    _rows("y0", n, y0.shape[1], n, PDW_NHY)
    _rows("dh", dh.shape[0], K, n, K)
    _rows("y_last", y_last.shape[0], y_last.shape[1], n, PDW_NHY)
    _len("n_done", n_done.shape[0], n)
    _len("status", status.shape[0], n)
    _len("t_sum", t_sum.shape[0], n)
    if K < 1:
        raise ValueError("dh must have at least one column")
    cdef list pending = []
    _fill_opts(&o, opts, pending)
    if grounds is not None and len(grounds) != n:
        raise ValueError("grounds must list %d GroundRef, got %d" % (n, len(grounds)))
    gbuf = np.zeros(max(n, 1), dtype=np.uintp)
    cdef size_t[::1] vg = gbuf
    cdef GroundRef gr
    cdef int has_g = grounds is not None
    if has_g:
        for i in range(n):
            gr = grounds[i]
            vg[i] = <size_t> &gr.g
    yo = np.empty((K, PDW_NHY))
    to = np.empty(K)
    cdef double[:, ::1] vy = yo
    cdef double[::1] vt = to
    cdef long k, m
    cdef double ts
    with nogil:
        for i in range(n):
            if has_g:
                o.ground = _ground_h
                o.ground_ctx = <const void *> vg[i]
            m = pdw_hybrid_walk_dh(&p[0], &y0[i, 0], K, &dh[i, 0], &o, &vy[0, 0], &vt[0],
                                   &status[i])
            n_done[i] = m
            ts = 0.0
            for k in range(m):
                ts += vt[k]
            t_sum[i] = ts
            for j in range(PDW_NHY):
                y_last[i, j] = vy[m - 1, j] if m > 0 else y0[i, j]
            if status[i] == _INTERRUPTED:
                break
    _raised(pending)
