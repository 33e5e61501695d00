# The model object for external solvers (`pdw.ode_function`), ``include``d by _core.pyx.
#
# Per call, the fast path takes the raw buffer of x (one PyObject_GetBuffer: C-contiguous
# float64 of shape (8,), checked once), runs the kernel into a preallocated array and returns a
# copy of it; anything else (a list, float32, a strided view) takes the general, converting path.

cdef inline bint _native_double(const char *fmt) noexcept:
    """The buffer format is one native float64 ("d", "@d" or "=d")."""
    if fmt == NULL:
        return False
    if fmt[0] == b'@' or fmt[0] == b'=':
        fmt += 1
    return fmt[0] == b'd' and fmt[1] == 0


cdef inline int _f64_vector(object x, Py_buffer *view) except -1:
    """1 when ``view`` now holds x's buffer, a C-contiguous float64 vector (release it);
    0 when x has no such buffer (the caller converts it)."""
    try:
        PyObject_GetBuffer(x, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT)
    except (TypeError, ValueError, BufferError):
        return 0
    if view.ndim == 1 and view.itemsize == 8 and _native_double(view.format):
        return 1
    PyBuffer_Release(view)
    return 0


cdef inline void _nan_unless_finite(const double *x, int nx, double *out,
                                    int n_out) noexcept nogil:
    """NaN in every entry of out (n_out) unless the state x (nx) is finite: NaN in, NaN out
    (the contact clamp would otherwise read a NaN depth as "no contact" and answer finite
    numbers, issue 26.5). nx comparisons a call."""
    cdef int i
    for i in range(nx):
        if not (x[i] - x[i] == 0.0):        # NaN or +-inf
            for i in range(n_out):
                out[i] = NAN
            return


cdef int _bad_state(Py_ssize_t n, int nx=PDW_NX) except -1:
    raise InvalidInputError("x must be a state of shape (%d,) [m, rad, m/s, rad/s%s], got shape "
                            "(%d,)" % (nx, ", m" if nx > PDW_NX else "", n))


cdef class OdeFunction:
    """f(t, x) of Eq. A.4 with the discrete state fixed: the model object for external solvers.

    Built (and validated) by `pdw.ode_function`; every call goes straight to the compiled
    kernel. The fast path takes a C-contiguous float64 array of shape (8,) (what ``solve_ivp``
    passes): its buffer is read in place, with one check of shape, type and layout per call.
    Anything else (a list, another dtype, a strided view) takes a slower converting path.
    The state has the kernel's size ``nx``: 8 (`pdw.STATE`), or 10 under LuGre friction (the
    bristle deflections z1, z2 [m] follow, ``pdw.core._layout.STATE_LAYOUTS``).
    A state with a NaN or infinite component gives NaN in every entry of f (and of jac)
    (eight comparisons a call; the kernel alone would clamp a NaN depth to "no contact" and
    answer finite numbers). Each call returns a *fresh* array (a copy of an
    internal buffer), so a caller may keep what it gets (``solve_ivp`` does).
    """
    cdef const pdw_kernel *kern
    cdef readonly int nx                   # the state size of the kernel (8, or 10 with LuGre)
    cdef double p[PDW_NP]
    cdef int _flags[2]
    cdef double _anchors[PDW_NANCHOR]      # s0_1, s0_2, then the approach speeds v_in1, v_in2
    cdef double work[PDW_NWORK]
    cdef object _f_out                     # ndarray (8,): the kernel writes here, calls return a copy
    cdef object _j_out                     # ndarray (8, 8), the same for the Jacobian
    cdef double *_f_ptr
    cdef double *_j_ptr

    def __cinit__(self, int k, const double[::1] p, int f1, int f2, double a1, double a2):
        cdef double[::1] fo
        cdef double[:, ::1] jo
        self.kern = _kernel(k)
        self.nx = self.kern.nx
        if self.nx < 1 or self.nx > PDW_NX_MAX:
            raise ValueError("kernel %d has a state of %d entries" % (k, self.nx))
        _len("p", p.shape[0], PDW_NP)
        memcpy(self.p, &p[0], PDW_NP * sizeof(double))
        memset(self._anchors, 0, PDW_NANCHOR * sizeof(double))
        self.set_discrete(f1, f2, a1, a2)
        self._f_out = np.zeros(self.nx)
        self._j_out = np.zeros((self.nx, self.nx))
        fo = self._f_out
        jo = self._j_out
        self._f_ptr = &fo[0]               # both arrays are private and never resized
        self._j_ptr = &jo[0, 0]

    def set_discrete(self, int f1, int f2, double a1, double a2, v_in=None):
        """Replace the support flags (0 or 1) and the anchors (finite) [m]; ``v_in`` (two
        finite numbers [m/s], optional) the approach speeds of the lankarani_nikravesh and
        flores laws (kept when None)."""
        cdef double v1, v2
        if (f1 != 0 and f1 != 1) or (f2 != 0 and f2 != 1):
            raise ValueError("flags must be 0 or 1, got (%d, %d)" % (f1, f2))
        if not (a1 - a1 == 0.0 and a2 - a2 == 0.0):
            raise ValueError("anchors must be finite, got (%r, %r)" % (a1, a2))
        if v_in is not None:
            v1, v2 = v_in
            if not (v1 - v1 == 0.0 and v2 - v2 == 0.0):
                raise ValueError("approach speeds must be finite, got (%r, %r)" % (v1, v2))
            self._anchors[2] = v1
            self._anchors[3] = v2
        self._flags[0] = f1
        self._flags[1] = f2
        self._anchors[0] = a1
        self._anchors[1] = a2

    @property
    def flags(self):
        """The support flags (leg 1, leg 2) held fixed; 1 support, 0 swing."""
        return (self._flags[0], self._flags[1])

    @property
    def anchors(self):
        """Rolling coordinates (s0_1, s0_2) [m] held fixed (the ``consistent`` variant's)."""
        return (self._anchors[0], self._anchors[1])

    @property
    def approach_speeds(self):
        """Approach speeds (v_in1, v_in2) [m/s] held fixed (lankarani_nikravesh, flores)."""
        return (self._anchors[2], self._anchors[3])

    def __call__(self, t, x):
        """f(t, x): dx/dt of Eq. A.4 at the state x, shape (nx,) -> fresh ndarray (nx,).

        ``t`` [s] is ignored (the model is autonomous). An (N, 8) array gives ``batch(x)``.
        """
        cdef Py_buffer view
        cdef Py_ssize_t n
        if _f64_vector(x, &view):
            n = view.shape[0]
            if n != self.nx:
                PyBuffer_Release(&view)
                _bad_state(n, self.nx)
            self.kern.rhs(<const double *> view.buf, self.p, self._flags, self._anchors,
                          self._f_ptr, self.work)
            _nan_unless_finite(<const double *> view.buf, self.nx, self._f_ptr, self.nx)
            PyBuffer_Release(&view)
            return self._f_out.copy()
        return self.general(t, x)

    def general(self, t, x):
        """`__call__` through the converting path, for any array-like x (the path every call
        took before the raw-buffer path; kept callable for benchmarks/bench_io.py)."""
        cdef const double[::1] v
        cdef double[::1] o
        try:
            v = x
        except (ValueError, TypeError, BufferError):
            arr = _real_states(x, True, self.nx)   # real numbers, (nx,) or (N, nx), as given
            if arr.ndim == 2:
                return self.batch(arr)
            v = arr
        if v.shape[0] != self.nx:
            _bad_state(v.shape[0], self.nx)
        out = np.empty(self.nx)
        o = out
        self.kern.rhs(&v[0], self.p, self._flags, self._anchors, &o[0], self.work)
        _nan_unless_finite(&v[0], self.nx, &o[0], self.nx)
        return out

    def checked(self, x):
        """f at x if x is an ndarray, C-contiguous float64 (8,), every component finite;
        else None (`pdw.rhs`'s fast path: None sends it to its checked, general path)."""
        cdef Py_buffer view
        cdef Py_ssize_t i
        cdef const double *v
        if type(x) is not np.ndarray or not _f64_vector(x, &view):
            return None
        v = <const double *> view.buf
        if view.shape[0] != self.nx:
            PyBuffer_Release(&view)
            return None
        for i in range(self.nx):
            if not (v[i] - v[i] == 0.0):
                PyBuffer_Release(&view)
                return None
        self.kern.rhs(v, self.p, self._flags, self._anchors, self._f_ptr, self.work)
        PyBuffer_Release(&view)
        return self._f_out.copy()

    def jac(self, t, x):
        """df/dx at the state x (nx,) -> fresh ndarray (nx, nx), the symbolic Jacobian of the
        kernel (``t`` ignored). Same fast path and fallback as `__call__`."""
        cdef Py_buffer view
        cdef Py_ssize_t n
        cdef const double[::1] v
        cdef double[:, ::1] o
        if _f64_vector(x, &view):
            n = view.shape[0]
            if n != self.nx:
                PyBuffer_Release(&view)
                _bad_state(n, self.nx)
            self.kern.jacobian(<const double *> view.buf, self.p, self._flags, self._anchors,
                               self._j_ptr, self.work)
            _nan_unless_finite(<const double *> view.buf, self.nx, self._j_ptr, self.nx * self.nx)
            PyBuffer_Release(&view)
            return self._j_out.copy()
        v = _real_states(x, False, self.nx)
        if v.shape[0] != self.nx:
            _bad_state(v.shape[0], self.nx)
        out = np.empty((self.nx, self.nx))
        o = out
        self.kern.jacobian(&v[0], self.p, self._flags, self._anchors, &o[0, 0], self.work)
        _nan_unless_finite(&v[0], self.nx, &o[0, 0], self.nx * self.nx)
        return out

    def batch(self, const double[:, ::1] X, double[:, ::1] out=None):
        """f for each row of X (N, nx) -> (N, nx), one compiled loop (GIL released).

        ``out`` (N, nx), optional, receives the result (and is returned) instead of a new array.
        """
        cdef Py_ssize_t i, n = X.shape[0]
        cdef int nx = self.nx
        if X.shape[1] != nx:
            raise InvalidInputError("X must have shape (N, %d), got (%d, %d)"
                                    % (nx, n, X.shape[1]))
        if out is None:
            out = np.empty((n, nx))
        elif out.shape[0] != n or out.shape[1] != nx:
            raise InvalidInputError("out must have shape (%d, %d), got (%d, %d)"
                                    % (n, nx, out.shape[0], out.shape[1]))
        cdef double w[PDW_NWORK]
        with nogil:
            for i in range(n):
                self.kern.rhs(&X[i, 0], self.p, self._flags, self._anchors, &out[i, 0], w)
                _nan_unless_finite(&X[i, 0], nx, &out[i, 0], nx)
        return np.asarray(out)
