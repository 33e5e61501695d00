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

#include "pdw_sim.h"
#include "pdw_tableaus.h"

/* f(x) for the loop's current flags and anchors; counts one evaluation in s->n_rhs. */
static inline void pdw_ode_f(pdw_sim *s, const double *x, double *f)
{
    s->kernel->rhs(x, s->p, s->disc.flags, s->disc.anchors, f, s->work);
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

#endif /* PDW_ODE_H */
