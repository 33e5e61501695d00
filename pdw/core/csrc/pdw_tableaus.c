/* Coefficients of the explicit and Rosenbrock methods (see pdw_tableaus.h for the forms). */
#include "pdw_tableaus.h"

/* Classical fourth-order Runge-Kutta (Kutta 1901; Hairer, Norsett & Wanner, Solving ODEs I,
 * Table II.1.2, "the" Runge-Kutta method). */
const pdw_rk_tableau pdw_tableau_rk4 = {
    "rk4", 4, 4, 0, 0,
    {0.0, 0.5, 0.5, 1.0},
    {{0.0}, {0.5}, {0.0, 0.5}, {0.0, 0.0, 1.0}},
    {1.0/6.0, 1.0/3.0, 1.0/3.0, 1.0/6.0},
    {0.0},
};

/* Dormand & Prince (1980), "A family of embedded Runge-Kutta formulae", J. Comp. Appl. Math. 6;
 * Hairer, Norsett & Wanner, Solving ODEs I, Table II.5.2 (DOPRI5): order 5 with an embedded
 * order-4 solution, FSAL. e = b - bhat. */
const pdw_rk_tableau pdw_tableau_dopri5 = {
    "dopri5", 7, 5, 4, 1,
    {0.0, 1.0/5.0, 3.0/10.0, 4.0/5.0, 8.0/9.0, 1.0, 1.0},
    {
        {0.0},
        {1.0/5.0},
        {3.0/40.0, 9.0/40.0},
        {44.0/45.0, -56.0/15.0, 32.0/9.0},
        {19372.0/6561.0, -25360.0/2187.0, 64448.0/6561.0, -212.0/729.0},
        {9017.0/3168.0, -355.0/33.0, 46732.0/5247.0, 49.0/176.0, -5103.0/18656.0},
        {35.0/384.0, 0.0, 500.0/1113.0, 125.0/192.0, -2187.0/6784.0, 11.0/84.0},
    },
    {35.0/384.0, 0.0, 500.0/1113.0, 125.0/192.0, -2187.0/6784.0, 11.0/84.0, 0.0},
    {71.0/57600.0, 0.0, -71.0/16695.0, 71.0/1920.0, -17253.0/339200.0, 22.0/525.0, -1.0/40.0},
};

/* RODAS4 (Hairer & Wanner, Solving ODEs II, Sec. VI.4, "RODAS", METH=1 of the
 * authors' code rodas.f): 6 stages, order 4, embedded order 3, stiffly accurate and L-stable.
 * In the transformed form the solution is the point where stage 6 would be evaluated plus u_6:
 *   x_new = x + a61..a64 u + u_5 + u_6   (a6j = a5j, a65 = 1), error = u_6.               */
#define A51 1.221224509226641
#define A52 6.019134481288629
#define A53 12.53708332932087
#define A54 (-0.6878860361058950)
const pdw_ros_tableau pdw_tableau_rodas4 = {
    "rodas4", 6, 4, 3, 0.25,
    {
        {0.0},
        {1.544000000000000},
        {0.9466785280815826, 0.2557011698983284},
        {3.314825187068521, 2.896124015972201, 0.9986419139977817},
        {A51, A52, A53, A54},
        {A51, A52, A53, A54, 1.0},
    },
    {
        {0.0},
        {-5.668800000000000},
        {-2.430093356833875, -0.2063599157091915},
        {-0.1073529058151375, -9.594562251023355, -20.47028614809616},
        {7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160},
        {8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136,
         -6.058818238834054},
    },
    {A51, A52, A53, A54, 1.0, 1.0},
    {0.0, 0.0, 0.0, 0.0, 0.0, 1.0},
};
#undef A51
#undef A52
#undef A53
#undef A54
