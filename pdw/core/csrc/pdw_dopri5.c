/* Dormand-Prince 5(4), adaptive (tableau pdw_tableau_dopri5): 6 new f per step (FSAL),
 * local extrapolation (the order-5 solution is kept), error = h sum (b - bhat)_i k_i in
 * Hairer's scaled RMS norm. Step size: the PI controller of Hairer's DOPRI5 code,
 *     h_new = h * clamp(0.9 * err^-(1/5 - 0.75 beta) * err_prev^beta, 0.2, 10),  beta = 0.04,
 * no increase right after a rejection. Explicit: in stance with the foot stuck the friction
 * law makes the problem stiff (eigenvalue near -1e6 /s), so the steps are stability-bound to a
 * few microseconds there. Events: pdw_adaptive_advance. */
#include <math.h>
#include <string.h>
#include "pdw_ode.h"

static double dopri5_step(pdw_sim *s, void *ctx, const double *fx, double h, int new_point,
                          double *xnew, double *fnew, int *fnew_valid)
{
    double k[PDW_RK_MAXSTAGES][PDW_NX_MAX], errv[PDW_NX_MAX];
    (void)ctx; (void)new_point;
    memcpy(k[0], fx, sizeof k[0]);
    pdw_rk_stages(s, &pdw_tableau_dopri5, s->x, h, k, xnew, errv);
    pdw_copy_state(s, fnew, k[6]);
    *fnew_valid = 1;
    return pdw_err_norm(s, s->x, xnew, errv);
}

static const pdw_adaptive_method dopri5 = {
    dopri5_step, 1.0/5.0, 0.04, 0.9, 0.2, 10.0, 0,
};

int pdw_dopri5_advance(pdw_sim *s) { return pdw_adaptive_advance(s, &dopri5, NULL); }
