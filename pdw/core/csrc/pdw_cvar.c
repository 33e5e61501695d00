/* The continuous walker's variational equations by RODAS4 (pdw_cvar.h).
 *
 * y by RODAS4 (pdw_rodas4.c's transformed form, Hairer & Wanner II, Eq. IV.7.4'; the matrix
 * E = I/(gamma h) - A factored through its 4 x 4 Schur complement, cv_factor). Phi over the
 * same step by RODAS4 applied to the linear non-autonomous Phi' = A(t) Phi, A(t) = A(y(t)):
 *     E U_i = A(t_n + alpha_i h) P_i + sum_j (C_ij / h) U_j + gamma_i h A_t Phi_n,
 * P_i = Phi_n + sum_j a_ij U_j, Phi_{n+1} = Phi_n + sum m_i U_i, with E the same factors, the
 * stage times alpha_i and sums gamma_i of the original form (cv_stage_times: rodas.f's C_i,
 * D_i) and A_t = dA[f(y_n)] (dA[u] = sum_j dA/dy_j u_j) a central difference of the kernel's
 * symbolic Jacobian along f (largest state change dir_step, 1e-7: relative error ~1e-9).
 * A(t) at the inner stage times (0.21, 0.386, 0.63) comes from the cubic Hermite interpolant of
 * A between the step's ends (A and A_t at both; a_hermite, the default: 3 Jacobians a step,
 * each reused by the next step) or from the Jacobian at y's Hermite interpolant (6 a step); the
 * end times 0 and 1 are exact. Either interpolant is O(h^4): order 4 is kept. (The autonomous
 * augmented system (y, Phi), whose Jacobian [[A, 0], [dA[.] Phi, A]] needs dA along every
 * stage increment, took twice the Jacobians for the same accuracy.) With the approach speeds
 * (na = 2) the columns df/dv_in are central differences of f (step 1e-6 max(1, |v_in|)), as
 * variational.py's, and their dA[u] a mixed second difference (steps 1e-4); a parameter
 * state (np = 1) likewise, its column the difference of f between the caller's parameter
 * vectors p_plus and p_minus over dmu.
 * Steps: the error estimates of y and (phi_error) of Phi, an I controller (h_new = h clamp(0.9
 * err^(-1/4), 0.2, 6), no increase right after a rejection); without Phi's estimate the stiff
 * modes that Phi(0) = I and each saltation excite are not resolved (Phi off by 1e-4). Events:
 * after each accepted step, an event function that crossed in its direction is located on the
 * cubic Hermite extension of the step, then by a safeguarded Newton iteration on re-steps of y
 * of length s from y_n (d g / d s = grad g . f(y(s))) to rounding; the last step, of the located
 * length, advances Phi too.
 * About 550 lines, one unit: the y step, its Phi companion and the event location share the
 * step's context (factors, stages, A and A_t at its ends). */
#include <float.h>
#include <math.h>
#include <string.h>
#include "pdw_cvar.h"
#include "pdw_lu.h"
#include "pdw_tableaus.h"

#define NMAX PDW_CVAR_NMAX
#define NS PDW_ROS_MAXSTAGES

typedef struct cv_ctx {
    const pdw_cvar_model *m;
    pdw_cvar_stats *st;
    double *work;
    int n;
    double A[NMAX * NMAX];      /* A(y_n) */
    double E[PDW_NQ * PDW_NQ];  /* LU factors of the Schur complement of E (cv_factor) */
    int piv[PDW_NQ];
    double gh;                  /* gamma h of the factors */
    double lu_h;                /* h of the factors; 0: none */
    double u[NS][NMAX];         /* stage increments of y of the last attempt */
    double Y[NS][NMAX];         /* its stage points */
    double alpha[NS], gsum[NS]; /* cv_stage_times */
    double At[NMAX * NMAX];     /* dA[f(y_n)] (a_hermite: kept from the last step's end) */
    int at_valid;
} cv_ctx;

/* f at y with the parameter vector p */
static void cv_f_p(cv_ctx *c, const double *y, const double *p, double *f)
{
    const pdw_cvar_model *m = c->m;
    double an[PDW_NANCHOR];
    memcpy(an, m->anchors, sizeof an);
    if (m->na) { an[PDW_ANCHOR_V_IN1] = y[PDW_NX]; an[PDW_ANCHOR_V_IN2] = y[PDW_NX + 1]; }
    m->kernel->rhs(y, p, m->flags, an, f, c->work);
    for (int i = PDW_NX; i < c->n; ++i) f[i] = 0.0;
    c->st->n_rhs++;
}

static void cv_f(cv_ctx *c, const double *y, double *f)
{
    cv_f_p(c, y, c->m->p, f);
}

/* f at y with approach speed j replaced by v (na = 2) */
static void cv_f_v(cv_ctx *c, const double *y, int j, double v, double *f)
{
    double yy[NMAX];
    memcpy(yy, y, (size_t)c->n * sizeof(double));
    yy[PDW_NX + j] = v;
    cv_f(c, yy, f);
}

/* the kernel's 8 x 8 Jacobian at y into the leading block of J (n x n, row-major) */
static void cv_jac8(cv_ctx *c, const double *y, double *J)
{
    const pdw_cvar_model *m = c->m;
    double an[PDW_NANCHOR], J8[PDW_NX * PDW_NX];
    memcpy(an, m->anchors, sizeof an);
    if (m->na) { an[PDW_ANCHOR_V_IN1] = y[PDW_NX]; an[PDW_ANCHOR_V_IN2] = y[PDW_NX + 1]; }
    m->kernel->jacobian(y, m->p, m->flags, an, J8, c->work);
    c->st->n_jac++;
    for (int i = 0; i < PDW_NX; ++i)
        for (int j = 0; j < PDW_NX; ++j) J[i * c->n + j] = J8[i * PDW_NX + j];
}

/* A = df/dy (n x n) at y */
static void cv_jac(cv_ctx *c, const double *y, double *A)
{
    const int n = c->n;
    for (int i = 0; i < n * n; ++i) A[i] = 0.0;
    cv_jac8(c, y, A);
    for (int j = 0; j < c->m->na; ++j) {        /* df/dv_in: central differences */
        double fp[NMAX], fm[NMAX];
        const double v = y[PDW_NX + j], hv = 1e-6 * fmax(1.0, fabs(v));
        cv_f_v(c, y, j, v + hv, fp);
        cv_f_v(c, y, j, v - hv, fm);
        for (int i = 0; i < PDW_NX; ++i) A[i * n + PDW_NX + j] = (fp[i] - fm[i]) / (2.0 * hv);
    }
    if (c->m->np) {                             /* df/dmu: between p_plus and p_minus */
        double fp[NMAX], fm[NMAX];
        const int j = PDW_NX + c->m->na;
        cv_f_p(c, y, c->m->p_plus, fp);
        cv_f_p(c, y, c->m->p_minus, fm);
        for (int i = 0; i < PDW_NX; ++i) A[i * n + j] = (fp[i] - fm[i]) / c->m->dmu;
    }
}

/* D = dA[u] at y (n x n): central differences along u (one_sided: forward, from Ay = A(y)) */
static void cv_dA(cv_ctx *c, const pdw_cvar_opts *o, const double *y, const double *Ay,
                  const double *u, double *D)
{
    const int n = c->n;
    double umax = 0.0, yp[NMAX], ym[NMAX], Jm[NMAX * NMAX];
    for (int i = 0; i < n; ++i) umax = fmax(umax, fabs(u[i]));
    for (int i = 0; i < n * n; ++i) D[i] = 0.0;
    if (!(umax > 0.0)) return;
    double eps = o->dir_step / umax;
    for (int i = 0; i < n; ++i) { yp[i] = y[i] + eps * u[i]; ym[i] = y[i] - eps * u[i]; }
    cv_jac8(c, yp, D);
    if (o->one_sided) {
        for (int i = 0; i < PDW_NX; ++i)
            for (int j = 0; j < PDW_NX; ++j)
                D[i * n + j] = (D[i * n + j] - Ay[i * n + j]) / eps;
    } else {
        cv_jac8(c, ym, Jm);
        for (int i = 0; i < PDW_NX; ++i)
            for (int j = 0; j < PDW_NX; ++j)
                D[i * n + j] = (D[i * n + j] - Jm[i * n + j]) / (2.0 * eps);
    }
    if (c->m->np) {                 /* d(df/dmu)[u]: a mixed second difference */
        double a[NMAX], b[NMAX], cc[NMAX], d[NMAX];
        const double e2 = 1e-4 / umax;
        const int j = PDW_NX + c->m->na;
        for (int i = 0; i < n; ++i) { yp[i] = y[i] + e2 * u[i]; ym[i] = y[i] - e2 * u[i]; }
        cv_f_p(c, yp, c->m->p_plus, a);
        cv_f_p(c, yp, c->m->p_minus, b);
        cv_f_p(c, ym, c->m->p_plus, cc);
        cv_f_p(c, ym, c->m->p_minus, d);
        for (int i = 0; i < PDW_NX; ++i)
            D[i * n + j] = ((a[i] - b[i]) - (cc[i] - d[i])) / (2.0 * e2 * c->m->dmu);
    }
    if (!c->m->na) return;
    eps = 1e-4 / umax;              /* the mixed second differences of the df/dv_in columns */
    for (int i = 0; i < n; ++i) { yp[i] = y[i] + eps * u[i]; ym[i] = y[i] - eps * u[i]; }
    for (int j = 0; j < c->m->na; ++j) {
        double a[NMAX], b[NMAX], cc[NMAX], d[NMAX];
        const double v = y[PDW_NX + j], hv = 1e-4 * fmax(1.0, fabs(v));
        cv_f_v(c, yp, j, v + hv, a);
        cv_f_v(c, yp, j, v - hv, b);
        cv_f_v(c, ym, j, v + hv, cc);
        cv_f_v(c, ym, j, v - hv, d);
        for (int i = 0; i < PDW_NX; ++i)
            D[i * n + PDW_NX + j] = ((a[i] - b[i]) - (cc[i] - d[i])) / (4.0 * eps * hv);
    }
}

static double cv_norm(int len, const double *a, const double *b, const double *e, double rtol,
                      double atol)
{
    double s = 0.0;
    for (int i = 0; i < len; ++i) {
        const double sc = atol + rtol * fmax(fabs(a[i]), fabs(b[i]));
        const double q = e[i] / sc;
        s += q * q;
    }
    return sqrt(s / len);
}

/* The Rosenbrock matrix E = I/(gamma h) - A has A's structure: rows 0..3 [0, I, 0] (q' = qd),
 * rows 4..7 [Aq, Av, Avin], rows 8.. zero (v_in' = 0). With d = 1/(gamma h),
 *     E [a; b; c] = [r; s; t]  <=>  c = t / d,  S b = s + Aq r / d + Avin c,  a = (r + b) / d,
 * S = d I - Av - Aq / d: only the 4 x 4 Schur complement S is factored (pdw_rodas4.c's way).
 * Factor S for step h into c->E (PDW_NQ x PDW_NQ). Returns 0, or -1 if singular. */
static int cv_factor(cv_ctx *c, double h)
{
    const int n = c->n;
    const double gh = pdw_tableau_rodas4.gamma * h, d = 1.0 / gh;
    for (int i = 0; i < PDW_NQ; ++i)
        for (int j = 0; j < PDW_NQ; ++j)
            c->E[i * PDW_NQ + j] = -c->A[(PDW_NQ + i) * n + PDW_NQ + j]
                                 - gh * c->A[(PDW_NQ + i) * n + j];
    for (int i = 0; i < PDW_NQ; ++i) c->E[i * PDW_NQ + i] += d;
    c->gh = gh;
    return pdw_lu_factor(PDW_NQ, c->E, c->piv);
}

/* Solve E X = B in place for the ncols columns of B (n x ncols, row-major; ncols 1 for a
 * vector) with the factors of cv_factor. */
static inline void cv_solve(const cv_ctx *c, double *restrict B, const int n, const int ncols)
{
    const double gh = c->gh;
    const double *A = c->A, *LU = c->E;
    double W[PDW_NQ][NMAX];
    for (int r = PDW_NX; r < n; ++r)                /* c = gamma h t */
        for (int q = 0; q < ncols; ++q) B[r * ncols + q] *= gh;
    for (int r = 0; r < PDW_NQ; ++r) {              /* s + gamma h Aq r + Avin c */
        for (int q = 0; q < ncols; ++q) W[r][q] = B[(PDW_NQ + r) * ncols + q];
        for (int k = 0; k < PDW_NQ; ++k) {
            const double a = gh * A[(PDW_NQ + r) * n + k];
            for (int q = 0; q < ncols; ++q) W[r][q] += a * B[k * ncols + q];
        }
        for (int k = PDW_NX; k < n; ++k) {
            const double a = A[(PDW_NQ + r) * n + k];
            for (int q = 0; q < ncols; ++q) W[r][q] += a * B[k * ncols + q];
        }
    }
    for (int k = 0; k < PDW_NQ; ++k) {              /* S b = W (pdw_lu.h's factors) */
        const int p = c->piv[k];
        if (p != k)
            for (int q = 0; q < ncols; ++q) { const double t = W[k][q]; W[k][q] = W[p][q]; W[p][q] = t; }
    }
    for (int i = 1; i < PDW_NQ; ++i)
        for (int j = 0; j < i; ++j) {
            const double l = LU[i * PDW_NQ + j];
            for (int q = 0; q < ncols; ++q) W[i][q] -= l * W[j][q];
        }
    for (int i = PDW_NQ - 1; i >= 0; --i) {
        for (int j = i + 1; j < PDW_NQ; ++j) {
            const double u = LU[i * PDW_NQ + j];
            for (int q = 0; q < ncols; ++q) W[i][q] -= u * W[j][q];
        }
        for (int q = 0; q < ncols; ++q) W[i][q] *= LU[i * PDW_NQ + i];
    }
    for (int r = 0; r < PDW_NQ; ++r)
        for (int q = 0; q < ncols; ++q) {
            B[r * ncols + q] = gh * (B[r * ncols + q] + W[r][q]);
            B[(PDW_NQ + r) * ncols + q] = W[r][q];
        }
}

/* One attempt of y from y_n (f_n = f(y_n)) with step h: ynew, the stages in c; the error norm
 * (INFINITY when E is singular). */
static double cv_step_y(cv_ctx *c, const pdw_cvar_opts *o, const double *y_n, const double *f_n,
                        double h, double *ynew)
{
    const pdw_ros_tableau *T = &pdw_tableau_rodas4;
    const int n = c->n;
    if (c->lu_h != h) {
        c->lu_h = 0.0;
        if (cv_factor(c, h)) return INFINITY;
        c->lu_h = h;
    }
    const double ih = 1.0 / h;
    memcpy(c->Y[0], y_n, (size_t)n * sizeof(double));
    memcpy(c->u[0], f_n, (size_t)n * sizeof(double));
    cv_solve(c, c->u[0], n, 1);
    for (int i = 1; i < T->stages; ++i) {
        for (int k = 0; k < n; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->a[i][j] * c->u[j][k];
            c->Y[i][k] = y_n[k] + acc;
        }
        cv_f(c, c->Y[i], c->u[i]);
        for (int k = 0; k < n; ++k) {
            double acc = 0.0;
            for (int j = 0; j < i; ++j) acc += T->C[i][j] * c->u[j][k];
            c->u[i][k] += ih * acc;
        }
        cv_solve(c, c->u[i], n, 1);
    }
    double errv[NMAX];
    for (int k = 0; k < n; ++k) {
        double acc = 0.0, err = 0.0;
        for (int j = 0; j < T->stages; ++j) { acc += T->m[j] * c->u[j][k]; err += T->e[j] * c->u[j][k]; }
        ynew[k] = y_n[k] + acc;
        errv[k] = err;
    }
    return cv_norm(PDW_NX, y_n, ynew, errv, o->rtol, o->atol);
}

static void cv_hermite(int n, const double *x0, const double *f0, const double *x1,
                       const double *f1, double h, double th, double *out);

/* The stage times alpha_i and the sums gamma_i = sum_j gamma_ij of RODAS4's original form
 * (Hairer & Wanner II, Eq. IV.7.1; rodas.f's C_i and D_i) from the transformed tableau: with
 * Gamma^-1 = diag(1/gamma) - C, gamma_i the row sums of Gamma and alpha_i = sum_k a_ik gamma_k. */
static void cv_stage_times(double *alpha, double *gsum)
{
    const pdw_ros_tableau *T = &pdw_tableau_rodas4;
    double Gi[NS][NS] = {{0.0}}, G[NS][NS] = {{0.0}};
    for (int i = 0; i < T->stages; ++i) {
        Gi[i][i] = 1.0 / T->gamma;
        for (int j = 0; j < i; ++j) Gi[i][j] = -T->C[i][j];
    }
    for (int j = 0; j < T->stages; ++j) {
        G[j][j] = T->gamma;
        for (int i = j + 1; i < T->stages; ++i) {
            double acc = 0.0;
            for (int k = j; k < i; ++k) acc += Gi[i][k] * G[k][j];
            G[i][j] = -T->gamma * acc;
        }
    }
    for (int i = 0; i < T->stages; ++i) {
        gsum[i] = 0.0;
        for (int j = 0; j <= i; ++j) gsum[i] += G[i][j];
    }
    for (int i = 0; i < T->stages; ++i) {
        alpha[i] = 0.0;
        for (int k = 0; k < i; ++k) alpha[i] += T->a[i][k] * gsum[k];
    }
    /* rounding: the stiffly accurate last stages sit at alpha = 1 with gamma_i = 0 exactly
     * (rodas.f: C5 = C6 = 1, D5 = D6 = 0); the computed sums are off by ~1e-15 */
    for (int i = 0; i < T->stages; ++i) {
        if (fabs(alpha[i] - 1.0) < 1e-12) alpha[i] = 1.0;
        if (fabs(gsum[i]) < 1e-12) gsum[i] = 0.0;
    }
}

/* Phi over a step [t_n, t_n + h] of y (y_n -> ynew, f_n and fnew their f; E factored for h):
 * RODAS4 on the linear non-autonomous Phi' = A(y(t)) Phi (Eq. IV.7.4' with its f_t term:
 *     E U_i = A(y(t_n + alpha_i h)) P_i + sum_j (C_ij / h) U_j + gamma_i h A_t Phi_n,
 * P_i = Phi_n + sum_j a_ij U_j, A_t = dA[f_n] the time derivative of A along y), y(t) the cubic
 * Hermite interpolant of the step (error O(h^4): order 4 is kept). The stage times 0 and 1
 * reuse A(y_n) and A(ynew) (written to Anew, the next step's): three new Jacobians a step, and
 * A_t from two more. Returns the error norm of Phi; Phinew. n a constant at the call sites
 * (PDW_NX or NMAX), so that the loops unroll. A's and A_t's rows 0..3 are [0, I, 0] and 0,
 * rows 8.. zero: the products need rows 4..7 only. */
static inline double cv_step_phi_n(cv_ctx *c, const pdw_cvar_opts *o, const double *Phi,
                                   double h, const double *y_n, const double *f_n,
                                   const double *ynew, const double *fnew, double *Phinew,
                                   double *Anew, double *Atnew, const int n)
{
    const pdw_ros_tableau *T = &pdw_tableau_rodas4;
    const int nn = n * n;
    double U[NS][NMAX * NMAX], P[NMAX * NMAX], Ai[NMAX * NMAX], D[NMAX * NMAX];
    double AtP[PDW_NQ * NMAX], yi[NMAX];
    const double ih = 1.0 / h;
    int have_new = 0;
    const double *Dn = D;
    if (o->a_hermite) {
        if (!c->at_valid) { cv_dA(c, o, y_n, c->A, f_n, c->At); c->at_valid = 1; }
        Dn = c->At;
        cv_jac(c, ynew, Anew);
        cv_dA(c, o, ynew, Anew, fnew, Atnew);
        have_new = 1;
    } else {
        cv_dA(c, o, y_n, c->A, f_n, D);
    }
    for (int r = 0; r < PDW_NQ; ++r)
        for (int q = 0; q < n; ++q) {
            double acc = 0.0;
            for (int k = 0; k < n; ++k) acc += Dn[(PDW_NQ + r) * n + k] * Phi[k * n + q];
            AtP[r * n + q] = h * acc;
        }
    for (int i = 0; i < T->stages; ++i) {
        double *R = U[i];
        for (int k = 0; k < nn; ++k) { P[k] = Phi[k]; R[k] = 0.0; }
        for (int j = 0; j < i; ++j) {           /* contiguous inner loops: they vectorize */
            const double a = T->a[i][j], cc = ih * T->C[i][j];
            const double *Uj = U[j];
            for (int k = 0; k < nn; ++k) { P[k] += a * Uj[k]; R[k] += cc * Uj[k]; }
        }
        const double *A = c->A;
        const double al = c->alpha[i];
        if (al == 1.0) {
            if (!have_new) { cv_jac(c, ynew, Anew); have_new = 1; }
            A = Anew;
        } else if (al != 0.0 && o->a_hermite) {
            /* A's rows 4..7 from its cubic Hermite interpolant (A, dA/dt at both ends) */
            const double th = al;
            for (int r = PDW_NQ; r < PDW_NX; ++r)
                for (int k = 0; k < n; ++k) {
                    const int e = r * n + k;
                    const double a0 = c->A[e], a1 = Anew[e];
                    Ai[e] = (1.0 - th)*a0 + th*a1
                          + th*(th - 1.0)*((1.0 - 2.0*th)*(a1 - a0) + (th - 1.0)*h*Dn[e]
                                           + th*h*Atnew[e]);
                }
            A = Ai;
        } else if (al != 0.0) {
            cv_hermite(n, y_n, f_n, ynew, fnew, h, al, yi);
            cv_jac(c, yi, Ai);
            A = Ai;
        }
        for (int r = 0; r < PDW_NQ; ++r)
            for (int q = 0; q < n; ++q) R[r * n + q] += P[(PDW_NQ + r) * n + q];
        const double gi = c->gsum[i];
        for (int r = PDW_NQ; r < PDW_NX; ++r) {
            for (int q = 0; q < n; ++q) R[r * n + q] += gi * AtP[(r - PDW_NQ) * n + q];
            for (int k = 0; k < n; ++k) {
                const double a = A[r * n + k];
                for (int q = 0; q < n; ++q) R[r * n + q] += a * P[k * n + q];
            }
        }
        cv_solve(c, R, n, n);
    }
    if (!have_new) cv_jac(c, ynew, Anew);
    double errv[NMAX * NMAX];
    for (int k = 0; k < nn; ++k) { Phinew[k] = Phi[k]; errv[k] = 0.0; }
    for (int j = 0; j < T->stages; ++j) {
        const double mj = T->m[j], ej = T->e[j];
        const double *Uj = U[j];
        for (int k = 0; k < nn; ++k) { Phinew[k] += mj * Uj[k]; errv[k] += ej * Uj[k]; }
    }
    return cv_norm(nn, Phi, Phinew, errv, o->phi_rtol, o->phi_atol);
}

static double cv_step_phi(cv_ctx *c, const pdw_cvar_opts *o, const double *Phi, double h,
                          const double *y_n, const double *f_n, const double *ynew,
                          const double *fnew, double *Phinew, double *Anew, double *Atnew)
{
#define CV_PHI(N_) cv_step_phi_n(c, o, Phi, h, y_n, f_n, ynew, fnew, Phinew, Anew, Atnew, N_)
    switch (c->n) {                 /* n a constant in each: the loops unroll */
    case PDW_NX: return CV_PHI(PDW_NX);
    case PDW_NX + 1: return CV_PHI(PDW_NX + 1);
    case PDW_NX + 2: return CV_PHI(PDW_NX + 2);
    default: return CV_PHI(NMAX);
    }
#undef CV_PHI
}

/* event function k at y (shifted) and, if grad is not NULL, its gradient (n) */
static double cv_event(const pdw_cvar_model *m, const pdw_cvar_event *e, const double *y,
                       double *grad, int n)
{
    const int leg = e->leg, o = 1 - leg;
    const double lr = m->l - m->r, th = y[2 + leg], w = y[6 + leg];
    double g = 1.0;
    if (grad) for (int i = 0; i < n; ++i) grad[i] = 0.0;
    switch (e->kind) {
    case PDW_CVAR_EV_HEIGHT:
        g = y[1] - m->r - lr * cos(th);
        if (grad) { grad[1] = 1.0; grad[2 + leg] = lr * sin(th); }
        break;
    case PDW_CVAR_EV_RATE:
        g = y[5] + (lr * sin(th) + m->r) * w;
        if (grad) { grad[5] = 1.0; grad[2 + leg] = lr * cos(th) * w; grad[6 + leg] = lr * sin(th) + m->r; }
        break;
    case PDW_CVAR_EV_AHEAD:
        g = lr * (sin(th) - sin(y[2 + o]));
        if (grad) { grad[2 + leg] = lr * cos(th); grad[2 + o] = -lr * cos(y[2 + o]); }
        break;
    case PDW_CVAR_EV_THETA:
        g = th;
        if (grad) grad[2 + leg] = 1.0;
        break;
    default:
        return 1.0;
    }
    return g - e->dir * PDW_CVAR_EVENT_SHIFT;
}

static int cv_crossed(const pdw_cvar_event *e, double g0, double g1)
{
    if (e->kind == PDW_CVAR_EV_NONE) return 0;
    const int up = g0 < 0.0 && g1 >= 0.0, down = g0 > 0.0 && g1 <= 0.0;
    return e->dir > 0.0 ? up : e->dir < 0.0 ? down : (up || down);
}

static void cv_hermite(int n, const double *x0, const double *f0, const double *x1,
                       const double *f1, double h, double th, double *out)
{
    for (int i = 0; i < n; ++i)
        out[i] = (1.0 - th)*x0[i] + th*x1[i]
               + th*(th - 1.0)*((1.0 - 2.0*th)*(x1[i] - x0[i]) + (th - 1.0)*h*f0[i] + th*h*f1[i]);
}

/* the crossing of event e on the Hermite extension of [0, h] (g0 at 0, g1 at h of opposite
 * signs): bisection to h * 1e-13 */
static double cv_locate_hermite(const pdw_cvar_model *m, const pdw_cvar_event *e, int n,
                                const double *x0, const double *f0, const double *x1,
                                const double *f1, double h, double g0)
{
    double a = 0.0, b = 1.0, xi[NMAX];
    for (int it = 0; it < 60 && b - a > 1e-13; ++it) {
        const double mid = 0.5 * (a + b);
        cv_hermite(n, x0, f0, x1, f1, h, mid, xi);
        const double g = cv_event(m, e, xi, NULL, n);
        if ((g < 0.0) == (g0 < 0.0) && g != 0.0) a = mid; else b = mid;
    }
    return 0.5 * (a + b) * h;
}

int pdw_cvar_interval(const pdw_cvar_model *m, const pdw_cvar_opts *o, const pdw_cvar_event *ev,
                      int n_ev, double *t, double *y, double *Phi, double *h, int *k_ev,
                      pdw_cvar_stats *st, double *work)
{
    cv_ctx c;
    const int n = PDW_NX + m->na + m->np;
    double f_n[NMAX], ynew[NMAX], fnew[NMAX], ys[NMAX], fs[NMAX], grad[NMAX];
    double Phinew[NMAX * NMAX], Anew[NMAX * NMAX], Atnew[NMAX * NMAX];
    double g_old[PDW_CVAR_MAXEV], g_new[PDW_CVAR_MAXEV];
    int last_rejected = 0;
    c.m = m; c.st = st; c.work = work; c.n = n; c.lu_h = 0.0; c.at_valid = 0;
    cv_stage_times(c.alpha, c.gsum);
    if (n_ev > PDW_CVAR_MAXEV) n_ev = PDW_CVAR_MAXEV;
    cv_f(&c, y, f_n);
    cv_jac(&c, y, c.A);
    for (int k = 0; k < n_ev; ++k) g_old[k] = cv_event(m, &ev[k], y, NULL, n);
    double hh = *h;
    for (;;) {
        if (o->max_steps > 0 && st->n_steps + st->n_rejected >= o->max_steps) return PDW_CVAR_BUDGET;
        const double rem = o->t_max - *t;
        if (!(rem > 0.0)) return PDW_CVAR_T_MAX;
        int last = 0;
        double hs = hh;
        if (hs >= rem) { hs = rem; last = 1; }
        if (!(hs > 8.0 * DBL_EPSILON * fmax(fabs(*t), 1e-3))) return PDW_CVAR_STEP_SIZE;
        double err = cv_step_y(&c, o, y, f_n, hs, ynew);
        int phi_done = 0;
        if (err <= 1.0) cv_f(&c, ynew, fnew);
        if (o->phi_error && err <= 1.0) {
            err = fmax(err, cv_step_phi(&c, o, Phi, hs, y, f_n, ynew, fnew, Phinew, Anew, Atnew));
            phi_done = 1;
        }
        if (!(err <= 1.0)) {
            double fac = 0.2;
            if (isfinite(err)) fac = fmin(1.0, fmax(0.2, 0.9 * pow(err, -0.25)));
            hh = hs * fac;
            st->n_rejected++;
            last_rejected = 1;
            continue;
        }
        double h_next = hs * fmin(6.0, fmax(0.2, 0.9 * pow(fmax(err, 1e-10), -0.25)));
        if (last_rejected) h_next = fmin(h_next, hs);
        last_rejected = 0;
        int kb = -1;
        double sb = INFINITY;
        for (int k = 0; k < n_ev; ++k) {
            g_new[k] = cv_event(m, &ev[k], ynew, NULL, n);
            if (!cv_crossed(&ev[k], g_old[k], g_new[k])) continue;
            const double s = cv_locate_hermite(m, &ev[k], n, y, f_n, ynew, fnew, hs, g_old[k]);
            if (s < sb) { sb = s; kb = k; }
        }
        if (kb >= 0) {
            /* safeguarded Newton on re-steps: g(y(s)) = 0 within the bracket (lo, hi] */
            double lo = 0.0, hi = hs, s = sb, s_done = 0.0;
            const double glo = g_old[kb];
            for (int it = 0; it < 12; ++it) {
                if (!(s > lo && s <= hi)) s = 0.5 * (lo + hi);
                if (!(cv_step_y(&c, o, y, f_n, s, ys) < INFINITY)) return PDW_CVAR_STEP_SIZE;
                s_done = s;
                const double g = cv_event(m, &ev[kb], ys, grad, n);
                if (g == 0.0) break;
                if ((g < 0.0) == (glo < 0.0)) lo = s; else hi = s;
                double gd = 0.0;
                cv_f(&c, ys, fs);
                for (int i = 0; i < n; ++i) gd += grad[i] * fs[i];
                const double ds = -g / gd;
                if (!isfinite(ds)) { s = 0.5 * (lo + hi); continue; }
                if (fabs(ds) <= 4.0 * DBL_EPSILON * fmax(*t + s, 1e-3)) break;
                s += ds;
                if (hi - lo <= 4.0 * DBL_EPSILON * fmax(*t + hi, 1e-3)) { s = hi; }
            }
            /* the factors in c are those of the step of length s_done (the last cv_step_y) */
            s = s_done;
            cv_f(&c, ys, fs);
            cv_step_phi(&c, o, Phi, s, y, f_n, ys, fs, Phinew, Anew, Atnew);
            memcpy(y, ys, (size_t)n * sizeof(double));
            memcpy(Phi, Phinew, (size_t)(n * n) * sizeof(double));
            *t += s;
            *k_ev = kb;
            *h = fmin(h_next, fmax(s, 1e-3 * h_next));
            st->n_steps++;
            return PDW_CVAR_EVENT;
        }
        if (!phi_done) cv_step_phi(&c, o, Phi, hs, y, f_n, ynew, fnew, Phinew, Anew, Atnew);
        memcpy(y, ynew, (size_t)n * sizeof(double));
        memcpy(Phi, Phinew, (size_t)(n * n) * sizeof(double));
        for (int i = 0; i < n; ++i)
            if (!isfinite(y[i])) return PDW_CVAR_STEP_SIZE;
        *t = last ? o->t_max : *t + hs;
        st->n_steps++;
        memcpy(g_old, g_new, sizeof g_old);
        memcpy(f_n, fnew, (size_t)n * sizeof(double));
        memcpy(c.A, Anew, (size_t)(n * n) * sizeof(double));
        if (o->a_hermite) memcpy(c.At, Atnew, (size_t)(n * n) * sizeof(double));
        c.lu_h = 0.0;
        hh = h_next;
        *h = hh;
        if (last) return PDW_CVAR_T_MAX;
    }
}
