# The continuous walker's variational equations, compiled (pdw_cvar.c; issue #24): one
# interval of constant support flags for pdw/analysis/stepmap/variational.py, ``include``d by
# _core.pyx after _ode.pxi (it reads an OdeFunction's kernel, parameters and discrete state).

cdef extern from "pdw_cvar.h":
    ctypedef struct pdw_cvar_event:
        int kind
        int leg
        double dir
    ctypedef struct pdw_cvar_model:
        const pdw_kernel *kernel
        const double *p
        int flags[2]
        double anchors[4]
        int na
        double l, r
        int np
        const double *p_plus
        const double *p_minus
        double dmu
    ctypedef struct pdw_cvar_opts:
        double rtol, atol, phi_rtol, phi_atol, t_max, dir_step
        int phi_error
        int a_hermite
        int one_sided
        long max_steps
    ctypedef struct pdw_cvar_stats:
        long n_steps, n_rejected, n_rhs, n_jac
    enum:
        PDW_CVAR_MAXEV, PDW_CVAR_NMAX
    int pdw_cvar_interval(const pdw_cvar_model *m, const pdw_cvar_opts *o,
                          const pdw_cvar_event *ev, int n_ev, double *t, double *y, double *Phi,
                          double *h, int *k_ev, pdw_cvar_stats *st, double *work) noexcept nogil


@_named_buffers
def cvar_interval(OdeFunction f not None, double l, double r, int na, events, double t,
                  double[::1] y, double[:, ::1] Phi, double h, double t_max, *,
                  double rtol=1e-10, double atol=1e-12, double phi_rtol=1e-10,
                  double phi_atol=1e-10, double dir_step=1e-7, OdeFunction f_plus=None,
                  OdeFunction f_minus=None, double dmu=0.0,
                  bint phi_error=False, bint one_sided=False, bint a_hermite=True, long max_steps=200000, stats=None):
    """Integrate (y, Phi) of f (its flags and anchors held) from t to the first crossing of
    ``events`` (a sequence of (kind, leg, dir): pdw_cvar.h's PDW_CVAR_EV_* codes, leg 0 or 1,
    crossing direction +1, -1 or 0), in place: y (8 + na,) and Phi (8 + na, 8 + na), na 0 or
    2 (approach speeds after x). l, r: leg length and foot radius [m]. Returns (status, t,
    index of the event or -1, next step h): status 0 an event, 1 t_max, -1 the step size
    failed, -2 max_steps. ``a_hermite`` (default): A at the inner stage times from its cubic
    Hermite interpolant (pdw_cvar.h); ``one_sided``: forward differences for dA/dt.
    ``f_plus``, ``f_minus`` (the same kernel as f, other parameters) and ``dmu`` (their
    parameters' distance): y carries a parameter mu last (y (9 + na,), Phi (9 + na, 9 + na)),
    df/dmu the difference of their f over dmu (pdw_cvar.h's np). ``stats`` (a list of 4 ints, optional) accumulates steps, rejections,
    f and Jacobian evaluations."""
    cdef pdw_cvar_model m
    cdef pdw_cvar_opts o
    cdef pdw_cvar_stats st
    cdef pdw_cvar_event ev[PDW_CVAR_MAXEV]
    cdef double work[PDW_NWORK]
    cdef int n_ev = len(events), k_ev = -1, rc, i
    cdef int npar = 0 if f_plus is None else 1
    cdef int n = PDW_NX + na + npar
    if f.nx != PDW_NX:
        raise InvalidInputError("cvar_interval: a Coulomb-friction kernel (nx = %d), got nx = %d"
                                % (PDW_NX, f.nx))
    if na != 0 and na != 2:
        raise ValueError("na must be 0 or 2, got %d" % na)
    if n_ev > PDW_CVAR_MAXEV:
        raise ValueError("at most %d events, got %d" % (PDW_CVAR_MAXEV, n_ev))
    if y.shape[0] != n or Phi.shape[0] != n or Phi.shape[1] != n:
        raise ValueError("y must be (%d,) and Phi (%d, %d)" % (n, n, n))
    for i in range(n_ev):
        ev[i].kind, ev[i].leg, ev[i].dir = int(events[i][0]), int(events[i][1]), float(events[i][2])
        if ev[i].leg != 0 and ev[i].leg != 1:
            raise ValueError("event leg must be 0 or 1")
    m.kernel = f.kern
    m.p = f.p
    m.flags[0] = f._flags[0]
    m.flags[1] = f._flags[1]
    for i in range(4):
        m.anchors[i] = f._anchors[i]
    m.na = na
    m.l = l
    m.r = r
    m.np = npar
    m.p_plus = m.p_minus = NULL
    m.dmu = dmu
    if npar:
        if f_minus is None or f_plus.kern != f.kern or f_minus.kern != f.kern:
            raise ValueError("f_plus and f_minus: both, with f's kernel")
        if not dmu != 0.0:
            raise ValueError("dmu must be nonzero")
        m.p_plus = f_plus.p
        m.p_minus = f_minus.p
    o.rtol, o.atol, o.t_max, o.dir_step = rtol, atol, t_max, dir_step
    o.phi_rtol, o.phi_atol = phi_rtol, phi_atol
    o.phi_error = phi_error
    o.one_sided = one_sided
    o.a_hermite = a_hermite
    o.max_steps = max_steps
    st.n_steps = st.n_rejected = st.n_rhs = st.n_jac = 0
    with nogil:
        rc = pdw_cvar_interval(&m, &o, ev, n_ev, &t, &y[0], &Phi[0, 0], &h, &k_ev, &st, work)
    if stats is not None:
        stats[0] += st.n_steps
        stats[1] += st.n_rejected
        stats[2] += st.n_rhs
        stats[3] += st.n_jac
    return rc, t, k_ev, h
