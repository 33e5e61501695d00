/* The sin/cos of a block of lanes in one loop each, vectorized through glibc's libmvec.
 *
 * glibc declares its vector variants (_ZGV*_sin, _ZGV*_cos) only under -ffast-math, which pdw
 * does not use; the `declare simd` below is that declaration, nothing else: the vector
 * routines are called with exactly these arguments. Compiled with -fopenmp-simd (no OpenMP
 * runtime). At the default x86-64 baseline (SSE2) GCC calls the 2-lane _ZGVbN2v_sin/cos;
 * PDW_CFLAGS=-mavx2 gives the 4-lane _ZGVdN4v_*. sin and cos are in separate loops: in one
 * loop GCC fuses them into sincos, which has no vector variant it can call. libmvec's results
 * are within 4 ulp of the correctly rounded ones, not bitwise libm's (docs/ensemble.md). */
#include <math.h>
#include "pdw_batch.h"

#pragma omp declare simd notinbranch
double sin(double);
#pragma omp declare simd notinbranch
double cos(double);

static void vsin(int n, const double *restrict a, double *restrict s)
{
#pragma omp simd
    for (int i = 0; i < n; ++i) s[i] = sin(a[i]);
}

static void vcos(int n, const double *restrict a, double *restrict c)
{
#pragma omp simd
    for (int i = 0; i < n; ++i) c[i] = cos(a[i]);
}

void pdw_batch_sincos(int n, const double *a, double *s, double *c)
{
    vsin(n, a, s);
    vcos(n, a, c);
}
