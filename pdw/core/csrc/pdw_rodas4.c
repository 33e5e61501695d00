/* RODAS4: linearly implicit (Rosenbrock) method of order 4 with an embedded order-3 solution,
 * stiffly accurate and L-stable (Hairer & Wanner, Solving ODEs II, Sec. VI.4; tableau
 * pdw_tableau_rodas4). Per step: one symbolic Jacobian J = df/dx (kernel->jacobian) at x_n,
 * one factorisation of E = I/(gamma h) - J, 6 f and 6 solves with E.
 * The state is x = [q, qd] and f = [qd, qdd(q, qd)], so J = [[0, I], [A, B]] exactly (the
 * generated jacobian writes the upper blocks as 0 and I). With d = 1/(gamma h),
 *     E [u; v] = [r; s]  <=>  S v = s + A r / d,  u = (r + v) / d,  S = d I - B - A / d,
 * so only the 4x4 Schur complement S is factored (partial pivoting, pdw_lu.h) instead of the
 * 8x8 E: the same solution up to rounding, at a fraction of the cost. Elimination on the
 * diagonal block d I without pivoting is backward stable here: with d >= 1 (h <= 1/gamma = 4 s)
 * the factors satisfy |L||U| <= 3 |E| entrywise-maximum, like the pivoted 8x8 LU's.
 * J is kept across rejected attempts and the event redo from the same x_n; S is refactored
 * when h changes. Step size: I controller h_new = h * clamp(0.9 err^(-1/4), 0.2, 6), no
 * increase right after a rejection; a singular E counts as a rejection (h * 0.2).
 * With LuGre's bristle states (s->nx > PDW_NX) J has no such form: the full nx x nx E is factored
 * (partial pivoting) instead.
 * L-stability damps the stuck-friction mode (eigenvalue near -1e6 /s) in one step, so the
 * steps follow accuracy, not stability: no friction chatter at steps of milliseconds. */
#include <math.h>
#include <string.h>
#include "pdw_ode.h"
#include "pdw_lu.h"

typedef struct rodas_ctx {
    int nx;                 /* state size: PDW_NX (Schur path) or more (LuGre: full LU of E) */
    double J[PDW_NX_MAX * PDW_NX_MAX];
    double E[PDW_NX_MAX * PDW_NX_MAX];  /* nx > PDW_NX: LU factors of I/(gamma h) - J */
    int pivE[PDW_NX_MAX];
    double S[PDW_NQ * PDW_NQ];  /* LU factors of the Schur complement d I - B - A/d */
    int piv[PDW_NQ];
    double gh;              /* gamma h = 1/d of the factors */
    double lu_h;            /* h of the factors in S; 0: none */
} rodas_ctx;

#define J_A(J, i, j) (J)[(PDW_NQ + (i)) * PDW_NX + (j)]            /* d qdd / d q  */
#define J_B(J, i, j) (J)[(PDW_NQ + (i)) * PDW_NX + PDW_NQ + (j)]   /* d qdd / d qd */

/* Factor S = d I - B - A / d, d = 1/(gamma h). Returns 0, or -1 if singular. */
static int rodas_factor(rodas_ctx *c, double gh)
{
    const double d = 1.0 / gh;
    if (c->nx != PDW_NX) {          /* with the bristle states J has no [[0, I], [A, B]] form */
        const int n = c->nx;
        for (int i = 0; i < n * n; ++i) c->E[i] = -c->J[i];
        for (int i = 0; i < n; ++i) c->E[i * n + i] += d;
        c->gh = gh;
        return pdw_lu_factor(n, c->E, c->pivE);
    }
    for (int i = 0; i < PDW_NQ; ++i)
        for (int j = 0; j < PDW_NQ; ++j)
            c->S[i * PDW_NQ + j] = -J_B(c->J, i, j) - gh * J_A(c->J, i, j);
    for (int i = 0; i < PDW_NQ; ++i) c->S[i * PDW_NQ + i] += d;
    c->gh = gh;
    return pdw_lu_factor(PDW_NQ, c->S, c->piv);
}

/* Solve (I/(gamma h) - J) b_new = b in place, b = [r; s] (PDW_NX), with the factors of S. */
static inline void rodas_solve(const rodas_ctx *c, double *b)
{
    double w[PDW_NQ];
    if (c->nx != PDW_NX) { pdw_lu_solve(c->nx, c->E, c->pivE, b); return; }
    for (int i = 0; i < PDW_NQ; ++i) {
        double acc = 0.0;
        for (int j = 0; j < PDW_NQ; ++j) acc += J_A(c->J, i, j) * b[j];
        w[i] = b[PDW_NQ + i] + c->gh * acc;
    }
    pdw_lu_solve(PDW_NQ, c->S, c->piv, w);
    for (int i = 0; i < PDW_NQ; ++i) {
        b[i] = c->gh * (b[i] + w[i]);
        b[PDW_NQ + i] = w[i];
    }
}

static double rodas4_step(pdw_sim *s, void *vctx, const double *fx, double h, int new_point,
                          double *xnew, double *fnew, int *fnew_valid)
{
    const pdw_ros_tableau *T = &pdw_tableau_rodas4;
    rodas_ctx *c = (rodas_ctx *)vctx;
    double u[PDW_ROS_MAXSTAGES][PDW_NX_MAX], xs[PDW_NX_MAX], errv[PDW_NX_MAX];
    const int nx = s->nx;
    (void)fnew; (void)fnew_valid;
    if (new_point) {
        pdw_sim_jacobian(s, s->x, c->J, s->work);
        s->n_jac++;
        c->lu_h = 0.0;
    }
    if (c->lu_h != h) {
        c->lu_h = 0.0;
        if (rodas_factor(c, T->gamma * h)) return INFINITY;
        c->lu_h = h;
    }
    const double ih = 1.0 / h;
    pdw_copy_state(s, u[0], fx);
    rodas_solve(c, u[0]);
    for (int i = 1; i < T->stages; ++i) {
        for (int k = 0; k < nx; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->a[i][j] * u[j][k];
            xs[k] = s->x[k] + acc;
        }
        pdw_ode_f(s, xs, u[i]);
        for (int k = 0; k < nx; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->C[i][j] * u[j][k];
            u[i][k] += ih * acc;
        }
        rodas_solve(c, u[i]);
    }
    for (int k = 0; k < nx; ++k) {
        double acc = 0.0, err = 0.0;
        for (int j = 0; j < T->stages; ++j) { acc += T->m[j] * u[j][k]; err += T->e[j] * u[j][k]; }
        xnew[k] = s->x[k] + acc;
        errv[k] = err;
    }
    return pdw_err_norm(s, s->x, xnew, errv);
}

const pdw_adaptive_method pdw_rodas4_method = {
    rodas4_step, 1.0/4.0, 0.0, 0.9, 0.2, 6.0, 1,
};

int pdw_rodas4_advance(pdw_sim *s)
{
    rodas_ctx c;
    c.lu_h = 0.0;
    c.nx = s->nx;
    return pdw_adaptive_advance(s, &pdw_rodas4_method, &c);
}
