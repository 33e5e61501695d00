/* Velocity Verlet ("cdm2"), second order, fixed step, one f evaluation per step.
 *
 * The leapfrog / central difference scheme with the velocity at the right time. With
 * a_n = qdd(q_n, v_n) and forces that depend on the velocity (contact damping, friction), the
 * velocity at the end of the step is needed before it is known; we use the half-step velocity
 * predictor:
 *     v_{n+1/2} = v_n + h/2 a_n
 *     q_{n+1}   = q_n + h v_{n+1/2}
 *     v*        = v_{n+1/2} + h/2 a_n                (predicted v_{n+1}, explicit Euler)
 *     a_{n+1}   = qdd(q_{n+1}, v*)
 *     v_{n+1}   = v_{n+1/2} + h/2 a_{n+1}
 * q_{n+1} is q's Taylor polynomial to h^2 (local error O(h^3)); v_{n+1} is Heun's method
 * (trapezoidal rule with an Euler predictor), local error O(h^3): second order in q and v. For
 * forces independent of the velocity it is exactly velocity Verlet (symplectic).
 * a_{n+1} is kept (s->cache) as the next step's a_n; when the flags or anchors change between
 * steps it is recomputed at (q_n, v_n) with the new discrete state. */
#include <string.h>
#include "pdw_ode.h"

static int verlet_step(pdw_sim *s, double h, double *xnew)
{
    double *a = s->cache + PDW_NQ;      /* cache = f(q_n, v_n*) = [v, a]; a_n in the lower half */
    double xp[PDW_NX_MAX], vh[PDW_NQ], zd[PDW_NX_MAX];
    const double *q = s->x, *v = s->x + PDW_NQ;
    if (!s->cache_valid) { pdw_ode_f(s, s->x, s->cache); s->cache_valid = 1; }
    for (int i = 0; i < PDW_NQ; ++i) {
        vh[i] = v[i] + 0.5 * h * a[i];
        xp[i] = q[i] + h * vh[i];
        xp[PDW_NQ + i] = vh[i] + 0.5 * h * a[i];
    }
    /* LuGre's bristle states (beyond [q, qd]): Heun, like v -- Euler predictor, trapezoid */
    for (int i = PDW_NX; i < s->nx; ++i) {
        zd[i] = s->cache[i];
        xp[i] = s->x[i] + h * zd[i];
    }
    pdw_ode_f(s, xp, s->cache);          /* a_{n+1} at (q_{n+1}, v*) */
    for (int i = 0; i < PDW_NQ; ++i) {
        xnew[i] = xp[i];
        xnew[PDW_NQ + i] = vh[i] + 0.5 * h * a[i];
    }
    for (int i = PDW_NX; i < s->nx; ++i) xnew[i] = s->x[i] + 0.5 * h * (zd[i] + s->cache[i]);
    return 0;
}

int pdw_verlet_advance(pdw_sim *s) { return pdw_fixed_advance(s, verlet_step); }
