# The representative states of the step-size check (pdw.sim.stepsize.stance_states) in one
# compiled call: the first fixed-step `simulate` of a process with parameters of no preset
# computes them (issue 23: the first call of a process). ``include``d by _core.pyx.

from libc.math cimport sin

# the grids of pdw.sim.stepsize._hip_height: 97 depths, 3 refinements
DEF _NGRID = 97


cdef inline void _foot_state(const pdw_kernel *kern, const double *x, const double *p,
                             const int *flags, const double *trig, double *kin,
                             double *con) noexcept nogil:
    """The kinematics and contact stages of `rhs_batch` of one row with anchors (0, 0), the
    same functions on the same inputs (trig: pdw_trig of x, which reads the angles alone)."""
    cdef double a[PDW_NANCHOR]
    cdef int j
    for j in range(PDW_NANCHOR):
        a[j] = 0.0
    kern.kinematics(x, trig, p, a, kin)
    kern.contact(kin, flags, p, con)


@_named_buffers
def stance_search(int k, double[:, ::1] x, const double[::1] p, const int[:, ::1] flags,
                  const int[::1] foot, const double[::1] force, const double[::1] depths,
                  double lr, int i_yd, int i_vx, int i_fn, int nkin, int ncontact):
    """`pdw.sim.stepsize._stance_state` of each row of x (N, NX), in place, bit for bit.

    Per row: the support foot ``foot[i]`` stuck (x_o' -= its slip velocity), in single stance
    (foot 1) not sinking (y_o' = -lr sin(theta2) theta2', lr = l - r), and y_o set so that the
    support feet carry ``force[i]`` [N] in total: three grids of 97 depths below the lowest
    support foot (the first ``depths`` (97,), then numpy.linspace between the two depths that
    bracket the force), then linear interpolation. Contact as `rhs_batch`'s with anchors 0 (its kinematics and contact stages);
    i_yd, i_vx (in KIN) and i_fn (in CONTACT) the layout's indices; nkin, ncontact their
    widths. flags (N, 2), foot, force (N,)."""
    cdef const pdw_kernel *kern = _kernel(k)
    cdef Py_ssize_t n = x.shape[0]
    _rows("x", n, x.shape[1], n, kern.nx)
    _len("p", p.shape[0], PDW_NP)
    _rows("flags", flags.shape[0], flags.shape[1], n, 2)
    _len("foot", foot.shape[0], n)
    _len("force", force.shape[0], n)
    _len("depths", depths.shape[0], _NGRID)
    _flags_ok(flags)
    if nkin != PDW_NKIN or ncontact != PDW_NCONTACT or not (0 <= i_yd < nkin and
                                                             0 <= i_vx < nkin and
                                                             0 <= i_fn < ncontact):
        raise ValueError("stance_search: layout indices out of range")
    cdef Py_ssize_t i
    for i in range(n):
        if foot[i] != 0 and foot[i] != 1:
            raise ValueError("foot must hold 0 or 1, got %d in row %d" % (foot[i], i))
    cdef double xr[PDW_NX_MAX]
    cdef double trig[4]
    cdef double kin[2 * PDW_NKIN]
    cdef double con[2 * PDW_NCONTACT]
    cdef double d[_NGRID]
    cdef double e[_NGRID]
    cdef Py_ssize_t j, g, kk, r
    cdef int f, nx = kern.nx, done
    cdef double y0, ymin, v, lo, hi, step, a, b, ea, eb
    with nogil:
        for i in range(n):
            for j in range(nx):
                xr[j] = x[i, j]
            f = foot[i]
            pdw_trig(xr, trig)              # the angles do not change below
            _foot_state(kern, xr, &p[0], &flags[i, 0], trig, kin, con)
            xr[PDW_X_XD_O] -= kin[f * nkin + i_vx]
            if f == 1:
                xr[PDW_X_YD_O] = -lr * sin(xr[PDW_X_THETA2]) * xr[PDW_X_THETAD2]
            _foot_state(kern, xr, &p[0], &flags[i, 0], trig, kin, con)
            ymin = 0.0                      # numpy.min over the support feet (NaN wins)
            done = 0
            for j in range(2):
                if flags[i, j] > 0:
                    v = kin[j * nkin + i_yd]
                    if done == 0 or v < ymin or v != v:
                        ymin = v if ymin == ymin or done == 0 else ymin
                        done = 1
            y0 = xr[PDW_X_Y_O] - ymin
            for g in range(_NGRID):
                d[g] = depths[g]
            done = 0
            for r in range(4):
                for g in range(_NGRID):
                    xr[PDW_X_Y_O] = y0 - d[g]
                    _foot_state(kern, xr, &p[0], &flags[i, 0], trig, kin, con)
                    e[g] = (con[i_fn] + con[ncontact + i_fn]) - force[i]
                kk = 0                      # numpy.argmax(e > 0): the first, else 0
                while kk < _NGRID and not e[kk] > 0:
                    kk += 1
                if kk == _NGRID:
                    kk = 0
                if r == 3:
                    break
                if e[kk] <= 0:              # not even the deepest carries the force
                    xr[PDW_X_Y_O] = y0 - d[_NGRID - 1]
                    done = 1
                    break
                if kk == 0:
                    xr[PDW_X_Y_O] = y0 - d[0]
                    done = 1
                    break
                lo, hi = d[kk - 1], d[kk]
                step = (hi - lo) / (_NGRID - 1)         # numpy.linspace(lo, hi, 97)
                for g in range(_NGRID - 1):
                    if step != 0:
                        d[g] = g * step + lo
                    else:
                        d[g] = (g / <double>(_NGRID - 1)) * (hi - lo) + lo
                d[_NGRID - 1] = hi
            if not done:                    # d[k - 1], e[k - 1] wrap as in Python
                a = d[kk - 1] if kk > 0 else d[_NGRID - 1]
                ea = e[kk - 1] if kk > 0 else e[_NGRID - 1]
                b, eb = d[kk], e[kk]
                xr[PDW_X_Y_O] = y0 - (a - ea * (b - a) / (eb - ea))
            for j in range(nx):
                x[i, j] = xr[j]
