/* The Jacobian df/dx of x' = f(x) = [qd, qdd] from the partials of the dynamics (Eq. A.4):
 * M qdd = F(x), so dqdd/dx = M^-1 A with A = dF/dx (PDW_NQ x PDW_NX, row-major). One routine
 * for every generated kernel's composed Jacobian (derive/emit.py) and the shaped-ground kernel
 * (pdw_terrain.c). Caller-allocated arrays; nothing allocates. */
#ifndef PDW_JACOBIAN_H
#define PDW_JACOBIAN_H

#include "pdw_model.h"
#include "pdw_linalg.h"

/* J (PDW_NX x PDW_NX, row-major) = [[0, I], [M^-1 A]] for the mass matrix M (PDW_NQ x PDW_NQ,
 * the diagonal-block form of pdw_linalg.h) and A (PDW_NQ x PDW_NX). */
static inline void pdw_jacobian_from_dynamics(const double *restrict M, const double *restrict A,
                                              double *restrict J)
{
    double col[PDW_NQ], sol[PDW_NQ], fac[PDW_DBLOCK_NFAC];
    pdw_dblock_factor(M, fac);
    for (int i = 0; i < PDW_NX*PDW_NX; ++i) J[i] = 0.0;
    for (int i = 0; i < PDW_NQ; ++i) J[i*PDW_NX + PDW_NQ + i] = 1.0;
    for (int j = 0; j < PDW_NX; ++j) {
        for (int i = 0; i < PDW_NQ; ++i) col[i] = A[i*PDW_NX + j];
        pdw_dblock_solve(M, fac, col, sol);
        for (int i = 0; i < PDW_NQ; ++i) J[(PDW_NQ + i)*PDW_NX + j] = sol[i];
    }
}

#endif /* PDW_JACOBIAN_H */
