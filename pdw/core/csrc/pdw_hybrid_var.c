/* Exact derivative of the hybrid walker's step map (continuation, Floquet multipliers).
 *
 * The step map y+ = P(y0) of pdw_hybrid_step is Delta(phi_T(y0)(y0)): the stance flow phi up
 * to the heel-strike time T(y0), at which the swing foot's height g(y) = y_sw vanishes, then
 * the impact-and-relabel map Delta. Its Jacobian (4x4) is
 *
 *     DP = DDelta(y-) S Phi(T),   S = I - f(y-) grad g(y-)^T / (grad g(y-) . f(y-)),
 *
 * with Phi(T) the solution of the variational equations Phi' = A(y(t)) Phi, Phi(0) = I,
 * A = d ydot / d y, and S the saltation matrix of the state-dependent event (the derivative
 * of the strike time, dT/dy0 = -grad g Phi / (grad g . f)). A, grad g and the data of DDelta
 * are emitted by derive/hybrid.py (pdw_hybrid_stance_jac_terms, pdw_hybrid_swing_foot_grad,
 * pdw_hybrid_impact_jac_terms). DDelta differentiates the impact's KKT system
 * K(q) s = b(q, qd-), s = (qd+, Lambda): ds = K^{-1} (db - dK s).
 *
 * The augmented system (y, Phi) (20 components) is integrated by the same Dormand-Prince 5(4)
 * as the step map, with error control on all components, from 0 to the strike time located
 * by pdw_hybrid_step (so the event is the step map's own, to event_tol). Nothing allocates. */
#include <math.h>
#include <string.h>
#include "pdw_hybrid_sim.h"
#include "pdw_dp5.h"

#define NY 4
#define NA 20

/* ydot (4) and A = d ydot / d y (4x4 row-major); returns -1 on a singular M_r */
int pdw_hybrid_rhs_jac(const double *y, const double *p, double *ydot, double *A)
{
    double Mr[4], fr[2], dMf[16];
    pdw_hybrid_stance(y, p, Mr, fr);
    const double det = Mr[0]*Mr[3] - Mr[1]*Mr[2];
    if (!(det != 0.0) || !isfinite(det)) return -1;
    const double pdd0 = (Mr[3]*fr[0] - Mr[1]*fr[1]) / det;
    const double pdd1 = (Mr[0]*fr[1] - Mr[2]*fr[0]) / det;
    ydot[0] = y[PDW_HY_THETAD_ST];
    ydot[1] = y[PDW_HY_THETAD_SW];
    ydot[2] = pdd0;
    ydot[3] = pdd1;
    pdw_hybrid_stance_jac_terms(y, p, dMf);
    memset(A, 0, 16*sizeof(double));
    A[0*4 + 2] = 1.0;
    A[1*4 + 3] = 1.0;
    for (int k = 0; k < 4; ++k) {
        double r0 = dMf[8 + k], r1 = dMf[12 + k];
        if (k < 2) {
            const double *dM = dMf + 4*k;
            r0 -= dM[0]*pdd0 + dM[1]*pdd1;
            r1 -= dM[2]*pdd0 + dM[3]*pdd1;
        }
        A[2*4 + k] = (Mr[3]*r0 - Mr[1]*r1) / det;
        A[3*4 + k] = (Mr[0]*r1 - Mr[2]*r0) / det;
    }
    return 0;
}

/* derivative (4x4 row-major) of the impact-and-relabel map y- -> y+ at y- */
int pdw_hybrid_impact_jac(const double *p, const double *ym, double *D)
{
    double x[PDW_NX], MJ[32], dK[64], K[36], rhs[6], sol[6], Kc[36], ds[6];
    pdw_hybrid_full_state(ym, p, x);
    pdw_hybrid_impact_terms(x, p, MJ);
    pdw_hybrid_impact_jac_terms(ym, p, dK);
    const double *M = MJ, *J2 = MJ + 24, *qdm = x + PDW_NQ, *dqd = dK + 48;
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
    memcpy(Kc, K, sizeof K);
    if (pdw_hybrid_solve(6, Kc, rhs, sol)) return PDW_HYBRID_SINGULAR;
    for (int k = 0; k < 4; ++k) {
        /* db/dy_k - dK/dy_k s; dK nonzero only for the angles (k < 2) */
        double b[6];
        for (int i = 0; i < 4; ++i) {
            double s = 0.0;
            for (int j = 0; j < 4; ++j) s += M[i*4 + j]*dqd[j*4 + k];
            b[i] = s;
        }
        b[4] = b[5] = 0.0;
        if (k < 2) {
            const double *dM = dK + 16*k, *dJ = dK + 32 + 8*k;
            for (int i = 0; i < 4; ++i) {
                double s = 0.0;
                for (int j = 0; j < 4; ++j) s += dM[i*4 + j]*(qdm[j] - sol[j]);
                for (int a = 0; a < 2; ++a) s += dJ[a*4 + i]*sol[4 + a];
                b[i] += s;
            }
            for (int a = 0; a < 2; ++a) {
                double s = 0.0;
                for (int j = 0; j < 4; ++j) s += dJ[a*4 + j]*sol[j];
                b[4 + a] = -s;
            }
        }
        memcpy(Kc, K, sizeof K);
        if (pdw_hybrid_solve(6, Kc, b, ds)) return PDW_HYBRID_SINGULAR;
        /* y+ = (ym_sw, ym_st, qd+_theta2, qd+_theta1) */
        D[0*4 + k] = (k == PDW_HY_THETA_SW);
        D[1*4 + k] = (k == PDW_HY_THETA_ST);
        D[2*4 + k] = ds[PDW_X_THETA2];
        D[3*4 + k] = ds[PDW_X_THETA1];
    }
    return PDW_HYBRID_OK;
}

/* ---- the augmented system ----------------------------------------------------------------- */

/* d/dt (y, Phi) = (f(y), A(y) Phi), Phi 4x4 row-major after y */
static int faug(const double *p, const double *u, double *du)
{
    double A[16];
    if (pdw_hybrid_rhs_jac(u, p, du, A)) return -1;
    const double *Phi = u + NY;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += A[i*4 + k]*Phi[k*4 + j];
            du[NY + i*4 + j] = s;
        }
    return 0;
}

static int dopri_aug(const double *p, const double *u, const double *k1, double h, double *un,
                     double *k7, double *err)
{
    double k2[NA], k3[NA], k4[NA], k5[NA], k6[NA], t[NA];
    int bad = 0;
    for (int i = 0; i < NA; ++i) t[i] = u[i] + h*A21*k1[i];
    bad |= faug(p, t, k2);
    for (int i = 0; i < NA; ++i) t[i] = u[i] + h*(A31*k1[i] + A32*k2[i]);
    bad |= faug(p, t, k3);
    for (int i = 0; i < NA; ++i) t[i] = u[i] + h*(A41*k1[i] + A42*k2[i] + A43*k3[i]);
    bad |= faug(p, t, k4);
    for (int i = 0; i < NA; ++i)
        t[i] = u[i] + h*(A51*k1[i] + A52*k2[i] + A53*k3[i] + A54*k4[i]);
    bad |= faug(p, t, k5);
    for (int i = 0; i < NA; ++i)
        t[i] = u[i] + h*(A61*k1[i] + A62*k2[i] + A63*k3[i] + A64*k4[i] + A65*k5[i]);
    bad |= faug(p, t, k6);
    for (int i = 0; i < NA; ++i)
        un[i] = u[i] + h*(B1*k1[i] + B3*k3[i] + B4*k4[i] + B5*k5[i] + B6*k6[i]);
    bad |= faug(p, un, k7);
    for (int i = 0; i < NA; ++i)
        err[i] = h*(E1*k1[i] + E3*k3[i] + E4*k4[i] + E5*k5[i] + E6*k6[i] + E7*k7[i]);
    return bad;
}

int pdw_hybrid_step_jac(const double *p, const double *y0, const pdw_hybrid_opts *o,
                        pdw_hybrid_result *r, double *DP)
{
    return pdw_hybrid_step_sens(p, y0, o, r, DP, NULL, NULL, NULL, NULL);
}

int pdw_hybrid_step_sens(const double *p, const double *y0, const pdw_hybrid_opts *o,
                         pdw_hybrid_result *r, double *DP, double *dym_dy0, double *dym_ddh,
                         double *dT_dy0, double *dT_ddh)
{
    double u[NA], k1[NA], un[NA], k7[NA], err[NA];
    if (o->ground) return PDW_HYBRID_SINGULAR;
    pdw_hybrid_step(p, y0, 0.0, 0.0, o, r, NULL, NULL, 0);
    if (r->status != PDW_HYBRID_OK) return r->status;
    const double T = r->t_strike;
    memcpy(u, y0, NY*sizeof(double));
    memset(u + NY, 0, 16*sizeof(double));
    for (int i = 0; i < 4; ++i) u[NY + 5*i] = 1.0;
    if (faug(p, u, k1)) return PDW_HYBRID_SINGULAR;
    double t = 0.0, h = o->h0 > 0.0 ? o->h0 : 1e-3;
    long n = 0;
    int reject = 0;
    while (t < T) {
        if (++n > o->max_steps) return PDW_HYBRID_MAX_STEPS;
        if (h > o->h_max) h = o->h_max;
        int last = 0;
        if (t + h >= T) { h = T - t; last = 1; }
        if (dopri_aug(p, u, k1, h, un, k7, err)) return PDW_HYBRID_SINGULAR;
        double en = 0.0;
        for (int i = 0; i < NA; ++i) {
            const double sc = o->atol + o->rtol*fmax(fabs(u[i]), fabs(un[i]));
            en += (err[i]/sc)*(err[i]/sc);
        }
        en = sqrt(en / NA);
        if (!isfinite(en)) return PDW_HYBRID_NONFINITE;
        if (en > 1.0) {
            h *= fmax(0.2, 0.9*pow(en, -0.2));
            reject = 1;
            if (h < 1e-14) return PDW_HYBRID_STEP_TINY;
            continue;
        }
        t = last ? T : t + h;
        memcpy(u, un, sizeof u);
        memcpy(k1, k7, sizeof k1);
        double fac = en > 0.0 ? 0.9*pow(en, -0.2) : 5.0;
        fac = fmin(5.0, fmax(0.2, fac));
        if (reject) fac = fmin(fac, 1.0);
        reject = 0;
        h *= fac;
    }
    /* saltation at the strike, evaluated at the step map's own pre-impact state */
    double f[NY], A[16], g[NY], S[16], SPhi[16], D[16];
    if (pdw_hybrid_rhs_jac(r->y_minus, p, f, A)) return PDW_HYBRID_SINGULAR;
    pdw_hybrid_swing_foot_grad(r->y_minus, p, g);
    double gf = 0.0;
    for (int i = 0; i < NY; ++i) gf += g[i]*f[i];
    if (!(fabs(gf) > 0.0)) return PDW_HYBRID_SINGULAR;   /* grazing strike */
    for (int i = 0; i < NY; ++i)
        for (int j = 0; j < NY; ++j) S[i*4 + j] = (i == j) - f[i]*g[j]/gf;
    const double *Phi = u + NY;
    for (int i = 0; i < NY; ++i)
        for (int j = 0; j < NY; ++j) {
            double s = 0.0;
            for (int k = 0; k < NY; ++k) s += S[i*4 + k]*Phi[k*4 + j];
            SPhi[i*4 + j] = s;
        }
    /* the event g(y) - dh = 0 (o->dh a constant): dT = (d dh - grad g Phi dy0) / (grad g . f),
     * dy- = Phi dy0 + f dT */
    if (dym_dy0) memcpy(dym_dy0, SPhi, sizeof SPhi);
    if (dym_ddh) for (int i = 0; i < NY; ++i) dym_ddh[i] = f[i] / gf;
    if (dT_ddh) *dT_ddh = 1.0 / gf;
    if (dT_dy0)
        for (int j = 0; j < NY; ++j) {
            double s = 0.0;
            for (int k = 0; k < NY; ++k) s += g[k]*Phi[k*4 + j];
            dT_dy0[j] = -s / gf;
        }
    if (pdw_hybrid_impact_jac(p, r->y_minus, D)) return PDW_HYBRID_SINGULAR;
    for (int i = 0; i < NY; ++i)
        for (int j = 0; j < NY; ++j) {
            double s = 0.0;
            for (int k = 0; k < NY; ++k) s += D[i*4 + k]*SPhi[k*4 + j];
            DP[i*4 + j] = s;
        }
    return PDW_HYBRID_OK;
}
