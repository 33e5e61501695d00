/* Coefficient tables of the Runge-Kutta and Rosenbrock methods, as data (pdw_tableaus.c).
 * One source of truth: the C loops use these structs and pdw/core/_core.pyx exposes them to Python
 * (pdw.core._core.rk_tableau / ros_tableau) so that the tests check the order conditions on the very
 * numbers the loops use. */
#ifndef PDW_TABLEAUS_H
#define PDW_TABLEAUS_H

enum { PDW_RK_MAXSTAGES = 7, PDW_ROS_MAXSTAGES = 6 };

/* Explicit Runge-Kutta (Butcher) tableau: stage i evaluates f at x + h sum_{j<i} a[i][j] k_j
 * (time t + c[i] h); the solution is x + h sum b[i] k_i; the embedded error estimate is
 * h sum e[i] k_i (e = b - bhat; all zero for a method without one). fsal: the last stage is
 * evaluated at the new solution (its f is the next step's first stage). */
typedef struct pdw_rk_tableau {
    const char *name;
    int stages;
    int order;              /* order of b */
    int embedded_order;     /* order of bhat (0: none) */
    int fsal;
    double c[PDW_RK_MAXSTAGES];
    double a[PDW_RK_MAXSTAGES][PDW_RK_MAXSTAGES];
    double b[PDW_RK_MAXSTAGES];
    double e[PDW_RK_MAXSTAGES];
} pdw_rk_tableau;

/* Rosenbrock method in the form of Hairer & Wanner (Solving ODEs II, Sec. IV.7, Eq. 7.4'),
 * autonomous case: with E = I/(gamma h) - J,
 *     E u_i = f(x + sum_{j<i} a[i][j] u_j) + sum_{j<i} (C[i][j]/h) u_j,
 *     x_new = x + sum m[i] u_i,   error estimate = sum e[i] u_i.                         */
typedef struct pdw_ros_tableau {
    const char *name;
    int stages;
    int order;
    int embedded_order;
    double gamma;
    double a[PDW_ROS_MAXSTAGES][PDW_ROS_MAXSTAGES];
    double C[PDW_ROS_MAXSTAGES][PDW_ROS_MAXSTAGES];
    double m[PDW_ROS_MAXSTAGES];
    double e[PDW_ROS_MAXSTAGES];
} pdw_ros_tableau;

extern const pdw_rk_tableau pdw_tableau_rk4;
extern const pdw_rk_tableau pdw_tableau_dopri5;
extern const pdw_ros_tableau pdw_tableau_rodas4;

#endif /* PDW_TABLEAUS_H */
