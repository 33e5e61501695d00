# The options a compiled loop reads (pdw_run_opts of csrc/pdw_sim.h), declared once for
# _core.pyx and _batch.pyx. A run's `opts` dict (pdw.sim.options.c_options) sets fields by these
# names, so an option with no argument of its own needs only its line here.
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


cdef void _set_opts(pdw_run_opts *o, dict opts) except *:
    """Set the fields of ``o`` named in ``opts`` (unknown names: ValueError naming them)."""
    cdef dict current
    if not opts:
        return
    current = o[0]                  # the struct as a dict (Cython converts both ways)
    unknown = sorted(set(opts) - set(current))
    if unknown:
        raise ValueError("opts: no field(s) %s in pdw_run_opts" % ", ".join(unknown))
    current.update(opts)
    o[0] = current
