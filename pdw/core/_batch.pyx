# cython: language_level=3
"""Thin Cython layer over the ensemble engine (csrc/pdw_batch.c): many walkers, W lanes in
lockstep, threads sharing one batch through a counter of walkers (or over disjoint ranges).

Private: the public API is `pdw.sim.batch.simulate_batch`. Every array is caller-allocated,
C-contiguous (typed memoryviews). `run_range` releases the GIL for the whole range.
"""
from cpython.exc cimport PyErr_CheckSignals
from libc.stdlib cimport malloc, free

import threading

from pdw.core import interrupt as _interrupt


cdef extern from "<stdlib.h>" nogil:
    int posix_memalign(void **memptr, size_t alignment, size_t size)


cdef extern from "pdw_model.h":
    enum:
        PDW_NX, PDW_NP, PDW_NKERNELS, PDW_NSTEP, PDW_STEP_RING
    ctypedef struct pdw_kernel:
        int variant
        int nx
    const pdw_kernel pdw_kernels[]


include "_opts.pxi"
include "_ground.pxi"


cdef extern from "pdw_sim.h":
    ctypedef struct pdw_sim:
        int status


cdef extern from "pdw_batch.h":
    enum:
        PDW_BATCH_MAXW
        PDW_BATCH_SERIAL
    ctypedef struct pdw_batch_job:
        const pdw_kernel *kernel
        long n
        const double *x0
        const double *p
        long p_stride
        const int *flags0
        const double *fall_hip_height
        const double *fall_depth
        pdw_run_opts opt
        int method
        const pdw_ground **grounds
        int *status
        int *stop_reason
        int *flags_final
        double *x_final
        double *t_final
        long *n_taken
        long *n_gait
        long *n_touch_down
        long *n_lift_off
        double *gait
        int *fail_reason
        int *fail_leg
        double *fail_t
        double *fail_x
        long *next_walker
        long *lane_steps
        int (*poll)(void *ctx) noexcept nogil
        void *poll_ctx
    long pdw_batch_cdm(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                       int vector) noexcept nogil
    long pdw_batch_method(const pdw_batch_job *job, long i0, long i1, int W,
                          pdw_sim *lanes) noexcept nogil
    ctypedef struct pdw_soa_state:
        int W
    int pdw_batch_isa_supported(int isa) noexcept nogil
    long pdw_batch_cdm_soa(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                           int vector, int isa, pdw_soa_state *S) noexcept nogil
    ctypedef struct pdw_ros_soa:
        int W
    long pdw_batch_rodas4_soa(const pdw_batch_job *job, long i0, long i1, int W,
                              pdw_sim *lanes, int vector, int isa, pdw_ros_soa *S) noexcept nogil


cdef extern from "pdw_sim.h":
    ctypedef struct pdw_method:
        int adaptive
    const pdw_method pdw_methods[]
    const int pdw_nmethods


MAX_LANES = PDW_BATCH_MAXW
SERIAL_WALKERS = PDW_BATCH_SERIAL
"""A block of at most this many walkers runs the scalar loop, one walker after the other
(pdw_batch_serial): the lanes would compute a whole chunk of 8 for them."""
ISAS = {"scalar": -1, "base": 0, "avx2": 1, "avx512": 2}
"""The cdm lane loops: "scalar" (every lane through the generated scalar stages), and the
structure-of-arrays step compiled for the x86-64 baseline (SSE2), AVX2 and AVX-512F."""


_lane_lock = threading.Lock()
_lane_steps = [0]


def lane_steps(reset=False):
    """Walker-steps the structure-of-arrays lane loops (cdm and rodas4) committed in this
    process since the last reset, over every thread; the other steps (events, failures, the
    first and last steps) went through the scalar step. A diagnostic: the tests check with it
    that the lanes, not only the scalar fallback, did the work. reset: zero it (after reading)."""
    with _lane_lock:
        n = _lane_steps[0]
        if reset:
            _lane_steps[0] = 0
    return n


def isa_supported(name):
    """Can this CPU run the cdm lane loop compiled for instruction set `name` (ISAS)?"""
    return bool(pdw_batch_isa_supported(ISAS[name]))


def best_isa():
    """The widest instruction set of ISAS this CPU runs."""
    return [n for n in ("avx512", "avx2", "base") if isa_supported(n)][0]


include "_poll.pxi"
include "_shapes.pxi"


# the output arrays of run_range: (const, C type, ndim) as _shapes.pxi's _fault reads them
_OUT_SPECS = {"status": (False, "int", 1), "stop_reason": (False, "int", 1),
              "flags_final": (False, "int", 2), "x_final": (False, "double", 2),
              "t_final": (False, "double", 1), "n_steps": (False, "long", 1),
              "n_gait_steps": (False, "long", 1), "n_touch_down": (False, "long", 1),
              "n_lift_off": (False, "long", 1), "gait": (False, "double", 3),
              "fail_reason": (False, "int", 1), "fail_leg": (False, "int", 1),
              "fail_t": (False, "double", 1), "fail_x": (False, "double", 2)}
_OUT_KEYS = tuple(_OUT_SPECS)


@_named_buffers
def run_range(int k, const double[:, ::1] x0, const double[:, ::1] p, const int[:, ::1] flags0,
              const double[::1] hip, const double[::1] depth, dict opts, dict out, long i0,
              long i1, int lanes, bint vector, *, int method=0, int isa=0,
              long[::1] next_walker=None, grounds=None):
    """Advance walkers [i0, i1) with `lanes` lanes (GIL released), writing rows of `out`.

    opts: the options of every walker, one record: pdw_run_opts's fields by name
    (`pdw.sim.options.c_options`), filled into the job's one embedded struct by _opts.pxi's
    `_fill_opts` (the filler `pdw.core._core.run` uses: the same fields, checks and derived
    values); the fall limits are each walker's (hip, depth), not the record's.
    method: index into the compiled method table (pdw.core.integrators.METHODS); 0 (cdm) takes
    the lockstep cdm loop (pdw_batch_cdm, `vector` applies; to rodas4's lanes too), any other
    the per-lane rounds of pdw_batch_method (dt is then the first step).
    next_walker: a shared (1,) counter (start it at i0): the threads that call this on the same
    range [i0, i1) take their walkers from it one by one (atomically), so every lane of every
    thread keeps busy until the batch runs out; None: the range is this call's alone.
    isa: the lane loop of cdm and rodas4, a value of ISAS (-1: per-lane scalar stages; an
    unsupported one falls back to it).
    grounds: None (every walker on flat ground), or N entries, each a `CGround` (that walker's
    shaped or patched ground, docs/terrain.md) or None (flat); needs isa = -1 and vector False
    (the per-lane scalar stages, bitwise the scalar runs).

    x0 (N, 8); p (N, NP) or (1, NP) (one vector for all); flags0 (N, 2) intc; hip, depth (N,).
    out: the dict of output arrays made by pdw.sim.batch (status, stop_reason, flags_final,
    x_final, t_final, n_steps, n_gait_steps, n_touch_down, n_lift_off, gait, fail_reason,
    fail_leg, fail_t, fail_x). Threads may call this at once on disjoint ranges of one `out`.
    Every PDW_BATCH_POLL lockstep steps the loop polls for Ctrl-C (main thread) and the
    thread's cancel token (`pdw.core.interrupt`); then it writes its running walkers as they
    are (status 0, running) and KeyboardInterrupt is raised here.
    """
    if k < 0 or k >= PDW_NKERNELS:
        raise ValueError("kernel id %d out of range [0, %d)" % (k, PDW_NKERNELS))
    if pdw_kernels[k].nx != PDW_NX:
        raise ValueError("kernel %d has a %d-entry state: the ensemble engine runs the smooth "
                         "Coulomb law's kernels only" % (k, pdw_kernels[k].nx))
    if lanes < 1 or lanes > PDW_BATCH_MAXW:
        raise ValueError("lanes must be in [1, %d], got %d" % (PDW_BATCH_MAXW, lanes))
    cdef long n = x0.shape[0]
    if x0.shape[1] != PDW_NX or p.shape[1] != PDW_NP or (p.shape[0] != n and p.shape[0] != 1):
        raise ValueError("x0 must be (N, %d) and p (N or 1, %d)" % (PDW_NX, PDW_NP))
    if not (0 <= i0 <= i1 <= n):
        raise ValueError("range [%d, %d) not within [0, %d]" % (i0, i1, n))
    if method < 0 or method >= pdw_nmethods:
        raise ValueError("method id %d out of range [0, %d)" % (method, pdw_nmethods))
    cdef pdw_batch_job job
    _fill_opts(&job.opt, opts, pdw_methods[method].adaptive, PDW_STEP_RING)   # the one filler
    if job.opt.record_every or job.opt.record_events:
        raise ValueError("opts: the ensemble records no samples and stores no events "
                         "(record_every and record_events must be 0)")
    missing = [key for key in _OUT_KEYS if key not in out]
    if missing:
        raise ValueError("out lacks the array(s) %s" % ", ".join(missing))
    cdef Py_ssize_t r
    for r in range(flags0.shape[0]):
        if flags0.shape[1] == 2 and ((flags0[r, 0] != 0 and flags0[r, 0] != 1)
                                     or (flags0[r, 1] != 0 and flags0[r, 1] != 1)):
            raise ValueError("flags0 row %d must be 0 or 1, got (%d, %d)"
                             % (r, flags0[r, 0], flags0[r, 1]))
    for key, spec in _OUT_SPECS.items():
        why = _fault("out[%r]" % key, out[key], spec)
        if why is not None:
            raise ValueError(why)
    cdef int[::1] status = out["status"]
    cdef int[::1] stop_reason = out["stop_reason"]
    cdef int[:, ::1] flags_final = out["flags_final"]
    cdef double[:, ::1] x_final = out["x_final"]
    cdef double[::1] t_final = out["t_final"]
    cdef long[::1] n_taken = out["n_steps"]
    cdef long[::1] n_gait = out["n_gait_steps"]
    cdef long[::1] n_td = out["n_touch_down"]
    cdef long[::1] n_lo = out["n_lift_off"]
    cdef double[:, :, ::1] gait = out["gait"]
    cdef int[::1] fail_reason = out["fail_reason"]
    cdef int[::1] fail_leg = out["fail_leg"]
    cdef double[::1] fail_t = out["fail_t"]
    cdef double[:, ::1] fail_x = out["fail_x"]
    if (status.shape[0] != n or x_final.shape[0] != n or gait.shape[0] != n
            or gait.shape[1] != PDW_STEP_RING or gait.shape[2] != PDW_NSTEP):
        raise ValueError("output arrays do not match N = %d" % n)
    # every other array, checked before a pointer is taken (issue 16: the compiled boundary)
    for name, got, want in (
            ("flags0", (flags0.shape[0], flags0.shape[1]), (n, 2)),
            ("hip", (hip.shape[0],), (n,)), ("depth", (depth.shape[0],), (n,)),
            ("out['stop_reason']", (stop_reason.shape[0],), (n,)),
            ("out['flags_final']", (flags_final.shape[0], flags_final.shape[1]), (n, 2)),
            ("out['x_final']", (x_final.shape[0], x_final.shape[1]), (n, PDW_NX)),
            ("out['t_final']", (t_final.shape[0],), (n,)),
            ("out['n_steps']", (n_taken.shape[0],), (n,)),
            ("out['n_gait_steps']", (n_gait.shape[0],), (n,)),
            ("out['n_touch_down']", (n_td.shape[0],), (n,)),
            ("out['n_lift_off']", (n_lo.shape[0],), (n,)),
            ("out['fail_reason']", (fail_reason.shape[0],), (n,)),
            ("out['fail_leg']", (fail_leg.shape[0],), (n,)),
            ("out['fail_t']", (fail_t.shape[0],), (n,)),
            ("out['fail_x']", (fail_x.shape[0], fail_x.shape[1]), (n, PDW_NX))):
        if got != want:
            raise ValueError("%s must have shape %s, got %s" % (name, want, got))
    if grounds is not None:
        if len(grounds) != n:
            raise ValueError("grounds must have N = %d entries, got %d" % (n, len(grounds)))
        if isa >= 0 or vector:
            raise ValueError("walkers on a ground run the per-lane scalar stages: isa must be "
                             "-1 and vector False")
        for r in range(n):
            if grounds[r] is not None and not isinstance(grounds[r], CGround):
                raise ValueError("grounds[%d] must be a CGround or None" % r)
    if n == 0 or i0 == i1:
        return 0
    job.grounds = NULL
    job.kernel = &pdw_kernels[k]
    job.n = n
    job.x0 = &x0[0, 0]
    job.p = &p[0, 0]
    job.p_stride = PDW_NP if p.shape[0] == n and n > 1 else 0
    job.flags0 = &flags0[0, 0]
    job.fall_hip_height = &hip[0]
    job.fall_depth = &depth[0]
    job.method = method
    job.status = &status[0]
    job.stop_reason = &stop_reason[0]
    job.flags_final = &flags_final[0, 0]
    job.x_final = &x_final[0, 0]
    job.t_final = &t_final[0]
    job.n_taken = &n_taken[0]
    job.n_gait = &n_gait[0]
    job.n_touch_down = &n_td[0]
    job.n_lift_off = &n_lo[0]
    job.gait = &gait[0, 0, 0]
    job.fail_reason = &fail_reason[0]
    job.fail_leg = &fail_leg[0]
    job.fail_t = &fail_t[0]
    job.fail_x = &fail_x[0, 0]
    cdef long lane_steps = 0
    job.lane_steps = &lane_steps
    job.next_walker = NULL
    if next_walker is not None:
        if next_walker.shape[0] != 1:
            raise ValueError("next_walker must have shape (1,), got (%d,)" % next_walker.shape[0])
        job.next_walker = &next_walker[0]
    cdef list pending = []
    job.poll = _poll
    job.poll_ctx = <void *> pending
    cdef const pdw_ground **gp = NULL
    cdef CGround cg
    if grounds is not None:
        gp = <const pdw_ground **> malloc(n * sizeof(pdw_ground *))
        if gp == NULL:
            raise MemoryError()
        for r in range(n):
            if grounds[r] is None:
                gp[r] = NULL
            else:
                cg = grounds[r]
                gp[r] = &cg.g
        job.grounds = gp
    cdef pdw_sim *sims = <pdw_sim *> malloc(lanes * sizeof(pdw_sim))
    if sims == NULL:
        free(gp)
        raise MemoryError()
    cdef pdw_soa_state *soa = NULL
    # 64-byte aligned: the first 8 lanes of a row are one cache line
    if posix_memalign(<void **> &soa, 64, sizeof(pdw_soa_state)) != 0:
        free(sims)
        free(gp)
        raise MemoryError()
    cdef pdw_ros_soa *ros = NULL
    if method != 0 and isa >= 0 and posix_memalign(<void **> &ros, 64, sizeof(pdw_ros_soa)) != 0:
        free(sims)
        free(soa)
        free(gp)
        raise MemoryError()
    cdef long done
    try:
        with nogil:
            if method == 0 and isa >= 0:
                done = pdw_batch_cdm_soa(&job, i0, i1, lanes, sims, vector, isa, soa)
            elif method == 0:
                done = pdw_batch_cdm(&job, i0, i1, lanes, sims, vector)
            elif isa >= 0:
                # rodas4's structure-of-arrays lanes (any other method: pdw_batch_method)
                done = pdw_batch_rodas4_soa(&job, i0, i1, lanes, sims, vector, isa, ros)
            else:
                done = pdw_batch_method(&job, i0, i1, lanes, sims)
    finally:
        free(sims)
        free(soa)
        free(ros)
        free(gp)
    with _lane_lock:
        _lane_steps[0] += lane_steps
    if pending:             # Ctrl-C (or a cancelled pool): the rows written so far stay
        raise pending[0]
    return done
