# The poll of a compiled loop that runs with the GIL released (``include``d by _batch.pyx and
# _hybrid.pyx, which cimport PyErr_CheckSignals and import pdw.core.interrupt as _interrupt).

cdef int _poll(void *ctx) noexcept nogil:
    """The loop's poll (every few hundred steps, GIL released): Python's signal handlers (main
    thread) and the thread's cancel token (`pdw.core.interrupt`); an exception is kept in ctx
    (a list) and stops the loop."""
    with gil:
        pending = <list> ctx
        if pending:
            return 1
        try:
            PyErr_CheckSignals()
            _interrupt.check()
        except BaseException as e:
            pending.append(e)
            return 1
    return 0
