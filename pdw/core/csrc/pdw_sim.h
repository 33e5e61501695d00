/* The compiled time loops: discrete contact state, recording, stop conditions.
 *
 * A pdw_sim holds everything one simulation needs. The caller (pdw/core/_core.pyx) allocates
 * every array; the loops allocate nothing. A loop advances until it finishes, fails, or
 * fills its event buffer; in the last case the caller grows the buffer and calls again,
 * and the loop resumes exactly where it stopped (all loop state lives in the struct). */
#ifndef PDW_SIM_H
#define PDW_SIM_H

#include <math.h>
#include <string.h>
#include "pdw_model.h"
#include "pdw_terrain.h"

/* Discrete state carried by every loop (docs/model.md sections 5 and 6). */
typedef struct pdw_discrete {
    int flags[2];       /* 1 = support, 0 = swing */
    int armed[2];       /* swing foot has been above ground while ahead of the other foot */
    double anchors[PDW_NANCHOR];  /* per foot, captured at touch-down (layout ANCHORS): the rolling
                                   * coordinate s_i (consistent variant's xi), then the approach
                                   * speed -v_y (Lankarani-Nikravesh and Flores damping) */
    int zone[2];        /* shaped ground with patches: the blend zone of each support foot's
                         * contact point (pdw_ground_zone; -1 swing); a change is an event that
                         * adaptive methods locate (docs/terrain.md) */
} pdw_discrete;

/* Why and where a loop failed. */
typedef struct pdw_failure {
    double t;           /* time of the last good state [s] */
    double x[PDW_NX_MAX];   /* that state (the first pdw_sim.nx entries) */
    int leg;            /* leg involved (fell through the ground), or -1 */
    int reason;         /* PDW_REASON_* */
} pdw_failure;

/* PDW_REASON_*: generated from derive/layout.py's REASON (pdw_model.h), with the messages
 * pdw/core/_layout.py's REASON_TEXT gives Python. */

/* Online gait analysis (docs/model.md section 8): the per-step descriptors of pdw/sim/gait.py, computed
 * as the events happen, in O(1) memory: the latest touch-down and lift-off of each leg, counts,
 * and the last PDW_STEP_RING complete steps (layout PDW_STEP_*) in a ring buffer. */
typedef struct pdw_gait {
    double td_t[2], td_x[2];    /* each leg's latest touch-down: time [s], contact point x_D [m] */
    double lo_t[2], lo_x[2];    /* each leg's latest lift-off */
    int has_td[2], has_lo[2];
    double prev_td_t;           /* the latest touch-down of either leg */
    int has_prev_td;
    int ds_leg;                 /* the latest step's double support ends at this leg's lift-off;
                                 * -1: none awaited */
    long n_steps;               /* complete steps so far (the rows pdw.steps would give) */
    long n_touch_down, n_lift_off;
    double ring[PDW_STEP_RING][PDW_NSTEP];   /* step k (from 0) is ring[k % PDW_STEP_RING] */
} pdw_gait;

/* PDW_STATUS_RECORDS_FULL and PDW_STATUS_POLL, the returns of a loop that never reach a Result
 * (the caller grows the record buffer, or checks for signals, and resumes), the record buffer
 * sizes and the poll interval: generated from derive/layout.py's RESUME (pdw_model.h), with
 * the messages pdw/core/_layout.py's RESUME_TEXT gives Python. */

/* The options a loop reads: pdw.sim.options' Integrator, Record, Stop and Limits as C (plus
 * n_steps and the fixed t_end, derived from them). Filled once before a run (pdw/core/_core.pyx
 * run; the ensemble's job->opt, pdw_batch.c) and never written by a loop: the loops read them
 * through s->opt, the run state is the rest of pdw_sim. A new stop condition is one field here
 * (and its line in pdw/core/_opts.pxi), the loop that tests it (pdw_discrete.c for the gait's),
 * and its option in pdw/sim/options.py with this field's name (c=...), which the run sets. */
typedef struct pdw_run_opts {
    /* Integrator */
    double dt;                  /* step [s] (adaptive methods: the first trial step) */
    long n_steps;               /* number of steps to take (fixed-step methods) */
    double t_end;               /* end time [s] (adaptive methods; = n_steps*dt for fixed) */
    double rtol, atol;          /* tolerances of adaptive methods */
    double h_max;               /* largest step of adaptive methods [s] */
    double event_tol;           /* adaptive methods: a flag switch is located to within this [s] */
    long max_steps;             /* adaptive methods: fail (PDW_REASON_BUDGET) once accepted +
                                 * rejected steps reach this; 0: no budget */
    /* Record */
    long record_every;          /* record every k-th step; 0 = record nothing */
    int record_events;          /* 1: store every event in `events`; 0: only count them (the
                                 * online gait analysis sees them either way) */
    /* Stop */
    long stop_steps;            /* stop (PDW_STATUS_DONE, PDW_STOP_STEPS) at this many complete
                                 * gait steps; 0: no limit */
    int stop_touch_down;        /* 1 or 2: stop (PDW_STATUS_DONE, PDW_STOP_TOUCH_DOWN) at that leg's
                                 * first touch-down (the state then is the event's); 0: off */
    int periodic_k;             /* stop (PDW_STATUS_PERIODIC) when the last periodic_k steps agree:
                                 * each PDW_PERIODIC_FIELDS descriptor within periodic_tol (relative,
                                 * max - min <= tol |latest|); 0: off. 2 <= k <= PDW_STEP_RING */
    double periodic_tol;
    /* Limits */
    double fall_hip_height;     /* fell when y_o < this [m] */
    double fall_depth;          /* fell when a foot is deeper than this [m] */
    double max_speed;           /* diverged when |qd_i| > this [m/s, rad/s] */
} pdw_run_opts;

typedef struct pdw_sim {
    /* --- model (inputs) --- */
    const pdw_kernel *kernel;
    int nx;                     /* size of the continuous state: kernel->nx (PDW_NX, or
                                 * PDW_NX_LUGRE with the bristle states) */
    double p[PDW_NP];           /* parameters + derived constants (pdw_precompute) */
    /* --- options (inputs, read only by the loops) --- */
    pdw_run_opts opt;
    /* --- outputs (caller-allocated) --- */
    double *rec_t;              /* (rec_capacity,) */
    double *rec_x;              /* (rec_capacity, nx) */
    int *rec_flags;             /* (rec_capacity, 2) */
    double *rec_contact;        /* (rec_capacity, PDW_NREC), may be NULL */
    long rec_capacity, n_rec;
    double *events;             /* (ev_capacity, PDW_NEVENT) */
    long ev_capacity, n_events;
    /* --- loop state --- */
    long n;                     /* steps taken (accepted) */
    double t;                   /* time of x [s] */
    double h;                   /* next step size of adaptive methods [s] */
    double x[PDW_NX_MAX];       /* state at step n: [U_n, U'_n] (and the bristle states z) */
    double u_prev[PDW_NQ];      /* U_{n-1} (central difference) */
    int started;
    pdw_discrete disc;
    double work[PDW_NWORK];
    double cache[PDW_NX_MAX];   /* method-private: f(x) (FSAL) or verlet's a_n, for exact resumption */
    int cache_valid;            /* cache holds a value for the current x and discrete state */
    double err_prev;            /* adaptive methods: previous accepted error (step controllers) */
    double h_prev;              /* adaptive methods: previous accepted step (0: none yet) */
    double cdm_kdiag[2], cdm_kinv[2];   /* cdm: K[2][2], K[3][3] of the last step and their
                                         * inverses (pdw_cdm_update; 0: none) */
    double cdm_dt, cdm_idt2, cdm_ih;    /* cdm: the dt that 1/dt^2 and 1/(2 dt) were computed for
                                         * (0: none) */
    /* --- work counters (every method) --- */
    long n_rhs, n_jac, n_rejected;
    /* --- online gait analysis (every method; see pdw_update_flags) --- */
    pdw_gait gait;
    /* --- termination --- */
    int status;                 /* PDW_STATUS_* */
    int stop_reason;            /* PDW_STOP_*: which stop condition ended the run (NONE: t_end or a failure) */
    pdw_failure failure;
    /* --- interruptibility (see PDW_STATUS_POLL) --- */
    long poll_every;            /* return PDW_STATUS_POLL every this many loop iterations; 0: never */
    long since_poll;            /* iterations since the last poll */
    /* --- the ground (docs/terrain.md) --- */
    const pdw_ground *ground;   /* NULL: flat (today's kernel, bitwise); else the shaped-ground
                                 * kernel of pdw_terrain.c on this caller-owned table */
} pdw_sim;

/* The stages of s's model: today's kernel on flat ground, the shaped-ground kernel on a ground.
 * Every loop calls these; with s->ground == NULL each is the kernel's own call. */
static inline void pdw_sim_kinematics(const pdw_sim *s, const double *x, const double *anchors,
                                      double *work)
{
    if (s->ground)
        pdw_terrain_kinematics(s->kernel, s->ground, x, work + PDW_WORK_TRIG, s->p, anchors,
                               work + PDW_WORK_KIN, work + PDW_WORK_GROUND,
                               work + PDW_WORK_GROUND_CELL);
    else s->kernel->kinematics(x, work + PDW_WORK_TRIG, s->p, anchors, work + PDW_WORK_KIN);
}

/* pdw_sim_kinematics of s->x with s's discrete state for pdw_update_flags_trig (on a shaped
 * ground pdw_terrain_flag_kinematics: the values its rules and the stages after it read). */
static inline void pdw_sim_flag_kinematics(const pdw_sim *s, double *work)
{
    if (s->ground)
        pdw_terrain_flag_kinematics(s->kernel, s->ground, s->x, work + PDW_WORK_TRIG, s->p,
                                    s->disc.anchors, s->disc.flags, s->opt.fall_depth,
                                    work + PDW_WORK_KIN, work + PDW_WORK_GROUND,
                                    work + PDW_WORK_GROUND_CELL);
    else s->kernel->kinematics(s->x, work + PDW_WORK_TRIG, s->p, s->disc.anchors,
                               work + PDW_WORK_KIN);
}

static inline void pdw_sim_contact(const pdw_sim *s, double *work)
{
    if (s->ground && s->ground->n_patches > 0)
        pdw_terrain_contact(s->kernel, s->ground, work + PDW_WORK_KIN, s->disc.flags, s->p,
                            work + PDW_WORK_CONTACT, 0);
    else s->kernel->contact(work + PDW_WORK_KIN, s->disc.flags, s->p, work + PDW_WORK_CONTACT);
    /* (a ground without patches: the kernel's own stage, as pdw_terrain_contact calls it) */
}

static inline void pdw_sim_rhs(const pdw_sim *s, const double *x, double *xdot, double *work)
{
    if (s->ground)
        pdw_terrain_rhs(s->kernel, s->ground, x, s->p, s->disc.flags, s->disc.anchors, xdot, work);
    else s->kernel->rhs(x, s->p, s->disc.flags, s->disc.anchors, xdot, work);
}

static inline void pdw_sim_jacobian(const pdw_sim *s, const double *x, double *J, double *work)
{
    if (s->ground)
        pdw_terrain_jacobian(s->kernel, s->ground, x, s->p, s->disc.flags, s->disc.anchors, J, work);
    else s->kernel->jacobian(x, s->p, s->disc.flags, s->disc.anchors, J, work);
}

/* Copy a state of s's size (s->nx); the common size PDW_NX as a compile-time constant, so that
 * the copy stays inline in the time loops. */
static inline void pdw_copy_state(const pdw_sim *s, double *dst, const double *src)
{
    if (s->nx == PDW_NX) memcpy(dst, src, PDW_NX * sizeof(double));
    else memcpy(dst, src, (size_t)s->nx * sizeof(double));
}

/* Is a poll due (counts one loop iteration)? Sets s->status = PDW_STATUS_POLL when it is. */
static inline int pdw_poll_due(pdw_sim *s)
{
    if (s->poll_every <= 0 || ++s->since_poll < s->poll_every) return 0;
    s->since_poll = 0;
    s->status = PDW_STATUS_POLL;
    return 1;
}

/* Room for one more sample and a final one? (checked at the top of a loop iteration, where a
 * return resumes exactly) */
static inline int pdw_records_room(const pdw_sim *s)
{
    return s->opt.record_every <= 0 || s->n_rec + 2 <= s->rec_capacity;
}

/* Initialise the discrete state for x0 and initial flags: anchors of support legs at x0
 * (kinematics on ground g; NULL: flat). */
void pdw_discrete_init(const pdw_kernel *k, const pdw_ground *g, const double *p, const double *x,
                       const int flags0[2], pdw_discrete *d, double *work);

/* Update flags and arming once from s->x (docs/model.md section 5); each flag change is an event:
 * stored in s->events (if record_events), counted, and fed to the online gait analysis
 * (s->gait), which checks the stop conditions (stop_steps, periodic_k) at each complete step.
 * Leaves the trig and kinematics of s->x (with the new anchors) in s->work. Returns 0; -1 when
 * the event buffer is full (nothing changed then; the caller returns PDW_STATUS_EVENTS_FULL);
 * 1 when a stop condition was met (s->status and s->stop_reason are set: the caller stores the
 * final sample with pdw_record_final and returns s->status). */
int pdw_update_flags(pdw_sim *s, double t);

/* pdw_update_flags with the trig of s->x already in s->work (PDW_WORK_TRIG): the ensemble
 * engine (pdw_batch.c) computes the sin/cos of all its lanes in one vector loop first. */
int pdw_update_flags_trig(pdw_sim *s, double t);

/* Room for `n` more events (always, when events are not stored)? */
static inline int pdw_events_room(const pdw_sim *s, long n)
{
    return !s->opt.record_events || s->n_events + n <= s->ev_capacity;
}

/* Reset the online gait analysis (before the first step). */
void pdw_gait_init(pdw_gait *g);

/* The checks of pdw_check_feet and pdw_check_state in their order, with the failure's status,
 * reason and leg set (pdw_discrete.c): the slow path, taken only when a check failed. */
int pdw_check_feet_fail(pdw_sim *s, double t);
int pdw_check_state_fail(pdw_sim *s, const double *xnew, double t);

/* After pdw_update_flags: fell if a foot is deeper than fall_depth (sets status, returns 1). */
static inline int pdw_check_feet(pdw_sim *s, double t)
{
    const double *kin = s->work + PDW_WORK_KIN;
    if (kin[PDW_KIN_Y_D] < -s->opt.fall_depth || kin[PDW_NKIN + PDW_KIN_Y_D] < -s->opt.fall_depth)
        return pdw_check_feet_fail(s, t);
    return 0;
}

/* Check a new state (finite, speeds, hip height, on a shaped ground the hip within a leg length
 * of the defined extent's ends); on failure sets s->status and s->failure and returns nonzero.
 * Inline, every check one flag and one branch for all (a NaN fails every comparison here): only
 * a failed state takes pdw_check_state_fail, which finds the first failed check in order. */
static inline int pdw_check_state(pdw_sim *s, const double *xnew, double t)
{
    int ok = 1;
    for (int i = 0; i < PDW_NQ; ++i) ok &= xnew[i] - xnew[i] == 0.0;     /* finite */
    for (int i = PDW_NQ; i < PDW_NX; ++i) ok &= fabs(xnew[i]) <= s->opt.max_speed;
    for (int i = PDW_NX; i < s->nx; ++i) ok &= xnew[i] - xnew[i] == 0.0;
    ok &= xnew[PDW_X_Y_O] >= s->opt.fall_hip_height;
    if (s->ground)
        ok &= (xnew[PDW_X_X_O] - s->p[PDW_P_L] >= s->ground->s_min)
              & (xnew[PDW_X_X_O] + s->p[PDW_P_L] <= s->ground->s_max);
    return ok ? 0 : pdw_check_state_fail(s, xnew, t);
}
/* The central difference method's start-up and one update (pdw_cdm.c), shared by
 * pdw_cdm_advance and the lane loop of pdw_batch.c. */
void pdw_cdm_start(pdw_sim *s);
int pdw_cdm_update(pdw_sim *s, const double *M, const double *C, const double *QmG, double t);

/* A stop condition ended the run at s->x (time t) right after pdw_update_flags: store the
 * sample if step n is a recording step (contact forces computed here). */
void pdw_record_final(pdw_sim *s, double t);

/* Store a sample of s->x at time t now, whatever n (if there is room); the contact forces are
 * taken from s->work's contact block, which the caller must have filled for s->x. */
void pdw_record_now(pdw_sim *s, double t);

/* Store sample n (time t) if it is a recording step. */
static inline void pdw_record(pdw_sim *s, double t)
{
    if (s->opt.record_every <= 0 || s->n % s->opt.record_every != 0) return;
    pdw_record_now(s, t);
}

/* Would pdw_update_flags change the discrete state (flag, arming) at state x? Returns a bit
 * mask (bit i: leg i), 0 if nothing would change. Mirrors pdw_update_flags's rules exactly;
 * adaptive methods use it to locate switches inside a step. work: PDW_NWORK scratch. */
int pdw_switch_pending(const pdw_sim *s, const double *x, double *work);

/* --- the integrators: one module each, all behind this contract ---------------------------
 * advance(s): take steps from s->x (time s->t, step count s->n) until s->t reaches t_end (or
 * n_steps for fixed-step methods), updating the discrete state once per step through
 * pdw_update_flags, recording through pdw_record, checking each new state with
 * pdw_check_state, counting work in n_rhs / n_jac / n_rejected. When pdw_update_flags reports
 * a stop condition (returns 1) the method stores the final sample (fixed step: pdw_record_final;
 * adaptive: always, as at t_end) and returns s->status at once.
 * Returns s->status: PDW_STATUS_DONE, PDW_STATUS_PERIODIC, a failure, or
 * PDW_STATUS_EVENTS_FULL (the caller grows s->events and calls again; the method resumes where
 * it stopped). */
typedef int (*pdw_advance_fn)(pdw_sim *s);

typedef struct pdw_method {
    const char *name;
    int order;          /* order of accuracy of the state on smooth problems */
    int adaptive;       /* 1: uses rtol/atol and t_end; 0: fixed step dt, n_steps */
    pdw_advance_fn advance;
} pdw_method;

extern const pdw_method pdw_methods[];
extern const int pdw_nmethods;

/* The paper's central difference method (docs/model.md section 7). Returns s->status. */
int pdw_cdm_advance(pdw_sim *s);

/* Integrators beyond the paper's (docs/integrators.md); one module each. */
int pdw_verlet_advance(pdw_sim *s);   /* pdw_verlet.c: velocity Verlet, order 2, fixed step */
int pdw_rk4_advance(pdw_sim *s);      /* pdw_rk4.c: classical Runge-Kutta, order 4, fixed step */
int pdw_dopri5_advance(pdw_sim *s);   /* pdw_dopri5.c: Dormand-Prince 5(4), adaptive */
int pdw_rodas4_advance(pdw_sim *s);   /* pdw_rodas4.c: Rosenbrock RODAS4(3), adaptive, stiff */

#endif /* PDW_SIM_H */
