/* The ensemble engine's lane loop: the paper's central difference method (pdw_cdm.c, docs/model.md
 * section 7, Eqs. 13-17) for a block of W walkers in lockstep; see pdw_batch.h.
 *
 * Per step: (1) the sin/cos of every running lane in one vector loop (pdw_batch_trig.c);
 * (2) per lane, the generated scalar stages (kinematics, contact, cdm_terms) and the discrete
 * logic of pdw_discrete.c, exactly as pdw_cdm_advance does them, in the same order. A lane whose
 * walker finishes (t_end, a stop condition, a fall, a divergence) writes its outputs and takes
 * the next walker of the range at once. With vector = 0 the trig is pdw_trig's scalar libm
 * calls: bitwise pdw_cdm_advance (the W = 1 fallback and the test reference). */
#include <math.h>
#include <string.h>
#include "pdw_batch.h"
#include "pdw_linalg.h"

/* Write lane s's walker i outputs. */
static void finish(const pdw_batch_job *job, long i, const pdw_sim *s)
{
    job->status[i] = s->status;
    job->stop_reason[i] = s->stop_reason;
    job->flags_final[2*i] = s->disc.flags[0];
    job->flags_final[2*i + 1] = s->disc.flags[1];
    memcpy(job->x_final + i*PDW_NX, s->x, PDW_NX * sizeof(double));
    job->t_final[i] = s->t;
    job->n_taken[i] = s->n;
    job->n_gait[i] = s->gait.n_steps;
    job->n_touch_down[i] = s->gait.n_touch_down;
    job->n_lift_off[i] = s->gait.n_lift_off;
    const long keep = s->gait.n_steps < PDW_STEP_RING ? s->gait.n_steps : PDW_STEP_RING;
    double *g = job->gait + i*PDW_STEP_RING*PDW_NSTEP;
    for (long r = 0; r < PDW_STEP_RING; ++r) {
        const long slot = (s->gait.n_steps - keep + r) % PDW_STEP_RING;
        for (int c = 0; c < PDW_NSTEP; ++c)
            g[r*PDW_NSTEP + c] = r < keep ? s->gait.ring[slot][c] : NAN;
    }
    const int failed = s->status == PDW_STATUS_FELL || s->status == PDW_STATUS_DIVERGED
                       || s->status == PDW_STATUS_SINGULAR;
    job->fail_reason[i] = failed ? s->failure.reason : PDW_REASON_NONE;
    job->fail_leg[i] = failed ? s->failure.leg : -1;
    job->fail_t[i] = failed ? s->failure.t : NAN;
    for (int j = 0; j < PDW_NX; ++j) job->fail_x[i*PDW_NX + j] = failed ? s->failure.x[j] : NAN;
}

/* Load walker i into lane s and take the start-up of pdw_cdm_advance. Returns 1 if the walker
 * is still running, 0 if it finished at once (a stop condition at t = 0). */
static int start(const pdw_batch_job *job, long i, pdw_sim *s)
{
    const double dt = job->dt;
    int flags0[2];
    memset(s, 0, sizeof *s);
    s->kernel = job->kernel;
    s->nx = PDW_NX;             /* the smooth Coulomb law only (_batch.pyx checks) */
    memcpy(s->p, job->p + i*job->p_stride, PDW_NP * sizeof(double));
    s->dt = dt;
    s->n_steps = job->n_steps;
    s->t_end = job->n_steps * dt;
    s->fall_hip_height = job->fall_hip_height[i];
    s->fall_depth = job->fall_depth[i];
    s->max_speed = job->max_speed;
    s->stop_steps = job->stop_steps;
    s->periodic_k = job->periodic_k;
    s->periodic_tol = job->periodic_tol;
    pdw_gait_init(&s->gait);
    memcpy(s->x, job->x0 + i*PDW_NX, PDW_NX * sizeof(double));
    flags0[0] = job->flags0[2*i];
    flags0[1] = job->flags0[2*i + 1];
    pdw_discrete_init(s->kernel, s->p, s->x, flags0, &s->disc, s->work);
    /* pdw_cdm_advance's start-up (no events stored: the update cannot return -1) */
    s->status = PDW_STATUS_RUNNING;
    if (pdw_update_flags(s, 0.0) > 0) { s->started = 1; return 0; }
    pdw_cdm_start(s);
    return 1;
}

/* One step of pdw_cdm_advance's loop for lane s, whose trig of x is in work (n > 0). Returns 1
 * while running, 0 when the walker finished (s->status set). */
static int step(pdw_sim *s)
{
    const pdw_kernel *k = s->kernel;
    const double dt = s->dt;
    double *trig = s->work + PDW_WORK_TRIG, *kin = s->work + PDW_WORK_KIN;
    double *contact = s->work + PDW_WORK_CONTACT, *M = s->work + PDW_WORK_M;
    double C[PDW_NQ*PDW_NQ], QmG[PDW_NQ];
    const double t = s->n * dt;
    if (s->n > 0 && pdw_update_flags_trig(s, t) > 0) return 0;     /* a stop condition */
    if (pdw_check_feet(s, t)) return 0;
    k->contact(kin, s->disc.flags, s->p, contact);
    k->cdm_terms(s->x, trig, s->p, contact, M, C, QmG);
    if (pdw_cdm_update(s, M, C, QmG, t)) return 0;
    if (s->n < s->n_steps) return 1;
    /* final flags at t_end (scalar trig, as pdw_cdm_advance) */
    if (pdw_update_flags(s, s->n * dt) == 0) s->status = PDW_STATUS_DONE;
    return 0;
}

long pdw_batch_cdm(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes, int vector)
{
    long walker[PDW_BATCH_MAXW], next = i0;
    double a[2*PDW_BATCH_MAXW], sn[2*PDW_BATCH_MAXW], cs[2*PDW_BATCH_MAXW];
    int running = 0;
    long since_poll = 0, done = 0;
    if (W < 1) W = 1;
    if (W > PDW_BATCH_MAXW) W = PDW_BATCH_MAXW;
    /* fill every lane (a walker that finishes at its start-up is written out at once) */
    for (int l = 0; l < W; ++l) {
        walker[l] = -1;
        while (next < i1) {
            const long i = next++;
            if (start(job, i, &lanes[l])) { walker[l] = i; running++; break; }
            finish(job, i, &lanes[l]);
            done++;
        }
    }
    while (running > 0) {
        if (job->poll && ++since_poll >= PDW_BATCH_POLL) {
            since_poll = 0;
            if (job->poll(job->poll_ctx)) {      /* stopped: write the running walkers as they are */
                for (int l = 0; l < W; ++l)
                    if (walker[l] >= 0) finish(job, walker[l], &lanes[l]);
                return done;
            }
        }
        /* (1) trig of every lane past its first step (at n = 0 the start-up left it in work) */
        if (vector) {
            for (int l = 0; l < W; ++l) {
                const double *x = lanes[l].x;
                a[l] = walker[l] >= 0 ? x[PDW_X_THETA1] : 0.0;
                a[W + l] = walker[l] >= 0 ? x[PDW_X_THETA2] : 0.0;
            }
            pdw_batch_sincos(2*W, a, sn, cs);
            for (int l = 0; l < W; ++l) {
                if (walker[l] < 0 || lanes[l].n == 0) continue;
                double *trig = lanes[l].work + PDW_WORK_TRIG;
                trig[PDW_TRIG_SIN_THETA1] = sn[l];
                trig[PDW_TRIG_COS_THETA1] = cs[l];
                trig[PDW_TRIG_SIN_THETA2] = sn[W + l];
                trig[PDW_TRIG_COS_THETA2] = cs[W + l];
            }
        } else {
            for (int l = 0; l < W; ++l)
                if (walker[l] >= 0 && lanes[l].n > 0) pdw_trig(lanes[l].x, lanes[l].work + PDW_WORK_TRIG);
        }
        /* (2) the step of every lane; refill the finished ones */
        for (int l = 0; l < W; ++l) {
            if (walker[l] < 0 || step(&lanes[l])) continue;
            finish(job, walker[l], &lanes[l]);
            walker[l] = -1;
            running--;
            done++;
            while (next < i1) {
                const long i = next++;
                if (start(job, i, &lanes[l])) { walker[l] = i; running++; break; }
                finish(job, i, &lanes[l]);
                done++;
            }
        }
    }
    return done;
}
