/* A bare-C central-difference loop: the yardstick of benchmarks/bench_cdm_step.py (issue 23).
 *
 * The paper's walker integrated by the central difference method of docs/model.md section 7
 * (Eqs. 13-17), written the obvious way a user with pdw's generated model functions would write
 * it: sin/cos, the generated kinematics, contact and cdm_terms stages of one kernel, the dense
 * system (M/dt^2 + C/(2dt)) U_{n+1} = Q_f - G + (2/dt^2) M U_n - (M/dt^2 - C/(2dt)) U_{n-1}
 * assembled with full 4x4 loops and solved by Gaussian elimination with partial pivoting, and the
 * contact flags of section 5 (lift-off, arming, touch-down with the anchor captured). No
 * recording, no stop conditions, no state checks, no interruption: what pdw's compiled loop does
 * on top of this is its own cost.
 *
 * Built by the Makefile (`make build/bench/libbare_cdm.so`, part of `make bench`) with pdw's own
 * compile flags (setup.py: -O3 -std=c99 -fno-math-errno), loaded with ctypes. */
#include <math.h>
#include <string.h>
#include "pdw_model.h"

/* Solve the n x n system A u = b (A row-major, overwritten; b overwritten) by Gaussian
 * elimination with partial pivoting. Returns 0, or -1 for a zero pivot. */
static int gauss_solve(int n, double *A, double *b, double *u)
{
    for (int c = 0; c < n; ++c) {
        int piv = c;
        for (int r = c + 1; r < n; ++r)
            if (fabs(A[r*n + c]) > fabs(A[piv*n + c])) piv = r;
        if (A[piv*n + c] == 0.0) return -1;
        if (piv != c) {
            for (int j = 0; j < n; ++j) {
                const double tmp = A[c*n + j]; A[c*n + j] = A[piv*n + j]; A[piv*n + j] = tmp;
            }
            const double tmp = b[c]; b[c] = b[piv]; b[piv] = tmp;
        }
        for (int r = c + 1; r < n; ++r) {
            const double f = A[r*n + c] / A[c*n + c];
            for (int j = c; j < n; ++j) A[r*n + j] -= f * A[c*n + j];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; --r) {
        double s = b[r];
        for (int j = r + 1; j < n; ++j) s -= A[r*n + j] * u[j];
        u[r] = s / A[r*n + r];
    }
    return 0;
}

static void trig_of(const double *x, double *trig)
{
    trig[PDW_TRIG_SIN_THETA1] = sin(x[PDW_X_THETA1]);
    trig[PDW_TRIG_COS_THETA1] = cos(x[PDW_X_THETA1]);
    trig[PDW_TRIG_SIN_THETA2] = sin(x[PDW_X_THETA2]);
    trig[PDW_TRIG_COS_THETA2] = cos(x[PDW_X_THETA2]);
}

/* The flags of section 5 from the kinematics of x: lift-off (Eq. 18a), the scuffing guard's
 * arming, touch-down (Eq. 18b) with the anchor and approach speed captured. Returns 1 when an
 * anchor changed (the kinematics must be recomputed). */
static int update_flags(const double *kin, int *flags, int *armed, double *anchors, int *n_td)
{
    int changed = 0;
    for (int i = 0; i < 2; ++i) {
        const double *ki = kin + i*PDW_NKIN, *kj = kin + (1 - i)*PDW_NKIN;
        const double y = ki[PDW_KIN_Y_D], vy = ki[PDW_KIN_V_Y];
        if (flags[i]) {
            if (y > 0.0 && vy > 0.0) { flags[i] = 0; armed[i] = 0; }
            continue;
        }
        if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) armed[i] = 0;
        else if (y > 0.0) armed[i] = 1;
        if (armed[i] && y < 0.0 && vy < 0.0) {
            flags[i] = 1;
            armed[i] = 0;
            anchors[i] = ki[PDW_KIN_S];
            anchors[PDW_ANCHOR_V_IN1 + i] = -vy;
            ++*n_td;
            changed = 1;
        }
    }
    return changed;
}

/* Run n_steps central-difference steps of kernel `kernel` (an index of pdw_kernels; a kernel
 * with PDW_NX states) from x0 (PDW_NX) with support flags flags0 (2) and the parameter vector p
 * (PDW_NP, after pdw_precompute). Writes the final state to x_out (PDW_NX). Returns the number of
 * touch-downs, or -1 (bad kernel, singular system). */
long bare_cdm_run(int kernel, const double *p, const double *x0, const int *flags0, double dt,
                  long n_steps, double *x_out)
{
    if (kernel < 0 || kernel >= PDW_NKERNELS || pdw_kernels[kernel].nx != PDW_NX) return -1;
    const pdw_kernel *k = &pdw_kernels[kernel];
    double x[PDW_NX], u_prev[PDW_NQ], xdot[PDW_NX], work[PDW_NWORK];
    double trig[4], kin[2*PDW_NKIN], contact[2*PDW_NCONTACT];
    double M[PDW_NQ*PDW_NQ], C[PDW_NQ*PDW_NQ], QmG[PDW_NQ], K[PDW_NQ*PDW_NQ], b[PDW_NQ], u[PDW_NQ];
    double anchors[PDW_NANCHOR] = {0.0};
    int flags[2] = {flags0[0] ? 1 : 0, flags0[1] ? 1 : 0}, armed[2] = {0, 0};
    int n_td = 0;
    memcpy(x, x0, sizeof x);
    /* anchors of the feet in contact at the start */
    trig_of(x, trig);
    k->kinematics(x, trig, p, anchors, kin);
    for (int i = 0; i < 2; ++i) {
        anchors[i] = flags[i] ? kin[i*PDW_NKIN + PDW_KIN_S] : 0.0;
        anchors[PDW_ANCHOR_V_IN1 + i] = flags[i] ? fmax(-kin[i*PDW_NKIN + PDW_KIN_V_Y], 0.0) : 0.0;
    }
    /* flags at x_0, then Eq. 13's start-up: U_-1 = U_0 - dt U'_0 + dt^2/2 U''_0 */
    k->kinematics(x, trig, p, anchors, kin);
    if (update_flags(kin, flags, armed, anchors, &n_td)) k->kinematics(x, trig, p, anchors, kin);
    k->rhs(x, p, flags, anchors, xdot, work);
    for (int i = 0; i < PDW_NQ; ++i)
        u_prev[i] = x[i] - dt*x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];
    for (long n = 0; n < n_steps; ++n) {
        if (n > 0) {
            trig_of(x, trig);
            k->kinematics(x, trig, p, anchors, kin);
            if (update_flags(kin, flags, armed, anchors, &n_td))
                k->kinematics(x, trig, p, anchors, kin);
        }
        k->contact(kin, flags, p, contact);
        k->cdm_terms(x, trig, p, contact, M, C, QmG);
        for (int i = 0; i < PDW_NQ; ++i) {
            double s = QmG[i];
            for (int j = 0; j < PDW_NQ; ++j) {
                const double m = M[i*PDW_NQ + j], c = C[i*PDW_NQ + j];
                K[i*PDW_NQ + j] = m/(dt*dt) + c/(2.0*dt);
                s += 2.0/(dt*dt) * m * x[j] - (m/(dt*dt) - c/(2.0*dt)) * u_prev[j];
            }
            b[i] = s;
        }
        if (gauss_solve(PDW_NQ, K, b, u)) return -1;
        for (int i = 0; i < PDW_NQ; ++i) {
            x[PDW_NQ + i] = (u[i] - u_prev[i]) / (2.0*dt);   /* Eq. 17 */
            u_prev[i] = x[i];
            x[i] = u[i];
        }
    }
    memcpy(x_out, x, sizeof x);
    return n_td;
}
