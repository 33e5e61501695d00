# The options a compiled loop reads (pdw_run_opts of csrc/pdw_sim.h), declared once for
# _core.pyx and _batch.pyx, and the ONE filler of that struct both entry points use
# (`_core.run` and `_batch.run_range` take a run's options as one record, never field by field).
# The record is a dict keyed by the struct's field names (`pdw.sim.options.c_options` makes it
# from the option objects): an option of the loops that is new needs its field in pdw_sim.h and
# its line here, nothing else in Cython (tests/test_run_opts.py checks the two agree).
# Needs _shapes.pxi's _count (included by the module too).
from libc.math cimport isfinite

cdef extern from "pdw_sim.h":
    ctypedef struct pdw_run_opts:
        double dt
        long n_steps
        double t_end
        double rtol, atol
        double h_max
        double event_tol
        long max_steps
        long record_every
        int record_events
        long stop_steps
        int stop_touch_down
        int periodic_k
        double periodic_tol
        double fall_hip_height
        double fall_depth
        double max_speed


cdef pdw_run_opts _OPTS_ZERO            # C static: every field 0 (off, or derived by the filler)
#: The fields of pdw_run_opts, each 0: a record's missing fields.
OPT_FIELDS = dict(<dict> _OPTS_ZERO)


cdef int _fill_opts(pdw_run_opts *o, dict opts, bint adaptive, int step_ring) except -1:
    """Fill ``o`` from a run's options ``opts`` (field name -> value; a field not given is 0:
    off), check them and derive what the loops read. The one filler of the struct, used by
    `_core.run` and `_batch.run_range`.

    Checked (an error names the field): unknown names; integers for the integer fields; dt finite and > 0; n_steps,
    record_every, stop_steps, max_steps counts in [0, MAX_COUNT]; stop_touch_down 0, 1 or 2;
    periodic_k 0 or in [2, step_ring]; periodic_tol >= 0; max_speed > 0; with an adaptive
    method rtol, atol and event_tol > 0. Derived: t_end 0 -> n_steps dt (fixed-step methods
    end there), h_max 0 -> t_end, max_steps -> 0 (no budget) for fixed-step methods.
    """
    if opts is None:
        raise TypeError("opts must be a dict of pdw_run_opts fields (pdw.sim.options.c_options)")
    for name, v in opts.items():
        zero = OPT_FIELDS.get(name)
        if zero is None:
            unknown = sorted(set(opts) - set(OPT_FIELDS))
            raise ValueError("opts: no field(s) %s in pdw_run_opts" % ", ".join(unknown))
        if type(zero) is int and not hasattr(v, "__index__"):   # 1.5 steps: no silent cut
            raise _InvalidInputError("opts[%r] = %r: pdw_run_opts.%s is an integer"
                                     % (name, v, name))
    cdef dict full = OPT_FIELDS.copy()
    full.update(opts)
    try:
        o[0] = full
    except (OverflowError, TypeError, ValueError):
        for name, zero in OPT_FIELDS.items():     # name the field that does not fit its C type
            one = OPT_FIELDS.copy()
            one[name] = full[name]
            try:
                o[0] = one
            except (OverflowError, TypeError, ValueError):
                raise _InvalidInputError("opts[%r] = %r does not fit pdw_run_opts.%s (a C %s)"
                                         % (name, full[name], name,
                                            "double" if isinstance(zero, float) else "integer")
                                         ) from None
        raise
    if not (o.dt > 0 and isfinite(o.dt)):
        raise ValueError("dt must be finite and > 0, got %r" % o.dt)
    _count("n_steps", o.n_steps, 0)
    _count("record_every", o.record_every, 0)
    _count("stop_steps", o.stop_steps, 0)
    _count("max_steps", o.max_steps, 0)
    if o.stop_touch_down < 0 or o.stop_touch_down > 2:
        raise ValueError("stop_touch_down must be 0 (off), 1 or 2, got %d" % o.stop_touch_down)
    if o.periodic_k < 0 or o.periodic_k == 1 or o.periodic_k > step_ring or not (o.periodic_tol >= 0):
        raise ValueError("periodic_k must be 0 (off) or in [2, %d] and periodic_tol >= 0, got %d, %r"
                         % (step_ring, o.periodic_k, o.periodic_tol))
    if not (o.max_speed > 0):
        raise ValueError("max_speed must be > 0, got %r" % o.max_speed)
    if adaptive and not (o.rtol > 0 and o.atol > 0 and o.event_tol > 0):
        raise ValueError("rtol, atol and event_tol must be > 0, got %r, %r, %r"
                         % (o.rtol, o.atol, o.event_tol))
    if o.t_end <= 0:
        o.t_end = o.n_steps * o.dt      # adaptive methods end exactly at t_end
    if o.h_max <= 0:
        o.h_max = o.t_end
    if not adaptive:
        o.max_steps = 0
    return 0
