/* Shared machinery of the integrators beyond the paper's (docs/integrators.md): the
 * right-hand side with the loop's discrete state, explicit Runge-Kutta stages from a tableau,
 * the error norm, and the two drivers every method plugs into:
 *
 *   pdw_fixed_advance     fixed step dt, n_steps steps; the discrete state is updated once per
 *                         step from x_n before the step (as the paper's loop, Fig. 3);
 *   pdw_adaptive_advance  error-controlled steps to t_end; flag switches (docs/model.md section 5)
 *                         are located inside a step to within event_tol and applied between
 *                         steps.
 *
 * Both follow THE INTEGRATOR CONTRACT of pdw_sim.h (resumption after EVENTS_FULL /
 * RECORDS_FULL, counters, recording, state checks). Nothing here allocates. */
#ifndef PDW_ODE_H
#define PDW_ODE_H

#include <math.h>
#include "pdw_sim.h"
#include "pdw_tableaus.h"

/* f(x) for the loop's current flags and anchors; counts one evaluation in s->n_rhs. */
static inline void pdw_ode_f(pdw_sim *s, const double *x, double *f)
{
    pdw_sim_rhs(s, x, f, s->work);
    s->n_rhs++;
}

/* Explicit Runge-Kutta step of size h from x with tableau T. k: (T->stages, PDW_NX_MAX) stage
 * derivatives (the first s->nx entries); k[0] must hold f(x) on entry. Writes xnew = x + h sum b_i k_i and, if errv is
 * not NULL, errv = h sum e_i k_i. For an FSAL tableau k[stages-1] is f(xnew) on return. */
void pdw_rk_stages(pdw_sim *s, const pdw_rk_tableau *T, const double *x, double h,
                   double (*k)[PDW_NX_MAX], double *xnew, double *errv);

/* Scaled RMS norm of an error vector (Hairer's): sqrt(mean((e_i / sc_i)^2)),
 * sc_i = atol + rtol * max(|x_i|, |xnew_i|). */
double pdw_err_norm(const pdw_sim *s, const double *x, const double *xnew, const double *errv);

/* A fixed-step method: one step of size h from s->x into xnew. May use s->cache (valid while
 * s->cache_valid; the driver clears it when the discrete state changes). Returns 0, or a
 * PDW_STATUS_* after setting s->status / s->failure. */
typedef int (*pdw_fixed_step_fn)(pdw_sim *s, double h, double *xnew);
int pdw_fixed_advance(pdw_sim *s, pdw_fixed_step_fn step);

/* An adaptive method: attempt a step of size h from s->x, f(s->x) given in fx. new_point is 1
 * on the first attempt from a new s->x or discrete state (re-evaluate a Jacobian then), 0 for
 * retries from the same point. Writes xnew; if the method computed f(xnew) it writes fnew and
 * sets *fnew_valid. Returns the scaled error norm (accept when <= 1), or INFINITY when the
 * step could not be computed (singular matrix): the driver then shrinks h. */
typedef double (*pdw_try_step_fn)(pdw_sim *s, void *ctx, const double *fx, double h,
                                  int new_point, double *xnew, double *fnew, int *fnew_valid);

typedef struct pdw_adaptive_method {
    pdw_try_step_fn step;
    double err_exponent;    /* 1/(q+1), q the lower order of the pair (local error h^(q+1)) */
    double pi_beta;         /* PI controller's beta (Hairer's DOPRI5: 0.04); 0: I controller */
    double safety;          /* 0.9 */
    double fac_min, fac_max;/* bounds of h_new/h */
    int predictive;         /* 1: Gustafsson's predictive controller (as Hairer's RODAS) */
} pdw_adaptive_method;

int pdw_adaptive_advance(pdw_sim *s, const pdw_adaptive_method *m, void *ctx);

/* The step-size control of pdw_adaptive_advance, shared with the ensemble's rodas4 lanes
 * (pdw_batch_ros.c) so that both take the same steps. */

/* h_new / h after an attempt rejected with error norm err (> 1, inf or NaN). */
static inline double pdw_reject_factor(const pdw_adaptive_method *m, double err)
{
    double fac = m->fac_min;
    if (isfinite(err)) fac = fmax(m->fac_min, m->safety * pow(err, -m->err_exponent));
    return fmin(1.0, fac);
}

/* h_new / h after an attempt accepted with error norm err <= 1, from the controller's memory
 * (s->err_prev, s->h_prev; before pdw_accept_memory updates it). */
static inline double pdw_accept_factor(const pdw_adaptive_method *m, const pdw_sim *s,
                                       double err, double h, int last_rejected)
{
    const double alpha = m->err_exponent - 0.75 * m->pi_beta;
    double fac = m->safety * pow(fmax(err, 1e-10), -alpha);
    if (m->pi_beta > 0.0) fac *= pow(s->err_prev, m->pi_beta);
    fac = fmin(m->fac_max, fmax(m->fac_min, fac));
    if (m->predictive && s->h_prev > 0.0) {
        /* Gustafsson (1994): h_new/h = safety (h/h_prev) (err_prev / err^2)^(1/(q+1)),
         * the smaller of this and the I controller's (Hairer & Wanner II, Eq. IV.8.21) */
        double g = m->safety * (h / s->h_prev)
                 * pow(s->err_prev / (fmax(err, 1e-10) * fmax(err, 1e-10)), m->err_exponent);
        g = fmin(m->fac_max, fmax(m->fac_min, g));
        fac = fmin(fac, g);
    }
    if (last_rejected) fac = fmin(fac, 1.0);
    return fac;
}

/* The controller's memory after an accepted step of size h with error err; h_next its next. */
static inline void pdw_accept_memory(const pdw_adaptive_method *m, pdw_sim *s, double err,
                                     double h, double h_next)
{
    s->err_prev = m->predictive ? fmax(err, 1e-2) : fmax(err, 1e-4);
    s->h_prev = h;
    s->h = h_next;
}

/* rodas4's method (pdw_rodas4.c), for the ensemble's rodas4 lanes. */
extern const pdw_adaptive_method pdw_rodas4_method;

#endif /* PDW_ODE_H */
