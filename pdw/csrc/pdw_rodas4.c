/* RODAS4: linearly implicit (Rosenbrock) method of order 4 with an embedded order-3 solution,
 * stiffly accurate and L-stable (Hairer & Wanner, Solving ODEs II, Sec. VI.4; tableau
 * pdw_tableau_rodas4). Per step: one symbolic Jacobian J = df/dx (kernel->jacobian) at x_n,
 * one 8x8 LU of E = I/(gamma h) - J with partial pivoting (pdw_lu.h), 6 f and 6 solves.
 * J is kept across rejected attempts and the event redo from the same x_n; E is refactored
 * when h changes. Step size: I controller h_new = h * clamp(0.9 err^(-1/4), 0.2, 6), no
 * increase right after a rejection; a singular E counts as a rejection (h * 0.2).
 * L-stability damps the stuck-friction mode (eigenvalue near -1e6 /s) in one step, so the
 * steps follow accuracy, not stability: no friction chatter at steps of milliseconds. */
#include <math.h>
#include <string.h>
#include "pdw_ode.h"
#include "pdw_lu.h"

typedef struct rodas_ctx {
    double J[PDW_NX * PDW_NX];
    double LU[PDW_NX * PDW_NX];
    int piv[PDW_NX];
    double lu_h;            /* h of the factors in LU; 0: none */
} rodas_ctx;

static double rodas4_step(pdw_sim *s, void *vctx, const double *fx, double h, int new_point,
                          double *xnew, double *fnew, int *fnew_valid)
{
    const pdw_ros_tableau *T = &pdw_tableau_rodas4;
    rodas_ctx *c = (rodas_ctx *)vctx;
    double u[PDW_ROS_MAXSTAGES][PDW_NX], xs[PDW_NX], errv[PDW_NX];
    (void)fnew; (void)fnew_valid;
    if (new_point) {
        s->kernel->jacobian(s->x, s->p, s->disc.flags, s->disc.anchors, c->J, s->work);
        s->n_jac++;
        c->lu_h = 0.0;
    }
    if (c->lu_h != h) {
        const double d = 1.0 / (T->gamma * h);
        for (int i = 0; i < PDW_NX * PDW_NX; ++i) c->LU[i] = -c->J[i];
        for (int i = 0; i < PDW_NX; ++i) c->LU[i * PDW_NX + i] += d;
        c->lu_h = 0.0;
        if (pdw_lu_factor(PDW_NX, c->LU, c->piv)) return INFINITY;
        c->lu_h = h;
    }
    const double ih = 1.0 / h;
    memcpy(u[0], fx, sizeof u[0]);
    pdw_lu_solve(PDW_NX, c->LU, c->piv, u[0]);
    for (int i = 1; i < T->stages; ++i) {
        for (int k = 0; k < PDW_NX; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->a[i][j] * u[j][k];
            xs[k] = s->x[k] + acc;
        }
        pdw_ode_f(s, xs, u[i]);
        for (int k = 0; k < PDW_NX; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->C[i][j] * u[j][k];
            u[i][k] += ih * acc;
        }
        pdw_lu_solve(PDW_NX, c->LU, c->piv, u[i]);
    }
    for (int k = 0; k < PDW_NX; ++k) {
        double acc = 0.0, err = 0.0;
        for (int j = 0; j < T->stages; ++j) { acc += T->m[j] * u[j][k]; err += T->e[j] * u[j][k]; }
        xnew[k] = s->x[k] + acc;
        errv[k] = err;
    }
    return pdw_err_norm(s, s->x, xnew, errv);
}

static const pdw_adaptive_method rodas4 = {
    rodas4_step, 1.0/4.0, 0.0, 0.9, 0.2, 6.0, 1,
};

int pdw_rodas4_advance(pdw_sim *s)
{
    rodas_ctx c;
    c.lu_h = 0.0;
    return pdw_adaptive_advance(s, &rodas4, &c);
}
