/* Micro-benchmark loops, timed in C so that no Python overhead is measured. */
#define _POSIX_C_SOURCE 199309L
#include <time.h>
#include "pdw_bench.h"

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e9 * (double)ts.tv_sec + (double)ts.tv_nsec;
}

double pdw_bench_rhs(const pdw_kernel *k, const double *x0, const double *p, const int *flags,
                     const double *anchors, long n, double *work, double *sink)
{
    double x[PDW_NX], xdot[PDW_NX], acc = 0.0;
    for (int i = 0; i < PDW_NX; ++i) x[i] = x0[i];
    const double t0 = now_ns();
    for (long it = 0; it < n; ++it) {
        k->rhs(x, p, flags, anchors, xdot, work);
        acc += xdot[PDW_NX - 1];
        x[PDW_X_THETAD1] += 1e-12 * xdot[PDW_X_THETAD2];  /* a dependency between iterations */
    }
    const double t1 = now_ns();
    *sink = acc;
    return (t1 - t0) / (double)n;
}

double pdw_bench_jacobian(const pdw_kernel *k, const double *x0, const double *p, const int *flags,
                          const double *anchors, long n, double *work, double *sink)
{
    double x[PDW_NX], J[PDW_NX*PDW_NX], acc = 0.0;
    for (int i = 0; i < PDW_NX; ++i) x[i] = x0[i];
    const double t0 = now_ns();
    for (long it = 0; it < n; ++it) {
        k->jacobian(x, p, flags, anchors, J, work);
        acc += J[PDW_NX*PDW_NX - 1];
        x[PDW_X_THETAD1] += 1e-12 * J[PDW_NX*PDW_NX - 2];
    }
    const double t1 = now_ns();
    *sink = acc;
    return (t1 - t0) / (double)n;
}
