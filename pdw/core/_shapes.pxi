# Shape checks of the compiled boundary, shared by _core.pyx and _hybrid.pyx (``include``d):
# every entry point checks its arrays once per call, before it takes a pointer.

cdef int _len(str name, Py_ssize_t got, Py_ssize_t want) except -1:
    if got != want:
        raise ValueError("%s must have shape (%d,), got (%d,)" % (name, want, got))
    return 0


cdef int _rows(str name, Py_ssize_t r, Py_ssize_t c, Py_ssize_t want_r, Py_ssize_t want_c) except -1:
    if r != want_r or c != want_c:
        raise ValueError("%s must have shape (%d, %d), got (%d, %d)" % (name, want_r, want_c, r, c))
    return 0
