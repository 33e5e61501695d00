# cython: language_level=3
"""Thin Cython layer over the generated C model and the compiled time loops.

Private: the public API is in `pdw.core.model` and `pdw.sim.simulation`. Every function
takes caller-allocated, C-contiguous float64 arrays (typed memoryviews; no NumPy
C headers). Time loops release the GIL and are entered once per simulation.
"""
import numpy as np

from pdw.core import interrupt as _interrupt
from pdw.core.errors import InvalidInputError

from cpython.exc cimport PyErr_CheckSignals
from libc.math cimport NAN
from libc.string cimport memset, memcpy
from cpython.buffer cimport (PyObject_GetBuffer, PyBuffer_Release, PyBUF_C_CONTIGUOUS,
                            PyBUF_FORMAT)


cdef extern from "pdw_model.h":
    enum:
        PDW_X_Y_O, PDW_X_THETA1, PDW_X_THETA2, PDW_X_XD_O, PDW_X_YD_O, PDW_X_THETAD2
        PDW_NX, PDW_NQ, PDW_NP, PDW_NPARAM, PDW_NKIN, PDW_NCONTACT, PDW_NENERGY, PDW_NWORK
        PDW_NKERNELS, PDW_NEVENT, PDW_NREC
        PDW_WORK_TRIG, PDW_WORK_KIN, PDW_WORK_CONTACT, PDW_WORK_M, PDW_WORK_F, PDW_WORK_QDD
        PDW_STATUS_RUNNING, PDW_STATUS_EVENTS_FULL
        PDW_NSTEP, PDW_STEP_RING, PDW_NANCHOR, PDW_ANCHOR_V_IN1, PDW_ANCHOR_V_IN2
        PDW_NX_MAX, PDW_NTRIG, PDW_NGROUND
        PDW_STATUS_RECORDS_FULL, PDW_STATUS_POLL  # derive/layout.py RESUME
        PDW_RECORD_CHUNK, PDW_RECORD_EXACT_MAX, PDW_POLL_EVERY
    ctypedef struct pdw_kernel:
        const char *name
        int variant
        unsigned features
        void (*kinematics)(const double *x, const double *trig, const double *p,
                           const double *anchors, double *kin) noexcept nogil
        void (*contact)(const double *kin, const int *flags, const double *p,
                        double *contact) noexcept nogil
        void (*contact_partials)(const double *kin, const int *flags, const double *p,
                                 double *contact) noexcept nogil
        void (*dynamics)(const double *x, const double *trig, const double *p,
                         const double *contact, double *M, double *f) noexcept nogil
        void (*cdm_terms)(const double *x, const double *trig, const double *p,
                          const double *contact, double *M, double *C, double *QmG) noexcept nogil
        void (*dynamics_jacobian)(const double *x, const double *trig, const double *p,
                                  const double *contact, const double *qdd, double *A) noexcept nogil
        void (*energies)(const double *x, const double *trig, const double *p,
                         double *e) noexcept nogil
        void (*rhs)(const double *x, const double *p, const int *flags, const double *anchors,
                    double *xdot, double *work) noexcept nogil
        void (*jacobian)(const double *x, const double *p, const int *flags,
                         const double *anchors, double *J, double *work) noexcept nogil
        int normal
        int friction
        int nx
    const pdw_kernel pdw_kernels[]
    void pdw_precompute(const double *params, double *p) noexcept nogil
    void pdw_trig(const double *x, double *trig) noexcept nogil


include "_opts.pxi"
include "_ground.pxi"


cdef extern from "pdw_sim.h":
    ctypedef struct pdw_discrete:
        int flags[2]
        int armed[2]
        double anchors[4]
    ctypedef struct pdw_failure:
        double t
        double x[1]         # PDW_NX_MAX entries; the first pdw_sim.nx are the state
        int leg
        int reason
    ctypedef struct pdw_gait:
        long n_steps
        long n_touch_down, n_lift_off
        double ring[1][1]
    ctypedef struct pdw_sim:
        const pdw_ground *ground
        long poll_every
        const pdw_kernel *kernel
        int nx
        double p[32]
        pdw_run_opts opt
        double *rec_t
        double *rec_x
        int *rec_flags
        double *rec_contact
        long rec_capacity, n_rec
        double *events
        long ev_capacity, n_events
        long n
        double t
        double h
        double x[1]         # PDW_NX_MAX entries; the first nx are the state
        double u_prev[4]
        int started
        pdw_discrete disc
        double work[1]
        long n_rhs, n_jac, n_rejected
        pdw_gait gait
        int status
        int stop_reason
        pdw_failure failure
    ctypedef int (*pdw_advance_fn)(pdw_sim *s) noexcept nogil
    ctypedef struct pdw_method:
        const char *name
        int order
        int adaptive
        pdw_advance_fn advance
    const pdw_method pdw_methods[]
    const int pdw_nmethods
    void pdw_discrete_init(const pdw_kernel *k, const pdw_ground *g, const double *p,
                           const double *x, const int *flags0, pdw_discrete *d,
                           double *work) noexcept nogil
    void pdw_gait_init(pdw_gait *g) noexcept nogil
    void pdw_terrain_rhs(const pdw_kernel *k, const pdw_ground *g, const double *x,
                         const double *p, const int *flags, const double *anchors,
                         double *xdot, double *work) noexcept nogil
    void pdw_terrain_jacobian(const pdw_kernel *k, const pdw_ground *g, const double *x,
                              const double *p, const int *flags, const double *anchors,
                              double *J, double *work) noexcept nogil
    void pdw_terrain_inv_normals(long n, const double *dh, double *inv_n) noexcept nogil
    void pdw_terrain_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                                const double *trig, const double *p, const double *anchors,
                                double *kin, double *gnd, double *cell) noexcept nogil
    void pdw_terrain_flag_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                                     const double *trig, const double *p,
                                     const double *anchors, const int *flags,
                                     double fall_depth, double *kin, double *gnd,
                                     double *cell) noexcept nogil


cdef extern from "pdw_tableaus.h":
    enum:
        PDW_RK_MAXSTAGES, PDW_ROS_MAXSTAGES
    ctypedef struct pdw_rk_tableau:
        const char *name
        int stages, order, embedded_order, fsal
        double c[7]
        double a[7][7]
        double b[7]
        double e[7]
    ctypedef struct pdw_ros_tableau:
        const char *name
        int stages, order, embedded_order
        double gamma
        double a[6][6]
        double C[6][6]
        double m[6]
        double e[6]
    const pdw_rk_tableau pdw_tableau_rk4
    const pdw_rk_tableau pdw_tableau_dopri5
    const pdw_ros_tableau pdw_tableau_rodas4


cdef extern from "pdw_bench.h":
    double pdw_bench_rhs(const pdw_kernel *k, const double *x0, const double *p, const int *flags,
                         const double *anchors, long n, double *work, double *sink) noexcept nogil
    double pdw_bench_jacobian(const pdw_kernel *k, const double *x0, const double *p,
                              const int *flags, const double *anchors, long n, double *work,
                              double *sink) noexcept nogil


NX = PDW_NX            # the mechanical state [q, qd]; a kernel's own size: kernel_nx(k)
NX_MAX = PDW_NX_MAX
NQ = PDW_NQ
NP = PDW_NP
NWORK = PDW_NWORK


def kernel_table():
    """[(name, variant index, feature mask)] in the order of the C table."""
    return [(pdw_kernels[i].name.decode(), pdw_kernels[i].variant, pdw_kernels[i].features)
            for i in range(PDW_NKERNELS)]


def kernel_nx(int k):
    """Size of kernel k's continuous state (layout STATE_LAYOUTS of its friction law)."""
    return _kernel(k).nx


cdef const pdw_kernel *_kernel(int k) except NULL:
    if k < 0 or k >= PDW_NKERNELS:
        raise IndexError("kernel index %d out of range [0, %d)" % (k, PDW_NKERNELS))
    return &pdw_kernels[k]


# --- the boundary: every shape is checked once per call, before a pointer is taken -----------

include "_shapes.pxi"
include "_stepcheck.pxi"


cdef int _flags_ok(const int[:, ::1] flags) except -1:
    cdef Py_ssize_t i, j
    for i in range(flags.shape[0]):
        for j in range(2):
            if flags[i, j] != 0 and flags[i, j] != 1:
                raise ValueError("flags[%d, %d] must be 0 or 1, got %d" % (i, j, flags[i, j]))
    return 0


cdef int _batch(const double[:, ::1] x, const double[::1] p, const int[:, ::1] flags,
                const double[:, ::1] anchors, str out_name, Py_ssize_t out_r, Py_ssize_t out_c,
                Py_ssize_t want_out_c, const double[:, ::1] work, int nx) except -1:
    cdef Py_ssize_t n = x.shape[0]
    _rows("x", n, x.shape[1], n, nx)
    _len("p", p.shape[0], PDW_NP)
    _rows("flags", flags.shape[0], flags.shape[1], n, 2)
    if anchors.shape[0] != n or anchors.shape[1] < 2 or anchors.shape[1] > PDW_NANCHOR:
        raise ValueError("anchors must have shape (%d, 2..%d) (layout ANCHORS), got (%d, %d)"
                         % (n, PDW_NANCHOR, anchors.shape[0], anchors.shape[1]))
    _rows(out_name, out_r, out_c, n, want_out_c)
    _rows("work", work.shape[0], work.shape[1], n, PDW_NWORK)
    _flags_ok(flags)
    return 0


@_named_buffers
def precompute(const double[::1] params, double[::1] p):
    """Fill the kernel parameter vector p (NP,) from the physical parameters (NPARAM,)."""
    _len("params", params.shape[0], PDW_NPARAM)
    _len("p", p.shape[0], PDW_NP)
    pdw_precompute(&params[0], &p[0])


cdef int _anchor_width(const double[:, ::1] anchors) except -1:
    if anchors.shape[1] < 2 or anchors.shape[1] > PDW_NANCHOR:
        raise ValueError("anchors must have 2 to %d columns (layout ANCHORS), got %d"
                         % (PDW_NANCHOR, anchors.shape[1]))
    return anchors.shape[1]


cdef inline void _anchors(const double[:, ::1] anchors, Py_ssize_t i, int na,
                          double *a) noexcept nogil:
    """Row i of anchors, padded with zeros to PDW_NANCHOR (s0 only: no approach speeds)."""
    cdef int j
    for j in range(PDW_NANCHOR):
        a[j] = anchors[i, j] if j < na else 0.0


@_named_buffers
def rhs_batch(int k, const double[:, ::1] x, const double[::1] p, const int[:, ::1] flags,
              const double[:, ::1] anchors, double[:, ::1] xdot, double[:, ::1] work):
    """f(x) (Eq. A.4) for each row; work (N, NWORK) receives every stage's output.

    Shapes (checked): x, xdot (N, NX); p (NP,); flags (N, 2) of 0/1; anchors (N, 2..NANCHOR)
    (s0 only, or s0 and the approach speeds; missing columns are zero)."""
    cdef const pdw_kernel *kern = _kernel(k)
    _batch(x, p, flags, anchors, "xdot", xdot.shape[0], xdot.shape[1], kern.nx, work, kern.nx)
    cdef Py_ssize_t i, n = x.shape[0]
    cdef double a[PDW_NANCHOR]
    cdef int na = _anchor_width(anchors)
    with nogil:
        for i in range(n):
            _anchors(anchors, i, na, a)
            kern.rhs(&x[i, 0], &p[0], &flags[i, 0], a, &xdot[i, 0], &work[i, 0])


@_named_buffers
def jacobian_batch(int k, const double[:, ::1] x, const double[::1] p, const int[:, ::1] flags,
                   const double[:, ::1] anchors, double[:, ::1] J, double[:, ::1] work):
    """df/dx (nx x nx row-major per row of J, shape (N, nx^2), nx = kernel_nx(k)); work as in
    rhs_batch, with partials."""
    cdef const pdw_kernel *kern = _kernel(k)
    _batch(x, p, flags, anchors, "J", J.shape[0], J.shape[1], kern.nx * kern.nx, work, kern.nx)
    cdef Py_ssize_t i, n = x.shape[0]
    cdef double a[PDW_NANCHOR]
    cdef int na = _anchor_width(anchors)
    with nogil:
        for i in range(n):
            _anchors(anchors, i, na, a)
            kern.jacobian(&x[i, 0], &p[0], &flags[i, 0], a, &J[i, 0], &work[i, 0])


@_named_buffers
def contact_batch(int k, const double[:, ::1] kin, const int[:, ::1] flags, const double[::1] p,
                  double[:, ::1] contact, bint partials=False):
    """The contact stage alone: per row, kin (N, 2*NKIN) -> contact (N, 2*NCONTACT) (forces
    only, or with ``partials`` the partial derivatives too); for tests of the force laws."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef Py_ssize_t i, n = kin.shape[0]
    _rows("kin", n, kin.shape[1], n, 2 * PDW_NKIN)
    _rows("flags", flags.shape[0], flags.shape[1], n, 2)
    _rows("contact", contact.shape[0], contact.shape[1], n, 2 * PDW_NCONTACT)
    _len("p", p.shape[0], PDW_NP)
    _flags_ok(flags)
    with nogil:
        for i in range(n):
            if partials:
                kern.contact_partials(&kin[i, 0], &flags[i, 0], &p[0], &contact[i, 0])
            else:
                kern.contact(&kin[i, 0], &flags[i, 0], &p[0], &contact[i, 0])


@_named_buffers
def energies_batch(int k, const double[:, ::1] x, const double[::1] p, double[:, ::1] e):
    """T, V_gravity, V_hip for each row of x (N, kernel_nx(k)) into e (N, NENERGY)."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef Py_ssize_t i, n = x.shape[0]
    _rows("x", n, x.shape[1], n, kern.nx)
    _len("p", p.shape[0], PDW_NP)
    _rows("e", e.shape[0], e.shape[1], n, PDW_NENERGY)
    cdef double trig[4]
    with nogil:
        for i in range(n):
            pdw_trig(&x[i, 0], trig)
            kern.energies(&x[i, 0], trig, &p[0], &e[i, 0])


@_named_buffers
def cdm_terms(int k, const double[::1] x, const double[::1] p, const double[::1] contact,
              double[::1] M, double[::1] C, double[::1] QmG):
    """M, the appendix C matrix and Q_f - G at x for given contact forces (central difference).

    Shapes (checked): x (NX,), p (NP,), contact (2 NCONTACT,), M, C (NQ*NQ,), QmG (NQ,)."""
    cdef const pdw_kernel *kern = _kernel(k)
    _len("x", x.shape[0], PDW_NX)
    _len("p", p.shape[0], PDW_NP)
    _len("contact", contact.shape[0], 2 * PDW_NCONTACT)
    _len("M", M.shape[0], PDW_NQ * PDW_NQ)
    _len("C", C.shape[0], PDW_NQ * PDW_NQ)
    _len("QmG", QmG.shape[0], PDW_NQ)
    cdef double trig[4]
    pdw_trig(&x[0], trig)
    kern.cdm_terms(&x[0], trig, &p[0], &contact[0], &M[0], &C[0], &QmG[0])


@_named_buffers
def bench(int k, str what, const double[::1] x, const double[::1] p, int f1, int f2,
          double a1, double a2, long n):
    """Mean ns per evaluation of `what` ("rhs" or "jacobian") over n calls in a C loop."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef int flags[2]
    cdef double anchors[PDW_NANCHOR]
    cdef double work[PDW_NWORK]
    cdef double sink = 0.0, ns
    if kern.nx != PDW_NX:
        raise ValueError("bench times the kernels of the smooth Coulomb law only")
    _len("x", x.shape[0], PDW_NX)
    _len("p", p.shape[0], PDW_NP)
    _count("n", n, 0)
    if (f1 != 0 and f1 != 1) or (f2 != 0 and f2 != 1):
        raise ValueError("flags must be 0 or 1, got (%d, %d)" % (f1, f2))
    cdef int j
    for j in range(PDW_NANCHOR):
        anchors[j] = 0.0
    flags[0] = f1; flags[1] = f2; anchors[0] = a1; anchors[1] = a2
    if what == "rhs":
        with nogil:
            ns = pdw_bench_rhs(kern, &x[0], &p[0], flags, anchors, n, work, &sink)
    elif what == "jacobian":
        with nogil:
            ns = pdw_bench_jacobian(kern, &x[0], &p[0], flags, anchors, n, work, &sink)
    else:
        raise ValueError("what must be 'rhs' or 'jacobian', got %r" % what)
    return ns


def _method_table():
    return tuple((pdw_methods[i].name.decode(), pdw_methods[i].order,
                  bool(pdw_methods[i].adaptive)) for i in range(pdw_nmethods))


_METHOD_TABLE = _method_table()


def method_table():
    """[(name, order, adaptive)] of the compiled integrators, in method-id order (a new list
    of the table read once from C)."""
    return list(_METHOD_TABLE)


def rk_tableau(str name):
    """The Butcher tableau the compiled loops use for ``name`` ("rk4" or "dopri5"): a dict with
    stages, order, embedded_order, fsal and arrays c (s,), A (s, s), b (s,), e = b - bhat (s,)."""
    cdef const pdw_rk_tableau *T
    if name == "rk4":
        T = &pdw_tableau_rk4
    elif name == "dopri5":
        T = &pdw_tableau_dopri5
    else:
        raise ValueError("no explicit Runge-Kutta tableau %r (rk4, dopri5)" % name)
    n = T.stages
    return {"name": T.name.decode(), "stages": n, "order": T.order,
            "embedded_order": T.embedded_order, "fsal": bool(T.fsal),
            "c": np.array([T.c[i] for i in range(n)]),
            "A": np.array([[T.a[i][j] for j in range(n)] for i in range(n)]),
            "b": np.array([T.b[i] for i in range(n)]),
            "e": np.array([T.e[i] for i in range(n)])}


def ros_tableau(str name="rodas4"):
    """The Rosenbrock tableau (Hairer-Wanner transformed form, see pdw_tableaus.h) of ``name``:
    a dict with stages, order, embedded_order, gamma and arrays a, C (s, s), m, e (s,)."""
    cdef const pdw_ros_tableau *T
    if name == "rodas4":
        T = &pdw_tableau_rodas4
    else:
        raise ValueError("no Rosenbrock tableau %r (rodas4)" % name)
    n = T.stages
    return {"name": T.name.decode(), "stages": n, "order": T.order,
            "embedded_order": T.embedded_order, "gamma": T.gamma,
            "a": np.array([[T.a[i][j] for j in range(n)] for i in range(n)]),
            "C": np.array([[T.C[i][j] for j in range(n)] for i in range(n)]),
            "m": np.array([T.m[i] for i in range(n)]),
            "e": np.array([T.e[i] for i in range(n)])}


# generated from derive/layout.py (pdw_model.h; the same in pdw.core._layout):
#: Loop iterations between two polls for signals (Ctrl-C) and a cancelled pool.
POLL_EVERY = PDW_POLL_EVERY
#: First size of the record buffers of an adaptive run [samples] (its step count is not known
#: in advance); they double as the run needs more and are trimmed to the samples recorded at its
#: end. A fixed-step run's buffers hold exactly its n_steps // record_every + 2 samples when
#: that is at most RECORD_EXACT_MAX, else they grow from RECORD_CHUNK as an adaptive run's.
RECORD_CHUNK = PDW_RECORD_CHUNK
RECORD_EXACT_MAX = PDW_RECORD_EXACT_MAX
_SAMPLE_BYTES = 8 * (1 + PDW_NX + 1 + PDW_NREC)


cdef tuple _records(long n, int nx, bint contact):
    """Record arrays for n samples: (t (n,), x (n, nx), flags (n, 2) intc, contact (n or 0,
    NREC)), C-contiguous views of one np.empty block (rows are read only once written, so
    reused memory is not cleared first; one block is reused by the allocator from one run to
    the next, where four arrays fault in fresh pages for several runs), or pdw's MemoryError
    saying how much recording needs."""
    cdef long nc = n if contact else 0
    try:
        block = np.empty(n * (2 + nx) + nc * PDW_NREC)     # t, x, flags (2 int = 1 double)
    except (MemoryError, ValueError):
        raise MemoryError("recording needs more than %.3g GB (%d samples of %d bytes): record "
                          "fewer samples (record_every) or none (record_every=0)"
                          % (n * _SAMPLE_BYTES / 1e9, n, _SAMPLE_BYTES)) from None
    t = block[:n]
    x = block[n:n * (1 + nx)].reshape(n, nx)
    flags = block[n * (1 + nx):n * (2 + nx)].view(np.intc).reshape(n, 2)
    c = block[n * (2 + nx):].reshape(nc, PDW_NREC)
    return t, x, flags, c


cdef dict _EMPTY_RECORDS = {}


cdef tuple _no_records(int nx):
    """The record arrays of a run that records nothing: empty (no element to write), made once
    per state size nx (a Result's t, x, flags of no samples are views of them)."""
    out = _EMPTY_RECORDS.get(nx)
    if out is None:
        out = _EMPTY_RECORDS[nx] = _records(0, nx, True)
    return out


cdef tuple _records_copy(tuple old, long n, long n_copy, int nx, bint contact):
    """Fresh record arrays for n samples (`_records`) holding the first n_copy of old's."""
    new = _records(n, nx, contact)
    cdef int i
    for i in range(4):
        if new[i].shape[0]:
            new[i][:n_copy] = old[i][:n_copy]
    return new


cdef object _grown(object a, long n):
    """a (rows, ...) copied into the first rows of n (the rest not yet written)."""
    out = np.empty((n,) + a.shape[1:], dtype=a.dtype)
    out[:a.shape[0]] = a
    return out


@_named_buffers
def first_runaway(const double[:, ::1] x, double hip_max, double angle_max):
    """Index of the first row of x (N, nx >= 4) whose hip height y_o exceeds hip_max or whose
    leg angle theta1 or theta2 exceeds angle_max in magnitude; -1 if none (NaN exceeds
    nothing). One pass over the rows, no copy (the runaway check of `pdw.simulate`)."""
    if x.shape[0] and x.shape[1] <= PDW_X_THETA2:
        raise ValueError("x must have at least %d columns, got %d" % (PDW_X_THETA2 + 1, x.shape[1]))
    cdef Py_ssize_t i, found = -1
    with nogil:
        for i in range(x.shape[0]):
            if (x[i, PDW_X_Y_O] > hip_max or x[i, PDW_X_THETA1] > angle_max
                    or x[i, PDW_X_THETA1] < -angle_max or x[i, PDW_X_THETA2] > angle_max
                    or x[i, PDW_X_THETA2] < -angle_max):
                found = i
                break
    return found


@_named_buffers
def run(int k, int method, const double[::1] x0, const double[::1] p, int f1, int f2,
        dict opts, *, bint record_contact=True, long max_records=0, long event_capacity=256,
        long poll_every=POLL_EVERY, buffers=None, approach_speeds0=None, CGround ground=None):
    """Run one simulation in compiled code (GIL released). Returns a dict of arrays and status.

    opts: the run's options, one record: pdw_run_opts's fields by name
    (`pdw.sim.options.c_options` makes it from the option objects), filled into the struct by
    _opts.pxi's `_fill_opts` (the one filler, shared with `pdw.core._batch.run_range`; a field
    not given is 0: off or derived). Fixed-step methods take n_steps steps of dt; adaptive
    ones integrate to t_end (0: n_steps*dt) with first step dt, locating flag switches to
    within event_tol [s], and fail (reason PDW_REASON_BUDGET) once max_steps (> 0) steps were
    tried. record_every k > 0 records every k-th step; record_events 0 stores no event (only
    counts). stop_steps > 0 stops at that many complete steps, periodic_k > 0 when the last
    periodic_k steps agree within periodic_tol (relative), stop_touch_down = 1 or 2 at that
    leg's first touch-down (the final state is the event's); "stop_reason" says which (layout
    STOP). The online gait analysis runs for every method: the result's "gait" holds the last
    min(n_gait_steps, PDW_STEP_RING) complete steps (rows of layout STEP, oldest first), with
    the step and event counts.

    The other arguments are this call's buffers, not options of the loop. record_contact:
    record the contact forces with the states. The record buffer first holds
    n_steps/record_every + 2 samples (or max_records; an adaptive run's, or one of more than
    RECORD_EXACT_MAX samples, at most RECORD_CHUNK); when a loop fills the event or the record
    buffer it returns PDW_STATUS_EVENTS_FULL / PDW_STATUS_RECORDS_FULL; this function then
    doubles that buffer and calls the loop again, which resumes where it stopped: no sample is
    dropped. Record arrays of its own that hold more than the samples recorded (an adaptive
    run, an early stop) are trimmed to them at the end (one copy). Every poll_every loop
    iterations the loop returns PDW_STATUS_POLL: signals are checked here (GIL held); on Ctrl-C
    the run stops and the result (so far) is returned with "interrupted" set to the
    KeyboardInterrupt.

    approach_speeds0: (v1, v2) [m/s] replaces the approach speeds of the feet that start in
    support (default: pdw_discrete_init's max(-v_y, 0)).
    ground: a `CGround` (a shaped or patched ground, docs/terrain.md): the run takes the
    shaped-ground kernel of pdw_terrain.c; None: flat, today's kernel.

    Shapes (checked): x0 (kernel_nx(k),), p (NP,).
    """
    cdef pdw_sim s
    cdef int flags0[2]
    cdef int nx = _kernel(k).nx
    _len("x0", x0.shape[0], nx)
    _len("p", p.shape[0], PDW_NP)
    if (f1 != 0 and f1 != 1) or (f2 != 0 and f2 != 1):
        raise ValueError("flags must be 0 or 1, got (%d, %d)" % (f1, f2))
    if method < 0 or method >= pdw_nmethods:
        raise ValueError("method id %d out of range [0, %d)" % (method, pdw_nmethods))
    memset(&s, 0, sizeof(pdw_sim))
    cdef bint adaptive = pdw_methods[method].adaptive
    _fill_opts(&s.opt, opts, adaptive, PDW_STEP_RING)
    # every count in [0, MAX_COUNT] before a size or a loop bound is made of it
    _count("max_records", max_records, 0)
    _count("event_capacity", event_capacity, 0)
    _count("poll_every", poll_every, 0)
    if poll_every == 1:     # the loop would poll before every step and never take one
        raise _InvalidInputError("poll_every = 1 is out of range; allowed: 0 (never) or "
                                 "integers in [2, %d]" % _MAX_COUNT)
    cdef long n_steps = s.opt.n_steps, record_every = s.opt.record_every
    cdef bint record_events = s.opt.record_events != 0
    cdef long n_rec_cap = 0
    if record_every > 0:
        n_rec_cap = n_steps // record_every + 2        # a fixed-step run's samples, exactly
        if max_records > 0:
            n_rec_cap = max_records
        elif adaptive or n_rec_cap > RECORD_EXACT_MAX:
            n_rec_cap = min(n_rec_cap, <long>RECORD_CHUNK)
        n_rec_cap = max(n_rec_cap, 3)
    cdef pdw_advance_fn advance = pdw_methods[method].advance
    s.kernel = _kernel(k)
    if ground is not None:
        s.ground = &ground.g
    s.nx = nx
    s.h = s.opt.dt
    memcpy(s.p, &p[0], PDW_NP * sizeof(double))
    s.poll_every = poll_every
    if buffers is not None and record_every > 0:
        # caller-owned record arrays (reused between runs: no fresh pages to fault in);
        # an adaptive run that fills them continues in fresh, larger copies
        rec_t, rec_x, rec_flags, rec_contact = buffers
        n_rec_cap = rec_t.shape[0]
        if not record_contact:
            rec_contact = np.zeros((0, PDW_NREC))
        # every buffer as long as rec_t, checked before a pointer is taken (issue 16)
        _rows("buffers[1] (x)", rec_x.shape[0], rec_x.shape[1] if rec_x.ndim == 2 else -1,
              n_rec_cap, nx)
        _rows("buffers[2] (flags)", rec_flags.shape[0],
              rec_flags.shape[1] if rec_flags.ndim == 2 else -1, n_rec_cap, 2)
        if record_contact:
            _rows("buffers[3] (contact)", rec_contact.shape[0],
                  rec_contact.shape[1] if rec_contact.ndim == 2 else -1, n_rec_cap, PDW_NREC)
    elif record_every == 0:     # nothing recorded: empty arrays, one set per state size
        rec_t, rec_x, rec_flags, rec_contact = _no_records(nx)
    else:
        rec_t, rec_x, rec_flags, rec_contact = _records(n_rec_cap, nx, record_contact)
    cdef bint owned = buffers is None or record_every == 0  # the record arrays are ours
    events = _zeros("the event buffer (event_capacity)",
                    (max(event_capacity, 4) if record_events else 1, PDW_NEVENT))
    cdef double[::1] v_t
    cdef double[:, ::1] v_x
    cdef int[:, ::1] v_f
    cdef double[:, ::1] v_c
    cdef double[:, ::1] v_e = events
    if n_rec_cap > 0:
        v_t = rec_t
        v_x = rec_x
        v_f = rec_flags
        v_c = rec_contact
        s.rec_t = &v_t[0]
        s.rec_x = &v_x[0, 0]
        s.rec_flags = &v_f[0, 0]
        if record_contact:
            s.rec_contact = &v_c[0, 0]
    s.rec_capacity = n_rec_cap
    s.events = &v_e[0, 0] if record_events else NULL
    s.ev_capacity = events.shape[0] if record_events else 0
    pdw_gait_init(&s.gait)
    memcpy(s.x, &x0[0], nx * sizeof(double))
    flags0[0] = f1; flags0[1] = f2
    pdw_discrete_init(s.kernel, s.ground, s.p, s.x, flags0, &s.disc, s.work)
    if approach_speeds0 is not None:        # feet that start in support: given approach speeds
        if f1:
            s.disc.anchors[PDW_ANCHOR_V_IN1] = approach_speeds0[0]
        if f2:
            s.disc.anchors[PDW_ANCHOR_V_IN2] = approach_speeds0[1]
    cdef int status
    interrupted = None
    while True:
        with nogil:
            status = advance(&s)
        if status == PDW_STATUS_POLL:
            try:
                PyErr_CheckSignals()
                _interrupt.check()          # a worker thread's task of an interrupted pool
            except KeyboardInterrupt as e:
                interrupted = e
                break
        elif status == PDW_STATUS_EVENTS_FULL:
            events = _grown(events, 2 * events.shape[0])
            v_e = events
            s.events = &v_e[0, 0]
            s.ev_capacity = events.shape[0]
        elif status == PDW_STATUS_RECORDS_FULL:
            # double the record arrays (copying what is there) and resume
            n_rec_cap = 2 * max(n_rec_cap, 2)
            rec_t, rec_x, rec_flags, rec_contact = _records_copy(
                (rec_t, rec_x, rec_flags, rec_contact), n_rec_cap, s.n_rec, nx, record_contact)
            v_t = rec_t
            v_x = rec_x
            v_f = rec_flags
            s.rec_t = &v_t[0]
            s.rec_x = &v_x[0, 0]
            s.rec_flags = &v_f[0, 0]
            if record_contact:
                v_c = rec_contact
                s.rec_contact = &v_c[0, 0]
            s.rec_capacity = n_rec_cap
            owned = True
        else:
            break
    n_rec = s.n_rec
    if owned and n_rec + 2 < n_rec_cap:
        # trim once (an adaptive run, an early stop): the memory of the samples recorded
        rec_t, rec_x, rec_flags, rec_contact = _records_copy(
            (rec_t, rec_x, rec_flags, rec_contact), n_rec, n_rec, nx, record_contact)
    cdef long n_gait = s.gait.n_steps
    cdef long n_keep = min(n_gait, <long>PDW_STEP_RING)
    cdef double *ring = &s.gait.ring[0][0]
    # fixed size (a view of the first n_keep rows is returned): the same memory however long
    # the run
    gait = np.empty((PDW_STEP_RING, PDW_NSTEP))
    cdef double[:, ::1] gv = gait
    cdef long r, c, slot
    for r in range(n_keep):
        slot = (n_gait - n_keep + r) % PDW_STEP_RING
        for c in range(PDW_NSTEP):
            gv[r, c] = ring[slot * PDW_NSTEP + c]
    return {
        "gait": gait[:n_keep],
        "n_gait_steps": n_gait,
        "event_counts": {"touch_down": s.gait.n_touch_down, "lift_off": s.gait.n_lift_off},
        "stop_reason": s.stop_reason,
        "status": status,
        "interrupted": interrupted,
        "t": rec_t[:n_rec], "x": rec_x[:n_rec], "flags": rec_flags[:n_rec],
        "contact": rec_contact[:n_rec] if record_contact else None,
        "events": events[:s.n_events].copy() if record_events else np.zeros((0, PDW_NEVENT)),
        "n_steps": s.n,
        "t_final": s.t,
        "stats": {"steps": s.n, "rhs": s.n_rhs, "jacobians": s.n_jac, "rejected": s.n_rejected},
        "x_final": np.array(<double[:nx]> s.x),
        "flags_final": (s.disc.flags[0], s.disc.flags[1]),
        "anchors_final": (s.disc.anchors[0], s.disc.anchors[1]),
        "approach_speeds_final": (s.disc.anchors[PDW_ANCHOR_V_IN1],
                                  s.disc.anchors[PDW_ANCHOR_V_IN2]),
        "failure": {"t": s.failure.t, "x": np.array(<double[:nx]> s.failure.x),
                    "leg": s.failure.leg, "reason": s.failure.reason},
    }


def _real_states(x, bint allow_rows, int nx=PDW_NX):
    """x as a C-contiguous float64 array of shape (nx,) (or (N, nx) when allow_rows): real
    numbers only, no strings, complex, booleans or reshaping (`pdw.core.checks.real_array`;
    finiteness is not checked per call)."""
    if isinstance(x, (str, bytes)):
        raise InvalidInputError("x must be an array of numbers, got the string %r" % (x,))
    try:
        arr = np.asarray(x)
    except (TypeError, ValueError):
        raise InvalidInputError("x must be an array of numbers, got %r" % (x,)) from None
    if arr.dtype.kind not in "iuf":
        raise InvalidInputError("x must hold real numbers (not %s)" % arr.dtype)
    if not (arr.shape == (nx,) or (allow_rows and arr.ndim == 2 and arr.shape[1] == nx)):
        raise InvalidInputError("x must have shape (%d,)%s, got %s"
                                % (nx, " or (N, %d)" % nx if allow_rows else "", arr.shape))
    return np.ascontiguousarray(arr, dtype=np.float64)


# --- the model object for external solvers (pdw.ode_function) ----------------------------

include "_ode.pxi"
include "_cvar.pxi"


@_named_buffers
def ground_inv_normals(const double[::1] dh):
    """1/N = 1/sqrt(1 + h'^2) (n,) of h' (n,) as the shaped-ground kernel computes it
    (pdw_terrain.c; pairs as the two feet, an odd last one paired with 0), for tests."""
    cdef long n = dh.shape[0]
    out = np.zeros(n)
    cdef double[::1] o = out
    if n:
        pdw_terrain_inv_normals(n, &dh[0], &o[0])
    return out


@_named_buffers
def ground_kinematics(int k, CGround ground not None, const double[::1] x, const double[::1] p,
                      int f1, int f2, const double[::1] anchors, fall_depth=None):
    """(kin (2, NKIN), gnd (2, NGROUND)) of kernel k's shaped-ground kinematics at x, for tests:
    pdw_terrain_kinematics, or with fall_depth [m] pdw_terrain_flag_kinematics with support flags
    (f1, f2) (the time loops' flag update, pdw_terrain.c)."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef int flags[2]
    cdef double trig[PDW_NTRIG]
    cdef double cell[2]
    _len("x", x.shape[0], kern.nx)
    _len("p", p.shape[0], PDW_NP)
    _len("anchors", anchors.shape[0], PDW_NANCHOR)
    flags[0] = f1
    flags[1] = f2
    cell[0] = cell[1] = -1.0
    kin = np.zeros((2, PDW_NKIN))
    gnd = np.zeros((2, PDW_NGROUND))
    cdef double[:, ::1] vk = kin
    cdef double[:, ::1] vg = gnd
    pdw_trig(&x[0], trig)
    if fall_depth is None:
        pdw_terrain_kinematics(kern, &ground.g, &x[0], trig, &p[0], &anchors[0], &vk[0, 0],
                               &vg[0, 0], cell)
    else:
        pdw_terrain_flag_kinematics(kern, &ground.g, &x[0], trig, &p[0], &anchors[0], flags,
                                    float(fall_depth), &vk[0, 0], &vg[0, 0], cell)
    return kin, gnd


@_named_buffers
def ground_stage(int k, CGround ground not None, const double[::1] x, const double[::1] p,
                 int f1, int f2, const double[::1] anchors, bint jacobian=False):
    """f(x) (nx,) or, with jacobian, df/dx (nx, nx) of kernel k on a compiled ground (the
    shaped-ground kernel, pdw_terrain.c), for tests; anchors (NANCHOR,)."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef int nx = kern.nx
    cdef int flags[2]
    cdef double work[PDW_NWORK]
    cdef double[::1] flat
    _len("x", x.shape[0], nx)
    _len("p", p.shape[0], PDW_NP)
    _len("anchors", anchors.shape[0], PDW_NANCHOR)
    flags[0] = f1
    flags[1] = f2
    out = np.zeros((nx, nx)) if jacobian else np.zeros(nx)
    flat = out.reshape(-1)
    if jacobian:
        pdw_terrain_jacobian(kern, &ground.g, &x[0], &p[0], flags, &anchors[0], &flat[0], work)
    else:
        pdw_terrain_rhs(kern, &ground.g, &x[0], &p[0], flags, &anchors[0], &flat[0], work)
    return out
