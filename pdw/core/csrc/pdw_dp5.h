/* The Dormand-Prince 5(4) coefficients of the hybrid integrators (pdw_hybrid_sim.c, and
 * pdw_hybrid_var.c's variational system), by the names of Hairer, Norsett & Wanner's Table
 * II.5.2, read from the one tableau of the project (pdw_tableau_dopri5, pdw_tableaus.c: data,
 * checked by tests/test_integrators.py), not written out again. The same values in the same
 * expressions as before: the hybrid results are bitwise unchanged. */
#ifndef PDW_DP5_H
#define PDW_DP5_H

#include "pdw_tableaus.h"

#define PDW_DP5(i, j) (pdw_tableau_dopri5.a[(i) - 1][(j) - 1])
#define A21 PDW_DP5(2, 1)
#define A31 PDW_DP5(3, 1)
#define A32 PDW_DP5(3, 2)
#define A41 PDW_DP5(4, 1)
#define A42 PDW_DP5(4, 2)
#define A43 PDW_DP5(4, 3)
#define A51 PDW_DP5(5, 1)
#define A52 PDW_DP5(5, 2)
#define A53 PDW_DP5(5, 3)
#define A54 PDW_DP5(5, 4)
#define A61 PDW_DP5(6, 1)
#define A62 PDW_DP5(6, 2)
#define A63 PDW_DP5(6, 3)
#define A64 PDW_DP5(6, 4)
#define A65 PDW_DP5(6, 5)
#define B1 (pdw_tableau_dopri5.b[0])
#define B3 (pdw_tableau_dopri5.b[2])
#define B4 (pdw_tableau_dopri5.b[3])
#define B5 (pdw_tableau_dopri5.b[4])
#define B6 (pdw_tableau_dopri5.b[5])
#define E1 (pdw_tableau_dopri5.e[0])
#define E3 (pdw_tableau_dopri5.e[2])
#define E4 (pdw_tableau_dopri5.e[3])
#define E5 (pdw_tableau_dopri5.e[4])
#define E6 (pdw_tableau_dopri5.e[5])
#define E7 (pdw_tableau_dopri5.e[6])

#endif
