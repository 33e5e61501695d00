/* The hybrid walker's step map (docs/model.md section 9); see pdw_hybrid_sim.h for the contract.
 *
 * Integrator: Dormand-Prince 5(4) (the RK45 of Hairer-Norsett-Wanner, FSAL), local
 * extrapolation (the 5th-order solution is propagated), RMS error norm with
 * sc_i = atol + rtol max(|y_i|, |ynew_i|), step factor 0.9 err^(-1/5) clipped to [0.2, 5]
 * (no growth right after a rejection), h <= h_max.
 *
 * Heel strike: within an accepted step [t, t + h] in which the armed swing foot's height
 * goes from > 0 to <= 0, the strike time t + tau is found by the Illinois variant of regula
 * falsi on g(tau) = y_sw(Phi_tau(y)), where Phi_tau is one Dormand-Prince step of size tau
 * from the step's start (so every trial state has the accuracy of a step no larger than an
 * accepted one), until the bracket is shorter than event_tol. The strike state is the
 * bracket's end with g <= 0 (the foot at, or a rounding error below, the ground). */
#include <math.h>
#include <string.h>
#include "pdw_hybrid_sim.h"
#include "pdw_dp5.h"

#define NY 4

void pdw_hybrid_default_opts(pdw_hybrid_opts *o)
{
    o->rtol = 1e-10;
    o->atol = 1e-12;
    o->h0 = 1e-3;
    o->h_max = 0.01;
    o->t_max = 5.0;
    o->event_tol = 1e-13;
    o->min_step_angle = 0.1;
    o->fall_angle = 1.4;
    o->max_steps = 100000;
    o->dt_out = 0.0;
    o->poll = NULL;
    o->poll_ctx = NULL;
    o->dh = 0.0;
    o->ground = NULL;
    o->ground_ctx = NULL;
    o->max_slope = 1.0;
}

/* ---- Dormand-Prince 5(4) ---------------------------------------------------------------- */

typedef struct stepper {
    const double *p;
    long n_rhs;
    int bad;        /* a singular mass matrix was met */
    const pdw_hybrid_opts *o;
    int stop;       /* o->poll asked to stop */
} stepper;

static void f(stepper *s, const double *y, double *dy)
{
    if (pdw_hybrid_rhs(y, s->p, dy)) s->bad = 1;
    if (++s->n_rhs % PDW_HYBRID_POLL_RHS == 0 && s->o && s->o->poll
        && s->o->poll(s->o->poll_ctx)) s->stop = 1;
}

/* One step of size h from y with k1 = f(y): ynew, k7 = f(ynew), and (if err) the error
 * estimate. */
static void dopri(stepper *s, const double *y, const double *k1, double h, double *ynew,
                  double *k7, double *err)
{
    double k2[NY], k3[NY], k4[NY], k5[NY], k6[NY], t[NY];
    for (int i = 0; i < NY; ++i) t[i] = y[i] + h*A21*k1[i];
    f(s, t, k2);
    for (int i = 0; i < NY; ++i) t[i] = y[i] + h*(A31*k1[i] + A32*k2[i]);
    f(s, t, k3);
    for (int i = 0; i < NY; ++i) t[i] = y[i] + h*(A41*k1[i] + A42*k2[i] + A43*k3[i]);
    f(s, t, k4);
    for (int i = 0; i < NY; ++i)
        t[i] = y[i] + h*(A51*k1[i] + A52*k2[i] + A53*k3[i] + A54*k4[i]);
    f(s, t, k5);
    for (int i = 0; i < NY; ++i)
        t[i] = y[i] + h*(A61*k1[i] + A62*k2[i] + A63*k3[i] + A64*k4[i] + A65*k5[i]);
    f(s, t, k6);
    for (int i = 0; i < NY; ++i)
        ynew[i] = y[i] + h*(B1*k1[i] + B3*k3[i] + B4*k4[i] + B5*k5[i] + B6*k6[i]);
    f(s, ynew, k7);
    if (err)
        for (int i = 0; i < NY; ++i)
            err[i] = h*(E1*k1[i] + E3*k3[i] + E4*k4[i] + E5*k5[i] + E6*k6[i] + E7*k7[i]);
}

static int finite4(const double *y)
{
    for (int i = 0; i < NY; ++i) if (!isfinite(y[i])) return 0;
    return 1;
}

static double energy(const double *p, const double *y)
{
    double e[PDW_NENERGY];
    pdw_hybrid_energies(y, p, e);
    return e[PDW_ENERGY_T] + e[PDW_ENERGY_V_GRAVITY] + e[PDW_ENERGY_V_HIP];
}

/* ---- linear algebra --------------------------------------------------------------------- */
int pdw_hybrid_solve(int n, double *A, double *b, double *x)
{
    for (int k = 0; k < n; ++k) {
        int piv = k;
        double big = fabs(A[k*n + k]);
        for (int i = k + 1; i < n; ++i)
            if (fabs(A[i*n + k]) > big) { big = fabs(A[i*n + k]); piv = i; }
        if (!(big > 0.0) || !isfinite(big)) return -1;
        if (piv != k) {
            for (int j = 0; j < n; ++j) {
                const double t = A[k*n + j]; A[k*n + j] = A[piv*n + j]; A[piv*n + j] = t;
            }
            const double t = b[k]; b[k] = b[piv]; b[piv] = t;
        }
        for (int i = k + 1; i < n; ++i) {
            const double m = A[i*n + k] / A[k*n + k];
            if (m == 0.0) continue;
            for (int j = k; j < n; ++j) A[i*n + j] -= m*A[k*n + j];
            b[i] -= m*b[k];
        }
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = b[i];
        for (int j = i + 1; j < n; ++j) s -= A[i*n + j]*x[j];
        x[i] = s / A[i*n + i];
    }
    return 0;
}

/* ---- impact ----------------------------------------------------------------------------- */
int pdw_hybrid_impact(const double *p, const double *ym, pdw_hybrid_result *r)
{
    double x[PDW_NX], MJ[32], K[36], rhs[6], sol[6];
    pdw_hybrid_full_state(ym, p, x);
    pdw_hybrid_impact_terms(x, p, MJ);
    const double *M = MJ, *J1 = MJ + 16, *J2 = MJ + 24;
    const double *qdm = x + PDW_NQ;
    /* [M  -J2^T] [qd+   ]   [M qd-]
     * [J2   0  ] [Lambda] = [  0  ] */
    memset(K, 0, sizeof K);
    for (int i = 0; i < 4; ++i) {
        double s = 0.0;
        for (int j = 0; j < 4; ++j) { K[i*6 + j] = M[i*4 + j]; s += M[i*4 + j]*qdm[j]; }
        rhs[i] = s;
        for (int a = 0; a < 2; ++a) {
            K[i*6 + 4 + a] = -J2[a*4 + i];
            K[(4 + a)*6 + i] = J2[a*4 + i];
        }
    }
    rhs[4] = rhs[5] = 0.0;
    if (pdw_hybrid_solve(6, K, rhs, sol)) return PDW_HYBRID_SINGULAR;
    double Tm = 0.0, Tp = 0.0;
    for (int i = 0; i < 4; ++i) {
        r->qd_minus[i] = qdm[i];
        r->qd_plus[i] = sol[i];
        for (int j = 0; j < 4; ++j) {
            Tm += 0.5*qdm[i]*M[i*4 + j]*qdm[j];
            Tp += 0.5*sol[i]*M[i*4 + j]*sol[j];
        }
    }
    r->T_minus = Tm;
    r->T_plus = Tp;
    r->impulse[0] = sol[4];
    r->impulse[1] = sol[5];
    for (int a = 0; a < 2; ++a) {
        double v = 0.0;
        for (int j = 0; j < 4; ++j) v += J1[a*4 + j]*sol[j];
        r->v_old[a] = v;
    }
    r->old_foot_down = !(r->v_old[1] > 0.0);
    /* relabel: the new stance leg is the old swing leg (leg 2), angles are continuous */
    r->y_plus[PDW_HY_THETA_ST] = ym[PDW_HY_THETA_SW];
    r->y_plus[PDW_HY_THETA_SW] = ym[PDW_HY_THETA_ST];
    r->y_plus[PDW_HY_THETAD_ST] = sol[PDW_X_THETA2];
    r->y_plus[PDW_HY_THETAD_SW] = sol[PDW_X_THETA1];
    return finite4(r->y_plus) ? PDW_HYBRID_OK : PDW_HYBRID_NONFINITE;
}

/* ---- stance phase ----------------------------------------------------------------------- */
typedef struct recorder {
    double *t, *y;
    long cap, n;
    int full;
} recorder;

static void rec_push(recorder *R, double t, const double *y)
{
    if (R->cap <= 0) return;
    if (R->n >= R->cap) { R->full = 1; return; }
    R->t[R->n] = t;
    memcpy(R->y + NY*R->n, y, NY*sizeof(double));
    R->n++;
}

/* samples at the multiples of dt_out in the absolute-time interval (ta, tb), by re-stepping
 * from (ta, y, k1) */
static void rec_dense(recorder *R, stepper *S, double dt_out, double ta, double tb,
                      const double *y, const double *k1)
{
    double ys[NY], ks[NY];
    if (R->cap <= 0 || dt_out <= 0.0) return;
    for (double k = floor(ta/dt_out) + 1.0; k*dt_out < tb && !S->stop; k += 1.0) {
        const double tau = k*dt_out - ta;
        if (tau <= 0.0) continue;
        dopri(S, y, k1, tau, ys, ks, NULL);
        rec_push(R, k*dt_out, ys);
    }
}

static void ground_check(const double *p, const double *y, const double *dy,
                         pdw_hybrid_result *r)
{
    double F[2];
    pdw_hybrid_ground_force(y, dy + 2, p, F);
    if (F[1] < r->Fn_min) r->Fn_min = F[1];
    const double ratio = fabs(F[0]) / fabs(F[1]);
    if (ratio > r->ratio_max) r->ratio_max = ratio;
}

/* the heel-strike event function: the swing foot's height above the ground under it,
 * y_sw - level (pdw_hybrid_opts); with dh = 0 and no ground exactly y_sw */
typedef struct floor_ctx {
    const pdw_hybrid_opts *o;
    double s0, h_st;
} floor_ctx;

static double gap(const floor_ctx *F, const double *foot, double *slope)
{
    double level = F->o->dh;
    if (F->o->ground) {
        double h = 0.0;
        F->o->ground(F->o->ground_ctx, F->s0 + foot[PDW_HYFOOT_X_SW], &h, slope);
        level += h - F->h_st;
    }
    return foot[PDW_HYFOOT_Y_SW] - level;
}

static int armed_now(const floor_ctx *F, const double *foot, const double *y,
                     const pdw_hybrid_opts *o, int armed)
{
    if (foot[PDW_HYFOOT_X_SW] <= foot[PDW_HYFOOT_X_ST]) return 0;
    if (gap(F, foot, NULL) > 0.0
        && y[PDW_HY_THETA_SW] - y[PDW_HY_THETA_ST] >= o->min_step_angle) return 1;
    return armed;
}

int pdw_hybrid_step(const double *p, const double *y0, double t0, double s0,
                    const pdw_hybrid_opts *o, pdw_hybrid_result *r,
                    double *rec_t, double *rec_y, long rec_cap)
{
    stepper S = {p, 0, 0, o, 0};
    recorder R = {rec_t, rec_y, rec_cap, 0, 0};
    double y[NY], k1[NY], ynew[NY], k7[NY], err[NY], foot[PDW_NHYFOOT], foot_new[PDW_NHYFOOT];
    double t = 0.0, h = o->h0 > 0.0 ? o->h0 : 1e-3;
    int armed = 0, reject = 0;
    memset(r, 0, sizeof *r);
    r->t0 = t0;
    r->s0 = s0;
    memcpy(r->y0, y0, sizeof r->y0);
    memcpy(y, y0, sizeof y);
    r->status = PDW_HYBRID_OK;
    floor_ctx F = {o, s0, 0.0};
    int off = 0;
    if (o->ground)
        off = o->ground(o->ground_ctx, s0 - p[PDW_P_R]*y0[PDW_HY_THETA_ST], &F.h_st, NULL);
    r->h_st = F.h_st;
    if (off) { r->status = PDW_HYBRID_OFF_GROUND; return r->status; }
    if (o->poll && o->poll(o->poll_ctx)) { r->status = PDW_HYBRID_INTERRUPTED; return r->status; }
    if (!finite4(y)) { r->status = PDW_HYBRID_NONFINITE; return r->status; }
    f(&S, y, k1);
    r->E0 = energy(p, y);
    r->Fn_min = INFINITY;
    r->ratio_max = 0.0;
    ground_check(p, y, k1, r);
    pdw_hybrid_swing_foot(y, p, foot);
    armed = armed_now(&F, foot, y, o, 0);
    rec_push(&R, t0, y);
    for (;;) {
        if (r->n_steps >= o->max_steps) { r->status = PDW_HYBRID_MAX_STEPS; break; }
        if (t >= o->t_max) { r->status = PDW_HYBRID_NO_STRIKE; break; }
        if (h > o->h_max) h = o->h_max;
        if (h < 1e-14 * (1.0 + t)) { r->status = PDW_HYBRID_STEP_TINY; break; }
        dopri(&S, y, k1, h, ynew, k7, err);
        if (S.stop) break;
        if (S.bad) { r->status = PDW_HYBRID_SINGULAR; break; }
        double en = 0.0;
        for (int i = 0; i < NY; ++i) {
            const double sc = o->atol + o->rtol*fmax(fabs(y[i]), fabs(ynew[i]));
            en += (err[i]/sc)*(err[i]/sc);
        }
        en = sqrt(en / NY);
        if (!isfinite(en) || !finite4(ynew)) {
            h *= 0.2; reject = 1; r->n_rejected++;
            continue;
        }
        if (en > 1.0) {
            h *= fmax(0.2, 0.9*pow(en, -0.2));
            reject = 1; r->n_rejected++;
            continue;
        }
        r->n_steps++;
        pdw_hybrid_swing_foot(ynew, p, foot_new);
        /* heel strike inside this step? */
        const double g_old = gap(&F, foot, NULL), g_new = gap(&F, foot_new, NULL);
        if (armed && g_old > 0.0 && g_new <= 0.0
            && foot_new[PDW_HYFOOT_X_SW] > foot_new[PDW_HYFOOT_X_ST]) {
            double a = 0.0, b = h, ga = g_old, gb = g_new;
            double yb[NY], kb[NY], ys[NY], ks[NY], fs[PDW_NHYFOOT];
            int side = 0;
            memcpy(yb, ynew, sizeof yb);
            for (int it = 0; it < 200 && b - a > o->event_tol && gb != 0.0; ++it) {
                double tau = (a*gb - b*ga) / (gb - ga);
                if (!(tau > a && tau < b)) tau = 0.5*(a + b);
                dopri(&S, y, k1, tau, ys, ks, NULL);
                pdw_hybrid_swing_foot(ys, p, fs);
                const double g = gap(&F, fs, NULL);
                if (g > 0.0) {
                    a = tau; ga = g;
                    if (side == -1) gb *= 0.5;
                    side = -1;
                } else {
                    b = tau; gb = g;
                    memcpy(yb, ys, sizeof yb);
                    if (side == 1) ga *= 0.5;
                    side = 1;
                }
            }
            rec_dense(&R, &S, o->dt_out, t0 + t, t0 + t + b, y, k1);
            t += b;
            f(&S, yb, kb);
            ground_check(p, yb, kb, r);
            const double dE = fabs(energy(p, yb) - r->E0);
            if (dE > r->dE_max) r->dE_max = dE;
            memcpy(y, yb, sizeof y);
            pdw_hybrid_swing_foot(y, p, foot);
            rec_push(&R, t0 + t, y);
            r->t_strike = t;
            memcpy(r->y_minus, y, sizeof y);
            r->vy_strike = foot[PDW_HYFOOT_VY_SW];
            r->x_touch = s0 + foot[PDW_HYFOOT_X_SW];
            r->step_length = r->x_touch - (s0 - p[PDW_P_R]*y0[PDW_HY_THETA_ST]);
            r->s0_next = r->x_touch + p[PDW_P_R]*y[PDW_HY_THETA_SW];
            r->h_touch = r->h_st + o->dh;
            if (o->ground) {
                double slope = 0.0, h = 0.0;
                if (o->ground(o->ground_ctx, r->x_touch, &h, &slope)) {
                    r->status = PDW_HYBRID_OFF_GROUND;
                    break;
                }
                r->h_touch = h + o->dh;
                if (fabs(slope) > o->max_slope) { r->status = PDW_HYBRID_TRIPPED; break; }
            }
            r->status = pdw_hybrid_impact(p, y, r);
            break;
        }
        if (o->dt_out > 0.0) rec_dense(&R, &S, o->dt_out, t0 + t, t0 + t + h, y, k1);
        t += h;
        memcpy(y, ynew, sizeof y);
        memcpy(k1, k7, sizeof k1);
        memcpy(foot, foot_new, sizeof foot);
        armed = armed_now(&F, foot, y, o, armed);
        ground_check(p, y, k1, r);
        const double dE = fabs(energy(p, y) - r->E0);
        if (dE > r->dE_max) r->dE_max = dE;
        if (o->dt_out <= 0.0) rec_push(&R, t0 + t, y);
        if (fabs(y[PDW_HY_THETA_ST]) >= o->fall_angle) { r->status = PDW_HYBRID_FELL; break; }
        /* step size for the next step */
        double fac = en > 0.0 ? 0.9*pow(en, -0.2) : 5.0;
        fac = fmin(5.0, fmax(0.2, fac));
        if (reject) fac = fmin(fac, 1.0);
        reject = 0;
        h *= fac;
    }
    if (S.stop) r->status = PDW_HYBRID_INTERRUPTED;
    if (r->status != PDW_HYBRID_OK && r->t_strike == 0.0) r->t_strike = t;
    r->n_rhs = S.n_rhs;
    r->n_rec = R.n;
    r->rec_full = R.full;
    return r->status;
}

long pdw_hybrid_walk(const double *p, const double *y0, double s0, long n_steps,
                     const pdw_hybrid_opts *o, pdw_hybrid_result *results,
                     double *rec_t, double *rec_y, long *rec_step, long rec_cap)
{
    double y[NY], t = 0.0, s = s0;
    long n_rec = 0;
    memcpy(y, y0, sizeof y);
    for (long k = 0; k < n_steps; ++k) {
        pdw_hybrid_result *r = results + k;
        const long cap = rec_cap > n_rec ? rec_cap - n_rec : 0;
        pdw_hybrid_step(p, y, t, s, o, r, cap ? rec_t + n_rec : NULL,
                        cap ? rec_y + NY*n_rec : NULL, cap);
        if (rec_cap > 0 && cap == 0) r->rec_full = 1;
        for (long i = 0; i < r->n_rec; ++i) rec_step[n_rec + i] = k;
        n_rec += r->n_rec;
        if (r->status != PDW_HYBRID_OK) return k;
        t += r->t_strike;
        s = r->s0_next;
        memcpy(y, r->y_plus, sizeof y);
    }
    return n_steps;
}

long pdw_hybrid_walk_dh(const double *p, const double *y0, long n_steps, const double *dh_seq,
                        const pdw_hybrid_opts *o, double *y_out, double *t_out, int *status)
{
    pdw_hybrid_opts ok = *o;
    pdw_hybrid_result r;
    double y[NY], s = 0.0;
    memcpy(y, y0, sizeof y);
    *status = PDW_HYBRID_OK;
    for (long k = 0; k < n_steps; ++k) {
        ok.dh = dh_seq[k];
        pdw_hybrid_step(p, y, 0.0, s, &ok, &r, NULL, NULL, 0);
        s = r.s0_next;
        if (r.status == PDW_HYBRID_OK && r.old_foot_down) r.status = PDW_HYBRID_FELL;
        if (r.status != PDW_HYBRID_OK) { *status = r.status; return k; }
        memcpy(y, r.y_plus, sizeof y);
        memcpy(y_out + NY*k, y, sizeof y);
        t_out[k] = r.t_strike;
    }
    return n_steps;
}
