/* Dense LU factorisation with partial (row) pivoting for the small n x n systems of the
 * linearly implicit methods (n = PDW_NX = 8: the Rosenbrock matrix I/(gamma h) - J).
 * Row-major arrays; the factors overwrite A: the unit lower L below the diagonal, U above it,
 * and on the diagonal the reciprocals 1/U_kk (the solves multiply: no division chain).
 * Allocation-free, static inline (n a compile-time constant at the call sites, so the loops
 * unroll): the loops factor once per step and solve once per stage. */
#ifndef PDW_LU_H
#define PDW_LU_H

#include <math.h>

/* Factor A (n x n, row-major) in place as P A = L U; piv[k] = row swapped with row k.
 * Returns 0, or -1 if a pivot is exactly zero or not finite (A singular to working precision). */
static inline int pdw_lu_factor(int n, double *restrict A, int *restrict piv)
{
    for (int k = 0; k < n; ++k) {
        int p = k;
        double amax = fabs(A[k*n + k]);
        for (int i = k + 1; i < n; ++i) {
            const double a = fabs(A[i*n + k]);
            if (a > amax) { amax = a; p = i; }
        }
        piv[k] = p;
        if (!(amax > 0.0) || !isfinite(amax)) return -1;
        if (p != k) {
            for (int j = 0; j < n; ++j) {
                const double tmp = A[k*n + j]; A[k*n + j] = A[p*n + j]; A[p*n + j] = tmp;
            }
        }
        const double inv = 1.0 / A[k*n + k];
        A[k*n + k] = inv;
        for (int i = k + 1; i < n; ++i) {
            const double l = A[i*n + k] * inv;
            A[i*n + k] = l;
            for (int j = k + 1; j < n; ++j) A[i*n + j] -= l * A[k*n + j];
        }
    }
    return 0;
}

/* Solve A x = b in place (b becomes x) with the factors of pdw_lu_factor. */
static inline void pdw_lu_solve(int n, const double *restrict LU, const int *restrict piv,
                                double *restrict b)
{
    for (int k = 0; k < n; ++k) {
        if (piv[k] != k) { const double tmp = b[k]; b[k] = b[piv[k]]; b[piv[k]] = tmp; }
    }
    for (int i = 1; i < n; ++i) {
        double s = b[i];
        for (int j = 0; j < i; ++j) s -= LU[i*n + j] * b[j];
        b[i] = s;
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = b[i];
        for (int j = i + 1; j < n; ++j) s -= LU[i*n + j] * b[j];
        b[i] = s * LU[i*n + i];
    }
}

#endif /* PDW_LU_H */
