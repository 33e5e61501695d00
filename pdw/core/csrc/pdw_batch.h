/* The ensemble engine: many walkers, one block of W lanes advanced in lockstep (docs/ensemble.md).
 *
 * A job describes N walkers (initial states, parameter vectors, fall thresholds) and the
 * caller-allocated per-walker outputs. pdw_batch_cdm advances walkers [i0, i1) of a job
 * through the paper's central difference method (pdw_cdm.c, docs/model.md section 7) in blocks of
 * W lanes: each lane is a pdw_sim (its own time, flags, arming, anchors, events, online gait
 * descriptors, through pdw_discrete.c), the sin/cos of all lanes are computed in one loop the
 * compiler vectorizes (pdw_batch_trig.c), and a lane whose walker finishes is refilled with
 * the next walker at once. Threads take disjoint ranges [i0, i1) of one job, or share one
 * range through job->next_walker. */
#ifndef PDW_BATCH_H
#define PDW_BATCH_H

#include "pdw_sim.h"
#include "pdw_tableaus.h"

enum { PDW_BATCH_MAXW = 64 };
/* the row stride of pdw_soa_state: the generated stages' PDW_SOA (generated/pdw_batch_gen.h) */
enum { PDW_SOA_STRIDE = 72 };
/* room for the generated stages' PDW_SOA_NKC rows of per-walker constants */
enum { PDW_SOA_KC_ROWS = 8 };

typedef struct pdw_batch_job {
    /* --- inputs --- */
    const pdw_kernel *kernel;
    long n;                     /* walkers */
    const double *x0;           /* (n, PDW_NX) initial states */
    const double *p;            /* (n, PDW_NP) parameter vectors; (1, PDW_NP) with p_stride 0 */
    long p_stride;              /* PDW_NP, or 0 (one parameter vector for all) */
    const int *flags0;          /* (n, 2) initial support flags */
    const double *fall_hip_height;  /* (n,) [m]: each walker's opt.fall_hip_height */
    const double *fall_depth;       /* (n,) [m]: each walker's opt.fall_depth */
    pdw_run_opts opt;           /* the options of every walker, as pdw.simulate's pdw_sim has
                                 * them (pdw/core/_core.pyx run); nothing recorded (record_every
                                 * = record_events = 0); t_end = n_steps dt for cdm. The fall
                                 * limits above replace opt's per walker */
    int method;                 /* index into pdw_methods (pdw_batch_method) */
    /* the ground of each walker (docs/terrain.md): NULL (all flat), else (n,) pointers, NULL
     * entries flat. A walker on a ground runs the shaped-ground kernel through the per-lane
     * scalar stages (pdw_batch_cdm or pdw_batch_method; _batch.pyx never gives grounds to the
     * structure-of-arrays loops): bitwise its pdw.simulate run. */
    const pdw_ground *const *grounds;
    /* --- outputs, per walker (caller-allocated) --- */
    int *status;                /* (n,) PDW_STATUS_* */
    int *stop_reason;           /* (n,) PDW_STOP_* */
    int *flags_final;           /* (n, 2) */
    double *x_final;            /* (n, PDW_NX) */
    double *t_final;            /* (n,) */
    long *n_taken;              /* (n,) steps taken */
    long *n_gait;               /* (n,) complete gait steps */
    long *n_touch_down, *n_lift_off;  /* (n,) */
    double *gait;               /* (n, PDW_STEP_RING, PDW_NSTEP): the last min(n_gait,
                                 * PDW_STEP_RING) steps, oldest first, rows beyond NaN */
    int *fail_reason, *fail_leg;/* (n,) PDW_REASON_*, leg (-1: none) */
    double *fail_t;             /* (n,) */
    double *fail_x;             /* (n, PDW_NX) */
    /* --- work sharing (may be NULL): the threads of one batch call their ranges on the whole
     * batch with one shared counter; each lane takes the next walker from it (atomically), so
     * no lane idles while a walker of the batch waits, whichever thread it would be in --- */
    long *next_walker;
    /* --- diagnostics (out, may be NULL): += the steps the structure-of-arrays lane loops
     * committed (the others went through the scalar step: events, failures, starts, ends) --- */
    long *lane_steps;
    /* --- interruptibility --- */
    int (*poll)(void *ctx);     /* called every PDW_BATCH_POLL lockstep steps (NULL: never); nonzero
                                 * stops: the running walkers are written with status running */
    void *poll_ctx;
} pdw_batch_job;

enum { PDW_BATCH_POLL = 512 };

/* The lanes of a block as structure of arrays: element i of lane l at a[i*PDW_SOA_STRIDE + l],
 * caller-allocated (64-byte aligned: a row's first 8 lanes are one cache line). The lane's pdw_sim holds everything else
 * (events, gait, counters, failure) and is brought up to date (x, u_prev, armed) whenever a
 * lane leaves the vector path. */
typedef struct pdw_soa_state {
    double x[PDW_NX*PDW_SOA_STRIDE], u_prev[PDW_NQ*PDW_SOA_STRIDE];
    double p[PDW_NP*PDW_SOA_STRIDE], anchors[PDW_NANCHOR*PDW_SOA_STRIDE];
    double hip[PDW_SOA_STRIDE], depth[PDW_SOA_STRIDE];
    /* 64-bit, as wide as the doubles: the lane loops that mix them vectorize with one vector
     * width (int32 rows halve it on AVX-512) */
    long long flags[2*PDW_SOA_STRIDE], armed[2*PDW_SOA_STRIDE], armed_next[2*PDW_SOA_STRIDE];
    long long upd[PDW_SOA_STRIDE];  /* 1: past the first step (the flags are updated first) */
    /* the lanes' step counters (the pdw_sim's n, t and n_rhs are brought up to date from n
     * when the lane leaves the vector path), each lane's n_steps, and 1 where the lane has a
     * walker: a round in which no walker has a rare step or its last commits with one vector
     * loop, without visiting the pdw_sim */
    long long n[PDW_SOA_STRIDE], nend[PDW_SOA_STRIDE], live[PDW_SOA_STRIDE];
    long long rare[PDW_SOA_STRIDE]; /* out: 1 = nothing committed, run the scalar step */
    double trig[PDW_NTRIG*PDW_SOA_STRIDE];
    double contact[2*PDW_NCONTACT*PDW_SOA_STRIDE];
    /* M[2][2], M[3][3] (the stage cdm_update keeps M, C and Q_f - G in registers) */
    double mdiag[2*PDW_SOA_STRIDE];
    /* the contact law's parameter-only temporaries of each lane (the kernel's contact_consts,
     * generated/pdw_batch_gen.h), computed again before the next step when kc_stale */
    double kc[PDW_SOA_KC_ROWS*PDW_SOA_STRIDE];
    int kc_stale;
    int first;      /* a lane may be at its first step (upd 0): set by a load */
    /* pdw_cdm_update's cache of the inverses of K's diagonal block, per lane: kdiag the
     * entries K[2][2], K[3][3] the inverses kinv were computed from (0: none) */
    double kdiag[2*PDW_SOA_STRIDE], kinv[2*PDW_SOA_STRIDE];
} pdw_soa_state;

/* The trig of lanes l < W from libm (bitwise pdw_trig): all lanes, or (only_first != 0) only
 * those at their first step (upd[l] == 0). */
void pdw_soa_trig_libm(pdw_soa_state *S, int W, int only_first);

/* The trig (PDW_NTRIG rows) of the leg angles of the SoA states x (PDW_NX rows), lanes
 * l < W, from libm: bitwise pdw_trig. */
void pdw_soa_trig_rows(int W, const double *x, double *trig);

/* rodas4's lanes as structure of arrays (pdw_batch_ros.inc; rows as pdw_soa_state's). A lane
 * holds its walker right after an accepted step (or its first); one attempt of every lane is
 * one call of the structure-of-arrays try step. */
typedef struct pdw_ros_soa {
    /* in: the lanes' points and attempts */
    double x[PDW_NX*PDW_SOA_STRIDE], fx[PDW_NX*PDW_SOA_STRIDE];   /* x and f(x) */
    double p[PDW_NP*PDW_SOA_STRIDE], anchors[PDW_NANCHOR*PDW_SOA_STRIDE];
    double hip[PDW_SOA_STRIDE], depth[PDW_SOA_STRIDE];
    double h[PDW_SOA_STRIDE];           /* the attempt's step */
    long long flags[2*PDW_SOA_STRIDE];  /* 64-bit: the generated contact stages' rows */
    int armed[2*PDW_SOA_STRIDE];
    int jac[PDW_SOA_STRIDE];            /* 1: a new point, J of x wanted */
    /* kept: J = d qdd / d x at x (row i*PDW_NX + j), the factors of the attempt */
    double J[PDW_NQ*PDW_NX*PDW_SOA_STRIDE];
    double LU[PDW_NQ*PDW_NQ*PDW_SOA_STRIDE], piv[PDW_NQ*PDW_SOA_STRIDE];
    /* out: the attempt */
    double xnew[PDW_NX*PDW_SOA_STRIDE], fnew[PDW_NX*PDW_SOA_STRIDE], err[PDW_SOA_STRIDE];
    int bad[PDW_SOA_STRIDE];    /* 1: singular matrix or non-finite error: the scalar step */
    double sing[PDW_SOA_STRIDE];/* 1.0: a zero or non-finite pivot */
    int rare[PDW_SOA_STRIDE];   /* 1: if accepted, a flag switch, a failure or a deep foot */
    /* scratch */
    double u[PDW_ROS_MAXSTAGES][PDW_NX*PDW_SOA_STRIDE], xs[PDW_NX*PDW_SOA_STRIDE];
    double trig[PDW_NTRIG*PDW_SOA_STRIDE], kin[2*PDW_NKIN*PDW_SOA_STRIDE];
    double contact[2*PDW_NCONTACT*PDW_SOA_STRIDE];
    double M[PDW_NQ*PDW_NQ*PDW_SOA_STRIDE], f[PDW_NQ*PDW_SOA_STRIDE], qdd[PDW_NQ*PDW_SOA_STRIDE];
    double A[PDW_NQ*PDW_NX*PDW_SOA_STRIDE], Jn[PDW_NQ*PDW_NX*PDW_SOA_STRIDE];
} pdw_ros_soa;

/* Instruction sets of the structure-of-arrays step (pdw_batch_soa_*.c); PDW_ISA_SCALAR: no
 * SoA step, every lane through the generated scalar stages (pdw_batch_cdm). */
enum { PDW_ISA_SCALAR = -1, PDW_ISA_BASE = 0, PDW_ISA_AVX2 = 1, PDW_ISA_AVX512 = 2 };

/* 1 if this CPU (and this build) can run the SoA step compiled for isa. */
int pdw_batch_isa_supported(int isa);

/* Advance walkers [i0, i1) of job as pdw_batch_cdm does, the ordinary steps of a block through
 * the structure-of-arrays step compiled for isa (S: caller-allocated). Falls back to
 * pdw_batch_cdm when the kernel has no batched stages or isa is PDW_ISA_SCALAR or unsupported.
 * Bitwise pdw_batch_cdm (and `pdw.simulate`) with vector = 0. Returns as pdw_batch_cdm. */
long pdw_batch_cdm_soa(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                       int vector, int isa, pdw_soa_state *S);

/* sin and cos of the n angles a into s and c through glibc's vector routines (libmvec). */
void pdw_batch_sincos(int n, const double *a, double *s, double *c);

/* Advance walkers [i0, i1) of job with W lanes (1 <= W <= PDW_BATCH_MAXW); lanes: W
 * caller-allocated pdw_sim. vector: 1 = vector sin/cos, 0 = scalar (bitwise `pdw.simulate`).
 * Returns the number of walkers finished (i1 - i0; fewer when job->poll stopped the range). */
long pdw_batch_cdm(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes, int vector);

/* Advance walkers [i0, i1) of job with any method of pdw_methods (job->method), W lanes in
 * rounds: each round takes one step (one accepted step of an adaptive method) of every lane
 * through the method's own advance (pdw_sim.h's contract, resumed exactly through
 * PDW_STATUS_POLL), so that each lane keeps its own time, step size, accept/reject, flags and
 * located events and every walker is bitwise its `pdw.simulate` run; a finished lane takes the
 * next walker. Returns the walkers finished (fewer when job->poll stopped the range). */
long pdw_batch_method(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes);

/* Advance walkers [i0, i1) of job one after the other, each through its method's own advance
 * (job->method; pdw.simulate's loop, so bitwise its run by construction), polled every
 * PDW_BATCH_POLL loop iterations; lanes: 1 caller-allocated pdw_sim. The structure-of-arrays
 * loops take it for small blocks (pdw_batch_serial_pays). Returns as pdw_batch_method. */
long pdw_batch_serial(const pdw_batch_job *job, long i0, long i1, pdw_sim *lanes);

/* The most walkers a block may hold for which the serial loop beats the structure-of-arrays
 * lanes: those compute ceil(W/8)*8 lanes whatever the walkers, each lane-step ~1/4 of a scalar
 * step (benchmarks/bench_batch.py). */
enum { PDW_BATCH_SERIAL = 2 };

/* 1 if walkers [i0, i1) in blocks of W lanes run faster through pdw_batch_serial: a block
 * would hold at most PDW_BATCH_SERIAL walkers, and the trig is libm's (vector = 0: the serial
 * loop is bitwise the lanes; vector = 1 stays in the lanes, so that a walker's libmvec
 * numbers do not depend on the range or chunk it is in: pdw.simulate_batch gives a whole
 * batch of at most PDW_BATCH_SERIAL walkers vector = 0 instead). */
int pdw_batch_serial_pays(long i0, long i1, int W, int vector);

/* Advance walkers [i0, i1) of job with rodas4 (job->method must name it), as
 * pdw_batch_method does, the ordinary steps of the lanes through the structure-of-arrays try
 * step compiled for isa (pdw_batch_ros.inc; S caller-allocated, 64-byte aligned): each lane
 * keeps its own time, step size, accept/reject and Jacobian; a lane whose accepted step
 * has a flag switch (located by the scalar step), a failure, or that starts, ends or runs
 * out of budget takes that step through the scalar rodas4. Bitwise pdw_batch_method (and
 * `pdw.simulate`) with vector = 0; vector = 1: the lanes' sin/cos from libmvec (not bitwise).
 * Falls back to pdw_batch_method where the kernel has no batched stages or isa is
 * PDW_ISA_SCALAR or unsupported. */
long pdw_batch_rodas4_soa(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                          int vector, int isa, pdw_ros_soa *S);

/* --- the lane scheduler, shared by the lane loops (pdw_batch.c) ------------------------------
 *
 * Every lane loop (pdw_batch_cdm, pdw_batch_method, pdw_batch_cdm_soa, pdw_batch_rodas4_soa and
 * the serial fast path) is pdw_lanes_run with its own pdw_lane_ops: the scheduler fills the W
 * lanes with walkers of [i0, i1) (pdw_batch_take), writes a walker that finishes at its start
 * at once, polls job->poll every poll_rounds rounds and on a stop writes the running walkers as
 * they are (status running), and otherwise calls the loop's round until no lane runs. A round
 * advances its lanes and hands each lane whose walker finished to pdw_lanes_retire, which
 * writes that walker and refills the lane. */
typedef struct pdw_lanes pdw_lanes;

typedef struct pdw_lane_ops {
    /* Load walker i into lane l. Returns 1 if it runs, 0 if it finished at once (its pdw_sim,
     * L->sims[l], then holds the outcome). */
    int (*start)(pdw_lanes *L, long i, int l);
    /* Advance the running lanes (L->walker[l] >= 0); pdw_lanes_retire each that finished. */
    void (*round)(pdw_lanes *L);
    /* May be NULL: after the first fill, before the first round. */
    void (*begin)(pdw_lanes *L);
    /* May be NULL: bring lane l's pdw_sim up to date before a stop writes it. */
    void (*park)(pdw_lanes *L, int l);
} pdw_lane_ops;

struct pdw_lanes {
    const pdw_batch_job *job;
    const pdw_lane_ops *ops;
    void *ctx;                  /* the lane loop's own state */
    pdw_sim *sims;              /* (W,) the lanes' walkers */
    int W;                      /* lanes, 1 .. PDW_BATCH_MAXW */
    int running;                /* lanes with a walker */
    long walker[PDW_BATCH_MAXW];/* lane l's walker, -1: none */
    long next, i1;              /* the range's next walker (without job->next_walker), its end */
    long done;                  /* walkers written */
    long lane_steps;            /* += by the loop: steps committed by a structure-of-arrays step */
};

/* Run walkers [i0, i1) of job through W lanes (clamped to [1, PDW_BATCH_MAXW]) of sims with
 * ops; ctx: the loop's state (L->ctx). poll_rounds: rounds between job->poll calls. Adds
 * L->lane_steps to job->lane_steps. Returns the walkers written as finished (fewer than
 * i1 - i0 when job->poll stopped the range). */
long pdw_lanes_run(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *sims,
                   const pdw_lane_ops *ops, void *ctx, long poll_rounds);

/* Lane l's walker finished: write it, and fill the lane with the next walker (or none). */
void pdw_lanes_retire(pdw_lanes *L, int l);

/* The next walker of [*next, i1) for a lane, or -1 when none is left: from the shared counter
 * job->next_walker when there is one (atomically: threads share it), else from *next. */
static inline long pdw_batch_take(const pdw_batch_job *job, long *next, long i1)
{
    long i;
    if (job->next_walker) i = __atomic_fetch_add(job->next_walker, 1, __ATOMIC_RELAXED);
    else i = (*next)++;
    return i < i1 ? i : -1;
}

/* Write lane s's walker i into job's outputs. */
void pdw_batch_finish(const pdw_batch_job *job, long i, const pdw_sim *s);
/* Load walker i into lane s for a method of pdw_methods (job->method) with the settings
 * pdw.simulate gives its pdw_sim, returning (PDW_STATUS_POLL) every poll_every loop
 * iterations (2: after each accepted step). */
void pdw_batch_start_method(const pdw_batch_job *job, long i, pdw_sim *s, long poll_every);

#endif /* PDW_BATCH_H */
