/* The ensemble engine's rodas4 lanes (docs/ensemble.md): W walkers attempt their steps in
 * lockstep through the structure-of-arrays try step (pdw_batch_ros.inc, one per instruction
 * set), each with its own time, step size, Jacobian and accept/reject.
 *
 * A lane is either *vector* (its walker sits right after an accepted step, its point and f in
 * the SoA rows) or *scalar* for one step. Every round:
 *   (1) each scalar lane takes one accepted step through the method's own advance
 *       (pdw_rodas4_advance, returning after it through PDW_STATUS_POLL, as pdw_batch_method),
 *       or finishes and takes the next walker; then it is vector again;
 *   (2) each vector lane gets its attempt's step size as pdw_adaptive_advance computes it; an
 *       attempt that would be the run's last, too small, or past the step budget makes the lane
 *       scalar instead (the scalar driver takes that step);
 *   (3) one call of the try step attempts every vector lane at once;
 *   (4) per lane, pdw_adaptive_advance's decision: rejected -> the next attempt with the
 *       smaller step (Jacobian kept); accepted and ordinary -> committed; accepted with a
 *       flag switch inside (located by the scalar driver), a failed check or a deep foot, or a
 *       singular matrix / non-finite error -> the lane is scalar for this step.
 * A vector lane's rejected attempts are not committed to its pdw_sim: a lane made scalar
 * mid-way restarts the step from its last accepted point, where pdw_rodas4_advance itself would
 * start (new point, no rejection before), and takes the same rejections again. So every
 * walker is bitwise its pdw_batch_method (and `pdw.simulate`) run, with vector = 0 (libm's
 * sin/cos per lane); vector = 1 takes the lanes' sin/cos from glibc's vector routines (within
 * 4 ulp: not bitwise; a walker's numbers still do not depend on its lane or thread). */
#include <float.h>
#include <math.h>
#include <string.h>
#include "pdw_batch.h"
#include "pdw_ode.h"

void pdw_soa_ros_try_base(int kernel, pdw_ros_soa *S, int W, int any_jac, double rtol,
                          double atol, double max_speed, int vector);
void pdw_soa_ros_try_avx2(int kernel, pdw_ros_soa *S, int W, int any_jac, double rtol,
                          double atol, double max_speed, int vector);
void pdw_soa_ros_try_avx512(int kernel, pdw_ros_soa *S, int W, int any_jac, double rtol,
                            double atol, double max_speed, int vector);

int pdw_soa_has_ros_kernel_base(int kernel);

enum { LANE_SCALAR = 0, LANE_VECTOR = 1 };

/* SoA lane l from its pdw_sim, right after an accepted step (or its first); fresh: a new walker
 * (its parameters and limits too). f(x) as the next iteration of pdw_adaptive_advance computes
 * it when an event invalidated it. */
static void ros_load(pdw_ros_soa *S, int l, pdw_sim *s, int fresh)
{
    if (!s->cache_valid) { pdw_ode_f(s, s->x, s->cache); s->cache_valid = 1; }
    for (int i = 0; i < PDW_NX; ++i) {
        S->x[i*PDW_SOA_STRIDE + l] = s->x[i];
        S->fx[i*PDW_SOA_STRIDE + l] = s->cache[i];
    }
    for (int i = 0; i < PDW_NANCHOR; ++i) S->anchors[i*PDW_SOA_STRIDE + l] = s->disc.anchors[i];
    for (int i = 0; i < 2; ++i) {
        S->flags[i*PDW_SOA_STRIDE + l] = s->disc.flags[i];
        S->armed[i*PDW_SOA_STRIDE + l] = s->disc.armed[i];
    }
    if (fresh) {
        for (int j = 0; j < PDW_NP; ++j) S->p[j*PDW_SOA_STRIDE + l] = s->p[j];
        S->hip[l] = s->opt.fall_hip_height;
        S->depth[l] = s->opt.fall_depth;
    }
}

/* Lane d a copy of lane l0 (a lane computed but not attempted: ordinary numbers). */
static void ros_copy_lane(pdw_ros_soa *S, int d, int l0)
{
#define COPY(a, rows) for (int i = 0; i < (rows); ++i) S->a[i*PDW_SOA_STRIDE + d] = S->a[i*PDW_SOA_STRIDE + l0]
    COPY(x, PDW_NX); COPY(fx, PDW_NX); COPY(p, PDW_NP); COPY(anchors, PDW_NANCHOR);
    COPY(flags, 2); COPY(armed, 2); COPY(J, PDW_NQ*PDW_NX);
#undef COPY
    S->hip[d] = S->hip[l0];
    S->depth[d] = S->depth[l0];
    S->h[d] = S->h[l0];
    S->jac[d] = 1;
}

/* pdw_batch_rodas4_soa's state: the try step, and per lane its mode and attempt */
typedef struct ros_loop {
    pdw_ros_soa *S;
    void (*tryfn)(int, pdw_ros_soa *, int, int, double, double, double, int);
    int kernel, vector;
    long nrej[PDW_BATCH_MAXW];              /* rejections of the lane's current step so far */
    double hcur[PDW_BATCH_MAXW];            /* the step size pdw_sim's h would have now */
    int mode[PDW_BATCH_MAXW], fresh[PDW_BATCH_MAXW], newpt[PDW_BATCH_MAXW];
    int lastrej[PDW_BATCH_MAXW], loaded[PDW_BATCH_MAXW];
} ros_loop;

/* a new walker starts scalar: its first step through pdw_rodas4_advance */
static int ros_start(pdw_lanes *L, long i, int l)
{
    ros_loop *c = L->ctx;
    pdw_batch_start_method(L->job, i, &L->sims[l], 2);
    c->fresh[l] = 1;
    c->mode[l] = LANE_SCALAR;
    return 1;
}

static void ros_round(pdw_lanes *L)
{
    ros_loop *c = L->ctx;
    pdw_ros_soa *S = c->S;
    const pdw_batch_job *job = L->job;
    const pdw_adaptive_method *m = &pdw_rodas4_method;
    const double t_end = job->opt.t_end;
    const int W = L->W, W8 = (W + 7) & ~7;
    const long *walker = L->walker;
    pdw_sim *lanes = L->sims;
    /* (1) the scalar lanes: one accepted step each, or the end of the walker */
    for (int l = 0; l < W; ++l) {
        while (walker[l] >= 0 && c->mode[l] == LANE_SCALAR) {
            pdw_sim *s = &lanes[l];
            if (pdw_rodas4_advance(s) == PDW_STATUS_POLL) {
                ros_load(S, l, s, c->fresh[l]);
                c->fresh[l] = 0;
                c->loaded[l] = 1;
                c->mode[l] = LANE_VECTOR;
                c->newpt[l] = 1;
                c->lastrej[l] = 0;
                c->nrej[l] = 0;
                c->hcur[l] = s->h;
                break;
            }
            pdw_lanes_retire(L, l);
        }
    }
    /* (2) the vector lanes' attempts, as pdw_adaptive_advance's loop sets them up */
    int any = 0, any_jac = 0, l0 = -1;
    for (int l = 0; l < W; ++l) {
        S->jac[l] = 0;
        if (walker[l] < 0 || c->mode[l] != LANE_VECTOR) continue;
        const pdw_sim *s = &lanes[l];
        const double h = fmin(c->hcur[l], s->opt.h_max);
        const double rem = t_end - s->t;
        if ((s->opt.max_steps > 0 && s->n + s->n_rejected + c->nrej[l] >= s->opt.max_steps)
            || h >= rem - 1e-12 * fmax(1.0, t_end)
            || !(h > 8.0 * DBL_EPSILON * fmax(fabs(s->t), 1e-3))) {
            c->mode[l] = LANE_SCALAR;       /* the budget, the last step, a step too small */
            continue;
        }
        S->h[l] = h;
        S->jac[l] = c->newpt[l];
        any = 1;
        any_jac |= c->newpt[l];
        if (l0 < 0) l0 = l;
    }
    if (!any) return;
    for (int l = 0; l < W8; ++l) {
        if (l < W && walker[l] >= 0 && c->mode[l] == LANE_VECTOR) continue;
        if (!c->loaded[l]) { ros_copy_lane(S, l, l0); c->loaded[l] = 1; }
        S->jac[l] = 0;
    }
    /* (3) every vector lane's attempt */
    c->tryfn(c->kernel, S, W, any_jac, job->opt.rtol, job->opt.atol, job->opt.max_speed,
             c->vector);
    /* (4) pdw_adaptive_advance's decision, per lane */
    for (int l = 0; l < W; ++l) {
        if (walker[l] < 0 || c->mode[l] != LANE_VECTOR) continue;
        pdw_sim *s = &lanes[l];
        const double err = S->err[l], h = S->h[l];
        s->n_jac += c->newpt[l];
        s->n_rhs += PDW_ROS_MAXSTAGES - 1;
        if (S->bad[l]) { c->mode[l] = LANE_SCALAR; continue; }
        c->newpt[l] = 0;
        if (!(err <= 1.0)) {
            c->hcur[l] = h * pdw_reject_factor(m, err);
            c->nrej[l]++;
            c->lastrej[l] = 1;
            continue;
        }
        if (S->rare[l]) { c->mode[l] = LANE_SCALAR; continue; }
        /* an ordinary accepted step: pdw_adaptive_advance's commit */
        const double h_next = h * pdw_accept_factor(m, s, err, h, c->lastrej[l]);
        for (int i = 0; i < PDW_NX; ++i) {
            const double xn = S->xnew[i*PDW_SOA_STRIDE + l], fn = S->fnew[i*PDW_SOA_STRIDE + l];
            s->x[i] = xn;
            s->cache[i] = fn;
            S->x[i*PDW_SOA_STRIDE + l] = xn;
            S->fx[i*PDW_SOA_STRIDE + l] = fn;
        }
        s->cache_valid = 1;
        s->n_rhs++;
        s->t = s->t + h;
        s->n++;
        s->n_rejected += c->nrej[l];
        pdw_accept_memory(m, s, err, h, h_next);
        L->lane_steps++;
        c->newpt[l] = 1;
        c->lastrej[l] = 0;
        c->nrej[l] = 0;
        c->hcur[l] = s->h;
    }
}

static const pdw_lane_ops ros_ops = {ros_start, ros_round, NULL, NULL};

long pdw_batch_rodas4_soa(const pdw_batch_job *job, long i0, long i1, int W, pdw_sim *lanes,
                          int vector, int isa, pdw_ros_soa *S)
{
    const long kid = job->kernel - pdw_kernels;
    ros_loop c;
    c.S = S;
    c.tryfn = NULL;
    c.kernel = (int)kid;
    c.vector = vector;
    if (isa == PDW_ISA_BASE) c.tryfn = pdw_soa_ros_try_base;
    else if (isa == PDW_ISA_AVX2) c.tryfn = pdw_soa_ros_try_avx2;
    else if (isa == PDW_ISA_AVX512) c.tryfn = pdw_soa_ros_try_avx512;
    if (kid < 0 || kid >= PDW_NKERNELS || !pdw_soa_has_ros_kernel_base((int)kid)
        || c.tryfn == NULL || !pdw_batch_isa_supported(isa)
        || pdw_methods[job->method].advance != pdw_rodas4_advance
        || pdw_tableau_rodas4.stages != PDW_ROS_MAXSTAGES)
        return pdw_batch_method(job, i0, i1, W, lanes);
    if (pdw_batch_serial_pays(i0, i1, W, vector)) return pdw_batch_serial(job, i0, i1, lanes);
    memset(S, 0, sizeof *S);
    for (int l = 0; l < PDW_BATCH_MAXW; ++l) {
        c.loaded[l] = 0;
        c.mode[l] = LANE_SCALAR;
    }
    return pdw_lanes_run(job, i0, i1, W, lanes, &ros_ops, &c, PDW_BATCH_POLL);
}
