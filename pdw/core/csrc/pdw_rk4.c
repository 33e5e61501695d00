/* Classical fourth-order Runge-Kutta, fixed step (tableau pdw_tableau_rk4): 4 f per step.
 * The discrete state is updated once per step from x_n before the step, as in the paper's
 * loop; nothing is located inside a step. */
#include <stddef.h>
#include "pdw_ode.h"

static int rk4_step(pdw_sim *s, double h, double *xnew)
{
    double k[4][PDW_NX_MAX];
    pdw_ode_f(s, s->x, k[0]);
    pdw_rk_stages(s, &pdw_tableau_rk4, s->x, h, k, xnew, NULL);
    return 0;
}

int pdw_rk4_advance(pdw_sim *s) { return pdw_fixed_advance(s, rk4_step); }
