/* The ensemble engine: many walkers, one block of W lanes advanced in lockstep (docs/ensemble.md).
 *
 * A job describes N walkers (initial states, parameter vectors, fall thresholds) and the
 * caller-allocated per-walker outputs. pdw_batch_cdm advances walkers [i0, i1) of a job
 * through the paper's central difference method (pdw_cdm.c, docs/model.md section 7) in blocks of
 * W lanes: each lane is a pdw_sim (its own time, flags, arming, anchors, events, online gait
 * descriptors, through pdw_discrete.c), the sin/cos of all lanes are computed in one loop the
 * compiler vectorizes (pdw_batch_trig.c), and a lane whose walker finishes is refilled with
 * the next walker at once. Threads take disjoint ranges [i0, i1) of one job. */
#ifndef PDW_BATCH_H
#define PDW_BATCH_H

#include "pdw_sim.h"

enum { PDW_BATCH_MAXW = 64 };

typedef struct pdw_batch_job {
    /* --- inputs --- */
    const pdw_kernel *kernel;
    long n;                     /* walkers */
    const double *x0;           /* (n, PDW_NX) initial states */
    const double *p;            /* (n, PDW_NP) parameter vectors; (1, PDW_NP) with p_stride 0 */
    long p_stride;              /* PDW_NP, or 0 (one parameter vector for all) */
    const int *flags0;          /* (n, 2) initial support flags */
    const double *fall_hip_height;  /* (n,) [m] */
    const double *fall_depth;       /* (n,) [m] */
    double dt;                  /* step [s] */
    long n_steps;               /* steps to take (t_end = n_steps dt) */
    double max_speed;
    long stop_steps;            /* 0: off */
    int periodic_k;             /* 0: off */
    double periodic_tol;
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
    /* --- interruptibility --- */
    int (*poll)(void *ctx);     /* called every PDW_BATCH_POLL lockstep steps (NULL: never); nonzero
                                 * stops: the running walkers are written with status running */
    void *poll_ctx;
} pdw_batch_job;

enum { PDW_BATCH_POLL = 512 };

/* sin and cos of the n angles a into s and c through glibc's vector routines (libmvec). */
void pdw_batch_sincos(int n, const double *a, double *s, double *c);

/* Advance walkers [i0, i1) of job with W lanes (1 <= W <= PDW_BATCH_MAXW); lanes: W
 * caller-allocated pdw_sim. vector: 1 = vector sin/cos, 0 = scalar (bitwise `pdw.simulate`).
 * Returns the number of walkers finished (i1 - i0; fewer when job->poll stopped the range). */
long pdw_batch_cdm(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes, int vector);

#endif /* PDW_BATCH_H */
