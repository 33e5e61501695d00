#ifndef PDW_BENCH_H
#define PDW_BENCH_H
#include "pdw_model.h"
/* Mean nanoseconds per evaluation over n calls (the work array is the caller's). */
double pdw_bench_rhs(const pdw_kernel *k, const double *x0, const double *p, const int *flags,
                     const double *anchors, long n, double *work, double *sink);
double pdw_bench_jacobian(const pdw_kernel *k, const double *x0, const double *p, const int *flags,
                          const double *anchors, long n, double *work, double *sink);
#endif
