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
void pdw_batch_finish(const pdw_batch_job *job, long i, const pdw_sim *s)
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

/* ---- the lane scheduler (pdw_batch.h) ------------------------------------------------- */

/* Fill lane l with the next walker that does not finish at its start (walkers that do are
 * written at once); none left: walker -1. */
static void lanes_fill(pdw_lanes *L, int l)
{
    for (long i; (i = pdw_batch_take(L->job, &L->next, L->i1)) >= 0; ) {
        if (L->ops->start(L, i, l)) {
            L->walker[l] = i;
            L->running++;
            return;
        }
        pdw_batch_finish(L->job, i, &L->sims[l]);
        L->done++;
    }
    L->walker[l] = -1;
}

void pdw_lanes_retire(pdw_lanes *L, int l)
{
    pdw_batch_finish(L->job, L->walker[l], &L->sims[l]);
    L->walker[l] = -1;
    L->running--;
    L->done++;
    lanes_fill(L, l);
}

long pdw_lanes_run(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *sims,
                   const pdw_lane_ops *ops, void *ctx, long poll_rounds)
{
    pdw_lanes L;
    long since_poll = 0;
    L.job = job;
    L.ops = ops;
    L.ctx = ctx;
    L.sims = sims;
    L.W = W < 1 ? 1 : W > PDW_BATCH_MAXW ? PDW_BATCH_MAXW : W;
    L.running = 0;
    L.next = i0;
    L.i1 = i1;
    L.done = 0;
    L.lane_steps = 0;
    for (int l = 0; l < L.W; ++l) lanes_fill(&L, l);
    if (ops->begin && L.running > 0) ops->begin(&L);
    while (L.running > 0) {
        if (job->poll && ++since_poll >= poll_rounds) {
            since_poll = 0;
            if (job->poll(job->poll_ctx)) {
                /* stopped: the running walkers as they are (a lane of an adaptive method holds
                 * its last accepted step) */
                for (int l = 0; l < L.W; ++l) {
                    if (L.walker[l] < 0) continue;
                    if (ops->park) ops->park(&L, l);
                    pdw_batch_finish(job, L.walker[l], &L.sims[l]);
                    job->status[L.walker[l]] = PDW_STATUS_RUNNING;
                }
                break;
            }
        }
        ops->round(&L);
    }
    if (job->lane_steps) *job->lane_steps += L.lane_steps;
    return L.done;
}

/* Load walker i into lane s and take the start-up of pdw_cdm_advance. Returns 1 if the walker
 * is still running, 0 if it finished at once (a stop condition at t = 0). */
/* What every lane takes of walker i, whatever the method: its parameters, the job's options
 * with the walker's fall limits, initial state and discrete state (pdw_discrete_init last, on
 * the loaded x). The caller zeroes s first and sets the method's own options after. */
static void load_walker(const pdw_batch_job *job, long i, pdw_sim *s)
{
    int flags0[2];
    s->kernel = job->kernel;
    s->nx = PDW_NX;             /* the smooth Coulomb law only (_batch.pyx checks) */
    memcpy(s->p, job->p + i*job->p_stride, PDW_NP * sizeof(double));
    s->opt = job->opt;
    s->opt.fall_hip_height = job->fall_hip_height[i];
    s->opt.fall_depth = job->fall_depth[i];
    pdw_gait_init(&s->gait);
    s->ground = job->grounds ? job->grounds[i] : NULL;
    memcpy(s->x, job->x0 + i*PDW_NX, PDW_NX * sizeof(double));
    flags0[0] = job->flags0[2*i];
    flags0[1] = job->flags0[2*i + 1];
    pdw_discrete_init(s->kernel, s->ground, s->p, s->x, flags0, &s->disc, s->work);
}

static int start(const pdw_batch_job *job, long i, pdw_sim *s)
{
    memset(s, 0, sizeof *s);
    load_walker(job, i, s);
    s->opt.t_end = job->opt.n_steps * job->opt.dt;
    s->opt.max_steps = 0;       /* as pdw.simulate's fixed-step runs */
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
    const double dt = s->opt.dt;
    double *trig = s->work + PDW_WORK_TRIG, *kin = s->work + PDW_WORK_KIN;
    double *contact = s->work + PDW_WORK_CONTACT, *M = s->work + PDW_WORK_M;
    double C[PDW_NQ*PDW_NQ], QmG[PDW_NQ];
    const double t = s->n * dt;
    if (s->n > 0 && pdw_update_flags_trig(s, t) > 0) return 0;     /* a stop condition */
    if (pdw_check_feet(s, t)) return 0;
    if (s->ground) {            /* shaped ground: as pdw_cdm_advance (pdw_terrain.c) */
        pdw_sim_contact(s, s->work);
        pdw_terrain_cdm_terms(k, s->x, trig, s->p, contact, s->work + PDW_WORK_GROUND, M, C, QmG);
    } else {
        k->contact(kin, s->disc.flags, s->p, contact);
        k->cdm_terms(s->x, trig, s->p, contact, M, C, QmG);
    }
    if (pdw_cdm_update(s, M, C, QmG, t)) return 0;
    if (s->n < s->opt.n_steps) return 1;
    /* final flags at t_end (scalar trig, as pdw_cdm_advance) */
    if (pdw_update_flags(s, s->n * dt) == 0) s->status = PDW_STATUS_DONE;
    return 0;
}

/* ---- pdw_batch_cdm: the generated scalar stages per lane --------------------------------- */

static int cdm_start(pdw_lanes *L, long i, int l)
{
    return start(L->job, i, &L->sims[l]);
}

/* (1) the trig of every lane past its first step (at n = 0 the start-up left it in work),
 * (2) the step of every lane */
static void cdm_round(pdw_lanes *L)
{
    const int W = L->W, vector = *(const int *)L->ctx;
    pdw_sim *lanes = L->sims;
    if (vector) {
        double a[2*PDW_BATCH_MAXW] = {0.0}, sn[2*PDW_BATCH_MAXW], cs[2*PDW_BATCH_MAXW];
        for (int l = 0; l < W; ++l) {
            const double *x = lanes[l].x;
            a[l] = L->walker[l] >= 0 ? x[PDW_X_THETA1] : 0.0;
            a[W + l] = L->walker[l] >= 0 ? x[PDW_X_THETA2] : 0.0;
        }
        pdw_batch_sincos(2*W, a, sn, cs);
        for (int l = 0; l < W; ++l) {
            if (L->walker[l] < 0 || lanes[l].n == 0) continue;
            double *trig = lanes[l].work + PDW_WORK_TRIG;
            trig[PDW_TRIG_SIN_THETA1] = sn[l];
            trig[PDW_TRIG_COS_THETA1] = cs[l];
            trig[PDW_TRIG_SIN_THETA2] = sn[W + l];
            trig[PDW_TRIG_COS_THETA2] = cs[W + l];
        }
    } else {
        for (int l = 0; l < W; ++l)
            if (L->walker[l] >= 0 && lanes[l].n > 0) pdw_trig(lanes[l].x, lanes[l].work + PDW_WORK_TRIG);
    }
    for (int l = 0; l < W; ++l)
        if (L->walker[l] >= 0 && !step(&lanes[l])) pdw_lanes_retire(L, l);
}

static const pdw_lane_ops cdm_ops = {cdm_start, cdm_round, NULL, NULL};

long pdw_batch_cdm(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes, int vector)
{
    return pdw_lanes_run(job, i0, i1, W, lanes, &cdm_ops, &vector, PDW_BATCH_POLL);
}

/* Load walker i into lane s with the settings pdw/core/_core.pyx's run gives pdw.simulate's
 * pdw_sim (nothing recorded, events only counted), polling every poll_every loop iterations. */
void pdw_batch_start_method(const pdw_batch_job *job, long i, pdw_sim *s, long poll_every)
{
    const pdw_method *m = &pdw_methods[job->method];
    memset(s, 0, sizeof *s);
    load_walker(job, i, s);
    s->opt.h_max = job->opt.h_max > 0 ? job->opt.h_max : job->opt.t_end;
    s->opt.event_tol = job->opt.event_tol > 0.0 ? job->opt.event_tol : 1e-9;
    s->opt.max_steps = m->adaptive ? job->opt.max_steps : 0;
    s->h = job->opt.dt;
    s->poll_every = poll_every;
}

/* ---- pdw_batch_method: any method's own advance per lane ---------------------------------- */

/* a poll every 2 loop iterations returns after each (accepted) step: the drivers poll at the
 * top of an iteration, where a resumed call continues exactly */
static int method_start(pdw_lanes *L, long i, int l)
{
    pdw_batch_start_method(L->job, i, &L->sims[l], 2);
    return 1;
}

static void method_round(pdw_lanes *L)
{
    const pdw_advance_fn advance = pdw_methods[L->job->method].advance;
    for (int l = 0; l < L->W; ++l) {
        /* nothing recorded and events not stored: RECORDS_FULL and EVENTS_FULL cannot occur,
         * POLL is the end of this lane's step */
        if (L->walker[l] >= 0 && advance(&L->sims[l]) != PDW_STATUS_POLL) pdw_lanes_retire(L, l);
    }
}

static const pdw_lane_ops method_ops = {method_start, method_round, NULL, NULL};

long pdw_batch_method(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes)
{
    return pdw_lanes_run(job, i0, i1, W, lanes, &method_ops, NULL, PDW_BATCH_POLL);
}

/* ---- pdw_batch_serial: the scalar loop per walker (small batches) -------------------------- */

/* the method's own advance runs PDW_BATCH_POLL loop iterations per call: one lane, one walker
 * after the other, polled after every call */
static int serial_start(pdw_lanes *L, long i, int l)
{
    pdw_batch_start_method(L->job, i, &L->sims[l], PDW_BATCH_POLL);
    return 1;
}

static void serial_round(pdw_lanes *L)
{
    if (pdw_methods[L->job->method].advance(&L->sims[0]) != PDW_STATUS_POLL) pdw_lanes_retire(L, 0);
}

static const pdw_lane_ops serial_ops = {serial_start, serial_round, NULL, NULL};

long pdw_batch_serial(const pdw_batch_job *job, long i0, long i1, pdw_sim *lanes)
{
    return pdw_lanes_run(job, i0, i1, 1, lanes, &serial_ops, NULL, 1);
}

int pdw_batch_serial_pays(long i0, long i1, int W, int vector)
{
    const long block = (i1 - i0) < W ? (i1 - i0) : W;
    return !vector && block <= PDW_BATCH_SERIAL;
}

/* ---- the structure-of-arrays lane loop ------------------------------------------------ */

void pdw_soa_cdm_step_base(int kernel, pdw_soa_state *S, int W, double dt,
                           double max_speed, int vector);
void pdw_soa_cdm_step_avx2(int kernel, pdw_soa_state *S, int W, double dt,
                           double max_speed, int vector);
void pdw_soa_cdm_step_avx512(int kernel, pdw_soa_state *S, int W, double dt,
                             double max_speed, int vector);

int pdw_soa_has_kernel_base(int kernel);

int pdw_batch_isa_supported(int isa)
{
    if (isa == PDW_ISA_SCALAR || isa == PDW_ISA_BASE) return 1;
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
    __builtin_cpu_init();
    if (isa == PDW_ISA_AVX2) return __builtin_cpu_supports("avx2") != 0;
    /* the AVX-512 variant is compiled for Skylake-SP's set (F, VL, DQ, BW): the masks of the
     * lane loops' int rows need VL/DQ/BW to stay in vector registers */
    if (isa == PDW_ISA_AVX512)
        return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl")
               && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
#endif
    return 0;
}

/* pdw_soa_trig_libm's loop; skip: NULL, or lanes to leave alone (nonzero) */
static void trig_rows(int W, const double *x, double *trig, const long long *skip)
{
    for (int l = 0; l < W; ++l) {
        if (skip && skip[l]) continue;
        /* both angles first: GCC then fuses each sin/cos pair into one sincos call, as in
         * pdw_trig (the same results: glibc's sincos is its sin and cos) */
        const double a1 = x[PDW_X_THETA1*PDW_SOA_STRIDE + l], a2 = x[PDW_X_THETA2*PDW_SOA_STRIDE + l];
        const double s1 = sin(a1), c1 = cos(a1), s2 = sin(a2), c2 = cos(a2);
        trig[PDW_TRIG_SIN_THETA1*PDW_SOA_STRIDE + l] = s1;
        trig[PDW_TRIG_COS_THETA1*PDW_SOA_STRIDE + l] = c1;
        trig[PDW_TRIG_SIN_THETA2*PDW_SOA_STRIDE + l] = s2;
        trig[PDW_TRIG_COS_THETA2*PDW_SOA_STRIDE + l] = c2;
    }
}

void pdw_soa_trig_libm(pdw_soa_state *S, int W, int only_first)
{
    trig_rows(W, S->x, S->trig, only_first ? S->upd : NULL);
}

void pdw_soa_trig_rows(int W, const double *x, double *trig)
{
    /* every computed lane, the padding up to a multiple of 8 included (ordinary numbers) */
    trig_rows((W + 7) & ~7, x, trig, NULL);
}

/* Lane l of S from its pdw_sim (after a start or a scalar step). */
static void soa_load(pdw_soa_state *S, int l, const pdw_sim *s)
{
    for (int i = 0; i < PDW_NX; ++i) S->x[i*PDW_SOA_STRIDE + l] = s->x[i];
    for (int i = 0; i < PDW_NQ; ++i) S->u_prev[i*PDW_SOA_STRIDE + l] = s->u_prev[i];
    for (int i = 0; i < PDW_NANCHOR; ++i) S->anchors[i*PDW_SOA_STRIDE + l] = s->disc.anchors[i];
    for (int i = 0; i < 2; ++i) {
        S->flags[i*PDW_SOA_STRIDE + l] = s->disc.flags[i];
        S->armed[i*PDW_SOA_STRIDE + l] = s->disc.armed[i];
    }
    S->upd[l] = s->n > 0;
    S->n[l] = s->n;
    S->first |= s->n == 0;
}

/* The parts of lane l's pdw_sim that the SoA step advances, from S: the steps it committed
 * since the lane was loaded (n, t = n dt and n_rhs as each commit of pdw_cdm_advance sets
 * them), the state and the arming. */
static void soa_store(const pdw_soa_state *S, int l, pdw_sim *s)
{
    const long n = (long)S->n[l];
    s->n_rhs += n - s->n;
    s->n = n;
    s->t = n * s->opt.dt;
    for (int i = 0; i < PDW_NX; ++i) s->x[i] = S->x[i*PDW_SOA_STRIDE + l];
    for (int i = 0; i < PDW_NQ; ++i) s->u_prev[i] = S->u_prev[i*PDW_SOA_STRIDE + l];
    for (int i = 0; i < 2; ++i) s->disc.armed[i] = (int)S->armed[i*PDW_SOA_STRIDE + l];
}

/* pdw_batch_cdm_soa's state */
typedef struct soa_loop {
    pdw_soa_state *S;
    void (*stepfn)(int, pdw_soa_state *, int, double, double, int);
    int kernel, vector;
} soa_loop;

/* Start walker i in lane l (pdw_sim and S). Returns 1 if it runs, 0 if it finished at once. */
static int soa_start(pdw_lanes *L, long i, int l)
{
    pdw_soa_state *S = ((soa_loop *)L->ctx)->S;
    pdw_sim *s = &L->sims[l];
    if (!start(L->job, i, s)) return 0;
    for (int j = 0; j < PDW_NP; ++j) S->p[j*PDW_SOA_STRIDE + l] = s->p[j];
    S->hip[l] = s->opt.fall_hip_height;
    S->depth[l] = s->opt.fall_depth;
    S->nend[l] = s->opt.n_steps;
    S->live[l] = 1;
    S->kc_stale = 1;
    soa_load(S, l, s);
    return 1;
}

/* lanes without a walker and the padding lanes up to a multiple of 8 (computed, never read)
 * step a copy of lane 0: ordinary numbers, no denormal or NaN slow paths (if lane 0 has no
 * walker, none has) */
static void soa_begin(pdw_lanes *L)
{
    pdw_soa_state *S = ((soa_loop *)L->ctx)->S;
    for (int l = 1; l < ((L->W + 7) & ~7) && L->walker[0] >= 0; ++l) {
        if (l < L->W && L->walker[l] >= 0) continue;
        for (int j = 0; j < PDW_NP; ++j) S->p[j*PDW_SOA_STRIDE + l] = S->p[j*PDW_SOA_STRIDE];
        S->hip[l] = S->hip[0];
        S->depth[l] = S->depth[0];
        soa_load(S, l, &L->sims[0]);
    }
    S->kc_stale = 1;
}

static void soa_park(pdw_lanes *L, int l)
{
    soa_store(((soa_loop *)L->ctx)->S, l, &L->sims[l]);
}

/* one structure-of-arrays step of every lane; per lane its commit, or the scalar step */
static void soa_round(pdw_lanes *L)
{
    const soa_loop *c = L->ctx;
    pdw_soa_state *S = c->S;
    const pdw_batch_job *job = L->job;
    const int W = L->W;
    long committed = 0;     /* into L->lane_steps once (a long that the stores to s may alias) */
    /* (no restrict: a refill, pdw_lanes_retire, writes these rows through S) */
    long long *n = S->n, *upd = S->upd, *live = S->live;
    const long long *rare = S->rare, *nend = S->nend;
    long long visit = 0;
    c->stepfn(c->kernel, S, W, job->opt.dt, job->opt.max_speed, c->vector);
    for (int l = 0; l < W; ++l) visit |= live[l] & (rare[l] | (n[l] + 1 >= nend[l]));
    if (!visit) {
        /* the common round: every walker commits an ordinary step that is not its last */
        for (int l = 0; l < W; ++l) {
            n[l] += live[l];
            upd[l] |= live[l];
        }
        L->lane_steps += L->running;
        return;
    }
    for (int l = 0; l < W; ++l) {
        if (L->walker[l] < 0) continue;
        pdw_sim *s = &L->sims[l];
        int more;
        if (!rare[l]) {
            /* the common case: commit the step (pdw_sim's counters at soa_store) */
            committed++;
            upd[l] = 1;
            if (++n[l] < nend[l]) continue;
            /* final flags at t_end (scalar trig), as step() */
            soa_store(S, l, s);
            if (pdw_update_flags(s, s->n * s->opt.dt) == 0) s->status = PDW_STATUS_DONE;
            more = 0;
        } else {
            /* the scalar step from the same state and trig: it takes the event, the fall
             * or the failure exactly as pdw_cdm_advance */
            soa_store(S, l, s);
            for (int j = 0; j < PDW_NTRIG; ++j)
                s->work[PDW_WORK_TRIG + j] = S->trig[j*PDW_SOA_STRIDE + l];
            more = step(s);
            if (more) soa_load(S, l, s);
        }
        if (!more) {
            pdw_lanes_retire(L, l);     /* a refill loads the lane (soa_start) */
            live[l] = L->walker[l] >= 0;
        }
    }
    L->lane_steps += committed;
}

static const pdw_lane_ops soa_ops = {soa_start, soa_round, soa_begin, soa_park};

long pdw_batch_cdm_soa(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                       int vector, int isa, pdw_soa_state *S)
{
    const long kid = job->kernel - pdw_kernels;
    soa_loop c = {S, NULL, (int)kid, vector};
    if (isa == PDW_ISA_BASE) c.stepfn = pdw_soa_cdm_step_base;
    else if (isa == PDW_ISA_AVX2) c.stepfn = pdw_soa_cdm_step_avx2;
    else if (isa == PDW_ISA_AVX512) c.stepfn = pdw_soa_cdm_step_avx512;
    if (kid < 0 || kid >= PDW_NKERNELS || !pdw_soa_has_kernel_base((int)kid)
        || c.stepfn == NULL || !pdw_batch_isa_supported(isa))
        return pdw_batch_cdm(job, i0, i1, W, lanes, vector);
    if (pdw_batch_serial_pays(i0, i1, W, vector)) return pdw_batch_serial(job, i0, i1, lanes);
    memset(S, 0, sizeof *S);
    return pdw_lanes_run(job, i0, i1, W, lanes, &soa_ops, &c, PDW_BATCH_POLL);
}
