/* Small dense solves for the walker's 4x4 systems.
 *
 * The mass matrix (and the central difference matrix M/dt^2 + C/(2 dt)) has a diagonal
 * lower-right 2x2 block: M = [[A, B], [E, D]], D = diag(d0, d1). A Schur complement
 * S = A - B D^-1 E (2x2) solves it in a few dozen flops, with no pivoting search.
 * Row-major 4x4 arrays throughout. */
#ifndef PDW_LINALG_H
#define PDW_LINALG_H

enum { PDW_DBLOCK_NFAC = 6 };  /* fac = [1/d0, 1/d1, Sinv00, Sinv01, Sinv10, Sinv11] */

/* Factor K given id0 = 1/K[10] and id1 = 1/K[15] (a caller that knows them saves the two
 * divisions); returns 0 on success, -1 if K is singular or not finite. */
static inline int pdw_dblock_factor_inv(const double *restrict K, double id0, double id1,
                                        double *restrict fac)
{
    const double s00 = K[0] - K[2]*K[8]*id0 - K[3]*K[12]*id1;
    const double s01 = K[1] - K[2]*K[9]*id0 - K[3]*K[13]*id1;
    const double s10 = K[4] - K[6]*K[8]*id0 - K[7]*K[12]*id1;
    const double s11 = K[5] - K[6]*K[9]*id0 - K[7]*K[13]*id1;
    const double det = s00*s11 - s01*s10;
    const double idet = 1.0 / det;
    fac[0] = id0; fac[1] = id1;
    fac[2] = s11*idet; fac[3] = -s01*idet; fac[4] = -s10*idet; fac[5] = s00*idet;
    return (det != 0.0 && idet == idet && id0 == id0 && id1 == id1) ? 0 : -1;
}

/* Factor K; returns 0 on success, -1 if K is singular or not finite. */
static inline int pdw_dblock_factor(const double *restrict K, double *restrict fac)
{
    return pdw_dblock_factor_inv(K, 1.0 / K[10], 1.0 / K[15], fac);
}

/* Solve K u = b with the factors of pdw_dblock_factor. */
static inline void pdw_dblock_solve(const double *restrict K, const double *restrict fac,
                                    const double *restrict b, double *restrict u)
{
    const double y0 = b[2]*fac[0], y1 = b[3]*fac[1];
    const double r0 = b[0] - K[2]*y0 - K[3]*y1;
    const double r1 = b[1] - K[6]*y0 - K[7]*y1;
    u[0] = fac[2]*r0 + fac[3]*r1;
    u[1] = fac[4]*r0 + fac[5]*r1;
    u[2] = (b[2] - K[8]*u[0] - K[9]*u[1]) * fac[0];
    u[3] = (b[3] - K[12]*u[0] - K[13]*u[1]) * fac[1];
}

/* Factor and solve in one call; returns pdw_dblock_factor's code. */
static inline int pdw_solve_dblock(const double *restrict K, const double *restrict b,
                                   double *restrict u)
{
    double fac[PDW_DBLOCK_NFAC];
    const int rc = pdw_dblock_factor(K, fac);
    pdw_dblock_solve(K, fac, b, u);
    return rc;
}

#endif /* PDW_LINALG_H */
