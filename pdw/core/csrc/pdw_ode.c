/* Drivers and helpers shared by the fixed-step and adaptive integrators (see pdw_ode.h). */
#include <float.h>
#include <math.h>
#include <string.h>
#include "pdw_ode.h"

/* The stages for a state of nx entries; inlined with nx = PDW_NX a compile-time constant
 * (pdw_rk_stages), so that the common size keeps its unrolled loops. */
static inline void rk_stages(pdw_sim *s, const pdw_rk_tableau *T, const double *x, double h,
                             double (*k)[PDW_NX_MAX], double *xnew, double *errv, const int nx)
{
    double xs[PDW_NX_MAX];
    for (int i = 1; i < T->stages; ++i) {
        for (int c = 0; c < nx; ++c) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->a[i][j] * k[j][c];
            xs[c] = x[c] + h * acc;
        }
        pdw_ode_f(s, xs, k[i]);
    }
    for (int c = 0; c < nx; ++c) {
        double acc = 0.0, err = 0.0;
        for (int j = 0; j < T->stages; ++j) {
            acc += T->b[j] * k[j][c];
            err += T->e[j] * k[j][c];
        }
        xnew[c] = x[c] + h * acc;
        if (errv) errv[c] = h * err;
    }
    /* FSAL: the last stage point is the new solution up to rounding; use that exact point so
     * that k[stages-1] is f(xnew) bit for bit */
    if (T->fsal) pdw_copy_state(s, xnew, xs);
}

void pdw_rk_stages(pdw_sim *s, const pdw_rk_tableau *T, const double *x, double h,
                   double (*k)[PDW_NX_MAX], double *xnew, double *errv)
{
    if (s->nx == PDW_NX) rk_stages(s, T, x, h, k, xnew, errv, PDW_NX);
    else rk_stages(s, T, x, h, k, xnew, errv, s->nx);
}

double pdw_err_norm(const pdw_sim *s, const double *x, const double *xnew, const double *errv)
{
    double acc = 0.0;
    for (int i = 0; i < s->nx; ++i) {
        const double sc = s->atol + s->rtol * fmax(fabs(x[i]), fabs(xnew[i]));
        const double r = errv[i] / sc;
        acc += r * r;
    }
    return sqrt(acc / s->nx);
}

/* Contact forces of s->x into s->work (for the recorded sample), then store the sample. */
static void sample(pdw_sim *s)
{
    pdw_trig(s->x, s->work + PDW_WORK_TRIG);
    pdw_sim_kinematics(s, s->x, s->disc.anchors, s->work);
    pdw_sim_contact(s, s->work);
    pdw_record_now(s, s->t);
}

/* Did the part of the discrete state that f depends on change? */
static int forces_changed(const pdw_discrete *a, const pdw_discrete *b)
{
    if (a->flags[0] != b->flags[0] || a->flags[1] != b->flags[1]) return 1;
    for (int i = 0; i < PDW_NANCHOR; ++i)
        if (a->anchors[i] != b->anchors[i]) return 1;
    return 0;
}

/* ---------------------------------------------------------------- fixed step ------------- */

int pdw_fixed_advance(pdw_sim *s, pdw_fixed_step_fn step)
{
    const double dt = s->dt;
    double xnew[PDW_NX_MAX];
    s->status = PDW_STATUS_RUNNING;
    if (!s->started) {
        const int r = pdw_update_flags(s, 0.0);
        if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
        s->started = 1;
        s->n = 0;
        s->t = 0.0;
        s->cache_valid = 0;
        if (s->record_every > 0) sample(s);
        if (r > 0) return s->status;                        /* a stop condition */
    }
    while (s->n < s->n_steps) {
        if (!pdw_records_room(s)) { s->status = PDW_STATUS_RECORDS_FULL; return s->status; }
        if (pdw_poll_due(s)) return s->status;
        if (s->n > 0) {
            /* flags from (U_n, U'_n) before step n, as the paper's loop (Fig. 3) */
            const pdw_discrete before = s->disc;
            const int r = pdw_update_flags(s, s->t);
            if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
            if (r > 0) { pdw_record_final(s, s->t); return s->status; }   /* a stop condition */
            if (forces_changed(&before, &s->disc)) s->cache_valid = 0;
            if (pdw_check_feet(s, s->t)) return s->status;
            if (s->record_every > 0 && s->n % s->record_every == 0) sample(s);
        }
        if (step(s, dt, xnew)) return s->status;
        if (pdw_check_state(s, xnew, s->t)) return s->status;
        pdw_copy_state(s, s->x, xnew);
        s->n++;
        s->t = s->n * dt;
    }
    const int r = pdw_update_flags(s, s->t);
    if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
    if (s->record_every > 0 && s->n % s->record_every == 0) sample(s);
    if (r == 0) s->status = PDW_STATUS_DONE;           /* else: the stop condition's status */
    return s->status;
}

/* ---------------------------------------------------------------- adaptive --------------- */

/* Apply pdw_update_flags until nothing changes (a lift-off can arm the same leg at once), so
 * that no switch is pending at the start of the next step. Needs room for 6 events. Returns
 * pdw_update_flags's code: -1 (events full), 1 (a stop condition: s->status set), or 0. */
static int settle_flags(pdw_sim *s, double t)
{
    for (int it = 0; it < 3; ++it) {
        const pdw_discrete before = s->disc;
        const int r = pdw_update_flags(s, t);
        if (r) return r;
        if (memcmp(&before, &s->disc, sizeof before) == 0) break;
    }
    return 0;
}

/* Cubic Hermite interpolant on [0, h] at theta in [0, 1] (Hairer, Norsett & Wanner I, II.6). */
static void hermite(int nx, const double *x0, const double *f0, const double *x1,
                    const double *f1, double h, double th, double *out)
{
    for (int i = 0; i < nx; ++i)
        out[i] = (1.0 - th)*x0[i] + th*x1[i]
               + th*(th - 1.0)*((1.0 - 2.0*th)*(x1[i] - x0[i]) + (th - 1.0)*h*f0[i] + th*h*f1[i]);
}

/* Bisection of the switch predicate (pdw_switch_pending) on the Hermite extension of the step
 * [t, t + h]: false at 0, true at h. Returns tb in (0, h], the right end of a bracket of
 * width <= event_tol with the predicate true at tb. */
static double locate_switch(pdw_sim *s, const double *x0, const double *f0, const double *x1,
                            const double *f1, double h)
{
    double ta = 0.0, tb = h, xi[PDW_NX_MAX];
    while (tb - ta > s->event_tol) {
        const double tm = 0.5 * (ta + tb);
        if (tm <= ta || tm >= tb) break;
        hermite(s->nx, x0, f0, x1, f1, h, tm / h, xi);
        if (pdw_switch_pending(s, xi, s->work)) tb = tm; else ta = tm;
    }
    return tb;
}

static int fail_step_size(pdw_sim *s)
{
    s->status = PDW_STATUS_DIVERGED;
    s->failure.reason = PDW_REASON_STEP_SIZE;
    s->failure.leg = -1;
    s->failure.t = s->t;
    memcpy(s->failure.x, s->x, sizeof s->x);
    return s->status;
}

int pdw_adaptive_advance(pdw_sim *s, const pdw_adaptive_method *m, void *ctx)
{
    double xnew[PDW_NX_MAX], fnew[PDW_NX_MAX];
    const double t_end = s->t_end;
    int new_point = 1, last_rejected = 0;

    s->status = PDW_STATUS_RUNNING;
    if (s->event_tol <= 0.0) s->event_tol = 1e-9;
    if (!s->started) {
        s->t = 0.0;
        s->n = 0;
        s->err_prev = 1e-4;
        s->h_prev = 0.0;
        s->cache_valid = 0;
        const int r = settle_flags(s, 0.0);
        if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
        s->started = 1;
        if (s->record_every > 0) sample(s);
        if (r > 0) return s->status;                        /* a stop condition */
    }
    while (s->t < t_end) {
        /* room for what an accepted step may append; return here only (before a step), so
         * that a resumed call continues exactly */
        if (!pdw_events_room(s, 6)) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
        if (s->record_every > 0 && s->n_rec + 1 > s->rec_capacity) {
            s->status = PDW_STATUS_RECORDS_FULL;
            return s->status;
        }
        /* poll only where a resumed call continues exactly (new_point and last_rejected are
         * what a fresh call starts with: right after an accepted step) */
        if (new_point && !last_rejected && pdw_poll_due(s)) return s->status;
        if (s->max_steps > 0 && s->n + s->n_rejected >= s->max_steps) {
            fail_step_size(s);
            s->failure.reason = PDW_REASON_BUDGET;
            return s->status;
        }
        if (!s->cache_valid) { pdw_ode_f(s, s->x, s->cache); s->cache_valid = 1; }

        double h = fmin(s->h, s->h_max);
        int last = 0;
        const double rem = t_end - s->t;
        if (h >= rem - 1e-12 * fmax(1.0, t_end)) { h = rem; last = 1; }
        if (!(h > 8.0 * DBL_EPSILON * fmax(fabs(s->t), 1e-3))) return fail_step_size(s);

        int fnew_valid = 0;
        const double err = m->step(s, ctx, s->cache, h, new_point, xnew, fnew, &fnew_valid);
        new_point = 0;
        if (!(err <= 1.0)) {                               /* rejected (or NaN / singular) */
            s->h = h * pdw_reject_factor(m, err);
            s->n_rejected++;
            last_rejected = 1;
            continue;
        }
        const double h_next = h * pdw_accept_factor(m, s, err, h, last_rejected);
        if (!fnew_valid) { pdw_ode_f(s, xnew, fnew); fnew_valid = 1; }

        /* a flag switch inside the step: locate it on the step's continuous extension, then
         * redo the step to end just after it (within event_tol) */
        double h_acc = h;
        if (pdw_switch_pending(s, xnew, s->work)) {
            const double tb = locate_switch(s, s->x, s->cache, xnew, fnew, h);
            if (tb < h) {
                fnew_valid = 0;
                const double e2 = m->step(s, ctx, s->cache, tb, 0, xnew, fnew, &fnew_valid);
                if (!isfinite(e2)) {                        /* could not redo: retry shorter */
                    s->h = tb;
                    s->n_rejected++;
                    last_rejected = 1;
                    continue;
                }
                if (!fnew_valid) { pdw_ode_f(s, xnew, fnew); fnew_valid = 1; }
                h_acc = tb;
                last = 0;
            }
        }
        if (pdw_check_state(s, xnew, s->t)) return s->status;
        pdw_copy_state(s, s->x, xnew);
        pdw_copy_state(s, s->cache, fnew);
        s->cache_valid = 1;
        s->t = last ? t_end : s->t + h_acc;
        s->n++;
        pdw_accept_memory(m, s, err, h, h_next);
        new_point = 1;
        last_rejected = 0;

        const pdw_discrete before = s->disc;
        if (settle_flags(s, s->t) > 0) {                    /* room checked above */
            if (s->record_every > 0) sample(s);             /* a stop condition: like t_end, */
            return s->status;                               /* the final state is recorded */
        }
        if (forces_changed(&before, &s->disc)) s->cache_valid = 0;
        if (pdw_check_feet(s, s->t)) return s->status;
        if (s->record_every > 0 && (s->n % s->record_every == 0 || s->t >= t_end)) sample(s);
    }
    s->status = PDW_STATUS_DONE;
    return s->status;
}
