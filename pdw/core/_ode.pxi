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


cdef inline void _nan_unless_finite(const double *x, double *out, int n_out) noexcept nogil:
    """NaN in every entry of out (n_out) unless the state x (PDW_NX) is finite: NaN in, NaN out
    (the contact clamp would otherwise read a NaN depth as "no contact" and answer finite
    numbers, issue 26.5). Eight comparisons a call."""
    cdef int i
    for i in range(PDW_NX):
        if not (x[i] - x[i] == 0.0):        # NaN or +-inf
            for i in range(n_out):
                out[i] = NAN
            return


cdef int _bad_state(Py_ssize_t n) except -1:
    raise InvalidInputError("x must be a state of shape (8,) [m, rad, m/s, rad/s], got shape (%d,)" % n)


cdef class OdeFunction:
    """f(t, x) of Eq. A.4 with the discrete state fixed: the model object for external solvers.

    Built (and validated) by `pdw.ode_function`; every call goes straight to the compiled
    kernel. The fast path takes a C-contiguous float64 array of shape (8,) (what ``solve_ivp``
    passes): its buffer is read in place, with one check of shape, type and layout per call.
    Anything else (a list, another dtype, a strided view) takes a slower converting path.
    A state with a NaN or infinite component gives NaN in every entry of f (and of jac)
    (eight comparisons a call; the kernel alone would clamp a NaN depth to "no contact" and
    answer finite numbers). Each call returns a *fresh* array (a copy of an
    internal buffer), so a caller may keep what it gets (``solve_ivp`` does).
    """
    cdef const pdw_kernel *kern
    cdef double p[PDW_NP]
    cdef int _flags[2]
    cdef double _anchors[PDW_NANCHOR]      # s0_1, s0_2 given; the approach speeds stay 0
    cdef double work[PDW_NWORK]
    cdef object _f_out                     # ndarray (8,): the kernel writes here, calls return a copy
    cdef object _j_out                     # ndarray (8, 8), the same for the Jacobian
    cdef double *_f_ptr
    cdef double *_j_ptr

    def __cinit__(self, int k, const double[::1] p, int f1, int f2, double a1, double a2):
        cdef double[::1] fo
        cdef double[:, ::1] jo
        self.kern = _kernel(k)
        if self.kern.nx != PDW_NX:
            raise ValueError("OdeFunction takes the kernels of the smooth Coulomb law only")
        _len("p", p.shape[0], PDW_NP)
        memcpy(self.p, &p[0], PDW_NP * sizeof(double))
        memset(self._anchors, 0, PDW_NANCHOR * sizeof(double))
        self.set_discrete(f1, f2, a1, a2)
        self._f_out = np.zeros(PDW_NX)
        self._j_out = np.zeros((PDW_NX, PDW_NX))
        fo = self._f_out
        jo = self._j_out
        self._f_ptr = &fo[0]               # both arrays are private and never resized
        self._j_ptr = &jo[0, 0]

    def set_discrete(self, int f1, int f2, double a1, double a2):
        """Replace the support flags (0 or 1) and the anchors (finite) [m]."""
        if (f1 != 0 and f1 != 1) or (f2 != 0 and f2 != 1):
            raise ValueError("flags must be 0 or 1, got (%d, %d)" % (f1, f2))
        if not (a1 - a1 == 0.0 and a2 - a2 == 0.0):
            raise ValueError("anchors must be finite, got (%r, %r)" % (a1, a2))
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

    def __call__(self, t, x):
        """f(t, x): dx/dt of Eq. A.4 at the state x, shape (8,) -> fresh ndarray (8,).

        ``t`` [s] is ignored (the model is autonomous). An (N, 8) array gives ``batch(x)``.
        """
        cdef Py_buffer view
        cdef Py_ssize_t n
        if _f64_vector(x, &view):
            n = view.shape[0]
            if n != PDW_NX:
                PyBuffer_Release(&view)
                _bad_state(n)
            self.kern.rhs(<const double *> view.buf, self.p, self._flags, self._anchors,
                          self._f_ptr, self.work)
            _nan_unless_finite(<const double *> view.buf, self._f_ptr, PDW_NX)
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
            arr = _real_states(x, True)    # real numbers, (8,) or (N, 8), never reshaped
            if arr.ndim == 2:
                return self.batch(arr)
            v = arr
        if v.shape[0] != PDW_NX:
            _bad_state(v.shape[0])
        out = np.empty(PDW_NX)
        o = out
        self.kern.rhs(&v[0], self.p, self._flags, self._anchors, &o[0], self.work)
        _nan_unless_finite(&v[0], &o[0], PDW_NX)
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
        if view.shape[0] != PDW_NX:
            PyBuffer_Release(&view)
            return None
        for i in range(PDW_NX):
            if not (v[i] - v[i] == 0.0):
                PyBuffer_Release(&view)
                return None
        self.kern.rhs(v, self.p, self._flags, self._anchors, self._f_ptr, self.work)
        PyBuffer_Release(&view)
        return self._f_out.copy()

    def jac(self, t, x):
        """df/dx at the state x (8,) -> fresh ndarray (8, 8), the symbolic Jacobian of the
        kernel (``t`` ignored). Same fast path and fallback as `__call__`."""
        cdef Py_buffer view
        cdef Py_ssize_t n
        cdef const double[::1] v
        cdef double[:, ::1] o
        if _f64_vector(x, &view):
            n = view.shape[0]
            if n != PDW_NX:
                PyBuffer_Release(&view)
                _bad_state(n)
            self.kern.jacobian(<const double *> view.buf, self.p, self._flags, self._anchors,
                               self._j_ptr, self.work)
            _nan_unless_finite(<const double *> view.buf, self._j_ptr, PDW_NX * PDW_NX)
            PyBuffer_Release(&view)
            return self._j_out.copy()
        v = _real_states(x, False)
        if v.shape[0] != PDW_NX:
            _bad_state(v.shape[0])
        out = np.empty((PDW_NX, PDW_NX))
        o = out
        self.kern.jacobian(&v[0], self.p, self._flags, self._anchors, &o[0, 0], self.work)
        _nan_unless_finite(&v[0], &o[0, 0], PDW_NX * PDW_NX)
        return out

    def batch(self, const double[:, ::1] X, double[:, ::1] out=None):
        """f for each row of X (N, 8) -> (N, 8), one compiled loop (GIL released).

        ``out`` (N, 8), optional, receives the result (and is returned) instead of a new array.
        """
        cdef Py_ssize_t i, n = X.shape[0]
        if X.shape[1] != PDW_NX:
            raise InvalidInputError("X must have shape (N, 8), got (%d, %d)" % (n, X.shape[1]))
        if out is None:
            out = np.empty((n, PDW_NX))
        elif out.shape[0] != n or out.shape[1] != PDW_NX:
            raise InvalidInputError("out must have shape (%d, 8), got (%d, %d)"
                                    % (n, out.shape[0], out.shape[1]))
        cdef double w[PDW_NWORK]
        with nogil:
            for i in range(n):
                self.kern.rhs(&X[i, 0], self.p, self._flags, self._anchors, &out[i, 0], w)
                _nan_unless_finite(&X[i, 0], &out[i, 0], PDW_NX)
        return np.asarray(out)
