/* The continuous walker's variational equations, compiled (issue #24; the driver with the flag
 * logic and the saltation matrices is pdw/analysis/stepmap/variational.py).
 *
 * pdw_cvar_interval integrates y' = f(y) (the kernel's f with the support flags held fixed; with
 * approach speeds the state is y = (x, v_in1, v_in2), v_in' = 0) together with its fundamental
 * matrix Phi' = A(y) Phi (A = df/dy) by RODAS4 (pdw_tableau_rodas4) applied to the augmented
 * system, from t until the first crossing of one of a list of event functions, located to
 * rounding and reached by a last step that ends on it. With np = 1 the state carries one
 * parameter mu last (mu' = 0, its column of A a difference of f between two parameter
 * vectors): Phi's last column is then the step's sensitivity to mu. Nothing allocates; the
 * caller gives every array. */
#ifndef PDW_CVAR_H
#define PDW_CVAR_H

#include "pdw_model.h"

/* event functions of the state (legs 0 and 1; l, r of pdw_cvar_model; th = theta_leg,
 * w = thetadot_leg; each shifted by -dir * PDW_CVAR_EVENT_SHIFT as variational.py's) */
enum {
    PDW_CVAR_EV_NONE = 0,       /* never crosses */
    PDW_CVAR_EV_HEIGHT = 1,     /* foot height y_o - r - (l - r) cos th [m] */
    PDW_CVAR_EV_RATE = 2,       /* normal rate ydot_o + ((l - r) sin th + r) w [m/s] */
    PDW_CVAR_EV_AHEAD = 3,      /* (l - r)(sin th - sin th_other): the foot ahead of the other [m] */
    PDW_CVAR_EV_THETA = 4       /* th [rad] (Eq. 11's gate) */
};
enum { PDW_CVAR_MAXEV = 8, PDW_CVAR_NA = 2, PDW_CVAR_NMAX = PDW_NX + PDW_CVAR_NA + 1 };
#define PDW_CVAR_EVENT_SHIFT 1e-14

/* returns of pdw_cvar_interval */
enum {
    PDW_CVAR_EVENT = 0,         /* an event: *k_ev its index, y and Phi at its time t */
    PDW_CVAR_T_MAX = 1,         /* t_max reached without an event */
    PDW_CVAR_STEP_SIZE = -1,    /* the step size fell below rounding (or the state is not finite) */
    PDW_CVAR_BUDGET = -2        /* max_steps steps (accepted + rejected) */
};

typedef struct pdw_cvar_event {
    int kind;                   /* PDW_CVAR_EV_* */
    int leg;                    /* 0 or 1 */
    double dir;                 /* +1: upward crossings only, -1: downward, 0: both */
} pdw_cvar_event;

typedef struct pdw_cvar_model {
    const pdw_kernel *kernel;   /* a Coulomb-friction kernel (nx = PDW_NX) */
    const double *p;            /* its parameter vector (PDW_NP) */
    int flags[2];               /* support flags, held fixed */
    double anchors[PDW_NANCHOR];/* anchors; the approach speeds are taken from y when na = 2 */
    int na;                     /* 0, or 2: y carries (v_in1, v_in2) after x */
    double l, r;                /* leg length and foot radius [m] (the event functions) */
    int np;                     /* 0, or 1: y carries a parameter mu last (mu' = 0), whose
                                 * column of A, df/dmu = (f(y; p_plus) - f(y; p_minus)) / dmu,
                                 * is the central difference of f between the parameter
                                 * vectors at mu +- dmu / 2 (f itself reads p): Phi's column
                                 * of mu is the step's sensitivity to the parameter */
    const double *p_plus, *p_minus;
    double dmu;
} pdw_cvar_model;

typedef struct pdw_cvar_opts {
    double rtol, atol;          /* error control of y */
    double phi_rtol, phi_atol;  /* error control of Phi (with phi_error) */
    double t_max;               /* end of the search [s] */
    double dir_step;            /* largest state change of the difference quotient of A along
                                 * a stage increment (the directional derivative dA[u]) */
    int phi_error;              /* 1: Phi's error estimate controls the step too */
    int a_hermite;              /* 1: A at the inner stage times from its cubic Hermite
                                 * interpolant (A and dA/dt at the step's ends) instead of the
                                 * Jacobian at y's interpolant: 3 Jacobians a step, not 6 */
    int one_sided;              /* 1: dA[u] by a forward difference from A(y_n) (half the
                                 * Jacobians of the central one) */
    long max_steps;
} pdw_cvar_opts;

typedef struct pdw_cvar_stats {
    long n_steps, n_rejected, n_rhs, n_jac;
} pdw_cvar_stats;

/* From (t, y, Phi) (n = PDW_NX + na + np; Phi n x n row-major) to the first crossing of events
 * ev[0 .. n_ev) (ties: the lowest index). h: the first trial step on entry, the next step on
 * return. work: PDW_NWORK doubles. Returns PDW_CVAR_*. */
int pdw_cvar_interval(const pdw_cvar_model *m, const pdw_cvar_opts *o, const pdw_cvar_event *ev,
                      int n_ev, double *t, double *y, double *Phi, double *h, int *k_ev,
                      pdw_cvar_stats *st, double *work);

#endif /* PDW_CVAR_H */
